// Chapter 8 demo: the runs of the steady-flow study and of where layers stop. incline.toml — a
// layer of glass beads on a rough base of fixed beads in a box periodic along and across the
// flow — set up for each layer given (incline::Layer: its angle θ, with gravity g (sin θ, 0,
// −cos θ) and the flow along +x; its count of beads; its bead–bead friction) and run with grbd's
// driver of `grbd run` on the parallel engine into <run name>.h5 (+ .xmf, .ckpt.h5) in the data
// directory, with the contacts in every record. ch08_incline and ch08_hstop measure them. Its own
// program, so that a change to the measurements does not run the simulations again.
//
// A box of a few thousand beads is too small to share among processes with profit (a process's
// sweeps wait for its neighbour's), so the layers are shared out instead: each process runs its
// layers alone, one after the other, the largest first to the least loaded process.
//
// Usage: `[mpiexec -n P] ch08_incline_run <data directory> <scene.toml> <end time [s], 0: the
// scene's> <layer>...`, a layer written θ, θ:n or θ:n:μ (incline.hpp).

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/io/run.hpp"
#include "grbd/parallel/mpi.hpp"
#include "grbd/parallel/run.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd_demo/demo.hpp"
#include "incline.hpp"

namespace {

constexpr const char* kProgram = "ch08_incline_run";

// The process of each layer: the layers by falling size, each to the process with the fewest
// beads so far (the lowest rank among equals), so that every process computes the same sharing.
std::vector<int> share(const std::vector<incline::Layer>& layers, std::uint64_t scene_count,
                       int processes) {
  std::vector<std::size_t> order(layers.size());
  std::iota(order.begin(), order.end(), 0);
  const auto size = [&](std::size_t i) {
    return layers[i].count > 0 ? layers[i].count : scene_count;
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return size(a) > size(b); });
  std::vector<std::uint64_t> load(static_cast<std::size_t>(processes), 0);
  std::vector<int> owner(layers.size(), 0);
  for (const std::size_t i : order) {
    const auto least = std::min_element(load.begin(), load.end()) - load.begin();
    owner[i] = static_cast<int>(least);
    load[static_cast<std::size_t>(least)] += size(i);
  }
  return owner;
}

// `run`: this process's layers, each alone on it.
void run_mine(const std::filesystem::path& dir, grbd::scene::Scene base, double end_time,
              const std::vector<incline::Layer>& layers) {
  const grbd::parallel::MpiEnvironment mpi;
  const grbd::Communicator& world = mpi.world();
  if (end_time > 0.0) grbd::scene::set_end_time(base, end_time, "end time");
  const std::vector<int> owner = share(layers, incline::beads(base).generator.count, world.size());
  const grbd::SelfCommunicator alone;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    if (owner[i] != world.rank()) continue;
    const std::string name = incline::run_name(layers[i]);
    grbd::io::RunOptions options;
    options.output = dir / (name + ".h5");
    options.checkpoint = dir / (name + ".ckpt.h5");
    options.overwrite = true;
    const grbd::io::RunResult result =
        grbd::parallel::run(incline::layer_scene(base, layers[i]), options, alone);
    std::printf("%s: %s: %llu steps in %.0f s (process %d of %d)\n", kProgram, name.c_str(),
                static_cast<unsigned long long>(result.steps), result.seconds, world.rank(),
                world.size());
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto code = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<scene.toml>", "<end time>", "<layer>..."},
          "runs the incline scene for each layer (θ, θ:n or θ:n:μ: angle in degrees, beads, "
          "bead-bead friction), the layers shared among the processes it was started on, each "
          "run on one, to the end time in seconds (0: the scene's), into <run name>.h5 with its "
          "contacts",
          4, 256)) {
    return *code;
  }
  try {
    const grbd::scene::Scene base = grbd::scene::load_scene(argv[2]);
    if (!base.domain.periodic[0] || !base.domain.periodic[1]) {
      throw grbd::Error(std::string(argv[2]) + ": expected a scene periodic along x and y");
    }
    const double end_time = grbd::demo::parse_number(argv[3], "end time");
    if (end_time < 0.0) throw grbd::Error("end time: expected 0 or a time > 0 [s]");
    std::vector<incline::Layer> layers;
    for (int i = 4; i < argc; ++i) layers.push_back(incline::parse_layer(argv[i]));
    run_mine(argv[1], base, end_time, layers);
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 8 steady-flow study");
  }
}
