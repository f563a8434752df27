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
  /// When the run began (the command line's start): a stop file older than this was left by an
  /// earlier run and is removed at the start; a newer one asks this run to stop.
  std::filesystem::file_time_type started = std::filesystem::file_time_type::clock::now();
  /// Called after every step (progress display) with the simulation, the step's report and the
  /// number of bodies of the run, on every process of a parallel run: the simulation holds the
  /// process's own bodies, the report and the number are the whole run's.
  std::function<void(const scene::Simulation&, const timestep::StepReport&, std::uint64_t)> on_step;
  /// Called with a warning the run goes on after: a restart whose scene text differs from the
  /// checkpoint's (the first line that differs). Without it, warnings are not reported.
  std::function<void(const std::string&)> on_warning;
};

/// Where two scene texts first differ: "" when they are equal, else a message naming the line of
/// `scene_file` and the two versions of it (`given` is the file's text, `saved` the other).
std::string scene_difference(const std::string& saved, const std::string& given,
                             const std::filesystem::path& scene_file);

/// Whether two paths name the same file: the same device and inode when both exist (other
/// spellings, links), else the same canonical path.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

/// Checks a run's files before anything is read, built or written: FileConflict for files that
/// coincide (the stop file included: it may be none of the others, and must be a regular file
/// when it exists) or a NUL in a name; IoError naming the file for an output or checkpoint whose folder
/// does not exist or cannot be written, a name that is a folder or not a regular file, an output
/// that another process holds open, and, on a fresh run without `overwrite`, an output, XDMF or
/// checkpoint that exists already. run() calls it first.
void check_run_files(const scene::Scene& scene, const RunOptions& options);

/// Whether options.stop_file exists (the run is asked to stop).
bool stop_requested(const RunOptions& options);
/// Removes options.stop_file once the stop it asked for is done, if it is a regular file (a
/// missing file is no error).
void remove_stop_file(const RunOptions& options);
/// Removes a stop file last written before options.started (an earlier run was killed before it
/// could remove it), with a warning through options.on_warning; a newer one stays and stops the
/// run at its first step boundary.
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
  /// The convergence of this run's steps and the distribution of every overlap they solved.
  RunAccuracy accuracy;
};

/// Runs `scene` to its end_time (or until *stop) on one process: run() with the one-process
/// communicator and no distribution.
RunResult run(const scene::Scene& scene, const RunOptions& options);

/// Makes the distribution of a scene among the processes of a run (parallel::run gives
/// parallel::SceneDecomposition); it may throw SceneError for a scene it cannot share.
using MakeDistribution = std::function<std::unique_ptr<scene::Distribution>()>;

/// A write of the output or of a checkpoint failed on some process of a parallel run: their
/// parallel HDF5 state is apart, so the files cannot be closed together any more. The output
/// holds every record counted before the failure, the last checkpoint is whole; the program must
/// end without closing HDF5 or finalizing MPI (parallel::MpiEnvironment::end_now), or it would
/// hang or crash in HDF5's collective clean-up.
class AbandonedFiles : public IoError {
 public:
  using IoError::IoError;
};

/// Runs `scene` to its end_time (or until *stop) on every process of `comm` (collective), the one
/// loop of every run, serial or parallel: a record at step 0 (fresh runs), every output.every
/// steps and at the end; a checkpoint every checkpoint.every steps and at the end (before the last
/// record when that is not a regular one, so that a restart from it gives the same records as an
/// uninterrupted run). `make_distribution` shares the scene among the processes (empty: the
/// serial engine, which needs one process).
///
/// Every phase that can fail on one process — the files' checks, the distribution, reading the
/// checkpoint, building the simulation, opening the output, each step, each record, each
/// checkpoint, the close — is agreed (io::agree): every process throws the same error. Throws
/// FileConflict, SceneError or IoError for bad input before the first step (nothing changed: an
/// existing output is truncated or cut back only after every check passed), IoError naming the
/// restart checkpoint for one that does not fit the scene, grbd::Error when a step fails (a
/// blow-up, a diverged solver: the output then holds every record and step row before the
/// failure, and the last checkpoint is the last valid state), and AbandonedFiles when a write
/// failed on many processes. A step that fails on one process while the others wait in its
/// exchanges ends every process after kAgreementPatience (Communicator::agree).
///
/// The stop (options.stop, set by a signal on any process, or the stop file, which rank 0 looks
/// for) is agreed at every step boundary: every process stops there, and the run writes its
/// checkpoint and returns. Warnings are given on rank 0 only; options.on_step on every process.
RunResult run(const scene::Scene& scene, const RunOptions& options, const Communicator& comm,
              const MakeDistribution& make_distribution);

}  // namespace grbd::io
