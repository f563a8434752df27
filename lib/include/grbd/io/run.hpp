#pragma once
/// \file
/// \brief A whole run of a scene (chapter 7): generators, steps, output records, checkpoints,
/// restart and a clean stop on request, as `grbd run` does it.

#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
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
  /// Replace an existing output, its XDMF and checkpoint on a fresh run (`grbd run --force`);
  /// without it a fresh run refuses to overwrite any of them.
  bool overwrite = false;
  /// Set from a signal handler: the run finishes its step, writes a checkpoint and returns.
  const volatile std::sig_atomic_t* stop = nullptr;
  /// A file whose existence asks the run to stop as on a signal: it is looked for at every step
  /// boundary (by rank 0 of a parallel run), and removed once the checkpoint is written. What a
  /// job on a cluster touches before its time is up, when a signal to mpirun might not leave the
  /// processes time enough to finish. Empty: none.
  std::filesystem::path stop_file;
  /// Called after every step (progress display) with the simulation, the step's report and the
  /// number of bodies of the run. In a parallel run it is called on rank 0 only, whose simulation
  /// holds its own bodies; the report and the number are the whole run's.
  std::function<void(const scene::Simulation&, const timestep::StepReport&, std::uint64_t)> on_step;
  /// Called with a warning the run goes on after: a restart whose scene text differs from the
  /// checkpoint's (the first line that differs). Without it, warnings are not reported.
  std::function<void(const std::string&)> on_warning;
};

/// Where two scene texts first differ: "" when they are equal, else a message naming the line of
/// `scene_file` and the two versions of it (`given` is the file's text, `saved` the other).
std::string scene_difference(const std::string& saved, const std::string& given,
                             const std::filesystem::path& scene_file);

/// A run's files that coincide (the output, its XDMF, the checkpoint, their temporary names, the
/// scene, its meshes and the restart checkpoint must be different files), or a file name with a
/// NUL character: a bad command line (`grbd run` exits 2).
class FileConflict : public IoError {
 public:
  using IoError::IoError;
};

/// Whether two paths name the same file: the same device and inode when both exist (other
/// spellings, links), else the same canonical path.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

/// Checks a run's files before anything is read, built or written: FileConflict for files that
/// coincide or a NUL in a name; IoError naming the file for an output or checkpoint whose folder
/// does not exist or cannot be written, a name that is a folder or not a regular file, an output
/// that another process holds open, and, on a fresh run without `overwrite`, an output, XDMF or
/// checkpoint that exists already. run() calls it first.
void check_run_files(const scene::Scene& scene, const RunOptions& options);

/// Whether options.stop_file exists (the run is asked to stop).
bool stop_requested(const RunOptions& options);
/// Removes options.stop_file once the stop it asked for is done (a missing file is no error).
void remove_stop_file(const RunOptions& options);
/// Removes a stop file that is there before the run starts (an earlier run was killed before it
/// could remove it), with a warning through options.on_warning.
void clear_stale_stop_file(const RunOptions& options);

/// The simulation a restart continues: `scene` built from `checkpoint`'s state (with
/// `distribution`, this process's part of a parallel run). Throws IoError naming `restart`, the
/// checkpoint's file, when the state does not fit the scene (the checkpoint is at fault).
std::unique_ptr<scene::Simulation> restored_simulation(const scene::Scene& scene,
                                                       const Checkpoint& checkpoint,
                                                       const std::filesystem::path& restart,
                                                       const scene::Distribution* distribution);

/// What a run did.
struct RunResult {
  bool interrupted = false;       ///< stopped by *stop or the stop file before the end
  bool stop_file = false;         ///< stopped by the stop file
  std::uint64_t steps = 0;        ///< steps done by this run
  std::uint64_t records = 0;      ///< records in the output at the end
  std::uint64_t checkpoints = 0;  ///< checkpoints written by this run
  double seconds = 0.0;           ///< wall time of the run [s]
  double step_seconds = 0.0;      ///< of which in steps [s]
  double output_seconds = 0.0;    ///< of which writing records and checkpoints [s]
  /// Times a run on many processes re-cut the domain to even the load (chapter 8; 0 serially).
  std::uint64_t rebalances = 0;
};

/// Runs `scene` to its end_time (or until *stop): a record at step 0 (fresh runs), every
/// output.every steps and at the end; a checkpoint every checkpoint.every steps and at the end
/// (before the last record when that is not a regular one, so that a restart from it gives the
/// same records as an uninterrupted run). Throws FileConflict, SceneError or IoError for bad
/// input before the first step (nothing changed: an existing output is truncated or cut back only
/// after every check passed), IoError naming the restart checkpoint for one that does not fit the
/// scene, and grbd::Error when a step fails (a blow-up, a diverged solver, a write that failed):
/// the output then holds every record and step row before the failure, and the last checkpoint is
/// the last valid state.
RunResult run(const scene::Scene& scene, const RunOptions& options);

}  // namespace grbd::io
