// Helpers over HDF5's C API for the output and checkpoint files.

#include "io/h5util.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <limits>

#include "grbd/core/checks.hpp"

namespace grbd::io::h5 {

Handle string_type(const std::string& file) {
  Handle type = check(H5Tcopy(H5T_C_S1), H5Tclose, file, "cannot create a string type");
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  return type;
}

void pack_rows(std::span<const timestep::BodyRecord> records,
               std::vector<timestep::PackedBody>& rows) {
  rows.resize(records.size());
  for (std::size_t i = 0; i < records.size(); ++i) timestep::pack(records[i], rows[i]);
}

void require_regular_file(const std::filesystem::path& path, const std::string& what) {
  if (const std::string problem = regular_file_problem(path, what); !problem.empty()) {
    fail(path.string(), problem);
  }
}

Handle body_row_type() {
  namespace at = timestep::packed;
  Handle type(H5Tcreate(H5T_COMPOUND, timestep::kPackedBodyBytes), H5Tclose);
  const hsize_t three = 3;
  Handle vector3(H5Tarray_create2(H5T_NATIVE_DOUBLE, 1, &three), H5Tclose);
  H5Tinsert(type.get(), "id", at::id, H5T_NATIVE_UINT64);
  H5Tinsert(type.get(), "shape", at::shape, H5T_NATIVE_UINT8);
  H5Tinsert(type.get(), "fixed", at::fixed, H5T_NATIVE_UINT8);
  H5Tinsert(type.get(), "material", at::material, H5T_NATIVE_UINT32);
  H5Tinsert(type.get(), "radius", at::radius, H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "half_extents", at::half_extents, vector3.get());
  H5Tinsert(type.get(), "half_length", at::half_length, H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "mass", at::mass, H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "K_Theta", at::K_Theta, vector3.get());
  return type;
}

Handle step_row_type() {
  Handle type(H5Tcreate(H5T_COMPOUND, sizeof(StepRow)), H5Tclose);
  H5Tinsert(type.get(), "step", HOFFSET(StepRow, step), H5T_NATIVE_UINT64);
  H5Tinsert(type.get(), "t", HOFFSET(StepRow, t), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "bodies", HOFFSET(StepRow, bodies), H5T_NATIVE_UINT64);
  H5Tinsert(type.get(), "contacts", HOFFSET(StepRow, contacts), H5T_NATIVE_UINT64);
  H5Tinsert(type.get(), "warm_started", HOFFSET(StepRow, warm_started), H5T_NATIVE_UINT64);
  H5Tinsert(type.get(), "iterations", HOFFSET(StepRow, iterations), H5T_NATIVE_INT32);
  H5Tinsert(type.get(), "converged", HOFFSET(StepRow, converged), H5T_NATIVE_UINT8);
  H5Tinsert(type.get(), "residual", HOFFSET(StepRow, residual), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "kinetic_energy", HOFFSET(StepRow, kinetic_energy), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "potential_energy", HOFFSET(StepRow, potential_energy), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "max_penetration", HOFFSET(StepRow, max_penetration), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "mean_penetration", HOFFSET(StepRow, mean_penetration), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "p99_penetration", HOFFSET(StepRow, p99_penetration), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "seconds_midpoint", HOFFSET(StepRow, seconds_midpoint), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "seconds_detection", HOFFSET(StepRow, seconds_detection),
            H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "seconds_assembly", HOFFSET(StepRow, seconds_assembly), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "seconds_solve", HOFFSET(StepRow, seconds_solve), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "seconds_update", HOFFSET(StepRow, seconds_update), H5T_NATIVE_DOUBLE);
  H5Tinsert(type.get(), "seconds_total", HOFFSET(StepRow, seconds_total), H5T_NATIVE_DOUBLE);
  return type;
}

Handle packed(hid_t type) {
  Handle copy(H5Tcopy(type), H5Tclose);
  H5Tpack(copy.get());
  return copy;
}

namespace {

void write_scalar_attribute(hid_t object, const char* name, hid_t file_type, hid_t memory_type,
                            const void* value, const std::string& file) {
  if (H5Aexists(object, name) > 0)
    check(H5Adelete(object, name), file, std::string("cannot replace attribute ") + name);
  Handle space = check(H5Screate(H5S_SCALAR), H5Sclose, file, "cannot create a dataspace");
  Handle attribute =
      check(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
            file, std::string("cannot create attribute ") + name);
  check(H5Awrite(attribute.get(), memory_type, value), file,
        std::string("cannot write attribute ") + name);
}

Handle open_attribute(hid_t object, const char* name, const std::string& file) {
  if (H5Aexists(object, name) <= 0) fail(file, std::string("attribute ") + name + " is missing");
  return check(H5Aopen(object, name, H5P_DEFAULT), H5Aclose, file,
               std::string("cannot open attribute ") + name);
}

// Opens an attribute that must hold one value.
Handle open_scalar_attribute(hid_t object, const char* name, const std::string& file) {
  Handle attribute = open_attribute(object, name, file);
  Handle space = check(H5Aget_space(attribute.get()), H5Sclose, file, "cannot read a dataspace");
  if (H5Sget_simple_extent_npoints(space.get()) != 1) {
    fail(file, std::string("attribute ") + name + " is not a scalar");
  }
  return attribute;
}

}  // namespace

void write_attribute(hid_t object, const char* name, double value, const std::string& file) {
  write_scalar_attribute(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value, file);
}

void write_attribute(hid_t object, const char* name, std::uint64_t value, const std::string& file) {
  write_scalar_attribute(object, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value, file);
}

void write_attribute(hid_t object, const char* name, const std::string& value,
                     const std::string& file) {
  Handle type = string_type(file);
  const char* text = value.c_str();
  write_scalar_attribute(object, name, type.get(), type.get(), &text, file);
}

double read_double(hid_t object, const char* name, const std::string& file) {
  Handle attribute = open_scalar_attribute(object, name, file);
  double value = 0.0;
  check(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &value), file,
        std::string("attribute ") + name + " is not a number");
  return value;
}

