/// \file
/// \brief The reader of FCLIB files: the HDF5 groups /fclib_local and /fclib_global, their sparse
/// matrices in any of the three storage kinds, with a check of every dataset before it is used.
///
/// HDF5 is used through its C API in serial mode with the default property lists. Every handle
/// lives in an RAII Handle, so nothing stays open when a check throws; HDF5's automatic printing of
/// its error stack is switched off while grbd reads (the innermost HDF5 message is put into the
/// grbd::Error instead), and the calls into HDF5 are serialized by a mutex because the library is
/// not built thread-safe.

#include "grbd/contact/fclib.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <system_error>
#include <utility>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// The largest row or column count, entry count or vector length read: Eigen's sparse matrices
/// index with int.
constexpr std::int64_t kMaxIndex = std::numeric_limits<int>::max();

/// Serializes grbd's calls into HDF5 (and the error-printing switch below).
std::mutex& hdf5_mutex() {
  static std::mutex mutex;
  return mutex;
}

/// Switches HDF5's automatic printing of the error stack off for its lifetime and restores the
/// previous handler afterwards.
class QuietErrors {
 public:
  QuietErrors() {
    H5Eget_auto2(H5E_DEFAULT, &function_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, function_, data_); }
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
};

/// An HDF5 identifier (file, group, dataset, dataspace, datatype) that is closed when the Handle
/// goes out of scope. A negative id is "no object".
class Handle {
 public:
  using Close = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Close close) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& other) noexcept
      : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      close_ = other.close_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  void reset() {
    if (id_ >= 0 && close_ != nullptr) close_(id_);
    id_ = H5I_INVALID_HID;
  }
  hid_t id_ = H5I_INVALID_HID;
  Close close_ = nullptr;
};

/// The description of the innermost error on HDF5's default error stack (where the failure was
/// detected), or "" if the stack is empty. Must be called right after the failing HDF5 call.
std::string hdf5_message() {
  std::string message;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* error, void* data) -> herr_t {
        if (n == 0 && error != nullptr && error->desc != nullptr) {
          *static_cast<std::string*>(data) = error->desc;
        }
        return 0;
      },
      &message);
  return message.empty() ? std::string() : " (HDF5: " + message + ")";
}

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

/// What a dataset's elements must be.
enum class Element { integer, real, string };

/// An open dataset with its shape: `length` entries (1 for a scalar dataspace).
struct Dataset {
  std::string name;
  Handle dataset;
  Handle type;
  hsize_t length = 0;
};

/// The header {m, n, nz, nzmax} of an FCLIB sparse matrix.
struct MatrixHeader {
  std::string group;
  std::int64_t m = 0;
  std::int64_t n = 0;
  std::int64_t nz = 0;
  std::int64_t nzmax = 0;
};

std::string storage_name(std::int64_t nz) {
  if (nz == -1) return "compressed columns (nz = -1)";
  if (nz == -2) return "compressed rows (nz = -2)";
  return "triplets (nz = " + std::to_string(nz) + ")";
}

/// An open FCLIB file and the checked reads of its objects. Every failure throws grbd::Error whose
/// message starts with the file's path.
class File {
 public:
  explicit File(const std::filesystem::path& path) : name_(path.string()) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (!std::filesystem::exists(status)) fail("no such file");
    if (std::filesystem::is_directory(status)) fail("is a directory, expected an HDF5 file");
    const htri_t is_hdf5 = H5Fis_hdf5(name_.c_str());
    if (is_hdf5 == 0) fail("is not an HDF5 file (no HDF5 signature found)");
    if (is_hdf5 < 0) fail("cannot be read as an HDF5 file" + hdf5_message());
    file_ = Handle(H5Fopen(name_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!file_.valid()) {
      fail("cannot be opened as an HDF5 file, it may be truncated or damaged" + hdf5_message());
    }
  }

  /// Throws grbd::Error "<file>: <message>".
  [[noreturn]] void fail(const std::string& message) const { throw Error(name_ + ": " + message); }

  const std::string& name() const { return name_; }

