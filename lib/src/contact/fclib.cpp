/// \file
/// \brief The reader of FCLIB files: the HDF5 groups /fclib_local and /fclib_global, their sparse
/// matrices in any of the three storage kinds, with a check of every dataset before it is used.
///
/// HDF5 is used through its C API in serial mode with the default property lists. Every handle
/// lives in an RAII Handle, so nothing stays open when a check throws; HDF5's automatic printing of
/// its error stack is switched off while grbd reads (the innermost HDF5 message is put into the
/// grbd::Error instead), and the calls into HDF5 are serialized by a mutex because the library is
/// not built thread-safe.
///
/// Nothing the file declares is trusted before it is checked against something else:
/// - the path must name a regular file (a FIFO or a device could block the reader forever), and
///   every group and dataset opened must be reached through hard links only (an external link can
///   name any file, a pipe included; a soft link is refused with it); datasets whose data lie in
///   other files (external storage, virtual datasets) are refused too;
/// - every element type is a standard integer or an IEEE 754 float, and a dataset stored without
///   compression cannot declare more bytes than the whole file has;
/// - the sizes are checked against each other before anything is allocated: n (the contacts) and
///   m (the degrees of freedom) come from the headers of W, or of M and H, and every vector, index
///   and value dataset must have the length they imply (mu n entries, q and w 3n, f m, the
///   entries of a sparse matrix at most nzmax);
/// - the problem read is checked as a whole (validate()), and a refusal names the file and the
///   dataset.

#include "grbd/contact/fclib.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <system_error>
#include <utility>

#include "shared/hdf5.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// The largest row or column count, entry count or vector length read: Eigen's sparse matrices
/// index with int.
constexpr std::int64_t kMaxIndex = std::numeric_limits<int>::max();

/// The longest fixed-length info string read (title, description, math_info): 1 MiB.
constexpr std::size_t kMaxStringBytes = std::size_t{1} << 20;

/// The largest chunk of a chunked dataset that is larger than the dataset's own data: HDF5 reads
/// (and, if compressed, inflates) whole chunks, so a chunk size is an allocation.
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{8} << 20;

using hdf5::Handle;
using hdf5::QuietErrors;

std::string type_class_name(H5T_class_t type_class) {
  switch (type_class) {
    case H5T_INTEGER:
      return "integer";
    case H5T_FLOAT:
      return "floating-point";
    case H5T_STRING:
      return "string";
    case H5T_COMPOUND:
      return "compound";
    case H5T_ARRAY:
      return "array";
    case H5T_VLEN:
      return "variable-length";
    case H5T_ENUM:
      return "enum";
    default:
      return "non-numeric";
  }
}

std::string object_kind(H5I_type_t type) {
  switch (type) {
    case H5I_GROUP:
      return "a group";
    case H5I_DATASET:
      return "a dataset";
    case H5I_DATATYPE:
      return "a named datatype";
    default:
      return "an object of unknown kind";
  }
}

/// Whether `type` is one of HDF5's standard integer types (1, 2, 4 or 8 bytes, signed or not,
/// either byte order): a type whose size, precision or offset was damaged is none of them.
bool standard_integer(hid_t type) {
  for (const hid_t standard :
       {H5T_STD_I8LE, H5T_STD_I8BE, H5T_STD_U8LE, H5T_STD_U8BE, H5T_STD_I16LE, H5T_STD_I16BE,
        H5T_STD_U16LE, H5T_STD_U16BE, H5T_STD_I32LE, H5T_STD_I32BE, H5T_STD_U32LE, H5T_STD_U32BE,
        H5T_STD_I64LE, H5T_STD_I64BE, H5T_STD_U64LE, H5T_STD_U64BE}) {
    if (H5Tequal(type, standard) > 0) return true;
  }
  return false;
}

/// Whether `type` is an IEEE 754 double or single in either byte order.
bool ieee_float(hid_t type) {
  for (const hid_t standard : {H5T_IEEE_F64LE, H5T_IEEE_F64BE, H5T_IEEE_F32LE, H5T_IEEE_F32BE}) {
    if (H5Tequal(type, standard) > 0) return true;
  }
  return false;
}

/// What a dataset's elements must be.
enum class Element { integer, real, string };

/// An open, checked dataset: its elements are of the kind asked for, it is scalar or
/// one-dimensional with `length` entries (1 for a scalar dataspace), and its data lie in the file.
struct Dataset {
  std::string name;
  Handle dataset;
  Handle type;
  hsize_t length = 0;
  bool variable_string = false;
};

/// The header {m, n, nz, nzmax} of an FCLIB sparse matrix.
struct MatrixHeader {
  std::string group;
  std::int64_t m = 0;
  std::int64_t n = 0;
  std::int64_t nz = 0;
  std::int64_t nzmax = 0;
};

/// A sparse matrix's header and its datasets p, i, x, opened and checked against the header (for
/// compressed storage the lengths of i and x are checked once p is read).
struct MatrixData {
  MatrixHeader h;
  Dataset p;
  Dataset i;
  Dataset x;
};

std::string storage_name(std::int64_t nz) {
  if (nz == -1) return "compressed columns (nz = -1)";
  if (nz == -2) return "compressed rows (nz = -2)";
  return "triplets (nz = " + std::to_string(nz) + ")";
}

std::string shape_text(std::int64_t rows, std::int64_t cols) {
  return std::to_string(rows) + " × " + std::to_string(cols);
}

/// The printable prefix of the `size` bytes at `text`, up to the first NUL.
std::string bounded_string(const char* text, std::size_t size) {
  return std::string(text, std::find(text, text + size, '\0'));
}