std::uint64_t read_uint(hid_t object, const char* name, const std::string& file) {
  Handle attribute = open_scalar_attribute(object, name, file);
  Handle type = check(H5Aget_type(attribute.get()), H5Tclose, file, "cannot read a type");
  if (H5Tget_class(type.get()) != H5T_INTEGER)
    fail(file, std::string("attribute ") + name + " is not an integer");
  std::uint64_t value = 0;
  check(H5Aread(attribute.get(), H5T_NATIVE_UINT64, &value), file,
        std::string("attribute ") + name + " is not an unsigned integer");
  return value;
}

std::string read_string(hid_t object, const char* name, const std::string& file) {
  Handle attribute = open_scalar_attribute(object, name, file);
  Handle type = check(H5Aget_type(attribute.get()), H5Tclose, file, "cannot read a type");
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) <= 0) {
    fail(file, std::string("attribute ") + name + " is not a variable-length string");
  }
  Handle memory = string_type(file);
  H5Tset_cset(memory.get(), H5Tget_cset(type.get()));  // no conversion between character sets
  char* text = nullptr;
  check(H5Aread(attribute.get(), memory.get(), &text), file,
        std::string("cannot read attribute ") + name);
  std::string value = text != nullptr ? text : "";
  H5free_memory(text);
  return value;
}

void describe(hid_t location, const char* name, const char* unit, const char* frame,
              const std::string& file) {
  Handle dataset = check(H5Dopen2(location, name, H5P_DEFAULT), H5Dclose, file,
                         std::string("cannot open dataset ") + name);
  write_attribute(dataset.get(), "unit", std::string(unit), file);
  if (frame != nullptr) write_attribute(dataset.get(), "frame", std::string(frame), file);
}

Handle create_table(hid_t location, const char* name, hid_t type, hsize_t chunk,
                    const std::string& file) {
  const hsize_t zero = 0;
  const hsize_t unlimited = H5S_UNLIMITED;
  Handle space =
      check(H5Screate_simple(1, &zero, &unlimited), H5Sclose, file, "cannot create a dataspace");
  Handle properties =
      check(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, file, "cannot create a property list");
  check(H5Pset_chunk(properties.get(), 1, &chunk), file, "cannot set a chunk size");
  // Chunks allocated as the table grows, not when first written: what collective writes of
  // parallel HDF5 need (the same file content either way).
  check(H5Pset_alloc_time(properties.get(), H5D_ALLOC_TIME_EARLY), file,
        "cannot set the allocation time");
  return check(
      H5Dcreate2(location, name, type, space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
      H5Dclose, file, std::string("cannot create dataset ") + name);
}

std::uint64_t rows(hid_t dataset, const std::string& file, const std::string& name) {
  Handle space = check(H5Dget_space(dataset), H5Sclose, file, "cannot read the shape of " + name);
  if (H5Sget_simple_extent_ndims(space.get()) != 1) fail(file, name + " is not one-dimensional");
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space.get(), &n, nullptr);
  return n;
}

void resize(hid_t dataset, std::uint64_t n, const std::string& file, const std::string& name) {
  const hsize_t size = n;
  check(H5Dset_extent(dataset, &size), file, "cannot resize " + name);
}

