// Chapter 5: the FCLIB reader never crashes on damaged files (issue 11, whose reproductions are in
// /work/shared/data/bad-inputs/README.md), as the OBJ reader's ObjReader.NeverCrashesOnGarbage
// does for OBJ files.
//
// Valid FCLIB files are written here with the HDF5 C API (a local problem in compressed rows with
// info strings and a guess, a local problem in triplets with compressed chunked datasets, a global
// problem with M in compressed columns and H in triplets), then damaged with seeded random edits:
// bytes flipped at random offsets, the file truncated, and datasets rewritten through HDF5 with
// other lengths, other types and extreme values (NaN, ±inf, 1e308, ±2³¹, negative indices),
// replaced by strings or groups, deleted, turned into soft or external links, or given
// attributes. Every read must either succeed with a consistent result (a local problem that
// validate() accepts, a global problem whose sizes agree) or throw grbd::Error: no crash, no other
// exception, nothing printed by HDF5, each read quick, and no HDF5 object left open.
//
// HDF5 1.10.8 itself loses a few blocks of its free lists on the error paths of some damaged
// object headers (H5Oopen of a header whose address points into other metadata: "ring type
// mismatch occurred for cache entry", "actual len exceeds EOA"); it says so at exit ("HDF5:
// infinite loop closing library ... FL,FL,...") and LeakSanitizer reports the blocks. The original
// reader does the same on these files, and no reader can avoid it short of not opening the object.
// So in sanitizer builds this test's allocations are exempt from leak checking (HDF5's free lists
// emptied first, so that no block from another test is reused); every other FCLIB test runs under
// LeakSanitizer as usual.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <typeinfo>
#include <vector>

#include "grbd/contact/fclib.hpp"
#include "grbd/contact/local_problem.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/hdf5.hpp"
#include "grbd_test/temp_dir.hpp"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

namespace {

namespace fs = std::filesystem;
using grbd::contact::GlobalProblem;
using grbd::contact::LocalProblem;
using grbd::test::H5;
using grbd::test::QuietHdf5;
using grbd::test::TempDir;

// Aborts the test program, naming the input, if a read has not finished after `limit`: a reader
// that blocks or loops must fail the suite, not hang it. (stdout: the test captures stderr.)
class Watchdog {
 public:
  explicit Watchdog(std::chrono::seconds limit) : limit_(limit), thread_([this] { watch(); }) {}
  ~Watchdog() {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    changed_.notify_one();
    thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  void arm(const std::string& what) {
    const std::lock_guard lock(mutex_);
    what_ = what;
    deadline_ = std::chrono::steady_clock::now() + limit_;
    armed_ = true;
  }
  void disarm() {
    const std::lock_guard lock(mutex_);
    armed_ = false;
  }

 private:
  void watch() {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      changed_.wait_for(lock, std::chrono::milliseconds(200));
      if (armed_ && std::chrono::steady_clock::now() > deadline_) {
        std::printf("FATAL: %s has not finished after %lld s: the FCLIB reader hangs\n",
                    what_.c_str(), static_cast<long long>(limit_.count()));
        std::fflush(stdout);
        std::abort();
      }
    }
  }

