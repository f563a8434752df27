// The grbd command line (chapter 7): run a scene, check it, summarise an output file.
//
//   grbd run <scene.toml> [--output FILE] [--checkpoint FILE] [--restart CKPT] [--end-time T]
//            [--quiet] [--progress auto|bar|lines]
//   grbd validate <scene.toml>
//   grbd info <output.h5>
//   grbd fclib <FCLIB file or folder>... [--tol T] [--max-iterations N] [--csv FILE]
//   grbd bench [--list] [NAME...] [Google Benchmark options]
//
// Exit codes (also in `grbd --help`):
//   0    done
//   1    the run failed (a solver diverged, a file could not be written)
//   2    bad command line
//   3    bad input: a scene, checkpoint, output or FCLIB file that cannot be used (nothing was
//        run)
//   4    stopped because the stop file (--stop-file, default <checkpoint>.stop) appeared: the
//        step was finished, a checkpoint written, the output closed and the stop file removed
//   130  stopped by SIGINT, 143 by SIGTERM: the step was finished, a checkpoint written and the
//        output closed; `grbd run <scene> --restart <checkpoint>` continues
//
// Under mpirun (mpirun -np P grbd run ...) the run is shared among the processes (chapter 8):
// rank 0 prints progress, summary and errors; every process exits with the same code. A step that
// fails on one process while the others wait in its exchanges ends every process through
// MPI_Abort with code 1 once the agreement's patience has passed. A signal to mpirun itself:
// mpirun's own exit code (Open MPI: 1), after every process has written its checkpoint.

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "grbd/contact/fclib_bench.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/io/output.hpp"
#include "grbd/io/run.hpp"
#include "grbd/parallel/chute.hpp"
#include "grbd/parallel/mpi.hpp"
#include "grbd/parallel/run.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"
#include "grbd/version.hpp"

extern char** environ;  // POSIX: the environment, for posix_spawn

namespace {

constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;
constexpr int kExitInput = 3;
constexpr int kExitStopFile = 4;

constexpr const char* kExitCodes =
    "Exit codes: 0 done; 1 the run failed (a solver diverged, a state blew up, a file could not be "
    "written, out of memory); 2 bad command line (also: files that coincide); 3 bad input "
    "(scene, checkpoint, output or FCLIB file; an output folder that cannot be written; an "
    "existing result without --force), nothing run or changed; 4 stopped by the stop file after "
    "writing a checkpoint; 130 / 143 stopped by SIGINT / SIGTERM after writing a checkpoint "
    "(continue with --restart). Under mpirun every process exits with the same code and rank 0 "
    "reports it; a signal to mpirun itself ends it with mpirun's own code (Open MPI: 1) once every "
    "process has written the checkpoint: the stop file (4) is the way to a code of grbd's.";
constexpr const char* kSceneFormat =
    "The scene format: chapter 7 of the book, section \"Scene files\" (every key, its unit, "
    "default and range).";
constexpr const char* kValidateExitCodes =
    "Exit codes: 0 the scene is valid; 2 bad command line; 3 the scene cannot be read or built "
    "(the message names file, line and key); 1 out of memory.";
constexpr const char* kInfoExitCodes =
    "Exit codes: 0 done; 2 bad command line; 3 not a readable grbd output file.";
constexpr const char* kChuteExitCodes =
    "Exit codes: 0 done; 1 the CSV could not be written; 2 bad command line (also a --csv that is "
    "the output, its XDMF or scene, a folder, a device or FIFO, a read-only file or a file that is "
    "not an earlier table of grbd chute); 3 not a "
    "readable grbd output file (or one a run is writing).";
constexpr const char* kFclibExitCodes =
    "Exit codes: 0 every problem was solved (converged or not: the table says); 1 the CSV could "
    "not be written; 2 bad command line (also a CSV that is one of the problems); 3 a file the "
    "FCLIB reader refuses (the files before it were solved, an earlier CSV is left as it was).";
constexpr const char* kBenchExitCodes =
    "Exit codes: 0 every program ran; 1 a program failed, or none is built; 2 bad command line, "
    "or no program matches a name.";

volatile std::sig_atomic_t g_signal = 0;

// Where the processes of a parallel run other than rank 0 write their messages.
std::ostream& null_stream() {
  static std::ostream none(nullptr);
  return none;
}

extern "C" void on_signal(int signal) { g_signal = signal; }

void install_handlers() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

std::string clock_text(double seconds) {
  if (!(seconds >= 0.0) || seconds > 1e7) return "--:--";
  const auto s = static_cast<long>(seconds + 0.5);
  std::ostringstream out;
  if (s >= 3600)
    out << s / 3600 << ':' << std::setw(2) << std::setfill('0') << (s / 60) % 60;
  else
    out << s / 60;
  out << ':' << std::setw(2) << std::setfill('0') << s % 60;
  return out.str();
}

// The progress display: a bar redrawn in place on a terminal, a plain line every 10 s otherwise.
class Progress {
 public:
  Progress(bool bar, std::uint64_t total) : bar_(bar), total_(total) {}

