// Checkpoints (chapter 7): written atomically, read with a check of every dataset.

#include "grbd/io/checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "grbd/core/checks.hpp"
#include "grbd/core/hash.hpp"

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

// A 64-bit checksum of everything a checkpoint holds, word by word through SplitMix64's
// finaliser: a flipped bit anywhere in the values changes it (not a defence against forgery).
class Checksum {
 public:
  void add(std::uint64_t word) { h_ = mix64(h_ ^ word ^ (++k_ * 0x9e3779b97f4a7c15ULL)); }
  void add(double x) {
    std::uint64_t word = 0;
    std::memcpy(&word, &x, sizeof(x));
    add(word);
  }
  void add(const std::string& text) {
    add(static_cast<std::uint64_t>(text.size()));
    for (std::size_t i = 0; i < text.size(); i += 8) {
      std::uint64_t word = 0;
      std::memcpy(&word, text.data() + i, std::min<std::size_t>(8, text.size() - i));
      add(word);
    }
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0x6772626463686b70ULL;  // "grbdchkp"
  std::uint64_t k_ = 0;
};

std::uint64_t checksum(const Checkpoint& c) {
  const scene::SimulationState& s = c.state;
  Checksum sum;
  sum.add(c.scene_text);
  sum.add(s.t);
  for (std::uint64_t x : {s.steps, s.next_id, s.removed, c.output.records, c.output.steps,
                          c.output.bodies, static_cast<std::uint64_t>(s.bodies.size()),
                          static_cast<std::uint64_t>(s.warm_keys.size()),
                          static_cast<std::uint64_t>(s.generators.size())}) {
    sum.add(x);
  }
  sum.add(s.removed_mass);
  // Each body as packed (timestep::pack): its id, one word of shape, fixed and material, then
  // every double of the record in order, radius to u.
  timestep::PackedBody bytes;
  for (const timestep::BodyRecord& body : s.bodies) {
    timestep::pack(body, bytes);
    const auto word = [&]<class T>(std::size_t offset, T) {
      T value;
      std::memcpy(&value, bytes.data() + offset, sizeof(T));
      return value;
    };
    namespace at = timestep::packed;
    sum.add(word(at::id, std::uint64_t{}));
    sum.add(std::uint64_t{word(at::shape, std::uint8_t{})} |
            std::uint64_t{word(at::fixed, std::uint8_t{})} << 8 |
            std::uint64_t{word(at::material, std::uint32_t{})} << 16);
    for (std::size_t offset = at::radius; offset < timestep::kPackedBodyBytes; offset += 8) {
      sum.add(word(offset, double{}));
    }
  }
  for (std::size_t k = 0; k < s.warm_keys.size(); ++k) {
    const timestep::ContactKey& key = s.warm_keys[k];
    for (std::uint64_t x : {key.a, key.b, std::uint64_t{key.feature_a}, std::uint64_t{key.feature_b}})
      sum.add(x);
    for (int d = 0; d < 3; ++d) sum.add(s.warm_lambda[k][d]);
  }
  for (const scene::GeneratorState& g : s.generators) {
    sum.add(g.random);
    sum.add(g.created);
  }
  return sum.value();
}

}  // namespace