  std::chrono::seconds limit_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::string what_;
  std::chrono::steady_clock::time_point deadline_;
  bool armed_ = false;
  bool stop_ = false;
  std::thread thread_;
};

// Exempts the allocations of its lifetime (on this thread) from LeakSanitizer, in sanitizer builds
// only: see the note on HDF5 at the top.
class HdfLeaksExempt {
 public:
  HdfLeaksExempt() {
    H5garbage_collect();  // frees HDF5's free lists: no block allocated before is reused
#if defined(__SANITIZE_ADDRESS__)
    __lsan_disable();
#endif
  }
  ~HdfLeaksExempt() {
#if defined(__SANITIZE_ADDRESS__)
    __lsan_enable();
#endif
  }
  HdfLeaksExempt(const HdfLeaksExempt&) = delete;
  HdfLeaksExempt& operator=(const HdfLeaksExempt&) = delete;
};

// ---------------------------------------------------------------------------------------------
// The valid files.

// Object creation property lists without modification times, so that the files written are the
// same bytes in every run and the seeded edits hit the same places.
H5 untimed(hid_t plist_class) {
  H5 plist(H5Pcreate(plist_class), H5Pclose);
  H5Pset_obj_track_times(plist.get(), false);
  return plist;
}

void write_dataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type,
                   const void* data, hsize_t count, bool packed = false) {
  const H5 space(H5Screate_simple(1, &count, nullptr), H5Sclose);
  const H5 dcpl = untimed(H5P_DATASET_CREATE);
  if (packed && count > 0) {
    const hsize_t chunk = std::min<hsize_t>(count, 4);
    H5Pset_chunk(dcpl.get(), 1, &chunk);
    H5Pset_deflate(dcpl.get(), 6);
  }
  const H5 dataset(
      H5Dcreate2(file, name.c_str(), file_type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
      H5Dclose);
  ASSERT_GE(dataset.get(), 0) << name;
  if (count > 0) {
    ASSERT_GE(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), 0) << name;
  }
}

void write_integers(hid_t file, const std::string& name, const std::vector<std::int64_t>& values,
                    hid_t file_type = H5T_STD_I32LE, bool packed = false) {
  write_dataset(file, name, file_type, H5T_NATIVE_INT64, values.data(), values.size(), packed);
}

void write_reals(hid_t file, const std::string& name, const std::vector<double>& values,
                 hid_t file_type = H5T_IEEE_F64LE, bool packed = false) {
  write_dataset(file, name, file_type, H5T_NATIVE_DOUBLE, values.data(), values.size(), packed);
}

void make_group(hid_t file, const std::string& name) {
  const H5 gcpl = untimed(H5P_GROUP_CREATE);
  const H5 group(H5Gcreate2(file, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose);
  ASSERT_GE(group.get(), 0) << name;
}

// A scalar string dataset, fixed-length or variable-length.
void write_string(hid_t file, const std::string& name, const std::string& text, bool variable) {
  const H5 type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), variable ? H5T_VARIABLE : text.size() + 1);
  const H5 space(H5Screate(H5S_SCALAR), H5Sclose);
  const H5 dcpl = untimed(H5P_DATASET_CREATE);
  const H5 dataset(
      H5Dcreate2(file, name.c_str(), type.get(), space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
      H5Dclose);
  ASSERT_GE(dataset.get(), 0) << name;
  const char* pointer = text.c_str();
  ASSERT_GE(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
                     variable ? static_cast<const void*>(&pointer) : pointer),
            0);
}

struct Matrix {
  std::int64_t m, n, nz, nzmax;
  std::vector<std::int64_t> p, i;
  std::vector<double> x;
};

void write_matrix(hid_t file, const std::string& group, const Matrix& A,
                  hid_t integer_type = H5T_STD_I32LE, bool packed = false) {
  make_group(file, group);
  write_integers(file, group + "/m", {A.m}, integer_type);
  write_integers(file, group + "/n", {A.n}, integer_type);
  write_integers(file, group + "/nz", {A.nz}, integer_type);
  write_integers(file, group + "/nzmax", {A.nzmax}, integer_type);
  write_integers(file, group + "/p", A.p, integer_type, packed);
  write_integers(file, group + "/i", A.i, integer_type, packed);
  write_reals(file, group + "/x", A.x, H5T_IEEE_F64LE, packed);
}

// W of 3 contacts, 9 × 9, blocks (0, 0), (0, 1), (1, 0), (1, 1), (2, 2), in compressed rows.
Matrix local_W_rows() {
  Matrix W{9, 9, -2, 0, {0}, {}, {}};
  for (int r = 0; r < 9; ++r) {
    for (int c = 0; c < 9; ++c) {
      const bool coupled = r < 6 && c < 6;
      if (r == c || (coupled && r / 3 != c / 3 && (r + c) % 2 == 0)) {
        W.i.push_back(c);
        W.x.push_back(r == c ? 2.0 + 0.1 * r : 0.25);
      }
    }
    W.p.push_back(static_cast<std::int64_t>(W.i.size()));
  }
  W.nzmax = static_cast<std::int64_t>(W.x.size());
  return W;
}