  void update(const grbd::scene::Simulation& sim, const grbd::timestep::StepReport& report,
              std::uint64_t bodies) {
    const auto now = std::chrono::steady_clock::now();
    if (!started_) {
      started_ = true;
      start_ = now;
      last_ = now;
      first_step_ = report.step - 1;
    }
    const double since = std::chrono::duration<double>(now - last_).count();
    const bool last = report.step >= total_;
    if (since < (bar_ ? 0.2 : 10.0) && !last) return;
    last_ = now;
    // The rate of the last 30 s, not of the whole run: a pour falls freely at first and slows
    // down as contacts form, and the ETA follows the present rate.
    samples_.emplace_back(now, report.step);
    while (samples_.size() > 2 &&
           std::chrono::duration<double>(now - samples_[1].first).count() > kWindow) {
      samples_.pop_front();
    }
    const double window = std::chrono::duration<double>(now - samples_.front().first).count();
    const double since_start = std::chrono::duration<double>(now - start_).count();
    const double rate =
        window > 0.0        ? static_cast<double>(report.step - samples_.front().second) / window
        : since_start > 0.0 ? static_cast<double>(report.step - first_step_) / since_start
                            : 0.0;
    const double remaining = rate > 0.0 ? static_cast<double>(total_ - report.step) / rate : -1.0;
    const double fraction =
        total_ > 0 ? static_cast<double>(report.step) / static_cast<double>(total_) : 1.0;
    std::ostringstream line;
    line << std::fixed << std::setprecision(1) << std::setw(5) << 100.0 * fraction
         << "%  t = " << std::setprecision(4) << report.t << " / " << sim.scene().end_time
         << " s  step " << report.step << " / " << total_ << "  " << std::setprecision(1) << rate
         << " steps/s  ETA " << clock_text(remaining) << "  bodies " << bodies << "  contacts "
         << report.contacts << "  iterations " << report.iterations;
    if (bar_) {
      constexpr int kWidth = 24;
      const int filled = static_cast<int>(fraction * kWidth);
      std::string bar(static_cast<std::size_t>(filled), '#');
      bar.resize(kWidth, '.');
      std::cerr << "\r\033[K[" << bar << "] " << line.str() << std::flush;
      if (last) std::cerr << '\n';
    } else {
      std::cerr << line.str() << '\n' << std::flush;
    }
  }
  void finish() {
    if (bar_ && started_) std::cerr << '\n';
  }

