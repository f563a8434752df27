#pragma once
// Small helpers over HDF5's C API for the output and checkpoint files (private to the library).
// Every failure throws io::IoError naming the file and the object.

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "shared/hdf5.hpp"
#include "grbd/core/communicator.hpp"
#include "grbd/io/output.hpp"
#include "grbd/timestep/body_record.hpp"

namespace grbd::io::h5 {

using hdf5::Handle;

[[noreturn]] inline void fail(const std::string& file, const std::string& what) {
  throw IoError(file + ": " + what + hdf5::message());
}

inline Handle check(hid_t id, Handle::Close close, const std::string& file,
                    const std::string& what) {
  if (id < 0) fail(file, what);
  return Handle(id, close);
}

inline void check(herr_t status, const std::string& file, const std::string& what) {
  if (status < 0) fail(file, what);
}

/// A variable-length UTF-8 string type (attributes and string datasets).
Handle string_type(const std::string& file);

/// Packs records into `rows` (resized), for the tables /bodies of the output and a checkpoint.
void pack_rows(std::span<const timestep::BodyRecord> records,
               std::vector<timestep::PackedBody>& rows);
/// Throws IoError naming `path` ("no such <what>", "not a regular file") unless it is a regular
/// file (a FIFO or a device would block or never end).
void require_regular_file(const std::filesystem::path& path, const std::string& what);

/// One row of /steps.
struct StepRow {
  std::uint64_t step;
  double t;
  std::uint64_t bodies;
  std::uint64_t contacts;
  std::uint64_t warm_started;
  std::int32_t iterations;
  std::uint8_t converged;
  double residual;
  double kinetic_energy;
  double potential_energy;
  double max_penetration;
  double mean_penetration;
  double p99_penetration;
  double seconds_midpoint;
  double seconds_detection;
  double seconds_assembly;
  double seconds_solve;
  double seconds_update;
  double seconds_total;
};

/// The compound types of the rows in memory: a body's is a packed timestep::BodyRecord, whose
/// constants are the columns (its state is not), a step's the struct StepRow.
Handle body_row_type();
Handle step_row_type();
/// A packed copy of a compound type: what goes into the file, without padding bytes.
Handle packed(hid_t type);

void write_attribute(hid_t object, const char* name, double value, const std::string& file);
void write_attribute(hid_t object, const char* name, std::uint64_t value, const std::string& file);
void write_attribute(hid_t object, const char* name, const std::string& value,
                     const std::string& file);
double read_double(hid_t object, const char* name, const std::string& file);
std::uint64_t read_uint(hid_t object, const char* name, const std::string& file);
std::string read_string(hid_t object, const char* name, const std::string& file);

/// Gives the dataset `name` of `location` its unit (attribute `unit`, "1" for a pure number) and,
/// where the values are components in a frame, that frame (attribute `frame`, e.g. "I").
void describe(hid_t location, const char* name, const char* unit, const char* frame,
              const std::string& file);

/// An extendable 1-D dataset of `type`, chunked by `chunk` rows.
Handle create_table(hid_t location, const char* name, hid_t type, hsize_t chunk,
                    const std::string& file);
/// Rows of a 1-D dataset.
std::uint64_t rows(hid_t dataset, const std::string& file, const std::string& name);
/// Sets the rows of a 1-D extendable dataset.
void resize(hid_t dataset, std::uint64_t n, const std::string& file, const std::string& name);

/// File access for the processes of `comm` together: MPI-IO (parallel HDF5) when it has an MPI
/// communicator and more than one process, else HDF5's default.
Handle shared_access(const Communicator& comm, const std::string& file);
/// Transfer properties for a file opened with shared_access(): collective MPI-IO when `comm`
/// has more than one process, else HDF5's default. Every process then takes part in each write,
/// with its own rows or none.
Handle shared_transfer(const Communicator& comm, const std::string& file);
/// Writes n rows × cols of `data` at row `offset` of a dataset (cols = 0: 1-D), with the
/// transfer properties `transfer` (n may be 0: a process without rows of a collective write).
void write_at(hid_t dataset, hid_t memory_type, std::uint64_t offset, std::uint64_t n,
              std::uint64_t cols, const void* data, hid_t transfer, const std::string& file,
              const std::string& name);
/// Creates a contiguous dataset of total × cols and writes this process's n rows at `offset`
/// (write_at; with one process: total = n, offset 0).
void write_rows(hid_t location, const char* name, hid_t file_type, hid_t memory_type,
                std::uint64_t total, std::uint64_t cols, std::uint64_t offset, std::uint64_t n,
                const void* data, hid_t transfer, const std::string& file);
/// Writes a contiguous dataset of rows × cols (cols = 0: a 1-D dataset of `rows`).
void write_array(hid_t location, const char* name, hid_t file_type, hid_t memory_type,
                 std::uint64_t rows, std::uint64_t cols, const void* data, const std::string& file);
/// Reads a dataset that must be rows × cols (cols = 0: 1-D; rows = -1: any number of rows, which
/// is returned) into `data`, resized to fit.
template <class T>
std::uint64_t read_array(hid_t location, const char* name, hid_t memory_type, std::int64_t rows,
                         std::uint64_t cols, std::vector<T>& data, const std::string& file);

/// Reads rows [offset, offset + n) of a dataset that must be total × cols (cols = 0: 1-D) into
/// `data`, resized to n × cols.
template <class T>
void read_rows(hid_t location, const char* name, hid_t memory_type, std::uint64_t total,
               std::uint64_t cols, std::uint64_t offset, std::uint64_t n, std::vector<T>& data,
               const std::string& file);
/// The rows of an n × cols dataset (cols = 0: 1-D), checked against its shape and the bytes it
/// stores, as read_array() checks them.
std::uint64_t rows_of(hid_t location, const char* name, hid_t memory_type, std::uint64_t cols,
                      const std::string& file);
/// grbd's claim on an output file while it writes it: flock(LOCK_EX) on a descriptor of its own,
/// taken before HDF5 opens (and a new output truncates) the file and held until it is closed.
/// It is the lock HDF5 itself takes (flock), so a second grbd run, and any HDF5 program that has
/// the file open, are refused before anything is touched; HDF5's own lock is switched off for
/// the files opened with locked_access() under it.
class FileLock {
 public:
  /// Locks `path`, creating an empty file when `create` and there is none. Throws IoError naming
  /// the file when it cannot be opened or another process holds it.
  FileLock(const std::filesystem::path& path, bool create);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_ = -1;
};

/// Whether another process holds `path` open under a lock (a grbd run, or an HDF5 program): a
/// probe that takes and releases the lock; false when the file does not exist.
bool locked_elsewhere(const std::filesystem::path& path);

/// File access properties for a file held by a FileLock: HDF5's own lock off.
Handle locked_access(const std::string& file);

}  // namespace grbd::io::h5