void write_local_rows(const fs::path& path) {
  const H5 file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  ASSERT_GE(file.get(), 0);
  make_group(file.get(), "/fclib_local");
  write_integers(file.get(), "/fclib_local/spacedim", {3});
  write_matrix(file.get(), "/fclib_local/W", local_W_rows());
  make_group(file.get(), "/fclib_local/vectors");
  write_reals(file.get(), "/fclib_local/vectors/q", {-1, 0.1, 0, -0.5, 0, 0.2, -2, 0.3, 0.3});
  write_reals(file.get(), "/fclib_local/vectors/mu", {0.3, 0.6, 0.0});
  make_group(file.get(), "/fclib_local/info");
  write_string(file.get(), "/fclib_local/info/title", "fuzz base", false);
  write_string(file.get(), "/fclib_local/info/description", "three contacts, compressed rows",
               true);
  write_string(file.get(), "/fclib_local/info/math_info", "", false);
  make_group(file.get(), "/guesses");
  write_integers(file.get(), "/guesses/number_of_guesses", {1});
  make_group(file.get(), "/guesses/1");
  write_reals(file.get(), "/guesses/1/r", std::vector<double>(9, 0.5));
}

// The same problem with W in triplets (64-bit indices), compressed chunked x, q and mu.
void write_local_triplets(const fs::path& path) {
  const Matrix rows = local_W_rows();
  Matrix W{9, 9, 0, 0, {}, {}, {}};
  for (std::int64_t r = 0; r < 9; ++r) {
    for (auto k = rows.p[static_cast<std::size_t>(r)]; k < rows.p[static_cast<std::size_t>(r) + 1];
         ++k) {
      W.i.push_back(r);
      W.p.push_back(rows.i[static_cast<std::size_t>(k)]);
      W.x.push_back(rows.x[static_cast<std::size_t>(k)]);
    }
  }
  W.nz = static_cast<std::int64_t>(W.x.size());
  W.nzmax = W.nz + 2;
  const H5 file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  ASSERT_GE(file.get(), 0);
  make_group(file.get(), "/fclib_local");
  write_integers(file.get(), "/fclib_local/spacedim", {3}, H5T_STD_I64LE);
  write_matrix(file.get(), "/fclib_local/W", W, H5T_STD_I64LE, true);
  make_group(file.get(), "/fclib_local/vectors");
  write_reals(file.get(), "/fclib_local/vectors/q", {-1, 0.1, 0, -0.5, 0, 0.2, -2, 0.3, 0.3},
              H5T_IEEE_F64LE, true);
  write_reals(file.get(), "/fclib_local/vectors/mu", {0.3, 0.6, 0.0}, H5T_IEEE_F32LE, true);
}

// A global problem: 2 contacts, m = 6, M tridiagonal SPD in compressed columns, H in triplets.
void write_global(const fs::path& path) {
  Matrix M{6, 6, -1, 0, {0}, {}, {}};
  for (int c = 0; c < 6; ++c) {
    for (int r = std::max(0, c - 1); r <= std::min(5, c + 1); ++r) {
      M.i.push_back(r);
      M.x.push_back(r == c ? 4.0 : -1.0);
    }
    M.p.push_back(static_cast<std::int64_t>(M.i.size()));
  }
  M.nzmax = static_cast<std::int64_t>(M.x.size());
  const Matrix H{6, 6, 7, 7, {0, 3, 1, 2, 3, 4, 5}, {0, 0, 1, 2, 3, 4, 5}, {1, -1, 1, 1, 1, 1, 1}};
  const H5 file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  ASSERT_GE(file.get(), 0);
  make_group(file.get(), "/fclib_global");
  write_integers(file.get(), "/fclib_global/spacedim", {3});
  write_matrix(file.get(), "/fclib_global/M", M);
  write_matrix(file.get(), "/fclib_global/H", H, H5T_STD_U8LE);
  make_group(file.get(), "/fclib_global/vectors");
  write_reals(file.get(), "/fclib_global/vectors/f", {0, 0, -1, 0, 0, -2});
  write_reals(file.get(), "/fclib_global/vectors/w", {0, 0, 0, 0.1, 0, 0});
  write_reals(file.get(), "/fclib_global/vectors/mu", {0.5, 0.25});
  make_group(file.get(), "/fclib_global/info");
  write_string(file.get(), "/fclib_global/info/title", "fuzz global", true);
  make_group(file.get(), "/guesses");
  make_group(file.get(), "/guesses/1");
  write_reals(file.get(), "/guesses/1/r", std::vector<double>(6, 0.0));
}

