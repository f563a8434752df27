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
  std::filesystem::remove(options.stop_file, error);
}

void clear_stale_stop_file(const RunOptions& options) {
  if (!stop_requested(options)) return;
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
  const auto start = std::chrono::steady_clock::now();
  check_run_files(scene, options);
  clear_stale_stop_file(options);
  RunResult result;
  std::unique_ptr<scene::Simulation> simulation;
  std::unique_ptr<OutputFile> output;
  if (options.restart) {
    const Checkpoint checkpoint = read_checkpoint(*options.restart);
    if (const std::string difference =
            scene_difference(checkpoint.scene_text, scene.text, scene.file);
        !difference.empty() && options.on_warning) {
      options.on_warning(difference);
    }
    simulation = restored_simulation(scene, checkpoint, *options.restart, nullptr);
    std::error_code error;
    if (std::filesystem::exists(options.output, error)) {
      output =
          std::make_unique<OutputFile>(options.output, scene, checkpoint.output,
                                       RunIdentity{checkpoint.scene_text, checkpoint.state.bodies});
    } else {
      // A new output: its body table starts with every body of the checkpoint.
      output = std::make_unique<OutputFile>(options.output, scene);
      for (std::size_t i = 0; i < simulation->system().owned_count(); ++i) {
        simulation->created().push_back(simulation->system().record(i));
      }
    }
  } else {
    simulation = std::make_unique<scene::Simulation>(scene);
    output = std::make_unique<OutputFile>(options.output, scene);
    output->write_record(*simulation);
  }
  scene::Simulation& sim = *simulation;
  const std::uint64_t every = scene.output.every;
  const std::uint64_t checkpoint_every = scene.checkpoint.every;
  std::uint64_t saved_at = ~std::uint64_t{0};
  auto save = [&] {
    if (saved_at == sim.stepper().steps()) return;
    saved_at = sim.stepper().steps();
    const auto t0 = std::chrono::steady_clock::now();
    output->flush(sim);
    Checkpoint checkpoint{sim.save(), output->position(), scene.text};
    write_checkpoint(options.checkpoint, checkpoint);
    ++result.checkpoints;
    result.output_seconds += seconds_since(t0);
  };
  // Whether the current state is the last record: a fresh run has just written it; a restart has
  // it when the checkpoint's step is on the record grid (an extra last record was dropped).
  bool recorded = !options.restart || (every > 0 && sim.stepper().steps() % every == 0);
  try {
    while (!sim.finished()) {
      if (options.stop != nullptr && *options.stop != 0) {
        result.interrupted = true;
        break;
      }
      if (stop_requested(options)) {
        result.interrupted = result.stop_file = true;
        break;
      }
      const auto t0 = std::chrono::steady_clock::now();
      const timestep::StepReport report = sim.step();
      result.step_seconds += seconds_since(t0);
      ++result.steps;
      output->add_step(report, sim.system().size());
      recorded = false;
      const std::uint64_t step = sim.stepper().steps();
      if (every > 0 && step % every == 0) {
        const auto t1 = std::chrono::steady_clock::now();
        output->write_record(sim);
        result.output_seconds += seconds_since(t1);
        recorded = true;
      }
      if (checkpoint_every > 0 && step % checkpoint_every == 0) save();
      if (options.on_step) options.on_step(sim, report, sim.system().size());
    }
  } catch (...) {
    // A failed step (a blow-up, a diverged solver) leaves a state that is not data: no record,
    // no checkpoint of it. The rows of the steps before it are kept, and the file is closed;
    // a write that failed may fail again here, and then the first error is the one reported.
    try {
      output->close(sim);
    } catch (const Error&) {
    }
    throw;
  }
  // The checkpoint first: the extra last record (not on the regular grid) is not part of what a
  // restart continues from, so that it gives the same records as an uninterrupted run.
  save();
  if (!recorded && !result.interrupted) {
    const auto t1 = std::chrono::steady_clock::now();
    output->write_record(sim);
    result.output_seconds += seconds_since(t1);
  }
  output->close(sim);
  if (result.stop_file) remove_stop_file(options);
  result.records = output->position().records;
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace grbd::io
