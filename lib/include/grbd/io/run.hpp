#pragma once
/// \file
/// \brief A whole run of a scene (chapter 7): generators, steps, output records, checkpoints,
/// restart and a clean stop on request, as `grbd run` does it.

#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "grbd/io/checkpoint.hpp"
#include "grbd/io/output.hpp"
#include "grbd/scene/simulation.hpp"

namespace grbd::io {

/// How to run.
struct RunOptions {
  std::filesystem::path output;      ///< the HDF5 output (the XDMF goes beside it)
  std::filesystem::path checkpoint;  ///< where checkpoints are written
  /// Continue from this checkpoint (the output is reopened and cut back to it, or created when
  /// it does not exist).
  std::optional<std::filesystem::path> restart;
  /// Set from a signal handler: the run finishes its step, writes a checkpoint and returns.
  const volatile std::sig_atomic_t* stop = nullptr;
  /// Called after every step (progress display).
  std::function<void(const scene::Simulation&, const timestep::StepReport&)> on_step;
  /// Called with a warning the run goes on after: a restart whose scene text differs from the
  /// checkpoint's (the first line that differs). Without it, warnings are not reported.
  std::function<void(const std::string&)> on_warning;
};

/// Where two scene texts first differ: "" when they are equal, else a message naming the line of
/// `scene_file` and the two versions of it (`given` is the file's text, `saved` the other).
std::string scene_difference(const std::string& saved, const std::string& given,
                             const std::filesystem::path& scene_file);

/// What a run did.
struct RunResult {
  bool interrupted = false;       ///< stopped by *stop before the end
  std::uint64_t steps = 0;        ///< steps done by this run
  std::uint64_t records = 0;      ///< records in the output at the end
  std::uint64_t checkpoints = 0;  ///< checkpoints written by this run
  double seconds = 0.0;           ///< wall time of the run [s]
  double step_seconds = 0.0;      ///< of which in steps [s]
  double output_seconds = 0.0;    ///< of which writing records and checkpoints [s]
};

/// Runs `scene` to its end_time (or until *stop): a record at step 0 (fresh runs), every
/// output.every steps and at the end; a checkpoint every checkpoint.every steps and at the end
/// (before the last record when that is not a regular one, so that a restart from it gives the
/// same records as an uninterrupted run). Throws SceneError or IoError for bad input before the
/// first step, and grbd::Error when a step fails (the output then holds what was recorded).
RunResult run(const scene::Scene& scene, const RunOptions& options);

}  // namespace grbd::io