 private:
  bool bar_;
  std::uint64_t total_;
  static constexpr double kWindow = 30.0;  // [s] of samples the rate is taken over
  bool started_ = false;
  std::uint64_t first_step_ = 0;
  std::chrono::steady_clock::time_point start_, last_;
  std::deque<std::pair<std::chrono::steady_clock::time_point, std::uint64_t>> samples_;
};

// Throws InvalidArgument on a process whose scene text or end time differs from rank 0's: the
// processes of one run must run one scene.
void same_as_rank_0(const grbd::Communicator& world, const grbd::scene::Scene& scene,
                    const std::string& scene_file) {
  if (world.size() == 1) return;
  std::vector<std::byte> bytes(sizeof(double) + scene.text.size());
  std::memcpy(bytes.data(), &scene.end_time, sizeof(double));
  std::memcpy(bytes.data() + sizeof(double), scene.text.data(), scene.text.size());
  std::vector<std::byte> theirs = bytes;
  world.broadcast(theirs, 0);
  if (theirs == bytes) return;
  double end = 0.0;
  std::memcpy(&end, theirs.data(), sizeof(double));
  const bool same_text = theirs.size() == bytes.size() &&
                         std::equal(bytes.begin() + sizeof(double), bytes.end(),
                                    theirs.begin() + sizeof(double));
  throw grbd::InvalidArgument(
      scene_file + ": " +
      (same_text ? "the end time " + grbd::format_number(scene.end_time) + " s differs from rank 0's, " +
                       grbd::format_number(end) + " s"
                 : std::string("the scene differs from the one rank 0 read")) +
      ": every process of a run must be given the same scene and options");
}

// Each line of `text` indented by two spaces.
std::string indented(const std::string& text) {
  std::string out;
  std::size_t from = 0;
  while (from < text.size()) {
    const std::size_t end = text.find('\n', from);
    const std::size_t to = end == std::string::npos ? text.size() : end + 1;
    out += "  " + text.substr(from, to - from);
    from = to;
  }
  return out;
}

int run_command(const std::string& scene_file, const std::optional<std::string>& output,
                const std::optional<std::string>& checkpoint,
                const std::optional<std::string>& restart,
                const std::optional<std::string>& end_time,
                const std::optional<std::string>& stop_file, bool force, bool quiet,
                const std::string& progress) {
  // A stop file touched after this moment asks this run to stop (one from before was left by
  // an earlier run).
  const auto run_started = std::filesystem::file_time_type::clock::now();
  // Under mpirun: MPI for the run, rank 0 speaks for every process (one progress display, one
  // summary, one message per error); each process exits with the same code.
  const grbd::parallel::MpiEnvironment mpi;
  const grbd::Communicator& world = mpi.world();
  const bool speaker = world.rank() == 0;
  if (!speaker) quiet = true;
  std::ostream& errors = speaker ? std::cerr : null_stream();
  // Every process reads the scene and the options, and every error is agreed, so that one
  // process's (its own folder or command line under mpirun's MPMD syntax) ends them all with one
  // message; a scene or end time that differs from rank 0's is such an error.
  grbd::scene::Scene scene;
  try {
    grbd::io::agree(world, [&] { scene = grbd::scene::load_scene(scene_file); });
  } catch (const grbd::Error& e) {
    errors << "grbd run: " << e.what() << '\n';
    return kExitInput;
  }
  try {
    grbd::io::agree(world, [&] {
      // The rules of the scene's key end_time: a decimal time > 0 of at most 10¹² steps.
      if (end_time) {
        grbd::scene::set_end_time(scene, grbd::scene::parse_real(*end_time, "--end-time"),
                                  "--end-time");
      }
    });
    grbd::io::agree(world, [&] { same_as_rank_0(world, scene, scene_file); });
  } catch (const grbd::Error& e) {
    errors << "grbd run: " << e.what() << '\n';
    return kExitUsage;
  }
  grbd::io::RunOptions options;
  options.output = output ? std::filesystem::path(*output) : scene.output.file;
  options.checkpoint = checkpoint ? std::filesystem::path(*checkpoint) : scene.checkpoint.file;
  if (restart) options.restart = *restart;
  options.overwrite = force;
  options.started = run_started;
  options.stop_file = stop_file ? std::filesystem::path(*stop_file)
                                : std::filesystem::path(options.checkpoint.string() + ".stop");
  const bool bar = progress == "bar" || (progress == "auto" && isatty(STDERR_FILENO) != 0);
  Progress display(bar, scene.steps());
  bool started = false;  // an error after the first step is a failed run, not bad input
  options.on_step = [&](const grbd::scene::Simulation& sim, const grbd::timestep::StepReport& r,
                        std::uint64_t bodies) {
    started = true;
    if (!quiet) display.update(sim, r, bodies);
  };
  options.on_warning = [&](const std::string& warning) {
    errors << "grbd run: warning: " << warning << '\n';
  };
  install_handlers();
  options.stop = &g_signal;
  grbd::io::RunResult result;
  try {
    // One loop for any number of processes (io::run); a periodic scene, or more than one
    // process, shares the scene with a parallel::SceneDecomposition.
    result = grbd::parallel::run(scene, options, world);
  } catch (const grbd::io::AbandonedFiles& e) {
    // A write failed on some process: the parallel files cannot be closed together; end now.
    display.finish();
    errors << "grbd run: " << e.what() << '\n';
    mpi.end_now(kExitFailed);
  } catch (const grbd::io::FileConflict& e) {
    errors << "grbd run: " << e.what() << '\n';
    return kExitUsage;
  } catch (const grbd::scene::SceneError& e) {
    display.finish();
    errors << "grbd run: " << e.what() << '\n';
    return started ? kExitFailed : kExitInput;
  } catch (const grbd::io::IoError& e) {
    display.finish();
    errors << "grbd run: " << e.what() << '\n';
    return started ? kExitFailed : kExitInput;
  } catch (const grbd::Error& e) {
    display.finish();
    errors << "grbd run: the run failed: " << e.what() << '\n';
    return kExitFailed;
  }
  display.finish();
  if (!quiet) {
    std::cout << (result.interrupted ? "stopped" : "done") << ": " << result.steps << " steps in "
              << std::setprecision(3) << result.seconds << " s (output and checkpoints "
              << 100.0 * result.output_seconds / std::max(result.seconds, 1e-300) << " %"
              << (world.size() > 1 ? ", " + std::to_string(world.size()) + " processes" : "")
              << (result.rebalances > 0 ? ", " + std::to_string(result.rebalances) + " rebalances"
                                        : "")
              << "), " << result.records << " records in " << options.output.string()
              << ", checkpoint " << options.checkpoint.string() << '\n'
              << indented(result.accuracy.describe());
  }
  if (result.stop_file) return kExitStopFile;
  if (result.interrupted) return 128 + static_cast<int>(g_signal);
  return 0;
}

int validate_command(const std::string& scene_file) {
  try {
    const grbd::scene::Scene scene = grbd::scene::load_scene(scene_file);
    std::cout << grbd::scene::summary(scene);
    const auto start = std::chrono::steady_clock::now();
    // A periodic scene is built as its run builds it, on the parallel engine of one process.
    std::optional<grbd::parallel::SceneDecomposition> one;
    if (scene.domain.any_periodic()) one.emplace(grbd::self_communicator(), scene);
    const auto simulation = one ? std::make_unique<grbd::scene::Simulation>(scene, nullptr, *one)
                                : std::make_unique<grbd::scene::Simulation>(scene);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "  generated " << simulation->system().size() << " bodies in "
              << std::setprecision(3) << seconds << " s\n";
    for (std::size_t g = 0; g < scene.groups.size(); ++g) {
      if (scene.groups[g].generator.kind == grbd::scene::GeneratorKind::inflow) {
        std::cout << "  bodies " << scene.groups[g].name
                  << ": created by the inflow during the run\n";
      }
    }
    std::cout << "ok\n";
    return 0;
  } catch (const grbd::Error& e) {
    std::cerr << "grbd validate: " << e.what() << '\n';
    return kExitInput;
  }
}

int info_command(const std::string& file) {
  try {
    const grbd::io::OutputSummary s = grbd::io::read_summary(file);
    std::cout << "output " << file << "\n"
              << "  scene " << s.scene_file << ", written by grbd " << s.grbd_version << " on "
              << s.host << " at " << s.date << " (" << s.precision << ")\n"
              << "  bodies created: " << s.bodies << "\n"
              << "  records: " << s.records;
    if (s.records > 0) {
      std::cout << ", t = " << s.t_first << " … " << s.t_last << " s, " << s.bodies_last
                << " bodies in the last";
    }
    std::cout << "\n  steps: " << s.steps << ", wall time " << s.seconds << " s\n"
              << "  contacts: at most " << s.max_contacts << "\n";
    if (const std::uint64_t capped = s.accuracy.steps - s.accuracy.converged; capped > 0) {
      std::cout << "  " << capped << " steps stopped at the cap of " << s.non_converged_iterations
                << " iterations ([solver] max_iterations) before the tolerance\n";
    }
    std::cout << indented(s.accuracy.describe());
    return 0;
  } catch (const grbd::Error& e) {
    std::cerr << "grbd info: " << e.what() << '\n';
    return kExitInput;
  }
}

// The first line of grbd chute's table.
constexpr const char* kChuteCsvHeader = "t_s,bodies,flow_count,front_m";

// Why `csv` cannot take grbd chute's table ("" when it can): it is the output read, its XDMF or
// the scene that made it, an existing file that is not a regular one (a folder, a device, a FIFO)
// or not writable, a file that is not an earlier table of grbd chute, or a name in a folder that
// does not exist. The CSV replaces only an earlier table (or an empty regular file).
std::string csv_problem(const std::string& csv, const std::string& output,
                        const std::string& scene_file) {
  namespace fs = std::filesystem;
  const std::string quoted = '"' + csv + '"';
  if (csv.empty()) return "expected a file name, found \"\"";
  if (csv.find('\0') != std::string::npos) return quoted + ": the name contains a NUL character";
  const std::pair<std::string, std::string> inputs[] = {
      {output, "the output"},
      {grbd::io::OutputFile::xdmf_path(output).string(), "the output's XDMF"},
      {scene_file, "the scene"}};
  for (const auto& [path, role] : inputs) {
    if (!path.empty() && grbd::io::same_file(csv, path)) {
      return quoted + " is " + role + " \"" + path + "\": it would be destroyed";
    }
  }
  std::error_code error;
  const fs::path target(csv);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(folder, error)) {
    return quoted + ": the folder \"" + folder.string() + "\" does not exist";
  }
  const auto status = fs::status(target, error);
  if (fs::exists(status)) {
    if (fs::is_directory(status)) return quoted + " is a folder: give a file name";
    if (!fs::is_regular_file(status)) {
      return quoted + " is not a regular file (a device, a FIFO or a socket): give a file name";
    }
    if (::access(csv.c_str(), W_OK) != 0) return quoted + " is read-only: it is not replaced";
    // Only an earlier table of grbd chute is replaced (or an empty file), never another file.
    std::ifstream in(target);
    std::string first;
    std::getline(in, first);
    if (fs::file_size(target, error) > 0 && first != kChuteCsvHeader) {
      return quoted + " exists and is not a table of grbd chute (its first line is not \"" +
             std::string(kChuteCsvHeader) + "\"): give another name, or remove it first";
    }
  }
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    return quoted + ": the folder \"" + folder.string() + "\" is not writable";
  }
  return {};
}

