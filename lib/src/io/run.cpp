// A whole run of a scene (chapter 7).

#include "grbd/io/run.hpp"

#include <chrono>
#include <algorithm>
#include <memory>
#include <string_view>

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
  std::size_t line = 1, begin = 0;  // the line of the first differing character, and its start
  const std::size_t n = std::min(saved.size(), given.size());
  for (std::size_t i = 0; i < n && saved[i] == given[i]; ++i) {
    if (saved[i] == '\n') {
      ++line;
      begin = i + 1;
    }
  }
  const auto quoted = [&](const std::string& text) {
    return begin >= text.size() ? std::string("the end of the file")
                                : '"' + std::string(line_of(text, begin)) + '"';
  };
  return scene_file.string() + ":" + std::to_string(line) + ": the scene differs from the one the " +
         "checkpoint was written with: it has " + quoted(given) + ", the checkpoint's has " +
         quoted(saved) + "; the run continues with the scene given";
}

RunResult run(const scene::Scene& scene, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  RunResult result;
  std::unique_ptr<scene::Simulation> simulation;
  std::unique_ptr<OutputFile> output;
  if (options.restart) {
    const Checkpoint checkpoint = read_checkpoint(*options.restart);
    if (const std::string difference = scene_difference(checkpoint.scene_text, scene.text, scene.file);
        !difference.empty() && options.on_warning) {
      options.on_warning(difference);
    }
    simulation = std::make_unique<scene::Simulation>(scene, checkpoint.state);
    std::error_code error;
    if (std::filesystem::exists(options.output, error)) {
      output = std::make_unique<OutputFile>(options.output, scene, checkpoint.output);
    } else {
      // A new output: its body table starts with every body of the checkpoint.
      output = std::make_unique<OutputFile>(options.output, scene);
      for (std::size_t i = 0; i < simulation->system().size(); ++i) {
        simulation->created().push_back(simulation->constants(i));
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
  while (!sim.finished()) {
    if (options.stop != nullptr && *options.stop != 0) {
      result.interrupted = true;
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
    if (options.on_step) options.on_step(sim, report);
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
  result.records = output->position().records;
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace grbd::io
