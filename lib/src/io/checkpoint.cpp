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

#include "grbd/core/collectives.hpp"
#include "io/h5util.hpp"

namespace grbd::io {

namespace {

using timestep::WarmRow;
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

// A body's words for the checksum: its id, one word of shape, fixed and material, then every
// double of the packed record in order, radius to u.
void add_body(Checksum& sum, const timestep::PackedBody& bytes) {
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

// A warm start's key for the checksum: its four words, then its periodic image when it has one
// (version 4; a key of an earlier version has none, so that its checksum reads as before).
void add_key(Checksum& sum, const timestep::ContactKey& key) {
  for (std::uint64_t x : {key.a, key.b, key.feature_a, key.feature_b}) sum.add(x);
  if (key.image != 0) sum.add(key.image);
}

// Version 2's checksum: every value in one sequence (read, not written, since version 3).
std::uint64_t sequential_checksum(const Checkpoint& c) {
  const scene::SimulationState& s = c.state;
  Checksum sum;
  sum.add(c.scene_text);
  sum.add(s.t);
  for (std::uint64_t x :
       {s.steps, s.next_id, s.removed, c.output.records, c.output.steps, c.output.bodies,
        static_cast<std::uint64_t>(s.bodies.size()), static_cast<std::uint64_t>(s.warm_keys.size()),
        static_cast<std::uint64_t>(s.generators.size())}) {
    sum.add(x);
  }
  sum.add(s.removed_mass);
  timestep::PackedBody bytes;
  for (const timestep::BodyRecord& body : s.bodies) {
    timestep::pack(body, bytes);
    add_body(sum, bytes);
  }
  for (std::size_t k = 0; k < s.warm_keys.size(); ++k) {
    add_key(sum, s.warm_keys[k]);
    for (int d = 0; d < 3; ++d) sum.add(s.warm_lambda[k][d]);
  }
  for (const scene::GeneratorState& g : s.generators) {
    sum.add(g.random);
    sum.add(g.created);
  }
  return sum.value();
}

// The columns of a warm start's key: a, b, feature_a, feature_b, image (version 4).
constexpr std::size_t kKeyColumns = 5;

// [checksum]
// Version 3's checksum, which processes that each hold some rows form together: the sequence of
// the scene, the attributes, the numbers of rows and the generators, then the sum (modulo 2⁶⁴)
// over the rows of bodies and warm starts of a checksum of each row that starts with its kind
// and its row number — so that a row changed, moved or swapped with another changes it, and
// the sum does not depend on which process formed which part.
std::uint64_t header_checksum(const Checkpoint& c, std::uint64_t bodies, std::uint64_t warm) {
  const scene::SimulationState& s = c.state;
  Checksum sum;
  sum.add(c.scene_text);
  sum.add(s.t);
  for (std::uint64_t x :
       {s.steps, s.next_id, s.removed, c.output.records, c.output.steps, c.output.bodies, bodies,
        warm, static_cast<std::uint64_t>(s.generators.size())}) {
    sum.add(x);
  }
  sum.add(s.removed_mass);
  for (const scene::GeneratorState& g : s.generators) {
    sum.add(g.random);
    sum.add(g.created);
  }
  return sum.value();
}

// The checksum of the distribution's state, kept apart from the state's: the state's checksum is
// the same whatever the number of processes that wrote it, the cuts are theirs.
std::uint64_t distribution_checksum(const std::vector<double>& distribution) {
  Checksum sum;
  sum.add(static_cast<std::uint64_t>(distribution.size()));
  for (const double x : distribution) sum.add(x);
  return sum.value();
}

std::uint64_t body_checksum(std::uint64_t row, const timestep::PackedBody& body) {
  Checksum sum;
  sum.add(std::uint64_t{'b'});
  sum.add(row);
  add_body(sum, body);
  return sum.value();
}

std::uint64_t warm_checksum(std::uint64_t row, const WarmRow& warm) {
  Checksum sum;
  sum.add(std::uint64_t{'w'});
  sum.add(row);
  add_key(sum, warm.key);
  for (double x : warm.lambda) sum.add(x);
  return sum.value();
}

std::uint64_t combined_checksum(std::uint64_t header, std::uint64_t rows) {
  return mix64(header ^ mix64(rows));
}
// [checksum]

}  // namespace

namespace {

// Writes this process's part of the checkpoint into `temporary` (together with the other
// processes), flushed to the disk by rank 0.
void write_temporary(const Communicator& comm, const std::filesystem::path& temporary,
                     const Checkpoint& checkpoint) {
  const std::string file = temporary.string();
  const scene::SimulationState& s = checkpoint.state;
  // The rows: a serial run's in its own order (the order of its bodies is part of its state: a
  // restart that changed it would sweep its contacts in another order); many processes' in the
  // global order, bodies by id, warm starts by key, each key once.
  std::vector<timestep::PackedBody> bodies;
  h5::pack_rows(s.bodies, bodies);
  std::vector<WarmRow> warm(s.warm_keys.size());
  for (std::size_t k = 0; k < warm.size(); ++k) {
    warm[k].key = s.warm_keys[k];
    for (int d = 0; d < 3; ++d) warm[k].lambda[d] = s.warm_lambda[k][d];
  }
  if (comm.size() > 1) {
    grbd::collective::sort_across(
        comm, bodies, [](const timestep::PackedBody& row) { return timestep::packed_id(row); });
    grbd::collective::sort_across(comm, warm, [](const WarmRow& w) { return w.key; });
    warm.erase(std::unique(warm.begin(), warm.end(),
                           [](const WarmRow& a, const WarmRow& b) { return a.key == b.key; }),
               warm.end());
  }
  const grbd::collective::Block body_block = grbd::collective::block_of(comm, bodies.size());
  const grbd::collective::Block warm_block = grbd::collective::block_of(comm, warm.size());
  std::uint64_t rows[1] = {0};
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    rows[0] += body_checksum(body_block.offset + i, bodies[i]);
  }
  for (std::size_t k = 0; k < warm.size(); ++k) {
    rows[0] += warm_checksum(warm_block.offset + k, warm[k]);
  }
  comm.sum(rows);
  const std::uint64_t checksum =
      combined_checksum(header_checksum(checkpoint, body_block.total, warm_block.total), rows[0]);

  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  Handle handle = check(
      H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, h5::shared_access(comm, file).get()),
      H5Fclose, file, "cannot create the checkpoint");
  const Handle transfer = h5::shared_transfer(comm, file);
  const hid_t root = handle.get(), x = transfer.get();
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
  h5::write_attribute(root, "checksum", checksum, file);