Handle shared_access(const Communicator& comm, const std::string& file) {
  Handle access =
      check(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, file, "cannot create a property list");
  if (comm.size() > 1 && comm.mpi_comm() != nullptr) {
    check(H5Pset_fapl_mpio(access.get(), *static_cast<const MPI_Comm*>(comm.mpi_comm()),
                           MPI_INFO_NULL),
          file, "cannot set up parallel access (MPI-IO)");
  }
  return access;
}

Handle shared_transfer(const Communicator& comm, const std::string& file) {
  if (comm.size() == 1 || comm.mpi_comm() == nullptr) return Handle(H5P_DEFAULT, nullptr);
  Handle transfer =
      check(H5Pcreate(H5P_DATASET_XFER), H5Pclose, file, "cannot create a property list");
  check(H5Pset_dxpl_mpio(transfer.get(), H5FD_MPIO_COLLECTIVE), file,
        "cannot set collective transfers");
  return transfer;
}

void write_at(hid_t dataset, hid_t memory_type, std::uint64_t offset, std::uint64_t n,
              std::uint64_t cols, const void* data, hid_t transfer, const std::string& file,
              const std::string& name) {
  if (n == 0 && transfer == H5P_DEFAULT) return;  // alone, nothing to write
  Handle space = check(H5Dget_space(dataset), H5Sclose, file, "cannot read the shape of " + name);
  const hsize_t start[2] = {offset, 0};
  const hsize_t count[2] = {n, cols == 0 ? 1 : cols};
  const int dims = cols == 0 ? 1 : 2;
  Handle memory =
      check(H5Screate_simple(dims, count, nullptr), H5Sclose, file, "cannot create a dataspace");
  if (n == 0) {  // a process without rows takes part in the collective write with none
    check(H5Sselect_none(space.get()), file, "cannot select rows of " + name);
    check(H5Sselect_none(memory.get()), file, "cannot select rows of " + name);
  } else {
    check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), file,
          "cannot select rows of " + name);
  }
  check(H5Dwrite(dataset, memory_type, memory.get(), space.get(), transfer, data), file,
        "cannot write " + name);
}

void write_rows(hid_t location, const char* name, hid_t file_type, hid_t memory_type,
                std::uint64_t total, std::uint64_t cols, std::uint64_t offset, std::uint64_t n,
                const void* data, hid_t transfer, const std::string& file) {
  const hsize_t dims[2] = {total, cols};
  Handle space = check(H5Screate_simple(cols == 0 ? 1 : 2, dims, nullptr), H5Sclose, file,
                       "cannot create a dataspace");
  Handle dataset = check(
      H5Dcreate2(location, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose, file, std::string("cannot create dataset ") + name);
  if (total > 0) write_at(dataset.get(), memory_type, offset, n, cols, data, transfer, file, name);
}

void write_array(hid_t location, const char* name, hid_t file_type, hid_t memory_type,
                 std::uint64_t rows, std::uint64_t cols, const void* data,
                 const std::string& file) {
  write_rows(location, name, file_type, memory_type, rows, cols, 0, rows, data, H5P_DEFAULT, file);
}

std::uint64_t rows_of(hid_t location, const char* name, hid_t memory_type, std::uint64_t cols,
                      const std::string& file) {
  if (H5Lexists(location, name, H5P_DEFAULT) <= 0)
    fail(file, std::string("dataset ") + name + " is missing");
  Handle dataset = check(H5Dopen2(location, name, H5P_DEFAULT), H5Dclose, file,
                         std::string("cannot open dataset ") + name);
  Handle space = check(H5Dget_space(dataset.get()), H5Sclose, file,
                       std::string("cannot read the shape of ") + name);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  hsize_t dims[2] = {0, 0};
  const int expected_rank = cols == 0 ? 1 : 2;
  if (rank != expected_rank) {
    fail(file, std::string("dataset ") + name + ": expected " + std::to_string(expected_rank) +
                   " dimension(s), found " + std::to_string(rank));
  }
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (cols != 0 && dims[1] != cols) {
    fail(file, std::string("dataset ") + name + ": expected n × " + std::to_string(cols) +
                   " elements, found " + std::to_string(dims[0]) + " × " + std::to_string(dims[1]));
  }
  const std::uint64_t elements = dims[0] * (cols == 0 ? 1 : cols);
  // The file cannot hold more elements than it has bytes (a forged header must not allocate).
  const hsize_t storage = H5Dget_storage_size(dataset.get());
  if (elements > 0 && storage / H5Tget_size(memory_type) < elements / 16) {
    fail(file, std::string("dataset ") + name + " declares more elements than it stores");
  }
  return dims[0];
}

template <class T>
void read_rows(hid_t location, const char* name, hid_t memory_type, std::uint64_t total,
               std::uint64_t cols, std::uint64_t offset, std::uint64_t n, std::vector<T>& data,
               const std::string& file) {
  const std::uint64_t rows = rows_of(location, name, memory_type, cols, file);
  if (rows != total) {
    fail(file, std::string("dataset ") + name + ": expected " + std::to_string(total) +
                   (cols != 0 ? " × " + std::to_string(cols) : std::string()) +
                   " elements, found " + std::to_string(rows) +
                   (cols != 0 ? " × " + std::to_string(cols) : std::string()));
  }
  const std::uint64_t per_row = cols == 0 ? 1 : cols;
  data.resize(n * per_row);
  if (n == 0) return;
  if (offset + n > total) fail(file, std::string("dataset ") + name + ": rows out of range");
  Handle dataset = check(H5Dopen2(location, name, H5P_DEFAULT), H5Dclose, file,
                         std::string("cannot open dataset ") + name);
  Handle space = check(H5Dget_space(dataset.get()), H5Sclose, file,
                       std::string("cannot read the shape of ") + name);
  const hsize_t start[2] = {offset, 0};
  const hsize_t count[2] = {n, per_row};
  const int dims = cols == 0 ? 1 : 2;
  check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), file,
        std::string("cannot select rows of ") + name);
  Handle memory =
      check(H5Screate_simple(dims, count, nullptr), H5Sclose, file, "cannot create a dataspace");
  check(H5Dread(dataset.get(), memory_type, memory.get(), space.get(), H5P_DEFAULT, data.data()),
        file, std::string("cannot read dataset ") + name + " as the expected type");
}

