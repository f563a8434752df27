// A whole run of a scene (chapter 7).

#include "grbd/io/run.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "io/h5util.hpp"

namespace grbd::io {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string_view line_of(std::string_view text, std::size_t begin) {
  const std::size_t end = text.find('\n', begin);
  return text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin);
}

}  // namespace

std::string scene_difference(const std::string& saved, const std::string& given,
                             const std::filesystem::path& scene_file) {
  if (saved == given) return {};
  const std::size_t line = first_different_line(saved, given);
  std::size_t begin = 0;  // the start of that line, the same in both texts
  for (std::size_t k = 1; k < line; ++k) begin = given.find('\n', begin) + 1;
  const auto quoted = [&](const std::string& text) {
    return begin >= text.size() ? std::string("the end of the file")
                                : '"' + std::string(line_of(text, begin)) + '"';
  };
  return scene_file.string() + ":" + std::to_string(line) +
         ": the scene differs from the one the " + "checkpoint was written with: it has " +
         quoted(given) + ", the checkpoint's has " + quoted(saved) +
         "; the run continues with the scene given";
}

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code error;
  if (std::filesystem::equivalent(a, b, error)) return true;
  // A name that does not exist yet: its canonical form from the absolute path (weakly_canonical
  // of a relative name none of whose parts exists stays relative: "x" and "./x" would differ).
  const auto canonical = [](const std::filesystem::path& p, std::error_code& e) {
    const std::filesystem::path absolute = std::filesystem::absolute(p, e);
    return e ? absolute : std::filesystem::weakly_canonical(absolute, e);
  };
  std::error_code error_a, error_b;
  const auto ca = canonical(a, error_a);
  const auto cb = canonical(b, error_b);
  return !error_a && !error_b && ca == cb;
}