  const std::size_t n = bodies.size();
  std::vector<double> states(13 * n);
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(states.data() + 13 * i, bodies[i].data() + timestep::packed::q,
                13 * sizeof(double));
  }
  Handle body_type = h5::body_row_type();
  h5::write_rows(root, "bodies", h5::packed(body_type.get()).get(), body_type.get(),
                 body_block.total, 0, body_block.offset, n, bodies.data(), x, file);
  h5::write_rows(root, "states", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, body_block.total, 13,
                 body_block.offset, n, states.data(), x, file);

  const std::size_t m = warm.size();
  std::vector<std::uint64_t> keys(kKeyColumns * m);
  std::vector<double> lambda(3 * m);
  for (std::size_t k = 0; k < m; ++k) {
    const timestep::ContactKey& key = warm[k].key;
    std::uint64_t* row = keys.data() + kKeyColumns * k;
    row[0] = key.a;
    row[1] = key.b;
    row[2] = key.feature_a;
    row[3] = key.feature_b;
    row[4] = key.image;
    for (int d = 0; d < 3; ++d) lambda[3 * k + d] = warm[k].lambda[d];
  }
  h5::write_rows(root, "warm_start_keys", H5T_STD_U64LE, H5T_NATIVE_UINT64, warm_block.total,
                 kKeyColumns, warm_block.offset, m, keys.data(), x, file);
  h5::write_rows(root, "warm_start_lambda", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, warm_block.total, 3,
                 warm_block.offset, m, lambda.data(), x, file);

