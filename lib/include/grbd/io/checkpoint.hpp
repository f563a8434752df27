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

/// The format version written to checkpoints. Version 2 adds the attribute `checksum` over every
/// value; version 1 (without it) is still read.
inline constexpr std::uint64_t kCheckpointFormatVersion = 2;

/// Writes `checkpoint` to `path` atomically: into a temporary file beside it, flushed to the disk
/// (fsync), then renamed over `path`, so that a crash at any moment leaves either the previous
/// checkpoint or the new one. Throws IoError naming the file.
void write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);

/// Reads a checkpoint; throws IoError naming the file and the dataset or attribute that is
/// missing, of the wrong shape, or holds values that are not finite or out of range (a state,
/// λ_N < 0, removed_mass, next_id ≥ 2⁶³, more steps than 10¹², counters beyond what was created),
/// and "is damaged" when the values do not give the checksum written with them. What depends on
/// the scene (Δt against t and steps, each body's mass and inertia) is checked by
/// scene::Simulation's restart constructor.
Checkpoint read_checkpoint(const std::filesystem::path& path);

}  // namespace grbd::io
