#pragma once
/// \file
/// \brief Checkpoints (chapter 7): everything the next step needs, written atomically, so that a
/// run of 2N steps and a run of N steps, a restart and N more steps give bit-identical output.

#include <filesystem>
#include <string>

#include "grbd/io/output.hpp"
#include "grbd/scene/simulation.hpp"

namespace grbd::io {

/// What a checkpoint holds.
struct Checkpoint {
  scene::SimulationState state;  ///< bodies, clock, warm starts, generators
  OutputPosition output;         ///< how much of the output file belongs to the run so far
  std::string scene_text;        ///< the scene the run was started from
};

/// The format version written to checkpoints. Version 4's warm-start keys have a fifth column, the
/// periodic image of the contact (timestep::ContactKey::image). Version 3's `checksum` is formed
/// from the rows of bodies and warm starts independently, so that processes that each read or
/// write a slab of rows form it together; versions 3 (keys without an image), 2 (a checksum of
/// every value in sequence) and 1 (without one) are still read.
inline constexpr std::uint64_t kCheckpointFormatVersion = 4;

/// Writes `checkpoint` to `path` atomically: into a temporary file beside it, flushed to the disk
/// (fsync), then renamed over `path`, so that a crash at any moment leaves either the previous
/// checkpoint or the new one. Throws IoError naming the file.
void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);
/// The same by the processes of `comm` together (collective): each gives its own bodies and warm
/// starts in `checkpoint.state` (the rest is the same on every process), and the file holds
/// them in the global order, bodies by id and warm starts by key (each once), written with
/// parallel HDF5; rank 0 flushes and renames. With one process, the state's own order (a serial
/// run's order of bodies is part of its state). An error is thrown on every process.
void write_checkpoint(const Communicator& comm, const std::filesystem::path& path,
                      const Checkpoint& checkpoint);

/// Reads a checkpoint; throws IoError naming the file and the dataset or attribute that is
/// missing, of the wrong shape, or holds values that are not finite or out of range (a state,
/// λ_N < 0, removed_mass, next_id ≥ 2⁶³, more steps than 10¹², counters beyond what was created),
/// and "is damaged" when the values do not give the checksum written with them. What depends on
/// the scene (Δt against t and steps, each body's mass and inertia) is checked by
/// scene::Simulation's restart constructor.
Checkpoint read_checkpoint(const std::filesystem::path& path);
/// The same by the processes of `comm` together (collective): each reads every attribute and the
/// generators, and a slab of about 1/P of the rows of bodies and warm starts (rank r the r-th, in
/// the file's order) — its part of the checksum, summed over the processes, is checked against
/// the one written (a version 1 or 2 checkpoint is read whole by each, and then cut to its
/// slab). The slabs are not yet where the bodies belong: the parallel run sends each body to its
/// owner. An error is thrown on every process.
Checkpoint read_checkpoint(const Communicator& comm, const std::filesystem::path& path);

}  // namespace grbd::io