// The datasets of the three files, for the edits through HDF5.
const std::vector<std::string>& local_datasets() {
  static const std::vector<std::string> names = {
      "/fclib_local/spacedim",   "/fclib_local/W/m",        "/fclib_local/W/n",
      "/fclib_local/W/nz",       "/fclib_local/W/nzmax",    "/fclib_local/W/p",
      "/fclib_local/W/i",        "/fclib_local/W/x",        "/fclib_local/vectors/q",
      "/fclib_local/vectors/mu", "/fclib_local/info/title", "/guesses/1/r"};
  return names;
}
const std::vector<std::string>& global_datasets() {
  static const std::vector<std::string> names = {
      "/fclib_global/spacedim",   "/fclib_global/M/m",
      "/fclib_global/M/n",        "/fclib_global/M/nz",
      "/fclib_global/M/nzmax",    "/fclib_global/M/p",
      "/fclib_global/M/i",        "/fclib_global/M/x",
      "/fclib_global/H/m",        "/fclib_global/H/n",
      "/fclib_global/H/nz",       "/fclib_global/H/nzmax",
      "/fclib_global/H/p",        "/fclib_global/H/i",
      "/fclib_global/H/x",        "/fclib_global/vectors/f",
      "/fclib_global/vectors/w",  "/fclib_global/vectors/mu",
      "/fclib_global/info/title", "/guesses/1/r"};
  return names;
}

// ---------------------------------------------------------------------------------------------
// The edits.

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

class Editor {
 public:
  explicit Editor(std::uint64_t seed) : engine_(seed) {}

  std::size_t index(std::size_t size) {
    return std::uniform_int_distribution<std::size_t>(0, size - 1)(engine_);
  }
  bool chance(double p) { return std::uniform_real_distribution<double>(0.0, 1.0)(engine_) < p; }

  // 1 to 4 bytes of the file replaced: a bit flipped, or a random byte, or 0x00 / 0xff.
  void flip_bytes(const fs::path& path) {
    std::string bytes = read_bytes(path);
    const std::size_t flips = 1 + index(4);
    for (std::size_t k = 0; k < flips; ++k) {
      char& c = bytes[index(bytes.size())];
      switch (index(4)) {
        case 0:
          c = static_cast<char>(c ^ (1 << index(8)));
          break;
        case 1:
          c = static_cast<char>(index(256));
          break;
        case 2:
          c = '\0';
          break;
        default:
          c = static_cast<char>(0xff);
          break;
      }
    }
    write_bytes(path, bytes);
  }

  void truncate(const fs::path& path) {
    const std::string bytes = read_bytes(path);
    write_bytes(path, bytes.substr(0, index(bytes.size())));
  }

  // A value that breaks things: extremes, NaN, infinities, indices just out of range, negative.
  double nasty_value() {
    static const double values[] = {0.0,
                                    -1.0,
                                    1.0,
                                    2.0,
                                    3.0,
                                    9.0,
                                    -2.0,
                                    0.5,
                                    2147483647.0,
                                    -2147483648.0,
                                    4294967295.0,
                                    9007199254740992.0,
                                    1e308,
                                    -1e308,
                                    5e-324,
                                    std::numeric_limits<double>::quiet_NaN(),
                                    std::numeric_limits<double>::infinity(),
                                    -std::numeric_limits<double>::infinity()};
    if (chance(0.3)) return std::uniform_real_distribution<double>(-10.0, 10.0)(engine_);
    return values[index(std::size(values))];
  }