/// An open FCLIB file and the checked reads of its objects. Every failure throws grbd::Error whose
/// message starts with the file's path.
class File {
 public:
  explicit File(const std::filesystem::path& path) : name_(path.string()) {
    require_regular_file(path);
    const htri_t is_hdf5 = H5Fis_hdf5(name_.c_str());
    if (is_hdf5 == 0) fail("is not an HDF5 file (no HDF5 signature found)");
    if (is_hdf5 < 0) fail("cannot be read as an HDF5 file" + hdf5::message());
    file_ = Handle(H5Fopen(name_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!file_.valid()) {
      fail("cannot be opened as an HDF5 file, it may be truncated or damaged" + hdf5::message());
    }
  }

  /// Throws grbd::Error "<file>: <message>".
  [[noreturn]] void fail(const std::string& message) const { throw Error(name_ + ": " + message); }

  const std::string& name() const { return name_; }

  /// The size of the file in bytes.
  std::uint64_t size() const { return size_; }

  /// Whether `object` (an absolute path such as "/fclib_local/R") exists: every component is a
  /// link that resolves, every component but the last a group. A component that is a soft or an
  /// external link is refused (it exists, but grbd does not follow it).
  bool has(const std::string& object) const {
    std::size_t start = 1;
    while (start <= object.size()) {
      const std::size_t end = std::min(object.find('/', start), object.size());
      const std::string prefix = object.substr(0, end);
      const bool last = end == object.size();
      if (H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
      require_hard_link(prefix, last ? "a group or dataset" : "a group");
      if (H5Oexists_by_name(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
      if (!last) {
        const Handle handle(H5Oopen(file_.get(), prefix.c_str(), H5P_DEFAULT), H5Oclose);
        if (!handle.valid() || H5Iget_type(handle.get()) != H5I_GROUP) return false;
      }
      start = end + 1;
    }
    return true;
  }

  /// Opens `object`, which must be a group or a dataset (`expected`) reached through hard links
  /// only; names the first missing group on the way, or what the object is instead.
  Handle open(const std::string& object, H5I_type_t expected) const {
    const std::string what = expected == H5I_GROUP ? "group" : "dataset";
    std::size_t start = 1;
    while (start <= object.size()) {
      const std::size_t end = std::min(object.find('/', start), object.size());
      const std::string prefix = object.substr(0, end);
      const bool last = end == object.size();
      if (H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) {
        if (last) fail(what + " " + object + " is missing");
        fail("group " + prefix + " is missing (expected " + what + " " + object + ")");
      }
      require_hard_link(prefix, last ? "a " + what : "a group holding " + what + " " + object);
      if (H5Oexists_by_name(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) {
        if (last) fail(what + " " + object + " is missing");
        fail("group " + prefix + " is missing (expected " + what + " " + object + ")");
      }
      Handle handle(H5Oopen(file_.get(), prefix.c_str(), H5P_DEFAULT), H5Oclose);
      if (!handle.valid()) fail("cannot open " + prefix + hdf5::message());
      const H5I_type_t type = H5Iget_type(handle.get());
      if (last) {
        if (type != expected) fail(object + " is " + object_kind(type) + ", expected a " + what);
        return handle;
      }
      if (type != H5I_GROUP) {
        fail(prefix + " is " + object_kind(type) + ", expected a group holding " + what + " " +
             object);
      }
      start = end + 1;
    }
    fail("expected the path of a " + what + ", found \"" + object + "\"");
  }

  /// Opens dataset `name` and checks its element type, its rank (a scalar or one-dimensional
  /// dataspace, an empty one counts as 0 entries) and that its data lie in this file and fit in
  /// it. Nothing of its data is read.
  Dataset dataset(const std::string& name, Element element) const {
    Dataset d = open_dataset(name, element);
    check_storage(d);
    return d;
  }

  /// Opens dataset `name` as dataset() does, and checks that it has `count` entries, or at least
  /// `count` if `at_least`, before its storage: `expected` says where count comes from, e.g.
  /// "n + 1 = 31".
  Dataset dataset(const std::string& name, Element element, std::int64_t count, bool at_least,
                  const std::string& expected) const {
    Dataset d = open_dataset(name, element);
    check_length(d, count, at_least, expected);
    check_storage(d);
    return d;
  }

  /// Opens dataset `name` and checks its element type and rank (see dataset()).
  Dataset open_dataset(const std::string& name, Element element) const {
    Dataset d;
    d.name = name;
    d.dataset = open(name, H5I_DATASET);
    d.type = Handle(H5Dget_type(d.dataset.get()), H5Tclose);
    const Handle space(H5Dget_space(d.dataset.get()), H5Sclose);
    if (!d.type.valid() || !space.valid()) {
      fail("cannot read the type or shape of dataset " + name + hdf5::message());
    }
    check_element(d, element);
    switch (H5Sget_simple_extent_type(space.get())) {
      case H5S_NULL:
        d.length = 0;
        break;
      case H5S_SCALAR:
        d.length = 1;
        break;
      case H5S_SIMPLE: {
        const int rank = H5Sget_simple_extent_ndims(space.get());
        if (rank != 1) {
          fail("dataset " + name + " has rank " + std::to_string(rank) +
               ", expected a one-dimensional dataset");
        }
        hsize_t dims[1] = {0};
        if (H5Sget_simple_extent_dims(space.get(), dims, nullptr) != 1) {
          fail("cannot read the shape of dataset " + name + hdf5::message());
        }
        d.length = dims[0];
        break;
      }
      default:
        fail("cannot read the shape of dataset " + name + hdf5::message());
    }
    return d;
  }

  /// The first `count` entries of the dataset d (count ≤ d.length), converted to `memory_type`.
  template <class T>
  std::vector<T> read(const Dataset& d, hsize_t count, hid_t memory_type) const {
    std::vector<T> values(count);
    if (count == 0) return values;
    herr_t status = -1;
    if (count == d.length) {
      status = H5Dread(d.dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
    } else {
      const Handle file_space(H5Dget_space(d.dataset.get()), H5Sclose);
      const Handle memory_space(H5Screate_simple(1, &count, nullptr), H5Sclose);
      const hsize_t start = 0;
      if (file_space.valid() && memory_space.valid() &&
          H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &start, nullptr, &count, nullptr) >=
              0) {
        status = H5Dread(d.dataset.get(), memory_type, memory_space.get(), file_space.get(),
                         H5P_DEFAULT, values.data());
      }
    }
    if (status < 0) fail("cannot read dataset " + d.name + hdf5::message());
    return values;
  }

  /// The first `count` integers of the dataset d.
  std::vector<std::int64_t> integers(const Dataset& d, std::int64_t count) const {
    return read<std::int64_t>(d, static_cast<hsize_t>(count), H5T_NATIVE_INT64);
  }

  /// The first `count` reals of the dataset d, each finite.
  std::vector<double> reals(const Dataset& d, std::int64_t count) const {
    return finite(d.name, read<double>(d, static_cast<hsize_t>(count), H5T_NATIVE_DOUBLE));
  }

  /// The single integer of dataset `name`.
  std::int64_t integer(const std::string& name) const {
    const Dataset d = dataset(name, Element::integer);
    if (d.length != 1) {
      fail("dataset " + name + " has " + std::to_string(d.length) +
           " entries, expected a single integer");
    }
    return read<std::int64_t>(d, 1, H5T_NATIVE_INT64).front();
  }

  /// The string of dataset `name` (a scalar or a one-entry dataset, fixed or variable length).
  std::string string(const std::string& name) const {
    const Dataset d = dataset(name, Element::string);
    if (d.length != 1) {
      fail("dataset " + name + " has " + std::to_string(d.length) +
           " entries, expected a single string");
    }
    const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
    if (!memory_type.valid()) fail("cannot read dataset " + name + hdf5::message());
    H5Tset_cset(memory_type.get(), H5Tget_cset(d.type.get()));
    if (d.variable_string) {
      H5Tset_size(memory_type.get(), H5T_VARIABLE);
      char* text = nullptr;
      if (H5Dread(d.dataset.get(), memory_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &text) < 0) {
        fail("cannot read dataset " + name + hdf5::message());
      }
      std::string result = text != nullptr ? std::string(text) : std::string();
      const Handle space(H5Dget_space(d.dataset.get()), H5Sclose);
      if (space.valid()) H5Dvlen_reclaim(memory_type.get(), space.get(), H5P_DEFAULT, &text);
      return result;
    }
    const std::size_t size = H5Tget_size(d.type.get());  // checked: 1 to kMaxStringBytes
    H5Tset_size(memory_type.get(), size);
    H5Tset_strpad(memory_type.get(), H5T_STR_NULLPAD);
    std::vector<char> buffer(size, '\0');
    if (H5Dread(d.dataset.get(), memory_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()) <
        0) {
      fail("cannot read dataset " + name + hdf5::message());
    }
    std::string result = bounded_string(buffer.data(), buffer.size());
    if (H5Tget_strpad(d.type.get()) == H5T_STR_SPACEPAD) {
      result.erase(result.find_last_not_of(' ') + 1);
    }
    return result;
  }

  /// The string of dataset `name`, or "" if it does not exist.
  std::string optional_string(const std::string& name) const {
    return has(name) ? string(name) : std::string();
  }

  /// Reads and checks the header {m, n, nz, nzmax} of the sparse matrix in `group`.
  MatrixHeader header(const std::string& group) const {
    open(group, H5I_GROUP);
    MatrixHeader h;
    h.group = group;
    h.m = integer(group + "/m");
    h.n = integer(group + "/n");
    h.nz = integer(group + "/nz");
    h.nzmax = integer(group + "/nzmax");
    if (h.m < 0 || h.m > kMaxIndex) {
      fail("dataset " + group + "/m is " + std::to_string(h.m) + ", expected a row count in [0, " +
           std::to_string(kMaxIndex) + "]");
    }
    if (h.n < 0 || h.n > kMaxIndex) {
      fail("dataset " + group + "/n is " + std::to_string(h.n) +
           ", expected a column count in [0, " + std::to_string(kMaxIndex) + "]");
    }
    if (h.nz < -2 || h.nz > kMaxIndex) {
      fail("dataset " + group + "/nz is " + std::to_string(h.nz) +
           ", expected -1 (compressed columns), -2 (compressed rows) or a triplet count in [0, " +
           std::to_string(kMaxIndex) + "]");
    }
    if (h.nzmax < 0) {
      fail("dataset " + group + "/nzmax is " + std::to_string(h.nzmax) + ", expected >= 0");
    }
    if (h.nz > h.nzmax) {
      fail("dataset " + group + "/nz declares " + std::to_string(h.nz) +
           " triplets, more than nzmax = " + std::to_string(h.nzmax) + " (dataset " + group +
           "/nzmax), the room for entries the matrix was written with");
    }
    return h;
  }

  /// Opens the datasets p, i and x of the sparse matrix with header h and checks their lengths
  /// against the header: for triplets each has at least nz entries, for compressed storage p has
  /// one more entry than columns (rows). Nothing is read.
  MatrixData matrix_data(const MatrixHeader& h) const {
    const std::string& g = h.group;
    MatrixData data;
    data.h = h;
    if (h.nz >= 0) {
      const std::string expected = "nz = " + std::to_string(h.nz);
      data.i = dataset(g + "/i", Element::integer, h.nz, true, expected);
      data.p = dataset(g + "/p", Element::integer, h.nz, true, expected);
      data.x = dataset(g + "/x", Element::real, h.nz, true, expected);
    } else {
      const bool by_columns = h.nz == -1;
      const std::int64_t outer = by_columns ? h.n : h.m;
      data.p = dataset(g + "/p", Element::integer, outer + 1, false,
                       std::string(by_columns ? "n" : "m") + " + 1 = " + std::to_string(outer + 1) +
                           " for " + storage_name(h.nz));
      data.i = dataset(g + "/i", Element::integer);
      data.x = dataset(g + "/x", Element::real);
    }
    return data;
  }

  /// Reads the entries of the sparse matrix (see matrix_data()), checks every index and sums
  /// duplicates.
  SparseMatrix matrix(const MatrixData& data) const {
    const MatrixHeader& h = data.h;
    const std::string& g = h.group;
    std::vector<Eigen::Triplet<double, int>> entries;
    if (h.nz >= 0) {
      const auto rows = integers(data.i, h.nz);
      const auto cols = integers(data.p, h.nz);
      const auto x = reals(data.x, h.nz);
      entries.reserve(x.size());
      for (std::size_t k = 0; k < x.size(); ++k) {
        check_index(g + "/i", "row", rows[k], h.m, k);
        check_index(g + "/p", "column", cols[k], h.n, k);
        entries.emplace_back(static_cast<int>(rows[k]), static_cast<int>(cols[k]), x[k]);
      }
    } else {
      const bool by_columns = h.nz == -1;
      const std::int64_t outer = by_columns ? h.n : h.m;
      const std::int64_t inner = by_columns ? h.m : h.n;
      const std::string outer_name = by_columns ? "n" : "m";
      const auto p = integers(data.p, outer + 1);
      if (p.front() != 0) {
        fail("dataset " + g + "/p starts with " + std::to_string(p.front()) + ", expected 0");
      }
      for (std::int64_t k = 0; k < outer; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        if (p[kk + 1] < p[kk]) {
          fail("dataset " + g + "/p is not monotone: p[" + std::to_string(k) +
               "] = " + std::to_string(p[kk]) + " > p[" + std::to_string(k + 1) +
               "] = " + std::to_string(p[kk + 1]));
        }
      }
      const std::int64_t count = p.back();
      if (count > h.nzmax) {
        fail("dataset " + g + "/p ends with p[" + outer_name + "] = " + std::to_string(count) +
             " entries, more than nzmax = " + std::to_string(h.nzmax) + " (dataset " + g +
             "/nzmax), the room for entries the matrix was written with");
      }
      const std::string expected = "p[" + outer_name + "] = " + std::to_string(count);
      check_length(data.i, count, true, expected);
      check_length(data.x, count, true, expected);
      const auto index = integers(data.i, count);
      const auto x = reals(data.x, count);
      entries.reserve(x.size());
      for (std::int64_t k = 0; k < outer; ++k) {
        for (auto e = p[static_cast<std::size_t>(k)]; e < p[static_cast<std::size_t>(k) + 1]; ++e) {
          const auto ee = static_cast<std::size_t>(e);
          check_index(g + "/i", by_columns ? "row" : "column", index[ee], inner, ee);
          const auto a = static_cast<int>(k);
          const auto b = static_cast<int>(index[ee]);
          entries.emplace_back(by_columns ? b : a, by_columns ? a : b, x[ee]);
        }
      }
    }
    SparseMatrix A(static_cast<Eigen::Index>(h.m), static_cast<Eigen::Index>(h.n));
    A.setFromTriplets(entries.begin(), entries.end());  // sums duplicates
    return A;
  }

  /// Checks `/fclib_*/spacedim` = 3.
  void require_3d(const std::string& root) const {
    const std::int64_t spacedim = integer(root + "/spacedim");
    if (spacedim != 3) {
      fail("dataset " + root + "/spacedim is " + std::to_string(spacedim) +
           ", expected 3: grbd reads only 3D problems");
    }
  }

  /// Refuses problems with equality constraints: /fclib_local/R or V, or a non-empty
  /// /fclib_global/G.
  void require_no_equality_constraints(FclibKind kind) const {
    if (kind == FclibKind::local) {
      std::string present;
      for (const char* name : {"/fclib_local/R", "/fclib_local/V"}) {
        if (has(name)) present += (present.empty() ? "" : " and ") + std::string(name);
      }
      if (!present.empty()) {
        fail("has equality constraints (" + present +
             " present); grbd reads only problems without equality constraints");
      }
    } else if (has("/fclib_global/G")) {
      const MatrixHeader G = header("/fclib_global/G");
      if (G.m > 0 && G.n > 0) {
        fail("has equality constraints (/fclib_global/G is " + shape_text(G.m, G.n) +
             "); grbd reads only problems without equality constraints");
      }
    }
  }

  /// The kind of problem the file holds (/fclib_local is preferred if both are present).
  FclibKind kind() const {
    if (has("/fclib_local")) {
      open("/fclib_local", H5I_GROUP);
      return FclibKind::local;
    }
    if (has("/fclib_global")) {
      open("/fclib_global", H5I_GROUP);
      return FclibKind::global;
    }
    fail("holds neither group /fclib_local nor /fclib_global: not an FCLIB problem");
  }

  /// The friction coefficients of the dataset d (n entries), finite and ≥ 0.
  std::vector<double> friction_coefficients(const Dataset& d, std::int64_t n) const {
    std::vector<double> mu = reals(d, n);
    for (std::size_t k = 0; k < mu.size(); ++k) {
      if (mu[k] < 0.0) {
        fail("dataset " + d.name + " entry " + std::to_string(k) + " is " + format_number(mu[k]) +
             ", expected a friction coefficient >= 0");
      }
    }
    return mu;
  }

  void check_length(const Dataset& d, std::int64_t count, bool at_least,
                    const std::string& expected) const {
    const auto n = static_cast<hsize_t>(count);
    if (at_least ? d.length < n : d.length != n) {
      fail("dataset " + d.name + " has " + std::to_string(d.length) + " entries, expected " +
           (at_least ? "at least " : "") + expected);
    }
  }

 private:
  /// Refuses a path that is not a regular file, that does not exist or that cannot be opened for
  /// reading, each with its own message, before HDF5 opens it: opening a FIFO blocks until a
  /// writer comes, forever if none does. Records the file's size.
  void require_regular_file(const std::filesystem::path& path) {
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(path, error);
    const std::string reason = error ? " (" + error.message() + ")" : std::string();
    switch (status.type()) {
      case std::filesystem::file_type::regular:
        break;
      case std::filesystem::file_type::not_found:
        fail("no such file" + reason);
      case std::filesystem::file_type::directory:
        fail("is a directory, expected an HDF5 file");
      case std::filesystem::file_type::fifo:
        fail(
            "is a FIFO (named pipe), not a regular file: grbd reads FCLIB problems from regular "
            "files only (reading a pipe blocks until something writes to it)");
      case std::filesystem::file_type::socket:
        fail("is a socket, not a regular file: grbd reads FCLIB problems from regular files only");
      case std::filesystem::file_type::block:
      case std::filesystem::file_type::character:
        fail("is a device, not a regular file: grbd reads FCLIB problems from regular files only");
      default:
        if (error) fail("cannot be accessed" + reason);
        fail("is not a regular file: grbd reads FCLIB problems from regular files only");
    }
    // O_NONBLOCK: should the path have been replaced by a FIFO since, open() does not wait.
    const int fd = ::open(name_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
      const int code = errno;
      fail("cannot be opened for reading (" + std::system_category().message(code) + ")");
    }
    struct stat info {};
    const int stat_result = ::fstat(fd, &info);
    ::close(fd);
    if (stat_result != 0 || !S_ISREG(info.st_mode)) {
      fail("is not a regular file: grbd reads FCLIB problems from regular files only");
    }
    size_ = static_cast<std::uint64_t>(info.st_size);
  }

  /// Refuses `object` unless it is a hard link: soft and external links (and user-defined ones)
  /// are not followed. `what` says what was expected there.
  void require_hard_link(const std::string& object, const std::string& what) const {
    H5L_info_t info;
    if (H5Lget_info(file_.get(), object.c_str(), &info, H5P_DEFAULT) < 0) {
      fail("cannot read the link " + object + hdf5::message());
    }
    if (info.type == H5L_TYPE_HARD) return;
    std::string kind = "a user-defined link";
    std::string target;
    if (info.type == H5L_TYPE_SOFT || info.type == H5L_TYPE_EXTERNAL) {
      const bool soft = info.type == H5L_TYPE_SOFT;
      kind = soft ? "a soft link" : "an external link";
      const std::size_t size = info.u.val_size;
      if (size > 0 && size <= 4096) {
        std::vector<char> value(size + 2, '\0');  // NUL-terminated whatever the link holds
        if (H5Lget_val(file_.get(), object.c_str(), value.data(), size, H5P_DEFAULT) >= 0) {
          if (soft) {
            target = " to " + bounded_string(value.data(), size);
          } else {  // one byte of flags, the file name, NUL, the object's path, NUL
            const std::string file = bounded_string(value.data() + 1, size - 1);
            const std::size_t at = std::min(size, file.size() + 2);
            target = " to " + bounded_string(value.data() + at, size - at) + " in file " + file;
          }
        }
      }
    }
    fail(object + " is " + kind + target + ", expected " + what +
         " stored in this file: grbd follows no links (an external link can name any file, even "
         "a pipe that blocks forever)");
  }

  /// Checks the element type of d against `element`: standard integers, IEEE floats (or
  /// integers where reals are read), strings of at most kMaxStringBytes.
  void check_element(Dataset& d, Element element) const {
    const std::string& name = d.name;
    const hid_t type = d.type.get();
    const H5T_class_t type_class = H5Tget_class(type);
    const std::size_t size = H5Tget_size(type);
    if (element == Element::string) {
      if (type_class != H5T_STRING) {
        fail("dataset " + name + " holds " + type_class_name(type_class) +
             " data, expected string data");
      }
      const htri_t variable = H5Tis_variable_str(type);
      if (variable < 0) fail("cannot read the string type of dataset " + name + hdf5::message());
      d.variable_string = variable > 0;
      if (!d.variable_string && (size == 0 || size > kMaxStringBytes)) {
        fail("dataset " + name + " holds a string of " + std::to_string(size) +
             " bytes, expected 1 to " + std::to_string(kMaxStringBytes) +
             " bytes (an info string)");
      }
      return;
    }
    const bool accepted = element == Element::integer
                              ? type_class == H5T_INTEGER
                              : (type_class == H5T_FLOAT || type_class == H5T_INTEGER);
    if (!accepted) {
      fail("dataset " + name + " holds " + type_class_name(type_class) + " data, expected " +
           (element == Element::integer ? "integer" : "floating-point") + " data");
    }
    if (type_class == H5T_INTEGER && !standard_integer(type)) {
      const bool size_ok = size == 1 || size == 2 || size == 4 || size == 8;
      fail("dataset " + name + " holds integers of " + std::to_string(size) + " bytes" +
           (size_ok
                ? " in a non-standard layout (precision " + std::to_string(H5Tget_precision(type)) +
                      " bits at offset " + std::to_string(H5Tget_offset(type)) + ")"
                : std::string()) +
           ", expected standard 1-, 2-, 4- or 8-byte integers");
    }
    if (type_class == H5T_FLOAT && !ieee_float(type)) {
      const bool size_ok = size == 4 || size == 8;
      fail("dataset " + name + " holds floating-point numbers of " + std::to_string(size) +
           " bytes" + (size_ok ? " in a non-IEEE layout" : "") +
           ", expected IEEE 754 doubles (8 bytes) or singles (4 bytes)");
    }
  }

  /// Checks that the data of d lie in this file and fit in it: no external storage or virtual
  /// layout; uncompressed data not larger than the file, a contiguous block inside it, chunks
  /// all written; compressed data stored at all; chunks not larger than needed.
  void check_storage(const Dataset& d) const {
    const std::string& name = d.name;
    const Handle plist_handle(H5Dget_create_plist(d.dataset.get()), H5Pclose);
    if (!plist_handle.valid()) fail("cannot read the storage of dataset " + name + hdf5::message());
    const hid_t plist = plist_handle.get();
    const H5D_layout_t layout = H5Pget_layout(plist);
    if (layout == H5D_VIRTUAL) {
      fail("dataset " + name +
           " is a virtual dataset, whose data lie in other files: grbd reads only data stored in "
           "the file itself");
    }
    if (layout != H5D_COMPACT && layout != H5D_CONTIGUOUS && layout != H5D_CHUNKED) {
      fail("cannot read the storage layout of dataset " + name + hdf5::message());
    }
    const int external = H5Pget_external_count(plist);
    if (external != 0) {
      fail("dataset " + name + " keeps its data in " +
           (external > 0 ? std::to_string(external) : std::string("some")) +
           " external file(s): grbd reads only data stored in the file itself");
    }
    if (d.variable_string) return;  // its single string lives in the file's heap
    const std::uint64_t element = H5Tget_size(d.type.get());
    const std::uint64_t length = d.length;
    const std::uint64_t bytes =
        element > 0 && length > std::numeric_limits<std::uint64_t>::max() / element
            ? std::numeric_limits<std::uint64_t>::max()
            : length * element;
    const std::string declared = "dataset " + name + " declares " + std::to_string(length) +
                                 " entries of " + std::to_string(element) + " bytes (" +
                                 std::to_string(bytes) + " bytes)";
    const int filters = layout == H5D_CHUNKED ? H5Pget_nfilters(plist) : 0;
    if (filters < 0) fail("cannot read the filters of dataset " + name + hdf5::message());
    if (filters == 0) {
      if (bytes > size_) {
        fail(declared + ", more than the " + std::to_string(size_) +
             " bytes of the whole file: uncompressed data that large cannot be in it");
      }
      if (layout == H5D_CONTIGUOUS && bytes > 0) {
        const haddr_t offset = H5Dget_offset(d.dataset.get());
        if (offset == HADDR_UNDEF) {
          fail(declared + " but stores none of them (its data were never written)");
        }
        if (offset > size_ || bytes > size_ - offset) {
          fail(declared + " at byte " + std::to_string(offset) + ", past the end of the " +
               std::to_string(size_) + "-byte file");
        }
      }
    }
    if (layout == H5D_CHUNKED) {
      hsize_t chunk[1] = {0};
      if (H5Pget_chunk(plist, 1, chunk) != 1) {
        fail("cannot read the chunks of dataset " + name + hdf5::message());
      }
      const std::uint64_t chunk_bytes =
          chunk[0] > std::numeric_limits<std::uint64_t>::max() / std::max<std::uint64_t>(element, 1)
              ? std::numeric_limits<std::uint64_t>::max()
              : chunk[0] * element;
      if (chunk_bytes > std::max(bytes, kMaxChunkBytes)) {
        fail("dataset " + name + " is stored in chunks of " + std::to_string(chunk_bytes) +
             " bytes, more than its " + std::to_string(bytes) + " bytes of data and than " +
             std::to_string(kMaxChunkBytes) + " bytes");
      }
      if (bytes > 0) {
        const hsize_t stored = H5Dget_storage_size(d.dataset.get());
        if (stored == 0) fail(declared + " but stores none of them (no chunk was written)");
        if (filters == 0 && stored < bytes) {
          fail(declared + " but stores only " + std::to_string(stored) +
               " bytes of them (chunks never written)");
        }
      }
    }
  }

  void check_index(const std::string& name, const char* what, std::int64_t index,
                   std::int64_t bound, std::size_t entry) const {
    if (index < 0 || index >= bound) {
      fail("dataset " + name + ": " + what + " index " + std::to_string(index) + " (entry " +
           std::to_string(entry) + ") out of range [0, " + std::to_string(bound) + ")");
    }
  }

  std::vector<double> finite(const std::string& name, std::vector<double> values) const {
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (!std::isfinite(values[k])) {
        fail("dataset " + name + " entry " + std::to_string(k) + " is " + format_number(values[k]) +
             ", expected a finite number");
      }
    }
    return values;
  }

  std::string name_;
  Handle file_;
  std::uint64_t size_ = 0;
};

std::vector<Vector3> to_vector3(const std::vector<double>& values) {
  std::vector<Vector3> result(values.size() / 3);
  for (std::size_t i = 0; i < result.size(); ++i) {
    result[i] = Vector3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
  }
  return result;
}

/// The sizes of a problem, from the headers of its matrices: n contacts (W is 3n × 3n, H is
/// m × 3n), m degrees of freedom (M is m × m) for a global problem.
struct Sizes {
  FclibKind kind = FclibKind::local;
  std::string root;          ///< "/fclib_local" or "/fclib_global"
  std::int64_t n = 0;        ///< contacts
  std::int64_t m = 0;        ///< degrees of freedom (global problems)
  MatrixHeader W, M, H;      ///< the headers read (W for local, M and H for global problems)
  std::string contacts_why;  ///< where n comes from, for messages

  std::string mu_name() const { return root + "/vectors/mu"; }
  /// "n = <n> (<why>)", the expected length of mu.
  std::string n_text() const { return "n = " + std::to_string(n) + " (" + contacts_why + ")"; }
  /// "3n = <3n> (<why>)", the expected length of a per-unknown dataset.
  std::string three_n() const {
    return "3n = " + std::to_string(3 * n) + " (" + contacts_why + "; " + mu_name() +
           " has n = " + std::to_string(n) + " entries)";
  }
  /// "m = <m> (...)", the expected length of a per-degree-of-freedom dataset.
  std::string m_text() const {
    return "m = " + std::to_string(m) + " (the size of " + M.group + ")";
  }
};

/// Checks the group of `kind` (a file of the other kind is named as such), spacedim = 3 and the
/// absence of equality constraints, then reads the headers of W (local) or M and H (global) and
/// derives n and m from them, checking that they agree. Nothing but the headers is read.
Sizes read_sizes(const File& file, FclibKind kind) {
  const bool local = kind == FclibKind::local;
  Sizes s;
  s.kind = kind;
  s.root = local ? "/fclib_local" : "/fclib_global";
  const std::string other = local ? "/fclib_global" : "/fclib_local";
  const char* name = local ? "local" : "global";
  const char* other_name = local ? "global" : "local";
  if (!file.has(s.root)) {
    if (file.has(other)) {
      file.fail(std::string("holds a ") + other_name + " problem (" + other + "), not a " + name +
                " one (group " + s.root + " is missing)");
    }
    file.fail("group " + s.root + " is missing: not a " + name + " FCLIB problem");
  }
  file.open(s.root, H5I_GROUP);
  file.require_3d(s.root);
  file.require_no_equality_constraints(kind);
  if (local) {
    s.W = file.header("/fclib_local/W");
    if (s.W.m != s.W.n || s.W.m % 3 != 0) {
      file.fail("matrix /fclib_local/W is " + shape_text(s.W.m, s.W.n) +
                ", expected a square 3n × 3n matrix for n contacts");
    }
    s.n = s.W.m / 3;
    s.contacts_why = "/fclib_local/W is " + shape_text(s.W.m, s.W.n) + " = 3n × 3n";
  } else {
    s.M = file.header("/fclib_global/M");
    if (s.M.m != s.M.n) {
      file.fail("matrix /fclib_global/M is " + shape_text(s.M.m, s.M.n) +
                ", expected a square m × m mass matrix");
    }
    s.m = s.M.m;
    s.H = file.header("/fclib_global/H");
    if (s.H.m != s.m || s.H.n % 3 != 0) {
      file.fail("matrix /fclib_global/H is " + shape_text(s.H.m, s.H.n) +
                ", expected m × 3n with " + s.m_text() + " and n contacts");
    }
    s.n = s.H.n / 3;
    s.contacts_why = "/fclib_global/H is " + shape_text(s.H.m, s.H.n) + " = m × 3n";
  }
  return s;
}

/// Checks the local problem read with validate() and throws grbd::Error naming the file and the
/// dataset that failed (`W`, `q`, `mu` are the datasets the problem came from).
void validate_read(const File& file, const LocalProblem& problem, const std::string& W,
                   const std::string& q, const std::string& mu) {
  try {
    validate(problem);
  } catch (const InvalidArgument& error) {
    const std::string message = error.what();
    const std::string& dataset = message.find("q of contact") != std::string::npos    ? q
                                 : message.find("mu of contact") != std::string::npos ? mu
                                                                                      : W;
    file.fail(dataset + " does not give a valid local problem: " + message);
  }
}

LocalProblem read_local(const File& file) {
  const Sizes s = read_sizes(file, FclibKind::local);
  // Every length is checked before anything is read.
  const Dataset mu = file.dataset(s.mu_name(), Element::real, s.n, false, s.n_text());
  const Dataset q =
      file.dataset("/fclib_local/vectors/q", Element::real, 3 * s.n, false, s.three_n());
  const MatrixData W = file.matrix_data(s.W);
  LocalProblem problem;
  problem.mu = file.friction_coefficients(mu, s.n);
  problem.q = to_vector3(file.reals(q, 3 * s.n));
  problem.W = to_block_sparse(file.matrix(W));
  validate_read(file, problem, "matrix /fclib_local/W", "dataset /fclib_local/vectors/q",
                "dataset " + s.mu_name());
  return problem;
}

GlobalProblem read_global(const File& file) {
  const Sizes s = read_sizes(file, FclibKind::global);
  // Every length is checked before anything is read.
  const Dataset mu = file.dataset(s.mu_name(), Element::real, s.n, false, s.n_text());
  const Dataset f = file.dataset("/fclib_global/vectors/f", Element::real, s.m, false, s.m_text());
  const Dataset w =
      file.dataset("/fclib_global/vectors/w", Element::real, 3 * s.n, false, s.three_n());
  const MatrixData M = file.matrix_data(s.M);
  const MatrixData H = file.matrix_data(s.H);
  GlobalProblem problem;
  problem.mu = file.friction_coefficients(mu, s.n);
  const auto f_values = file.reals(f, s.m);
  const auto w_values = file.reals(w, 3 * s.n);
  problem.f = Eigen::Map<const Eigen::VectorXd>(f_values.data(), s.m);
  problem.w = Eigen::Map<const Eigen::VectorXd>(w_values.data(), 3 * s.n);
  problem.M = file.matrix(M);
  problem.H = file.matrix(H);
  return problem;
}

FclibInfo read_info(const File& file) {
  FclibInfo info;
  info.kind = file.kind();
  const Sizes s = read_sizes(file, info.kind);
  file.dataset(s.mu_name(), Element::real, s.n, false, s.n_text());  // the count agrees
  info.contacts = static_cast<int>(s.n);
  info.title = file.optional_string(s.root + "/info/title");
  info.description = file.optional_string(s.root + "/info/description");
  info.math_info = file.optional_string(s.root + "/info/math_info");
  const std::string guess = "/guesses/1/r";
  if (file.has(guess)) {
    const Dataset r = file.dataset(guess, Element::real, 3 * s.n, false, s.three_n());
    info.guess = to_vector3(file.reals(r, 3 * s.n));
  }
  return info;
}

}  // namespace

/// Opens the file, determines its kind (/fclib_local if present, else /fclib_global), checks
/// spacedim = 3 and the absence of equality constraints, counts the contacts (from the header of
/// W, or of H; /fclib_*/vectors/mu must have one entry each) and reads the optional info strings
/// and the guess /guesses/1/r (3n entries). The matrices' entries are not read.
FclibInfo read_fclib_info(const std::filesystem::path& path) {
  const std::lock_guard lock(hdf5::mutex());
  const QuietErrors quiet;
  return read_info(File(path));
}

/// Reads /fclib_local: spacedim = 3, no R or V, W 3n × 3n in any storage kind (cut into 3 × 3
/// blocks), mu with n entries (finite, ≥ 0), q with 3n finite entries; the problem passes
/// validate().
LocalProblem read_fclib_local(const std::filesystem::path& path) {
  const std::lock_guard lock(hdf5::mutex());
  const QuietErrors quiet;
  return read_local(File(path));
}

/// Reads /fclib_global: spacedim = 3, no (non-empty) G, M m × m, H m × 3n, μ (n entries), f (m),
/// w (3n).
GlobalProblem read_fclib_global(const std::filesystem::path& path) {
  const std::lock_guard lock(hdf5::mutex());
  const QuietErrors quiet;
  return read_global(File(path));
}

/// Reads the local problem of the file, or its global problem converted with to_local(); an
/// InvalidArgument of to_local() (M not positive definite or numerically singular, ...) or of
/// validate() on its result is thrown again with the file's path and the global problem's
/// datasets in front.
LocalProblem read_fclib_as_local(const std::filesystem::path& path) {
  GlobalProblem global;
  {
    const std::lock_guard lock(hdf5::mutex());
    const QuietErrors quiet;
    const File file(path);
    if (file.kind() == FclibKind::local) return read_local(file);
    global = read_global(file);
  }
  const std::string source =
      path.string() +
      ": the global problem /fclib_global (M = /fclib_global/M, H = /fclib_global/H, f and w in "
      "/fclib_global/vectors)";
  LocalProblem local;
  try {
    local = to_local(global);
  } catch (const InvalidArgument& error) {
    throw InvalidArgument(source + " cannot be put in local form: " + error.what());
  }
  try {
    validate(local);
  } catch (const InvalidArgument& error) {
    throw InvalidArgument(
        source + " gives an invalid local problem W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w: " + error.what());
  }
  return local;
}

/// Reads the sparse matrix in `group` ("/fclib_local/W", or without the leading slash): checks
/// the header, the lengths of p, i and x for the storage kind, p monotone from 0 for compressed
/// storage, every index in range and every value finite; duplicates are summed. A matrix read on
/// its own has no vector to check its shape against: a row or column count larger than the file's
/// size in bytes is refused (grbd allocates 4 bytes per row and per column of it).
Eigen::SparseMatrix<double> read_fclib_matrix(const std::filesystem::path& path,
                                              const std::string& group) {
  std::string name;  // "/a/b": one leading slash, none repeated or trailing
  for (const char c : group) {
    if (c != '/' || (!name.empty() && name.back() != '/')) name += c;
  }
  if (!name.empty() && name.back() == '/') name.pop_back();
  if (name.empty()) {
    throw InvalidArgument("read_fclib_matrix: expected the path of a matrix group, found \"" +
                          group + "\"");
  }
  name.insert(name.begin(), '/');
  const std::lock_guard lock(hdf5::mutex());
  const QuietErrors quiet;
  const File file(path);
  const MatrixHeader h = file.header(name);
  const auto size = static_cast<std::int64_t>(std::min<std::uint64_t>(file.size(), kMaxIndex));
  if (h.m > size || h.n > size) {
    file.fail("matrix " + name + " declares " + shape_text(h.m, h.n) +
              ", a dimension larger than the file's " + std::to_string(file.size()) +
              " bytes: no data of the file backs it");
  }
  return file.matrix(file.matrix_data(h));
}

}  // namespace grbd::contact