// [chute command]
// The chute study's measurements from an output (chapter 8): per record the flow count F — the
// beads past the kink, those the outlet removed counted as past — and the front; then the times
// of the reference study.
int chute_command(const std::string& file, const std::optional<std::string>& csv, double kink_x,
                  double entry_count) {
  namespace par = grbd::parallel;
  const par::ChuteGeometry chute{kink_x, 10.0};
  try {
    const par::FlowSeries series = par::flow_series(file, chute);
    const std::vector<double>& t = series.t;
    const std::vector<double>& count = series.count;
    const std::vector<double>& fronts = series.front;
    const std::vector<double>& bodies = series.bodies;
    const double beads = series.beads;
    const par::FlowTimes times = par::flow_times(t, count, beads, entry_count);
    if (csv) {
      if (const std::string problem =
              csv_problem(*csv, file, grbd::io::read_summary(file).scene_file);
          !problem.empty()) {
        std::cerr << "grbd chute: --csv " << problem << '\n';
        return kExitUsage;
      }
      // Written under a temporary name and renamed once complete: an earlier CSV stays whole.
      const std::filesystem::path temporary = *csv + ".tmp";
      {
        std::ofstream out(temporary);
        out << kChuteCsvHeader << '\n' << std::setprecision(9);
        for (std::size_t k = 0; k < t.size(); ++k) {
          out << t[k] << ',' << bodies[k] << ',' << count[k] << ',' << fronts[k] << '\n';
        }
        if (!out.flush()) {
          std::error_code error;
          std::filesystem::remove(temporary, error);
          throw grbd::io::IoError(temporary.string() + ": cannot be written");
        }
      }
      std::error_code error;
      std::filesystem::rename(temporary, *csv, error);
      if (error) {
        std::filesystem::remove(temporary, error);
        throw grbd::io::IoError(*csv + ": cannot be written (" + error.message() + ")");
      }
    }
    const auto fixed = [](double x) {
      std::ostringstream out;
      out << std::setprecision(4) << x;
      return out.str();
    };
    const auto when = [&](const std::optional<double>& x) {
      return x ? fixed(*x) + " s" : std::string("never");
    };
    std::cout << "chute " << file << ": " << beads << " beads, " << t.size()
              << " records, t = " << t.front() << " … " << t.back() << " s, kink at x = " << kink_x
              << " m\n"
              << "  entry (" << entry_count << " beads past the kink): " << when(times.entry)
              << "\n  1 % past: " << when(times.first) << ", 95 % past: " << when(times.last)
              << "\n  flow duration (1 % to 95 %): " << when(times.duration());
    if (times.entry && times.last) {
      std::cout << ", from the entry to 95 %: " << fixed(*times.last - *times.entry) << " s";
    }
    std::cout << "\n  beads past the kink at the end: " << count.back() << " ("
              << fixed(100.0 * count.back() / beads) << " %), front " << fixed(fronts.back())
              << " m along the floors\n";
    return 0;
  } catch (const grbd::io::IoError& e) {
    std::cerr << "grbd chute: " << e.what() << '\n';
    return csv && std::string(e.what()).find(*csv) != std::string::npos ? kExitFailed : kExitInput;
  } catch (const grbd::Error& e) {
    std::cerr << "grbd chute: " << file << ": " << e.what() << '\n';
    return kExitInput;
  }
}
// [chute command]