namespace {

// Writes the checkpoint into `temporary`, flushed to the disk.
void write_temporary(const std::filesystem::path& temporary, const Checkpoint& checkpoint) {
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
    h5::write_attribute(root, "checksum", checksum(checkpoint), file);

    const std::size_t n = s.bodies.size();
    std::vector<timestep::PackedBody> rows;
    h5::pack_rows(s.bodies, rows);
    std::vector<double> states(13 * n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int d = 0; d < 7; ++d) states[13 * i + d] = s.bodies[i].state.q[d];
      for (int d = 0; d < 6; ++d) states[13 * i + 7 + d] = s.bodies[i].state.u[d];
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
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  try {
    write_temporary(temporary, checkpoint);
  } catch (const Error&) {
    std::error_code ignored;  // a partial temporary is of no use; the previous checkpoint stays
    std::filesystem::remove(temporary, ignored);
    throw;
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    throw IoError(path.string() +
                  ": cannot move the new checkpoint into place: " + error.message());
  }
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  sync_path(folder, O_RDONLY | O_DIRECTORY);
}

namespace {

// What a checkpoint can be checked against without its scene: finite values, counters in range.
void require_consistent(const Checkpoint& c, const std::string& file) {
  const scene::SimulationState& s = c.state;
  const auto refuse = [&](const std::string& what) { h5::fail(file, what); };
  if (s.next_id >= timestep::kStaticTag) {
    refuse("attribute next_id: expected an id below 2^63, found " + std::to_string(s.next_id));
  }
  if (s.removed > s.next_id) {
    refuse("attribute removed: " + std::to_string(s.removed) +
           " bodies removed, more than the " + std::to_string(s.next_id) + " created (next_id)");
  }
  if (!std::isfinite(s.removed_mass) || s.removed_mass < 0.0) {
    refuse("attribute removed_mass: expected a finite mass ≥ 0, found " +
           format_number(s.removed_mass));
  }
  if (s.steps > scene::kMaxSteps) {
    refuse("attribute steps: expected at most 10¹², found " + std::to_string(s.steps));
  }
  if (c.output.steps > s.steps || c.output.records > s.steps + 1 ||
      c.output.bodies > s.next_id) {
    refuse("attributes output_records, output_steps, output_bodies: expected at most steps + 1, "
           "steps and next_id, found " + std::to_string(c.output.records) + ", " +
           std::to_string(c.output.steps) + ", " + std::to_string(c.output.bodies));
  }
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (!s.bodies[i].state.q.allFinite() || !s.bodies[i].state.u.allFinite()) {
      refuse("dataset states, row " + std::to_string(i) + " (body " +
             std::to_string(s.bodies[i].id) + "): not finite");
    }
  }
  for (std::size_t k = 0; k < s.warm_lambda.size(); ++k) {
    if (!(s.warm_lambda[k][0] >= 0.0)) {
      refuse("dataset warm_start_lambda, row " + std::to_string(k) +
             ": expected a normal percussion lambda_N ≥ 0, found " +
             format_number(s.warm_lambda[k][0]));
    }
  }
  for (std::size_t g = 0; g < s.generators.size(); ++g) {
    if (s.generators[g].created > s.next_id) {
      refuse("dataset generators, row " + std::to_string(g) + ": " +
             std::to_string(s.generators[g].created) + " bodies created, more than next_id");
    }
  }
}

}  // namespace

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  const std::string file = path.string();
  h5::require_regular_file(path, "checkpoint file");
  if (H5Fis_hdf5(file.c_str()) <= 0) h5::fail(file, "is not an HDF5 file");
  Handle handle = check(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, file,
                        "cannot open the checkpoint (it may be damaged)");
  const hid_t root = handle.get();
  if (H5Aexists(root, "format") <= 0 ||
      h5::read_string(root, "format", file) != "grbd checkpoint") {
    h5::fail(file, "is not a grbd checkpoint (attribute format is not \"grbd checkpoint\")");
  }
  const std::uint64_t version = h5::read_uint(root, "format_version", file);
  if (version != kCheckpointFormatVersion && version != 1) {
    h5::fail(file, "format_version " + std::to_string(version) + ", this grbd reads versions 1 and " +
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

  std::vector<timestep::PackedBody> rows;
  Handle body_type = h5::body_row_type();
  const std::uint64_t n = h5::read_array(root, "bodies", body_type.get(), -1, 0, rows, file);
  std::vector<double> states;
  h5::read_array(root, "states", H5T_NATIVE_DOUBLE, static_cast<std::int64_t>(n), 13, states, file);
  s.bodies.resize(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    timestep::BodyRecord& body = s.bodies[i];
    try {
      body = timestep::unpack(rows[i]);
    } catch (const InvalidArgument& e) {
      h5::fail(file, "dataset bodies, row " + std::to_string(i) + ": " + e.what());
    }
    if (body.id >= s.next_id) {
      h5::fail(file, "dataset bodies, row " + std::to_string(i) + ": expected an id below "
                     "next_id = " + std::to_string(s.next_id) + ", found " +
                     std::to_string(body.id));
    }
    for (int d = 0; d < 7; ++d) body.state.q[d] = states[13 * i + d];
    for (int d = 0; d < 6; ++d) body.state.u[d] = states[13 * i + 7 + d];
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
  // Version 2 carries a checksum of every value: damage is named as damage.
  if (version >= 2 && h5::read_uint(root, "checksum", file) != checksum(c)) {
    h5::fail(file, "is damaged: the checksum of its values does not match the one written with it");
  }
  require_consistent(c, file);
  return c;
}

}  // namespace grbd::io