  // The generators' states are the same on every process: rank 0 writes them.
  std::vector<std::uint64_t> generators;
  for (const scene::GeneratorState& g : s.generators) {
    generators.push_back(g.random);
    generators.push_back(g.created);
  }
  const std::uint64_t g = s.generators.size();
  h5::write_rows(root, "generators", H5T_STD_U64LE, H5T_NATIVE_UINT64, g, 2, 0,
                 comm.rank() == 0 ? g : 0, generators.data(), x, file);
  // The distribution's state (the partition of a parallel run), the same on every process.
  if (const std::uint64_t d = s.distribution.size(); d > 0) {
    h5::write_rows(root, "distribution", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, d, 0, 0,
                   comm.rank() == 0 ? d : 0, s.distribution.data(), x, file);
    h5::write_attribute(root, "distribution_checksum", distribution_checksum(s.distribution),
                        file);
  }
  check(H5Fflush(root, H5F_SCOPE_LOCAL), file, "cannot flush the checkpoint");
  if (!handle.close()) h5::fail(file, "cannot close the checkpoint");
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint) {
  write_checkpoint(self_communicator(), path, checkpoint);
}

// [write checkpoint]
void write_checkpoint(const Communicator& comm, const std::filesystem::path& path,
                      const Checkpoint& checkpoint) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  const bool root = comm.rank() == 0;
  try {
    agree(comm, [&] { write_temporary(comm, temporary, checkpoint); });
    agree(comm, [&] {
      if (!root) return;
      sync_path(temporary, O_RDONLY);
      std::error_code error;
      std::filesystem::rename(temporary, path, error);
      if (error) {
        throw IoError(path.string() +
                      ": cannot move the new checkpoint into place: " + error.message());
      }
      const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
      sync_path(folder, O_RDONLY | O_DIRECTORY);
    });
  } catch (const Error&) {
    std::error_code ignored;  // a partial temporary is of no use; the previous checkpoint stays
    if (root) std::filesystem::remove(temporary, ignored);
    throw;
  }
}
// [write checkpoint]