int fclib_command(const std::vector<std::string>& inputs, double tol, int max_iterations,
                  const std::optional<std::string>& csv) {
  std::vector<std::filesystem::path> files;
  try {
    for (const std::string& input : inputs) {
      const auto found = grbd::contact::fclib_files(input);
      files.insert(files.end(), found.begin(), found.end());
    }
  } catch (const grbd::Error& e) {
    std::cerr << "grbd fclib: " << e.what() << '\n';
    return kExitInput;
  }
  // The CSV is written under a temporary name and renamed into place once every problem was
  // read and solved: a refused problem leaves an earlier CSV as it was, and no input is ever
  // the CSV (compared as files, whatever their spelling).
  std::filesystem::path temporary;
  if (csv) {
    for (const auto& file : files) {
      if (grbd::io::same_file(file, *csv)) {
        std::cerr << "grbd fclib: --csv " << *csv << " is the problem " << file.string()
                  << ": it would be destroyed\n";
        return kExitUsage;
      }
    }
    temporary = *csv + ".tmp";
  }
  try {
    std::ofstream history;
    if (csv) {
      history.open(temporary);
      if (!history) {
        std::cerr << "grbd fclib: cannot open " << temporary.string() << " for writing\n";
        return kExitFailed;
      }
      history << "problem,solver,k,relative_residual\n" << std::setprecision(7);
    }
    grbd::contact::FclibBenchOptions options;
    options.tol = tol;
    options.max_iterations = max_iterations;
    options.record_history = csv.has_value();
    bool header = false;  // printed with the first row: not before a file that is refused
    grbd::contact::fclib_bench(files, options, [&](const grbd::contact::FclibBenchRow& row) {
      if (!std::exchange(header, true)) std::cout << grbd::contact::fclib_table_header(max_iterations);
      std::cout << grbd::contact::fclib_table_line(row) << std::flush;
      for (std::size_t k = 0; k < row.history.size(); ++k) {
        history << row.problem << ',' << row.solver << ',' << k + 1 << ',' << row.history[k]
                << '\n';
      }
    });
    if (csv) {
      history.close();
      std::error_code error;
      if (!history) {
        std::filesystem::remove(temporary, error);
        std::cerr << "grbd fclib: cannot write " << temporary.string() << '\n';
        return kExitFailed;
      }
      std::filesystem::rename(temporary, *csv, error);
      if (error) {
        std::filesystem::remove(temporary, error);
        std::cerr << "grbd fclib: cannot move the CSV into place as " << *csv << '\n';
        return kExitFailed;
      }
    }
    return 0;
  } catch (const grbd::Error& e) {
    std::error_code error;
    if (csv) std::filesystem::remove(temporary, error);
    std::cerr << "grbd fclib: " << e.what() << '\n';
    return kExitInput;  // a file the reader refuses (the files before it were solved)
  }
}