  // One random edit of `name` in the open file: a single entry changed, the dataset rewritten
  // with another length, type or values, replaced by a string or a group, deleted, turned into a
  // link, or given an attribute.
  void edit_dataset(hid_t file, const std::string& name, const fs::path& self) {
    std::vector<double> values = current_values(file, name);
    const int kind = static_cast<int>(index(9));
    if (kind == 0 || kind == 1) {  // one entry poked, or a few
      if (values.empty()) values.push_back(0.0);
      for (int k = 0; k <= kind; ++k) values[index(values.size())] = nasty_value();
      rewrite(file, name, values, random_type());
    } else if (kind == 2) {  // another length
      const std::size_t lengths[] = {0, 1, values.size() + 1,
                                     values.size() > 0 ? values.size() - 1 : 2,
                                     2 * values.size() + 3};
      const std::size_t length = lengths[index(std::size(lengths))];
      values.resize(length, nasty_value());
      rewrite(file, name, values, random_type());
    } else if (kind == 3) {  // all values nasty, another type
      for (double& v : values) v = nasty_value();
      rewrite(file, name, values, random_type());
    } else if (kind == 4) {  // a string instead
      H5Ldelete(file, name.c_str(), H5P_DEFAULT);
      const H5 type(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(type.get(), 5);
      const H5 space(H5Screate(H5S_SCALAR), H5Sclose);
      const H5 dataset(H5Dcreate2(file, name.c_str(), type.get(), space.get(), H5P_DEFAULT,
                                  H5P_DEFAULT, H5P_DEFAULT),
                       H5Dclose);
      if (dataset.get() >= 0)
        H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, "1234");
    } else if (kind == 5) {  // a group instead, or nothing
      H5Ldelete(file, name.c_str(), H5P_DEFAULT);
      if (chance(0.5)) {
        const H5 group(H5Gcreate2(file, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                       H5Gclose);
      }
    } else if (kind == 6) {  // a soft link (dangling or not) or an external link
      H5Ldelete(file, name.c_str(), H5P_DEFAULT);
      switch (index(3)) {
        case 0:
          H5Lcreate_soft("/nowhere", file, name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
          break;
        case 1:
          H5Lcreate_external(self.c_str(), name.c_str(), file, name.c_str(), H5P_DEFAULT,
                             H5P_DEFAULT);
          break;
        default:
          H5Lcreate_external("/nonexistent/file.hdf5", "/x", file, name.c_str(), H5P_DEFAULT,
                             H5P_DEFAULT);
          break;
      }
    } else if (kind == 7) {  // an attribute of 1000 doubles, which the reader ignores
      const hsize_t count = 1000;
      const H5 space(H5Screate_simple(1, &count, nullptr), H5Sclose);
      const H5 attribute(H5Acreate_by_name(file, name.c_str(), "junk", H5T_IEEE_F64LE, space.get(),
                                           H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Aclose);
      if (attribute.get() >= 0) {
        const std::vector<double> junk(count, nasty_value());
        H5Awrite(attribute.get(), H5T_NATIVE_DOUBLE, junk.data());
      }
    } else {  // the whole group holding it deleted
      const std::string group = name.substr(0, name.rfind('/'));
      if (!group.empty()) H5Ldelete(file, group.c_str(), H5P_DEFAULT);
    }
  }

 private:
  hid_t random_type() {
    const hid_t types[] = {H5T_IEEE_F64LE, H5T_IEEE_F64BE, H5T_IEEE_F32LE, H5T_STD_I32LE,
                           H5T_STD_I64LE,  H5T_STD_U8LE,   H5T_STD_I16BE,  H5T_STD_U64LE};
    return types[index(std::size(types))];
  }

  // The values of a numeric dataset (empty if it cannot be read as numbers).
  static std::vector<double> current_values(hid_t file, const std::string& name) {
    const H5 dataset(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (dataset.get() < 0) return {};
    const H5 space(H5Dget_space(dataset.get()), H5Sclose);
    const hssize_t count = H5Sget_simple_extent_npoints(space.get());
    if (count <= 0 || count > 100000) return {};
    std::vector<double> values(static_cast<std::size_t>(count));
    if (H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) <
        0) {
      return {};
    }
    return values;
  }

  // Replaces `name` by a dataset of `type` holding `values` (converted, with HDF5's clipping of
  // what the type cannot hold).
  static void rewrite(hid_t file, const std::string& name, const std::vector<double>& values,
                      hid_t type) {
    H5Ldelete(file, name.c_str(), H5P_DEFAULT);
    const hsize_t count = values.size();
    const H5 space(H5Screate_simple(1, &count, nullptr), H5Sclose);
    const H5 dataset(
        H5Dcreate2(file, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        H5Dclose);
    if (dataset.get() >= 0 && count > 0) {
      H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
    }
  }

  std::mt19937_64 engine_;
};

// ---------------------------------------------------------------------------------------------
// The reads.

struct Tally {
  int inputs = 0;
  int reads = 0;
  int accepted = 0;
  int refused = 0;
  double slowest = 0.0;
  std::string slowest_read;
};

// Whether the global problem's sizes agree and its entries are finite.
::testing::AssertionResult consistent(const GlobalProblem& g) {
  const auto m = g.M.rows();
  const auto n3 = static_cast<Eigen::Index>(3 * g.mu.size());
  if (g.M.cols() != m || g.f.size() != m || g.H.rows() != m || g.H.cols() != n3 ||
      g.w.size() != n3) {
    return ::testing::AssertionFailure() << "sizes disagree";
  }
  const auto finite = [](const Eigen::SparseMatrix<double>& A) {
    for (Eigen::Index k = 0; k < A.nonZeros(); ++k) {
      if (!std::isfinite(A.valuePtr()[k])) return false;
    }
    return true;
  };
  if (!finite(g.M) || !finite(g.H) || !g.f.allFinite() || !g.w.allFinite()) {
    return ::testing::AssertionFailure() << "a non-finite entry";
  }
  for (const double mu : g.mu) {
    if (!(mu >= 0.0) || !std::isfinite(mu)) return ::testing::AssertionFailure() << "mu " << mu;
  }
  return ::testing::AssertionSuccess();
}

// Reads `path` with every reader (read_fclib_matrix of the group `matrix`); each must succeed with
// a consistent result or throw grbd::Error, within `limit` seconds.
void read_everything(const fs::path& path, const std::string& matrix, const std::string& input,
                     Watchdog& watchdog, Tally& tally, double limit) {
  const std::vector<std::pair<const char*, std::function<void()>>> readers = {
      {"read_fclib_info",
       [&] {
         const auto info = grbd::contact::read_fclib_info(path);
         EXPECT_GE(info.contacts, 0) << input;
         if (info.guess) {
           EXPECT_EQ(info.guess->size(), static_cast<std::size_t>(info.contacts)) << input;
         }
       }},
      {"read_fclib_local",
       [&] {
         const LocalProblem problem = grbd::contact::read_fclib_local(path);
         EXPECT_NO_THROW(grbd::contact::validate(problem)) << input;
       }},
      {"read_fclib_as_local",
       [&] {
         const LocalProblem problem = grbd::contact::read_fclib_as_local(path);
         EXPECT_NO_THROW(grbd::contact::validate(problem)) << input;
       }},
      {"read_fclib_global",
       [&] { EXPECT_TRUE(consistent(grbd::contact::read_fclib_global(path))) << input; }},
      {"read_fclib_matrix",
       [&] {
         const Eigen::SparseMatrix<double> A = grbd::contact::read_fclib_matrix(path, matrix);
         for (Eigen::Index k = 0; k < A.nonZeros(); ++k) {
           EXPECT_TRUE(std::isfinite(A.valuePtr()[k])) << input;
         }
       }},
  };
  ++tally.inputs;
  for (const auto& [name, read] : readers) {
    const std::string what = std::string(name) + " of " + input;
    watchdog.arm(what);
    const auto start = std::chrono::steady_clock::now();
    try {
      read();
      ++tally.accepted;
    } catch (const grbd::Error&) {
      ++tally.refused;
    } catch (const std::exception& error) {
      ADD_FAILURE() << what << " threw " << typeid(error).name() << ": " << error.what();
    } catch (...) {
      ADD_FAILURE() << what << " threw something that is not a std::exception";
    }
    watchdog.disarm();
    ++tally.reads;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > tally.slowest) {
      tally.slowest = seconds;
      tally.slowest_read = what;
    }
    EXPECT_LT(seconds, limit) << what;
  }
}

TEST(FclibReader, NeverCrashesOnDamagedFiles) {
  const HdfLeaksExempt exempt;
  const TempDir dir;
  Watchdog watchdog(std::chrono::seconds(60));
  struct Base {
    const char* name;
    void (*write)(const fs::path&);
    const std::vector<std::string>& datasets;
    const char* matrix;
  };
  const std::vector<Base> bases = {
      {"local-rows.hdf5", write_local_rows, local_datasets(), "/fclib_local/W"},
      {"local-triplets.hdf5", write_local_triplets, local_datasets(), "/fclib_local/W"},
      {"global.hdf5", write_global, global_datasets(), "/fclib_global/H"}};
  constexpr int kFlips = 350;       // per base file
  constexpr int kTruncations = 30;  // per base file
  constexpr int kEdits = 350;       // per base file
  constexpr double kLimit = 2.0;    // seconds per read
  Editor editor(20251124);
  Tally flips, truncations, edits;
  const fs::path work = dir / "damaged.hdf5";
  ::testing::internal::CaptureStderr();
  for (const Base& base : bases) {
    const fs::path valid = dir / base.name;
    base.write(valid);
    {  // The base itself reads with 4 of the 5 readers (local and global exclude each other).
      Tally check;
      read_everything(valid, base.matrix, base.name, watchdog, check, kLimit);
      EXPECT_EQ(check.accepted, 4) << base.name;
    }
    for (int k = 0; k < kFlips; ++k) {
      fs::copy_file(valid, work, fs::copy_options::overwrite_existing);
      editor.flip_bytes(work);
      read_everything(work, base.matrix,
                      std::string(base.name) + " with bytes flipped, input " + std::to_string(k),
                      watchdog, flips, kLimit);
    }
    for (int k = 0; k < kTruncations; ++k) {
      fs::copy_file(valid, work, fs::copy_options::overwrite_existing);
      editor.truncate(work);
      read_everything(work, base.matrix,
                      std::string(base.name) + " truncated, input " + std::to_string(k), watchdog,
                      truncations, kLimit);
    }
    for (int k = 0; k < kEdits; ++k) {
      fs::copy_file(valid, work, fs::copy_options::overwrite_existing);
      {
        const QuietHdf5 quiet;  // the edits fail on purpose at times (an edit of a damaged file)
        const H5 file(H5Fopen(work.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
        ASSERT_GE(file.get(), 0);
        const std::size_t edits = 1 + editor.index(3);
        for (std::size_t e = 0; e < edits; ++e) {
          editor.edit_dataset(file.get(), base.datasets[editor.index(base.datasets.size())], valid);
        }
      }
      read_everything(work, base.matrix,
                      std::string(base.name) + " edited through HDF5, input " + std::to_string(k),
                      watchdog, edits, kLimit);
    }
  }
  const std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed.substr(0, 2000), "") << "the reader printed on stderr";
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0) << "HDF5 objects left open";
  for (const auto& [name, tally] : {std::pair<const char*, const Tally&>{"bytes flipped", flips},
                                    {"truncated", truncations},
                                    {"edited through HDF5", edits}}) {
    std::printf(
        "FCLIB fuzz, %s: %d files, %d reads: %d accepted, %d refused; slowest read "
        "%.3f s (%s)\n",
        name, tally.inputs, tally.reads, tally.accepted, tally.refused, tally.slowest,
        tally.slowest_read.c_str());
    EXPECT_EQ(tally.accepted + tally.refused, tally.reads) << name;
    EXPECT_EQ(tally.reads, 5 * tally.inputs) << name;
    EXPECT_GT(tally.refused, 0) << name;
  }
  EXPECT_EQ(flips.inputs, 3 * kFlips);
  EXPECT_EQ(truncations.inputs, 3 * kTruncations);
  EXPECT_EQ(edits.inputs, 3 * kEdits);
  // Most damage is refused, but not all: a flipped byte inside a value, an attribute added.
  EXPECT_GT(flips.accepted, 0);
  EXPECT_GT(edits.accepted, 0);
}

}  // namespace