namespace {

// What a checkpoint can be checked against without its scene: finite values, counters in range.
// The rows of bodies and warm starts are this process's, from rows first_body and first_warm of
// the file.
void require_consistent(const Checkpoint& c, const std::string& file, std::uint64_t first_body,
                        std::uint64_t first_warm) {
  const scene::SimulationState& s = c.state;
  const auto refuse = [&](const std::string& what) { h5::fail(file, what); };
  if (s.next_id >= timestep::kStaticTag) {
    refuse("attribute next_id: expected an id below 2^63, found " + std::to_string(s.next_id));
  }
  if (s.removed > s.next_id) {
    refuse("attribute removed: " + std::to_string(s.removed) + " bodies removed, more than the " +
           std::to_string(s.next_id) + " created (next_id)");
  }
  if (!std::isfinite(s.removed_mass) || s.removed_mass < 0.0) {
    refuse("attribute removed_mass: expected a finite mass ≥ 0, found " +
           format_number(s.removed_mass));
  }
  if (s.steps > scene::kMaxSteps) {
    refuse("attribute steps: expected at most 10¹², found " + std::to_string(s.steps));
  }
  if (c.output.steps > s.steps || c.output.records > s.steps + 1 || c.output.bodies > s.next_id) {
    refuse(
        "attributes output_records, output_steps, output_bodies: expected at most steps + 1, "
        "steps and next_id, found " +
        std::to_string(c.output.records) + ", " + std::to_string(c.output.steps) + ", " +
        std::to_string(c.output.bodies));
  }
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (!s.bodies[i].state.q.allFinite() || !s.bodies[i].state.u.allFinite()) {
      refuse("dataset states, row " + std::to_string(first_body + i) + " (body " +
             std::to_string(s.bodies[i].id) + "): not finite");
    }
  }
  for (std::size_t k = 0; k < s.warm_lambda.size(); ++k) {
    if (!(s.warm_lambda[k][0] >= 0.0)) {
      refuse("dataset warm_start_lambda, row " + std::to_string(first_warm + k) +
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

namespace {

// What one process reads of a checkpoint: every attribute and the generators, and its slab of
// the bodies and warm starts (all of them for a version before 3, whose checksum covers the
// sequence of every value).
struct Part {
  Checkpoint checkpoint;
  std::uint64_t version = 0;
  std::uint64_t checksum = 0;    // as written (version ≥ 2)
  std::uint64_t rows_sum = 0;    // of this slab's rows (version 3)
  std::uint64_t bodies = 0;      // rows in the file
  std::uint64_t warm = 0;        // rows in the file
  std::uint64_t first_body = 0;  // global row of the slab's first body
  std::uint64_t first_warm = 0;  // global row of the slab's first warm start
};

// Rows [lo, hi) of n: this process's slab.
std::pair<std::uint64_t, std::uint64_t> slab(const Communicator& comm, std::uint64_t n) {
  const auto P = static_cast<std::uint64_t>(comm.size());
  const auto r = static_cast<std::uint64_t>(comm.rank());
  return {n / P * r + std::min(r, n % P), n / P * (r + 1) + std::min(r + 1, n % P)};
}

void read_part(const Communicator& comm, const std::filesystem::path& path, Part& part) {
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
  if (version < 1 || version > kCheckpointFormatVersion) {
    h5::fail(file, "format_version " + std::to_string(version) +
                       ", this grbd reads versions 1 to " +
                       std::to_string(kCheckpointFormatVersion));
  }
  part.version = version;
  Checkpoint& c = part.checkpoint;
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
  if (version >= 2) part.checksum = h5::read_uint(root, "checksum", file);

  // This process's rows: a slab, or every row for the sequential checksum of versions 1 and 2.
  Handle body_type = h5::body_row_type();
  const std::uint64_t n = h5::rows_of(root, "bodies", body_type.get(), 0, file);
  // A key's columns: a, b, feature_a, feature_b, and (version 4) the periodic image.
  const std::size_t columns = version >= 4 ? kKeyColumns : 4;
  const std::uint64_t m = h5::rows_of(root, "warm_start_keys", H5T_NATIVE_UINT64, columns, file);
  part.bodies = n;
  part.warm = m;
  const bool sliced = version >= 3;
  using Rows = std::pair<std::uint64_t, std::uint64_t>;
  const auto [body_lo, body_hi] = sliced ? slab(comm, n) : Rows{0, n};
  const auto [warm_lo, warm_hi] = sliced ? slab(comm, m) : Rows{0, m};
  part.first_body = body_lo;
  part.first_warm = warm_lo;
  std::vector<timestep::PackedBody> rows;
  h5::read_rows(root, "bodies", body_type.get(), n, 0, body_lo, body_hi - body_lo, rows, file);
  std::vector<double> states;
  h5::read_rows(root, "states", H5T_NATIVE_DOUBLE, n, 13, body_lo, body_hi - body_lo, states, file);
  s.bodies.resize(body_hi - body_lo);
  timestep::PackedBody packed;
  for (std::uint64_t i = 0; i < s.bodies.size(); ++i) {
    const std::string row = "dataset bodies, row " + std::to_string(body_lo + i) + ": ";
    timestep::BodyRecord& body = s.bodies[i];
    try {
      body = timestep::unpack(rows[i]);
    } catch (const InvalidArgument& e) {
      h5::fail(file, row + e.what());
    }
    if (body.id >= s.next_id) {
      h5::fail(file, row + "expected an id below next_id = " + std::to_string(s.next_id) +
                         ", found " + std::to_string(body.id));
    }
    for (int d = 0; d < 7; ++d) body.state.q[d] = states[13 * i + d];
    for (int d = 0; d < 6; ++d) body.state.u[d] = states[13 * i + 7 + d];
    if (sliced) {
      timestep::pack(body, packed);
      part.rows_sum += body_checksum(body_lo + i, packed);
    }
  }
  std::vector<std::uint64_t> keys;
  h5::read_rows(root, "warm_start_keys", H5T_NATIVE_UINT64, m, columns, warm_lo, warm_hi - warm_lo,
                keys, file);
  std::vector<double> lambda;
  h5::read_rows(root, "warm_start_lambda", H5T_NATIVE_DOUBLE, m, 3, warm_lo, warm_hi - warm_lo,
                lambda, file);
  const std::size_t w = warm_hi - warm_lo;
  s.warm_keys.resize(w);
  s.warm_lambda.resize(w);
  for (std::size_t k = 0; k < w; ++k) {
    const std::uint64_t* key = keys.data() + columns * k;
    const WarmRow row{{key[0], key[1], key[2], key[3], columns > 4 ? key[4] : 0},
                      {lambda[3 * k], lambda[3 * k + 1], lambda[3 * k + 2]}};
    if (row.key.image > 27 || row.key.image == 14) {
      h5::fail(file, "dataset warm_start_keys, row " + std::to_string(warm_lo + k) +
                         ": expected a periodic image code 0 to 27 other than 14, found " +
                         std::to_string(row.key.image));
    }
    s.warm_keys[k] = row.key;
    s.warm_lambda[k] = Vector3(row.lambda[0], row.lambda[1], row.lambda[2]);
    if (!s.warm_lambda[k].allFinite()) {
      h5::fail(file,
               "dataset warm_start_lambda, row " + std::to_string(warm_lo + k) + ": not finite");
    }
    if (sliced) part.rows_sum += warm_checksum(warm_lo + k, row);
  }
  std::vector<std::uint64_t> generators;
  const std::uint64_t g =
      h5::read_array(root, "generators", H5T_NATIVE_UINT64, -1, 2, generators, file);
  s.generators.resize(g);
  for (std::uint64_t k = 0; k < g; ++k)
    s.generators[k] = {generators[2 * k], generators[2 * k + 1]};
  if (H5Lexists(root, "distribution", H5P_DEFAULT) > 0) {
    h5::read_array(root, "distribution", H5T_NATIVE_DOUBLE, -1, 0, s.distribution, file);
    if (H5Aexists(root, "distribution_checksum") <= 0 ||
        h5::read_uint(root, "distribution_checksum", file) !=
            distribution_checksum(s.distribution)) {
      h5::fail(file,
               "is damaged: dataset distribution does not match its checksum "
               "(attribute distribution_checksum)");
    }
  }
  // Version 2 carries a checksum of every value in sequence: damage is named as damage.
  if (version == 2 && part.checksum != sequential_checksum(c)) {
    h5::fail(file, "is damaged: the checksum of its values does not match the one written with it");
  }
}

}  // namespace

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  return read_checkpoint(self_communicator(), path);
}

// [read checkpoint]
Checkpoint read_checkpoint(const Communicator& comm, const std::filesystem::path& path) {
  Part part;
  agree(comm, [&] { read_part(comm, path, part); });
  Checkpoint& c = part.checkpoint;
  if (part.version >= 3) {
    // The sum over every process's slab: the same on every process, and so the same verdict.
    std::uint64_t rows[1] = {part.rows_sum};
    comm.sum(rows);
    const std::uint64_t header = header_checksum(c, part.bodies, part.warm);
    if (part.checksum != combined_checksum(header, rows[0])) {
      throw IoError(path.string() +
                    ": is damaged: the checksum of its values does not match "
                    "the one written with it");
    }
  } else if (comm.size() > 1) {
    // Versions 1 and 2 were read whole: keep this process's slab.
    scene::SimulationState& s = c.state;
    const auto [lo, hi] = slab(comm, s.bodies.size());
    s.bodies = {s.bodies.begin() + static_cast<std::ptrdiff_t>(lo),
                s.bodies.begin() + static_cast<std::ptrdiff_t>(hi)};
    const auto [wlo, whi] = slab(comm, s.warm_keys.size());
    s.warm_keys = {s.warm_keys.begin() + static_cast<std::ptrdiff_t>(wlo),
                   s.warm_keys.begin() + static_cast<std::ptrdiff_t>(whi)};
    s.warm_lambda = {s.warm_lambda.begin() + static_cast<std::ptrdiff_t>(wlo),
                     s.warm_lambda.begin() + static_cast<std::ptrdiff_t>(whi)};
    part.first_body = lo;
    part.first_warm = wlo;
  }
  agree(
      comm, [&] { require_consistent(c, path.string(), part.first_body, part.first_warm); });
  return std::move(c);
}
// [read checkpoint]

}  // namespace grbd::io