// The benchmark programs of the chapters (grbd_add_benchmark) are built into the folder
// benchmarks/ beside this executable.
std::filesystem::path benchmark_folder() {
  std::error_code error;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
  return (error ? std::filesystem::path(".") : self.parent_path()) / "benchmarks";
}

std::vector<std::filesystem::path> benchmarks() {
  std::vector<std::filesystem::path> found;
  std::error_code error;
  for (std::filesystem::directory_iterator entry(benchmark_folder(), error), end;
       !error && entry != end; entry.increment(error)) {
    if (entry->is_regular_file() && ::access(entry->path().c_str(), X_OK) == 0) {
      found.push_back(entry->path());
    }
  }
  std::sort(found.begin(), found.end());
  return found;
}

int bench_command(const std::vector<std::string>& names, bool list,
                  const std::vector<std::string>& pass) {
  const auto all = benchmarks();
  if (all.empty()) {
    std::cerr << "grbd bench: no benchmark programs in " << benchmark_folder()
              << " (they are built with grbd: cmake --build <build folder>)\n";
    return kExitFailed;
  }
  if (list) {
    for (const auto& b : all) std::cout << b.filename().string() << '\n';
    return 0;
  }
  // A name selects the programs whose name contains it (ch05, sor, ch06_bench_step).
  std::vector<std::filesystem::path> chosen;
  for (const std::string& name : names) {
    std::size_t matched = 0;
    for (const auto& b : all) {
      if (b.filename().string().find(name) != std::string::npos &&
          std::find(chosen.begin(), chosen.end(), b) == chosen.end()) {
        chosen.push_back(b);
        ++matched;
      }
    }
    if (matched == 0) {
      std::cerr << "grbd bench: no benchmark matches '" << name << "'; grbd bench --list lists "
                << all.size() << '\n';
      return kExitUsage;
    }
  }
  if (names.empty()) chosen = all;
  int status = 0;
  for (const auto& b : chosen) {
    std::vector<std::string> args = {b.string()};
    args.insert(args.end(), pass.begin(), pass.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::cout << "== " << b.filename().string() << std::endl;
    pid_t pid = 0;
    if (posix_spawn(&pid, b.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
      std::cerr << "grbd bench: cannot start " << b << '\n';
      return kExitFailed;
    }
    int wstatus = 0;
    while (waitpid(pid, &wstatus, 0) < 0) {
      if (errno != EINTR) return kExitFailed;
    }
    if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0) {
      std::cerr << "grbd bench: " << b.filename().string() << " failed\n";
      status = kExitFailed;
    }
  }
  return status;
}

}  // namespace