template <class T>
std::uint64_t read_array(hid_t location, const char* name, hid_t memory_type, std::int64_t rows,
                         std::uint64_t cols, std::vector<T>& data, const std::string& file) {
  const std::uint64_t n = rows >= 0 ? static_cast<std::uint64_t>(rows)
                                    : rows_of(location, name, memory_type, cols, file);
  read_rows(location, name, memory_type, n, cols, 0, n, data, file);
  return n;
}

template std::uint64_t read_array<double>(hid_t, const char*, hid_t, std::int64_t, std::uint64_t,
                                          std::vector<double>&, const std::string&);
template std::uint64_t read_array<std::uint64_t>(hid_t, const char*, hid_t, std::int64_t,
                                                 std::uint64_t, std::vector<std::uint64_t>&,
                                                 const std::string&);
template std::uint64_t read_array<timestep::PackedBody>(hid_t, const char*, hid_t, std::int64_t,
                                                        std::uint64_t,
                                                        std::vector<timestep::PackedBody>&,
                                                        const std::string&);
template std::uint64_t read_array<StepRow>(hid_t, const char*, hid_t, std::int64_t, std::uint64_t,
                                           std::vector<StepRow>&, const std::string&);
template void read_rows<double>(hid_t, const char*, hid_t, std::uint64_t, std::uint64_t,
                                std::uint64_t, std::uint64_t, std::vector<double>&,
                                const std::string&);
template void read_rows<std::uint64_t>(hid_t, const char*, hid_t, std::uint64_t, std::uint64_t,
                                       std::uint64_t, std::uint64_t, std::vector<std::uint64_t>&,
                                       const std::string&);
template void read_rows<timestep::PackedBody>(hid_t, const char*, hid_t, std::uint64_t,
                                              std::uint64_t, std::uint64_t, std::uint64_t,
                                              std::vector<timestep::PackedBody>&,
                                              const std::string&);

FileLock::FileLock(const std::filesystem::path& path, bool create) {
  const std::string file = path.string();
  // O_NONBLOCK: a FIFO must not block the open; it is refused below, as any file that is not
  // a regular one.
  fd_ = ::open(file.c_str(), O_RDWR | O_CLOEXEC | O_NONBLOCK | (create ? O_CREAT : 0), 0666);
  if (fd_ < 0) throw IoError(file + ": cannot open the output file: " + std::strerror(errno));
  struct stat status {};
  if (::fstat(fd_, &status) != 0 || !S_ISREG(status.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    throw IoError(file + ": is not a regular file, as a grbd output file is");
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    throw IoError(file + (error == EWOULDBLOCK
                              ? ": is in use: another grbd run writes it, or another program has "
                                "it open (HDF5's lock); nothing was changed"
                              : ": cannot lock the file: " + std::string(std::strerror(error))));
  }
}

FileLock::~FileLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

bool locked_elsewhere(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // releases the probe's lock, if it got it
  return held;
}

Handle locked_access(const std::string& file) {
  Handle access =
      check(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, file, "cannot create a property list");
  check(H5Pset_file_locking(access.get(), false, true), file, "cannot set the file locking");
  return access;
}

}  // namespace grbd::io::h5