void check_run_files(const scene::Scene& scene, const RunOptions& options) {
  namespace fs = std::filesystem;
  struct File {
    fs::path path;
    std::string role;
    // The checkpoint may be the restart checkpoint: it is read before the first checkpoint
    // replaces it.
    bool checkpoint = false;
  };
  const fs::path xdmf = OutputFile::xdmf_path(options.output);
  // What the run writes: the checkpoint and the XDMF are renamed into place from a temporary.
  const std::vector<File> written = {
      {options.output, "the output"},
      {xdmf, "the output's XDMF"},
      {options.checkpoint, "the checkpoint", true},
      {options.checkpoint.string() + ".tmp", "the checkpoint's temporary file"},
      {xdmf.string() + ".tmp", "the XDMF's temporary file"}};
  std::vector<File> read = {{scene.file, "the scene file"}};
  for (const scene::StaticSpec& s : scene.statics) {
    if (!s.mesh_file.empty()) read.push_back({s.mesh_file, "the mesh of static " + s.name});
  }
  if (options.restart) read.push_back({*options.restart, "the restart checkpoint", true});
  const auto quoted = [](const fs::path& path) {
    std::string text = "\"";
    text += path.string();
    text += '"';
    return text;
  };
  for (const File& f : written) {
    if (f.path.empty()) throw IoError(f.role + ": expected a file name, found \"\"");
  }
  for (const std::vector<File>* files : {&written, &std::as_const(read)}) {
    for (const File& f : *files) {
      if (f.path.native().find('\0') != std::string::npos) {
        throw FileConflict(f.role + ": the file name " + quoted(f.path) +
                           " contains a NUL character");
      }
    }
  }
  for (std::size_t i = 0; i < written.size(); ++i) {
    for (std::size_t j = i + 1; j < written.size(); ++j) {
      if (same_file(written[i].path, written[j].path)) {
        throw FileConflict(written[i].role + " " + quoted(written[i].path) + " and " +
                           written[j].role + " " + quoted(written[j].path) +
                           " are the same file: give them different names");
      }
    }
    for (const File& input : read) {
      if (written[i].checkpoint && input.checkpoint) continue;
      if (same_file(written[i].path, input.path)) {
        throw FileConflict(written[i].role + " " + quoted(written[i].path) + " is " + input.role +
                           " " + quoted(input.path) + ": it would be destroyed");
      }
    }
  }
  // The stop file is removed once it has done its work: it must be none of the run's files.
  if (!options.stop_file.empty()) {
    if (options.stop_file.native().find('\0') != std::string::npos) {
      throw FileConflict("the stop file: the file name " + quoted(options.stop_file) +
                         " contains a NUL character");
    }
    for (const std::vector<File>* files : {&written, &std::as_const(read)}) {
      for (const File& f : *files) {
        if (same_file(options.stop_file, f.path)) {
          throw FileConflict("the stop file " + quoted(options.stop_file) + " is " + f.role + " " +
                             quoted(f.path) + ": it would be removed when the run stops");
        }
      }
    }
    std::error_code error;
    const auto status = fs::symlink_status(options.stop_file, error);
    if (fs::exists(status) && !fs::is_regular_file(status)) {
      throw FileConflict("the stop file " + quoted(options.stop_file) + " is " +
                         (fs::is_directory(status) ? "a folder" : "not a regular file") +
                         ": a stop file is a regular file that the run removes");
    }
  }
  for (const File& f : written) {
    std::error_code error;
    const fs::path folder = f.path.has_parent_path() ? f.path.parent_path() : fs::path(".");
    if (!fs::is_directory(folder, error)) {
      throw IoError(f.path.string() + ": " + f.role + " cannot be written: the folder " +
                    quoted(folder) + " does not exist");
    }
    if (::access(folder.c_str(), W_OK | X_OK) != 0) {
      throw IoError(f.path.string() + ": " + f.role + " cannot be written: the folder " +
                    quoted(folder) + " is not writable");
    }
    const auto status = fs::status(f.path, error);
    if (fs::exists(status) && !fs::is_regular_file(status)) {
      throw IoError(f.path.string() + ": " + f.role + " cannot be written: it is " +
                    (fs::is_directory(status) ? "a folder" : "not a regular file"));
    }
  }
  if (h5::locked_elsewhere(options.output)) {
    throw IoError(options.output.string() +
                  ": is in use: another grbd run writes it, or another program has it open "
                  "(HDF5's lock); nothing was changed");
  }
  if (!options.restart && !options.overwrite) {
    for (const File& f : {written[0], written[1], written[2]}) {
      std::error_code error;
      if (fs::exists(fs::symlink_status(f.path, error))) {
        throw IoError(f.path.string() + ": " + f.role +
                      " exists already: a fresh run does not "
                      "replace an earlier result; give another name, continue it with --restart, "
                      "or replace it with --force");
      }
    }
  }
}

bool stop_requested(const RunOptions& options) {
  std::error_code error;
  return !options.stop_file.empty() && std::filesystem::exists(options.stop_file, error);
}

void remove_stop_file(const RunOptions& options) {
  std::error_code error;
  if (std::filesystem::is_regular_file(std::filesystem::symlink_status(options.stop_file, error))) {
    std::filesystem::remove(options.stop_file, error);
  }
}

void clear_stale_stop_file(const RunOptions& options) {
  if (!stop_requested(options)) return;
  // A stop file touched since the run began asks this run to stop; an older one was left by a
  // run that was killed before it could remove it.
  std::error_code error;
  const auto touched = std::filesystem::last_write_time(options.stop_file, error);
  if (!error && touched >= options.started) return;
  remove_stop_file(options);
  if (options.on_warning) {
    options.on_warning(options.stop_file.string() +
                       ": removed the stop file that an earlier run left (it asks a run to stop)");
  }
}