  /// Whether `object` (an absolute path such as "/fclib_local/R") exists: every component is a
  /// link that resolves, every component but the last a group.
  bool has(const std::string& object) const {
    std::size_t start = 1;
    while (start <= object.size()) {
      const std::size_t end = std::min(object.find('/', start), object.size());
      const std::string prefix = object.substr(0, end);
      if (H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
      if (H5Oexists_by_name(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
      if (end < object.size()) {
        const Handle handle(H5Oopen(file_.get(), prefix.c_str(), H5P_DEFAULT), H5Oclose);
        if (!handle.valid() || H5Iget_type(handle.get()) != H5I_GROUP) return false;
      }
      start = end + 1;
    }
    return true;
  }

  /// Opens `object`, which must be a group or a dataset (`expected`); names the first missing
  /// group on the way, or what the object is instead.
  Handle open(const std::string& object, H5I_type_t expected) const {
    const std::string what = expected == H5I_GROUP ? "group" : "dataset";
    std::size_t start = 1;
    while (start <= object.size()) {
      const std::size_t end = std::min(object.find('/', start), object.size());
      const std::string prefix = object.substr(0, end);
      const bool last = end == object.size();
      if (H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0 ||
          H5Oexists_by_name(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) {
        if (last) fail(what + " " + object + " is missing");
        fail("group " + prefix + " is missing (expected " + what + " " + object + ")");
      }
      Handle handle(H5Oopen(file_.get(), prefix.c_str(), H5P_DEFAULT), H5Oclose);
      if (!handle.valid()) fail("cannot open " + prefix + hdf5_message());
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

  /// Opens dataset `name` and checks its element class and rank: a scalar or one-dimensional
  /// dataspace (an empty one counts as 0 entries).
  Dataset dataset(const std::string& name, Element element) const {
    Dataset d;
    d.name = name;
    d.dataset = open(name, H5I_DATASET);
    d.type = Handle(H5Dget_type(d.dataset.get()), H5Tclose);
    const Handle space(H5Dget_space(d.dataset.get()), H5Sclose);
    if (!d.type.valid() || !space.valid()) {
      fail("cannot read the type or shape of dataset " + name + hdf5_message());
    }
    const H5T_class_t type_class = H5Tget_class(d.type.get());
    const bool accepted = element == Element::integer ? type_class == H5T_INTEGER
                          : element == Element::real
                              ? (type_class == H5T_FLOAT || type_class == H5T_INTEGER)
                              : type_class == H5T_STRING;
    if (!accepted) {
      const char* expected = element == Element::integer ? "integer"
                             : element == Element::real  ? "floating-point"
                                                         : "string";
      fail("dataset " + name + " holds " + type_class_name(type_class) + " data, expected " +
           expected + " data");
    }
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
        H5Sget_simple_extent_dims(space.get(), dims, nullptr);
        d.length = dims[0];
        break;
      }
      default:
        fail("cannot read the shape of dataset " + name + hdf5_message());
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
    if (status < 0) fail("cannot read dataset " + d.name + hdf5_message());
    return values;
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

  /// The first `count` integers of dataset `name`, which must have `count` entries, or at least
  /// `count` if `at_least`; `expected` says where count comes from, e.g. "n + 1 = 31".
  std::vector<std::int64_t> integers(const std::string& name, std::int64_t count, bool at_least,
                                     const std::string& expected) const {
    const Dataset d = dataset(name, Element::integer);
    check_length(d, count, at_least, expected);
    return read<std::int64_t>(d, static_cast<hsize_t>(count), H5T_NATIVE_INT64);
  }

  /// The first `count` finite reals of dataset `name` (see integers()).
  std::vector<double> reals(const std::string& name, std::int64_t count, bool at_least,
                            const std::string& expected) const {
    const Dataset d = dataset(name, Element::real);
    check_length(d, count, at_least, expected);
    return finite(d.name, read<double>(d, static_cast<hsize_t>(count), H5T_NATIVE_DOUBLE));
  }

  /// All finite reals of dataset `name`, a vector of at most kMaxIndex / 3 entries.
  std::vector<double> reals(const std::string& name) const {
    const Dataset d = dataset(name, Element::real);
    if (d.length > static_cast<hsize_t>(kMaxIndex / 3)) {
      fail("dataset " + name + " has " + std::to_string(d.length) + " entries, more than the " +
           std::to_string(kMaxIndex / 3) + " that grbd reads");
    }
    return finite(d.name, read<double>(d, d.length, H5T_NATIVE_DOUBLE));
  }

  /// The number of entries of dataset `name` (any numeric type).
  hsize_t length(const std::string& name) const { return dataset(name, Element::real).length; }

  /// The string of dataset `name` (a scalar or a one-entry dataset, fixed or variable length).
  std::string string(const std::string& name) const {
    const Dataset d = dataset(name, Element::string);
    if (d.length != 1) {
      fail("dataset " + name + " has " + std::to_string(d.length) +
           " entries, expected a single string");
    }
    const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
    if (!memory_type.valid()) fail("cannot read dataset " + name + hdf5_message());
    H5Tset_cset(memory_type.get(), H5Tget_cset(d.type.get()));
    const htri_t variable = H5Tis_variable_str(d.type.get());
    if (variable < 0) fail("cannot read the string type of dataset " + name + hdf5_message());
    if (variable > 0) {
      H5Tset_size(memory_type.get(), H5T_VARIABLE);
      char* text = nullptr;
      if (H5Dread(d.dataset.get(), memory_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &text) < 0) {
        fail("cannot read dataset " + name + hdf5_message());
      }
      std::string result = text != nullptr ? std::string(text) : std::string();
      const Handle space(H5Dget_space(d.dataset.get()), H5Sclose);
      if (space.valid()) H5Dvlen_reclaim(memory_type.get(), space.get(), H5P_DEFAULT, &text);
      return result;
    }
    const std::size_t size = H5Tget_size(d.type.get());
    if (size == 0) fail("cannot read the string size of dataset " + name + hdf5_message());
    H5Tset_size(memory_type.get(), size);
    H5Tset_strpad(memory_type.get(), H5T_STR_NULLPAD);
    std::vector<char> buffer(size, '\0');
    if (H5Dread(d.dataset.get(), memory_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()) <
        0) {
      fail("cannot read dataset " + name + hdf5_message());
    }
    std::string result(buffer.data(),
                       std::find(buffer.begin(), buffer.end(), '\0') - buffer.begin());
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
    return h;
  }

  /// Reads the entries of the sparse matrix with header h, checks every index and sums duplicates.
  SparseMatrix matrix(const MatrixHeader& h) const {
    const std::string& g = h.group;
    std::vector<Eigen::Triplet<double, int>> entries;
    if (h.nz >= 0) {
      const std::string expected = "nz = " + std::to_string(h.nz);
      const auto rows = integers(g + "/i", h.nz, true, expected);
      const auto cols = integers(g + "/p", h.nz, true, expected);
      const auto x = reals(g + "/x", h.nz, true, expected);
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
      const auto p = integers(
          g + "/p", outer + 1, false,
          outer_name + " + 1 = " + std::to_string(outer + 1) + " for " + storage_name(h.nz));
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
      if (count > kMaxIndex) {
        fail("dataset " + g + "/p ends with " + std::to_string(count) + ", more than the " +
             std::to_string(kMaxIndex) + " entries that grbd reads");
      }
      const std::string expected = "p[" + outer_name + "] = " + std::to_string(count);
      const auto index = integers(g + "/i", count, true, expected);
      const auto x = reals(g + "/x", count, true, expected);
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
        fail("has equality constraints (/fclib_global/G is " + std::to_string(G.m) + " × " +
             std::to_string(G.n) + "); grbd reads only problems without equality constraints");
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

  /// The friction coefficients at `name`, finite and ≥ 0.
  std::vector<double> friction_coefficients(const std::string& name) const {
    std::vector<double> mu = reals(name);
    for (std::size_t k = 0; k < mu.size(); ++k) {
      if (mu[k] < 0.0) {
        fail("dataset " + name + " entry " + std::to_string(k) + " is " + format_number(mu[k]) +
             ", expected a friction coefficient >= 0");
      }
    }
    return mu;
  }

 private:
  void check_length(const Dataset& d, std::int64_t count, bool at_least,
                    const std::string& expected) const {
    const auto n = static_cast<hsize_t>(count);
    if (at_least ? d.length < n : d.length != n) {
      fail("dataset " + d.name + " has " + std::to_string(d.length) + " entries, expected " +
           (at_least ? "at least " : "") + expected);
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
};

std::string contacts_text(std::size_t n, const std::string& mu) {
  return "n = " + std::to_string(n) + " contacts, the entries of " + mu;
}

std::vector<Vector3> to_vector3(const std::vector<double>& values) {
  std::vector<Vector3> result(values.size() / 3);
  for (std::size_t i = 0; i < result.size(); ++i) {
    result[i] = Vector3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
  }
  return result;
}

/// Checks that the matrix with header h is rows × cols.
void require_shape(const File& file, const MatrixHeader& h, std::int64_t rows, std::int64_t cols,
                   const std::string& expected, const std::string& why) {
  if (h.m != rows || h.n != cols) {
    file.fail("matrix " + h.group + " is " + std::to_string(h.m) + " × " + std::to_string(h.n) +
              ", expected " + expected + " = " + std::to_string(rows) + " × " +
              std::to_string(cols) + " (" + why + ")");
  }
}

/// What a local and a global problem start with: the group of `kind` (a file of the other kind
/// is named as such), spacedim = 3, no equality constraints, and μ, which counts the contacts.
struct ProblemHead {
  std::vector<double> mu;  ///< one friction coefficient per contact
  std::int64_t n3 = 0;     ///< 3n, the number of contact unknowns
  std::string why;         ///< where n comes from, for messages
  /// "3n = <3n> (<why>)", the expected length of a per-unknown dataset.
  std::string three_n() const { return "3n = " + std::to_string(n3) + " (" + why + ")"; }
};

ProblemHead read_head(const File& file, FclibKind kind) {
  const bool local = kind == FclibKind::local;
  const std::string root = local ? "/fclib_local" : "/fclib_global";
  const std::string other = local ? "/fclib_global" : "/fclib_local";
  const char* name = local ? "local" : "global";
  const char* other_name = local ? "global" : "local";
  if (!file.has(root)) {
    if (file.has(other)) {
      file.fail(std::string("holds a ") + other_name + " problem (" + other + "), not a " + name +
                " one (group " + root + " is missing)");
    }
    file.fail("group " + root + " is missing: not a " + name + " FCLIB problem");
  }
  file.open(root, H5I_GROUP);
  file.require_3d(root);
  file.require_no_equality_constraints(kind);
  const std::string mu_name = root + "/vectors/mu";
  ProblemHead head;
  head.mu = file.friction_coefficients(mu_name);
  head.n3 = static_cast<std::int64_t>(3 * head.mu.size());
  head.why = contacts_text(head.mu.size(), mu_name);
  return head;
}

LocalProblem read_local(const File& file) {
  ProblemHead head = read_head(file, FclibKind::local);
  LocalProblem problem;
  problem.q = to_vector3(file.reals("/fclib_local/vectors/q", head.n3, false, head.three_n()));
  const MatrixHeader W = file.header("/fclib_local/W");
  require_shape(file, W, head.n3, head.n3, "3n × 3n", head.why);
  problem.W = to_block_sparse(file.matrix(W));
  problem.mu = std::move(head.mu);
  return problem;
}

GlobalProblem read_global(const File& file) {
  ProblemHead head = read_head(file, FclibKind::global);
  const MatrixHeader M = file.header("/fclib_global/M");
  require_shape(file, M, M.m, M.m, "a square m × m", "m = " + std::to_string(M.m) + " rows");
  const std::int64_t m = M.m;
  const std::string m_text = "m = " + std::to_string(m) + " (the size of /fclib_global/M)";
  const MatrixHeader H = file.header("/fclib_global/H");
  require_shape(file, H, m, head.n3, "m × 3n", m_text + ", " + head.why);
  const auto f = file.reals("/fclib_global/vectors/f", m, false, m_text);
  const auto w = file.reals("/fclib_global/vectors/w", head.n3, false, head.three_n());
  GlobalProblem problem;
  problem.f = Eigen::Map<const Eigen::VectorXd>(f.data(), static_cast<Eigen::Index>(f.size()));
  problem.w = Eigen::Map<const Eigen::VectorXd>(w.data(), static_cast<Eigen::Index>(w.size()));
  problem.M = file.matrix(M);
  problem.H = file.matrix(H);
  problem.mu = std::move(head.mu);
  return problem;
}

FclibInfo read_info(const File& file) {
  FclibInfo info;
  info.kind = file.kind();
  const std::string root = info.kind == FclibKind::local ? "/fclib_local" : "/fclib_global";
  file.require_3d(root);
  file.require_no_equality_constraints(info.kind);
  const std::string mu_name = root + "/vectors/mu";
  const hsize_t n = file.length(mu_name);
  if (n > static_cast<hsize_t>(kMaxIndex / 3)) {
    file.fail("dataset " + mu_name + " has " + std::to_string(n) + " entries, more than the " +
              std::to_string(kMaxIndex / 3) + " contacts that grbd reads");
  }
  info.contacts = static_cast<int>(n);
  info.title = file.optional_string(root + "/info/title");
  info.description = file.optional_string(root + "/info/description");
  info.math_info = file.optional_string(root + "/info/math_info");
  const std::string guess = "/guesses/1/r";
  if (file.has(guess)) {
    const auto n3 = static_cast<std::int64_t>(3 * n);
    info.guess = to_vector3(file.reals(
        guess, n3, false, "3n = " + std::to_string(n3) + " (" + contacts_text(n, mu_name) + ")"));
  }
  return info;
}

}  // namespace

/// Opens the file, determines its kind (/fclib_local if present, else /fclib_global), checks
/// spacedim = 3 and the absence of equality constraints, counts the contacts (the entries of
/// /fclib_*/vectors/mu) and reads the optional info strings and the guess /guesses/1/r (3n
/// entries). The matrices are not read.
FclibInfo read_fclib_info(const std::filesystem::path& path) {
  const std::lock_guard lock(hdf5_mutex());
  const QuietErrors quiet;
  return read_info(File(path));
}

/// Reads /fclib_local: spacedim = 3, no R or V, n = the entries of vectors/mu (finite, ≥ 0), q
/// with 3n finite entries, W 3n × 3n in any storage kind, cut into 3 × 3 blocks.
LocalProblem read_fclib_local(const std::filesystem::path& path) {
  const std::lock_guard lock(hdf5_mutex());
  const QuietErrors quiet;
  return read_local(File(path));
}

/// Reads /fclib_global: spacedim = 3, no (non-empty) G, μ (n entries), M m × m, H m × 3n, f (m),
/// w (3n).
GlobalProblem read_fclib_global(const std::filesystem::path& path) {
  const std::lock_guard lock(hdf5_mutex());
  const QuietErrors quiet;
  return read_global(File(path));
}

/// Reads the local problem of the file, or its global problem converted with to_local(); an
/// InvalidArgument of to_local() (M not positive definite, ...) is thrown again with the file's
/// path in front.
LocalProblem read_fclib_as_local(const std::filesystem::path& path) {
  GlobalProblem global;
  {
    const std::lock_guard lock(hdf5_mutex());
    const QuietErrors quiet;
    const File file(path);
    if (file.kind() == FclibKind::local) return read_local(file);
    global = read_global(file);
  }
  try {
    return to_local(global);
  } catch (const InvalidArgument& error) {
    throw InvalidArgument(path.string() + ": " + error.what());
  }
}

/// Reads the sparse matrix in `group` ("/fclib_local/W", or without the leading slash): checks
/// the header, the lengths of p, i and x for the storage kind, p monotone from 0 for compressed
/// storage, every index in range and every value finite; duplicates are summed.
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
  const std::lock_guard lock(hdf5_mutex());
  const QuietErrors quiet;
  const File file(path);
  return file.matrix(file.header(name));
}

}  // namespace grbd::contact
