// Checkpoints (chapter 7): written atomically, read with a check of every dataset.

#include "grbd/io/checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "io/h5util.hpp"

namespace grbd::io {

namespace {

using h5::check;
using h5::Handle;

// Flushes a file (or a folder, for the rename) to the disk.
void sync_path(const std::filesystem::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) throw IoError(path.string() + ": cannot open to flush it to the disk");
  const int status = ::fsync(fd);
  ::close(fd);
  if (status != 0) throw IoError(path.string() + ": cannot flush it to the disk (fsync)");
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  const std::string file = temporary.string();
  const scene::SimulationState& s = checkpoint.state;
  {
    std::lock_guard lock(hdf5::mutex());
    hdf5::QuietErrors quiet;
    Handle handle = check(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                          H5Fclose, file, "cannot create the checkpoint");
    const hid_t root = handle.get();
    h5::write_attribute(root, "format", std::string("grbd checkpoint"), file);
    h5::write_attribute(root, "format_version", kCheckpointFormatVersion, file);
    h5::write_attribute(root, "scene", checkpoint.scene_text, file);
    h5::write_attribute(root, "t", s.t, file);
    h5::write_attribute(root, "steps", s.steps, file);
    h5::write_attribute(root, "next_id", s.next_id, file);
    h5::write_attribute(root, "removed", s.removed, file);
    h5::write_attribute(root, "removed_mass", s.removed_mass, file);
    h5::write_attribute(root, "output_records", checkpoint.output.records, file);
    h5::write_attribute(root, "output_steps", checkpoint.output.steps, file);
    h5::write_attribute(root, "output_bodies", checkpoint.output.bodies, file);

    const std::size_t n = s.bodies.size();
    std::vector<h5::BodyRow> rows(n);
    std::vector<double> states(13 * n);
    for (std::size_t i = 0; i < n; ++i) {
      rows[i] = h5::body_row(s.bodies[i]);
      for (int d = 0; d < 7; ++d) states[13 * i + d] = s.states[i].q[d];
      for (int d = 0; d < 6; ++d) states[13 * i + 7 + d] = s.states[i].u[d];
    }
    Handle body_type = h5::body_row_type();
    h5::write_array(root, "bodies", h5::packed(body_type.get()).get(), body_type.get(), n, 0,
                    rows.data(), file);
    h5::write_array(root, "states", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, 13, states.data(), file);

    const std::size_t m = s.warm_keys.size();
    std::vector<std::uint64_t> keys(4 * m);
    std::vector<double> lambda(3 * m);
    for (std::size_t k = 0; k < m; ++k) {
      keys[4 * k] = s.warm_keys[k].a;
      keys[4 * k + 1] = s.warm_keys[k].b;
      keys[4 * k + 2] = s.warm_keys[k].feature_a;
      keys[4 * k + 3] = s.warm_keys[k].feature_b;
      for (int d = 0; d < 3; ++d) lambda[3 * k + d] = s.warm_lambda[k][d];
    }
    h5::write_array(root, "warm_start_keys", H5T_STD_U64LE, H5T_NATIVE_UINT64, m, 4, keys.data(),
                    file);
    h5::write_array(root, "warm_start_lambda", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, m, 3,
                    lambda.data(), file);

    std::vector<std::uint64_t> generators;
    for (const scene::GeneratorState& g : s.generators) {
      generators.push_back(g.random);
      generators.push_back(g.created);
    }
    h5::write_array(root, "generators", H5T_STD_U64LE, H5T_NATIVE_UINT64, s.generators.size(), 2,
                    generators.data(), file);
    check(H5Fflush(root, H5F_SCOPE_LOCAL), file, "cannot flush the checkpoint");
    if (!handle.close()) h5::fail(file, "cannot close the checkpoint");
  }
  sync_path(temporary, O_RDONLY);
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    throw IoError(path.string() +
                  ": cannot move the new checkpoint into place: " + error.message());
  }
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  sync_path(folder, O_RDONLY | O_DIRECTORY);
}

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  const std::string file = path.string();
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) h5::fail(file, "no such checkpoint file");
  if (H5Fis_hdf5(file.c_str()) <= 0) h5::fail(file, "is not an HDF5 file");
  Handle handle = check(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, file,
                        "cannot open the checkpoint (it may be damaged)");
  const hid_t root = handle.get();
  if (H5Aexists(root, "format") <= 0 ||
      h5::read_string(root, "format", file) != "grbd checkpoint") {
    h5::fail(file, "is not a grbd checkpoint (attribute format is not \"grbd checkpoint\")");
  }
  const std::uint64_t version = h5::read_uint(root, "format_version", file);
  if (version != kCheckpointFormatVersion) {
    h5::fail(file, "format_version " + std::to_string(version) + ", this grbd reads version " +
                       std::to_string(kCheckpointFormatVersion));
  }
  Checkpoint c;
  scene::SimulationState& s = c.state;
  c.scene_text = h5::read_string(root, "scene", file);
  s.t = h5::read_double(root, "t", file);
  if (!std::isfinite(s.t) || s.t < 0.0) h5::fail(file, "attribute t: expected a time ≥ 0");
  s.steps = h5::read_uint(root, "steps", file);
  s.next_id = h5::read_uint(root, "next_id", file);
  s.removed = h5::read_uint(root, "removed", file);
  s.removed_mass = h5::read_double(root, "removed_mass", file);
  c.output.records = h5::read_uint(root, "output_records", file);
  c.output.steps = h5::read_uint(root, "output_steps", file);
  c.output.bodies = h5::read_uint(root, "output_bodies", file);

  std::vector<h5::BodyRow> rows;
  Handle body_type = h5::body_row_type();
  const std::uint64_t n = h5::read_array(root, "bodies", body_type.get(), -1, 0, rows, file);
  std::vector<double> states;
  h5::read_array(root, "states", H5T_NATIVE_DOUBLE, static_cast<std::int64_t>(n), 13, states, file);
  s.bodies.resize(n);
  s.states.resize(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    const h5::BodyRow& row = rows[i];
    if (row.shape > static_cast<std::uint8_t>(collision::ShapeKind::capsule) || row.fixed > 1 ||
        row.id >= s.next_id) {
      h5::fail(file, "dataset bodies, row " + std::to_string(i) +
                         ": expected a shape 0–2, fixed 0 or 1 and an id below next_id");
    }
    s.bodies[i] = h5::body_constants(row);
    for (int d = 0; d < 7; ++d) s.states[i].q[d] = states[13 * i + d];
    for (int d = 0; d < 6; ++d) s.states[i].u[d] = states[13 * i + 7 + d];
  }
  std::vector<std::uint64_t> keys;
  const std::uint64_t m =
      h5::read_array(root, "warm_start_keys", H5T_NATIVE_UINT64, -1, 4, keys, file);
  std::vector<double> lambda;
  h5::read_array(root, "warm_start_lambda", H5T_NATIVE_DOUBLE, static_cast<std::int64_t>(m), 3,
                 lambda, file);
  s.warm_keys.resize(m);
  s.warm_lambda.resize(m);
  for (std::uint64_t k = 0; k < m; ++k) {
    s.warm_keys[k] = {keys[4 * k], keys[4 * k + 1], keys[4 * k + 2], keys[4 * k + 3]};
    s.warm_lambda[k] = Vector3(lambda[3 * k], lambda[3 * k + 1], lambda[3 * k + 2]);
    if (!s.warm_lambda[k].allFinite()) {
      h5::fail(file, "dataset warm_start_lambda, row " + std::to_string(k) + ": not finite");
    }
  }
  std::vector<std::uint64_t> generators;
  const std::uint64_t g =
      h5::read_array(root, "generators", H5T_NATIVE_UINT64, -1, 2, generators, file);
  s.generators.resize(g);
  for (std::uint64_t k = 0; k < g; ++k)
    s.generators[k] = {generators[2 * k], generators[2 * k + 1]};
  return c;
}

}  // namespace grbd::io
