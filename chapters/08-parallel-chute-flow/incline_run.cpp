// Chapter 8 demo: the runs of the steady-flow study. incline.toml — a layer of glass beads on a
// rough base of fixed beads in a box periodic along and across the flow — tilted to each angle θ
// given (gravity g (sin θ, 0, −cos θ), the flow along +x) and run with grbd's driver of
// `grbd run` on the parallel engine, on every process this program was started on, into
// incline_<θ>.h5 (+ .xmf, .ckpt.h5) in the data directory, with the contacts in every record.
// ch08_incline measures them. Its own program, so that a change to the measurements does not run
// the simulations again.
//
// Usage: `[mpiexec -n P] ch08_incline_run <data directory> <scene.toml> <angle in degrees>...`.

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "grbd/io/run.hpp"
#include "grbd/parallel/mpi.hpp"
#include "grbd/parallel/run.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd_demo/demo.hpp"
#include "incline.hpp"

namespace {

constexpr const char* kProgram = "ch08_incline_run";

// `run`: every angle's run, on every process this program was started on.
void run_all(const std::filesystem::path& dir, const grbd::scene::Scene& base,
             const std::vector<double>& angles) {
  const grbd::parallel::MpiEnvironment mpi;
  const grbd::Communicator& world = mpi.world();
  for (const double angle : angles) {
    grbd::io::RunOptions options;
    options.output = dir / (incline::run_name(angle) + ".h5");
    options.checkpoint = dir / (incline::run_name(angle) + ".ckpt.h5");
    options.overwrite = true;
    const grbd::io::RunResult result =
        grbd::parallel::run(incline::tilted(base, angle), options, world);
    if (world.rank() == 0) {
      std::printf("%s: theta = %g deg: %llu steps in %.0f s on %d processes\n", kProgram, angle,
                  static_cast<unsigned long long>(result.steps), result.seconds, world.size());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto code = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<scene.toml>", "<angle>..."},
          "runs the incline scene at each angle (in degrees), on every process it was started on, "
          "into incline_<angle>.h5 with its contacts",
          3, 64)) {
    return *code;
  }
  try {
    const grbd::scene::Scene base = grbd::scene::load_scene(argv[2]);
    if (!base.domain.periodic[0] || !base.domain.periodic[1]) {
      throw grbd::Error(std::string(argv[2]) + ": expected a scene periodic along x and y");
    }
    std::vector<double> angles;
    for (int i = 3; i < argc; ++i) angles.push_back(grbd::demo::parse_number(argv[i], "angle"));
    run_all(argv[1], base, angles);
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 8 steady-flow study");
  }
}