std::unique_ptr<scene::Simulation> restored_simulation(const scene::Scene& scene,
                                                       const Checkpoint& checkpoint,
                                                       const std::filesystem::path& restart,
                                                       const scene::Distribution* distribution) {
  try {
    return distribution != nullptr
               ? std::make_unique<scene::Simulation>(scene, &checkpoint.state, *distribution)
               : std::make_unique<scene::Simulation>(scene, checkpoint.state);
  } catch (const scene::StateError& e) {  // the checkpoint is at fault, not the scene
    throw IoError(restart.string() + ": does not fit the scene " + scene.file.string() + ": " +
                  e.what());
  }
}

RunResult run(const scene::Scene& scene, const RunOptions& options) {
  return run(scene, options, self_communicator(), {});
}

// [run loop]
RunResult run(const scene::Scene& scene, const RunOptions& options, const Communicator& comm,
              const MakeDistribution& make_distribution) {
  const auto start = std::chrono::steady_clock::now();
  const bool root = comm.rank() == 0;
  if (!make_distribution && comm.size() > 1) {
    throw InvalidArgument("io::run: a run on " + std::to_string(comm.size()) +
                          " processes needs a distribution of the scene (parallel::run)");
  }
  // Rank 0 checks the files and looks for a stale stop file; every process learns the verdict.
  agree(comm, [&] {
    if (!root) return;
    check_run_files(scene, options);
    clear_stale_stop_file(options);
  });
  std::unique_ptr<scene::Distribution> distribution;
  agree(comm, [&] {
    if (make_distribution) distribution = make_distribution();
  });
  RunResult result;
  result.accuracy.unit = scene.settings.tolerance_radius;
  std::unique_ptr<scene::Simulation> simulation;
  std::unique_ptr<OutputFile> output;
  if (options.restart) {
    Checkpoint checkpoint;
    agree(comm, [&] { checkpoint = read_checkpoint(comm, *options.restart); });
    if (const std::string difference =
            scene_difference(checkpoint.scene_text, scene.text, scene.file);
        root && !difference.empty() && options.on_warning) {
      options.on_warning(difference);
    }
    if (distribution) {
      // The cuts the checkpoint's run stepped on (after its balances), when it had as many
      // processes: then the restart steps as the run it continues, bit for bit.
      agree(comm, [&] {
        try {
          distribution->restore(checkpoint.state.distribution);
        } catch (const InvalidArgument& e) {
          throw IoError(options.restart->string() + ": dataset distribution: " + e.what());
        }
      });
      distribution->redistribute(checkpoint.state);
    }
    agree(comm, [&] {
      simulation = restored_simulation(scene, checkpoint, *options.restart, distribution.get());
    });
    // Whether the output exists, as rank 0 sees it.
    std::vector<std::byte> exists(1, std::byte{0});
    if (root) {
      std::error_code error;
      exists[0] = static_cast<std::byte>(std::filesystem::exists(options.output, error));
    }
    comm.broadcast(exists, 0);
    if (exists[0] == std::byte{0}) {
      // A new output: its body table starts with every body of the checkpoint.
      for (std::size_t i = 0; i < simulation->system().owned_count(); ++i) {
        simulation->created().push_back(simulation->system().record(i));
      }
    }
    // Rank 0 checks that an output it reopens is this run's, with the bodies the checkpoint holds.
    agree(comm, [&] {
      output = exists[0] != std::byte{0}
                   ? std::make_unique<OutputFile>(
                         options.output, scene, checkpoint.output,
                         RunIdentity{checkpoint.scene_text, checkpoint.state.bodies}, comm)
                   : std::make_unique<OutputFile>(options.output, scene, comm);
    });
  } else {
    agree(comm, [&] {
      simulation = distribution ? std::make_unique<scene::Simulation>(scene, nullptr, *distribution)
                                : std::make_unique<scene::Simulation>(scene);
    });
    agree(comm, [&] { output = std::make_unique<OutputFile>(options.output, scene, comm); });
  }
  scene::Simulation& sim = *simulation;
  // A write that failed on some process leaves the processes' parallel HDF5 state apart: the
  // file cannot be closed together any more (OutputFile::abandon), and the error says so.
  const auto written = [&](auto&& work) {
    try {
      agree(comm, work);
    } catch (const Error& e) {
      if (comm.size() == 1) throw;
      output->abandon();
      throw AbandonedFiles(e.what());
    }
  };
  const auto write_record = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    written([&] { output->write_record(sim); });
    result.output_seconds += seconds_since(t0);
  };
  if (!options.restart) write_record();
  const std::uint64_t every = scene.output.every;
  const std::uint64_t checkpoint_every = scene.checkpoint.every;
  std::uint64_t saved_at = ~std::uint64_t{0};
  const auto save = [&] {
    if (saved_at == sim.stepper().steps()) return;
    saved_at = sim.stepper().steps();
    const auto t0 = std::chrono::steady_clock::now();
    // The state a restart starts in (every body with its owner): the run goes on as it will.
    agree(comm, [&] { sim.settle(); });
    written([&] {
      output->flush(sim);
      Checkpoint checkpoint{sim.save(), output->position(), scene.text};
      if (distribution) checkpoint.state.distribution = distribution->state();
      write_checkpoint(comm, options.checkpoint, checkpoint);
    });
    ++result.checkpoints;
    result.output_seconds += seconds_since(t0);
  };
  // Whether the current state is the last record: a fresh run has just written it; a restart has
  // it when the checkpoint's step is on the record grid (an extra last record was dropped).
  bool recorded = !options.restart || (every > 0 && sim.stepper().steps() % every == 0);
  while (!sim.finished()) {
    // [agreed stop]
    // The stop, agreed by every process at a step boundary: a signal on any process, or the
    // stop file, which rank 0 looks for.
    const bool by_file = root && stop_requested(options);
    const bool by_signal = options.stop != nullptr && *options.stop != 0;
    std::vector<double> stops{by_file || by_signal ? 1.0 : 0.0, by_file ? 1.0 : 0.0};
    comm.max(stops);
    if (stops[0] > 0.0) {
      result.interrupted = true;
      result.stop_file = stops[1] > 0.0;
      break;
    }
    // [agreed stop]
    const auto t0 = std::chrono::steady_clock::now();
    timestep::StepReport report;
    try {
      // A step that fails on one process while the others wait in its exchanges ends every
      // process after the agreement's patience (Communicator::agree).
      agree(comm, [&] { report = sim.step(); });
    } catch (...) {
      // A failed step (a blow-up, a diverged solver) leaves a state that is not data: no record,
      // no checkpoint of it. The rows of the steps before it are kept, and the file is closed;
      // a write that failed may fail again here, and then the first error is the one reported.
      try {
        agree(comm, [&] { output->close(sim); });
      } catch (const Error&) {
      }
      throw;
    }
    result.step_seconds += seconds_since(t0);
    ++result.steps;
    std::uint64_t bodies[1] = {sim.system().owned_count()};
    comm.sum(bodies);
    output->add_step(report, bodies[0]);
    result.accuracy.add(report);
    recorded = false;
    const std::uint64_t step = sim.stepper().steps();
    if (every > 0 && step % every == 0) {
      write_record();
      recorded = true;
    }
    if (checkpoint_every > 0 && step % checkpoint_every == 0) save();
    if (root && options.on_step) options.on_step(sim, report, bodies[0]);
  }
  // The checkpoint first: the extra last record (not on the regular grid) is not part of what a
  // restart continues from, so that it gives the same records as an uninterrupted run.
  save();
  if (!recorded && !result.interrupted) write_record();
  written([&] { output->close(sim); });
  if (root && result.stop_file) remove_stop_file(options);
  result.records = output->position().records;
  result.rebalances = distribution ? distribution->rebalances() : 0;
  result.seconds = seconds_since(start);
  return result;
}
// [run loop]

}  // namespace grbd::io