int grbd_main(int argc, char** argv) {
  // Under mpirun every process runs this program: rank 0 alone speaks (a parse error, a missing
  // file, validate's summary), one message per job; the others exit with the same code. A failing
  // process of a run speaks for itself through parallel::abort_run().
  if (grbd::parallel::launcher_rank() > 0) {
    std::cout.rdbuf(nullptr);
    std::cerr.rdbuf(nullptr);
  }
  CLI::App app{"grbd: granular rigid body dynamics — run scenes, inspect their output"};
  app.footer(kExitCodes);
  app.set_version_flag("--version", std::string("grbd ") + GRBD_VERSION);
  app.require_subcommand(1);

  std::string scene_file;
  std::optional<std::string> output, checkpoint, restart, end_time, stop_file;
  bool quiet = false, force = false;
  std::string progress = "auto";
  CLI::App* run = app.add_subcommand("run", "Run a scene file: HDF5 + XDMF output, checkpoints");
  run->add_option("scene", scene_file, "The scene file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  run->add_option("-o,--output", output, "The HDF5 output (default: [output] file of the scene)");
  run->add_option("-c,--checkpoint", checkpoint,
                  "Where checkpoints go (default: [checkpoint] file of the scene)");
  run->add_option("-r,--restart", restart, "Continue from this checkpoint")
      ->check(CLI::ExistingFile);
  run->add_option("--end-time", end_time,
                  "Run to this time [s] instead of the scene's end_time (the same rules: a "
                  "decimal number > 0, at most 10^12 steps)");
  run->add_option("--stop-file", stop_file,
                  "When this file appears, finish the step, write a checkpoint, remove the file "
                  "and stop with exit code 4 (default: the checkpoint's name + .stop)");
  run->add_flag("-f,--force", force,
                "Replace an existing output, XDMF and checkpoint (a fresh run refuses to)");
  run->add_flag("-q,--quiet", quiet, "No progress and no summary; errors only");
  run->add_option("--progress", progress,
                  "auto (a bar on a terminal, else a line every 10 s), bar, lines")
      ->check(CLI::IsMember({"auto", "bar", "lines"}));
  run->footer(std::string(kSceneFormat) + " " + kExitCodes);

  std::string validate_file;
  CLI::App* validate =
      app.add_subcommand("validate", "Check a scene file and summarise it without running it");
  validate->add_option("scene", validate_file, "The scene file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  validate->footer(std::string(kSceneFormat) + " " + kValidateExitCodes);

  std::string info_file;
  CLI::App* info = app.add_subcommand(
      "info", "Summarise an output file: bodies, records, time range, solver statistics");
  info->add_option("output", info_file, "The HDF5 output of grbd run")
      ->required()
      ->check(CLI::ExistingFile);
  info->footer(kInfoExitCodes);

  std::string chute_file;
  std::optional<std::string> chute_csv;
  double chute_kink = -0.296;
  double chute_entry = 150.0;
  CLI::App* chute = app.add_subcommand(
      "chute",
      "Measure a chute run (chapter 8): the flow count past the kink, the front, the "
      "entry time and the flow duration");
  chute->add_option("output", chute_file, "The HDF5 output of grbd run")
      ->required()
      ->check(CLI::ExistingFile);
  chute->add_option("--csv", chute_csv,
                    "Also write t, bodies, flow count and front per record (replaces only an "
                    "earlier table of grbd chute)");
  // The numbers of the scene files' rules (scene::parse_real: decimal, no hexadecimal, no
  // spaces), finite and in range; the range named in plain words.
  const auto real_in = [](bool (*in_range)(double), const std::string& range) {
    return CLI::Validator(
        [=](const std::string& text) -> std::string {
          try {
            const double x = grbd::scene::parse_real(text, "the value");
            if (std::isfinite(x) && in_range(x)) return {};
          } catch (const grbd::Error&) {
          }
          return "expected a decimal number " + range + ", found \"" + text + "\"";
        },
        "NUMBER");
  };
  chute->add_option("--kink", chute_kink, "x of the kink [m], default -0.296 (the reference)")
      ->check(real_in([](double x) { return x >= -1e3 && x <= 1e3; },
                      "in [-1000, 1000] m such as -0.296"));
  chute->add_option("--entry", chute_entry, "beads past the kink that mark the entry, default 150")
      ->check(real_in([](double x) { return x >= 1.0 && x <= 1e15; },
                      "of at least 1 (and at most 1e15) such as 150"));
  chute->footer(kChuteExitCodes);

  std::vector<std::string> fclib_inputs;
  double fclib_tol = 1e-8;
  int fclib_max_iterations = 20000;
  std::optional<std::string> fclib_csv;
  CLI::App* fclib = app.add_subcommand(
      "fclib", "Solve FCLIB problems with SOR, JOR, APGD and Newton (chapter 5's bench): a table");
  fclib->add_option("problems", fclib_inputs, "FCLIB files (HDF5), or folders of *.hdf5 files")
      ->required();
  fclib->add_option("--tol", fclib_tol, "Stop once |F| <= tol |q| (natural map), default 1e-8")
      ->check(CLI::Validator(
          [](const std::string& text) -> std::string {
            double value = 0.0;
            if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || !(value > 0.0))
              return "expected a finite number > 0, found " + text;
            return {};
          },
          "T > 0"));
  fclib
      ->add_option("--max-iterations", fclib_max_iterations,
                   "At most this many iterations per solver and problem, default 20000; "
                   "Newton's methods at most " +
                       std::to_string(grbd::contact::kFclibNewtonIterations) +
                       " (each iteration a linear solve). The table's header gives the caps.")
      ->check(CLI::Range(1, 1 << 30));
  fclib->add_option("--csv", fclib_csv, "Write every iteration's |F|/|q| to this CSV file");
  fclib->footer(kFclibExitCodes);

  std::vector<std::string> bench_names;
  bool bench_list = false;
  CLI::App* bench = app.add_subcommand(
      "bench", "Run the chapters' Google Benchmark programs; other options go to them");
  bench->add_option("names", bench_names,
                    "Run the programs whose names contain these (default: all)");
  bench->add_flag("--list", bench_list, "List the benchmark programs");
  bench->allow_extras();
  bench->footer(
      "Options it does not know, e.g. --benchmark_filter=REGEX or --benchmark_min_time=0.1s, "
      "go to every program it runs. " +
      std::string(kBenchExitCodes));

  // An unknown subcommand is named as such (CLI11 would only say that an argument was not
  // expected).
  if (argc > 1 && argv[1][0] != '-') {
    const std::string word = argv[1];
    const auto subcommands = app.get_subcommands({});
    if (std::none_of(subcommands.begin(), subcommands.end(),
                     [&](const CLI::App* sub) { return sub->get_name() == word; })) {
      std::cerr << "grbd: unknown subcommand \"" << word
                << "\"; the subcommands are run, validate, info, fclib and bench (grbd --help)\n";
      return kExitUsage;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // Every error names its subcommand, as the run's own errors do ("grbd run: …").
    const auto parsed = app.get_subcommands();
    std::cerr << "grbd" << (parsed.empty() ? "" : " " + parsed.front()->get_name()) << ": "
              << e.what() << "\nRun with --help for more information.\n";
    return kExitUsage;
  }
  // Memory that runs out is an error with a message and an exit code, never an abort.
  try {
    if (run->parsed())
      return run_command(scene_file, output, checkpoint, restart, end_time, stop_file, force, quiet,
                         progress);
    if (validate->parsed()) return validate_command(validate_file);
    if (info->parsed()) return info_command(info_file);
    if (chute->parsed()) return chute_command(chute_file, chute_csv, chute_kink, chute_entry);
    if (fclib->parsed())
      return fclib_command(fclib_inputs, fclib_tol, fclib_max_iterations, fclib_csv);
    if (bench->parsed()) return bench_command(bench_names, bench_list, bench->remaining());
  } catch (const std::bad_alloc&) {
    std::cerr << "grbd: out of memory: the scene or file asks for more than this machine (or "
                 "its limits) can give\n";
    return kExitFailed;
  }
  return kExitUsage;
}

int main(int argc, char** argv) {
  const grbd::io::Hdf5Cleanup hdf5;  // first: see io::Hdf5Cleanup
  return grbd_main(argc, argv);
}
