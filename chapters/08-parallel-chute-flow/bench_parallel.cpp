// Chapter 8 benchmark: one step of the settled FCC pile of chapter 6 (pile.hpp) on P processes.
//
// Every process builds the whole pile and keeps the spheres whose centre its subdomain holds
// (grid_dims over the pile's box). The parallel step runs at exactly `iterations` SOR sweeps per
// step (min = max), warm-started; after 3 steps to settle the buffers, `steps` steps are timed.
// Rank 0 prints one line: P, spheres, contacts, the wall time of a step (the slowest process),
// its stages (midpoint, detection, assembly, solve, update: the slowest process's), the ghost
// exchange before the step, split bodies, ghosts, and at P = 1 also the serial MoreauStepper on the
// same pile in the same run, and the ratio parallel / serial.
//
// With iterations = 0 the step runs to the solver's tolerance instead (relative 10⁻⁶, at most
// 10 000 sweeps), averaging the split bodies every `average_every` sweeps, and the line gives the
// mean number of sweeps per step.
//
// Usage: mpiexec -n P ch08_bench_parallel [n = 14] [iterations = 100] [steps = 10]
//        [average_every = 1]
// (or alone, P = 1). Measured by hand; the chapter quotes what it printed.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "grbd/parallel/decomposition.hpp"
#include "grbd/parallel/mpi.hpp"
#include "grbd/parallel/stepper.hpp"
#include "pile.hpp"

namespace {

using namespace grbd;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

timestep::StepSettings settings_for(int iterations, double r) {
  timestep::StepSettings s;
  s.dt = 2e-4;
  if (iterations > 0) {
    s.solver.min_iterations = iterations;
    s.solver.max_iterations = iterations;
  } else {
    s.solver.rel_tol = 1e-6;
    s.solver.max_iterations = 10000;
  }
  s.tolerance_radius = r;
  s.skin = 0.2 * r;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && (std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help")) {
    std::printf(
        "usage: ch08_bench_parallel [n = 14] [iterations = 100] [steps = 10]\n"
        "  one step of the n × n × n FCC pile on the processes of mpiexec\n");
    return 0;
  }
  parallel::MpiEnvironment mpi;
  const Communicator& comm = mpi.world();
  const int n = argc > 1 ? std::atoi(argv[1]) : 14;
  const int iterations = argc > 2 ? std::atoi(argv[2]) : 100;
  const int steps = argc > 3 ? std::atoi(argv[3]) : 10;
  const int average_every = argc > 4 ? std::atoi(argv[4]) : 1;
  if (n < 1 || iterations < 0 || steps < 1 || average_every < 1) {
    std::fprintf(stderr,
                 "ch08_bench_parallel: expected positive n, steps and average_every, "
                 "and iterations >= 0\n");
    return 2;
  }
  const double r = 1e-3;
  try {
    timestep::BodySystem whole;
    timestep::StaticGeometry statics;
    demo::fcc_pile(whole, statics, n, n, n, r);
    const timestep::MaterialTable materials = demo::glass_materials();
    parallel::Box box;
    for (const body::State& x : whole.states()) box.extend(x.q.head<3>());
    box.extend(box.min() - Vector3::Constant(r));
    box.extend(box.max() + Vector3::Constant(r));
    const parallel::CartesianGrid grid(box, parallel::grid_dims(comm.size(), box.sizes()));
    timestep::BodySystem mine;
    for (std::size_t i = 0; i < whole.size(); ++i) {
      if (grid.owner_of(whole.states()[i].q.head<3>()) == comm.rank()) mine.add(whole.record(i));
    }
    parallel::ParallelStepper stepper(comm, grid, mine, statics, materials,
                                      settings_for(iterations, r), {r, average_every});
    for (int k = 0; k < 3; ++k) stepper.step();
    // total, midpoint, detection, assembly, solve, update, exchange, averaging; traffic
    std::vector<double> t(11, 0.0);
    std::size_t contacts = 0;
    long sweeps = 0;
    const double averaging0 = stepper.averaging_seconds();
    const Communicator::Traffic traffic0 = comm.traffic();
    for (int k = 0; k < steps; ++k) {
      const auto t0 = Clock::now();
      const timestep::StepReport report = stepper.step();
      const double total = seconds_since(t0);
      t[0] += total;
      t[1] += report.seconds.midpoint;
      t[2] += report.seconds.detection;
      t[3] += report.seconds.assembly;
      t[4] += report.seconds.solve;
      t[5] += report.seconds.update;
      t[6] += total - report.seconds.total;
      contacts = report.contacts;
      sweeps += report.iterations;
    }
    t[7] = stepper.averaging_seconds() - averaging0;
    t[8] = static_cast<double>(comm.traffic().messages - traffic0.messages);
    t[9] = static_cast<double>(comm.traffic().bytes - traffic0.bytes);
    t[10] = static_cast<double>(comm.traffic().collectives - traffic0.collectives);
    comm.max(t);
    std::vector<std::uint64_t> counts{stepper.split_bodies(), mine.ghost_count()};
    comm.sum(counts);
    double serial = 0.0;
    if (comm.size() == 1 && iterations > 0) {
      timestep::MoreauStepper reference(whole, statics, materials, settings_for(iterations, r));
      for (int k = 0; k < 3; ++k) reference.step();
      const auto t0 = Clock::now();
      for (int k = 0; k < steps; ++k) reference.step();
      serial = seconds_since(t0) / steps;
    }
    if (comm.rank() == 0) {
      const double ms = 1e3 / steps;
      std::printf(
          "ch08_bench_parallel: P = %d, %zu spheres, %zu contacts, %.1f sweeps a step "
          "(averaged every %d): step %.1f ms "
          "(midpoint %.1f, detection %.1f, assembly %.1f, solve %.1f of which averaging "
          "%.1f, update %.1f, ghost exchange %.1f), per step and process at most %.0f "
          "messages, %.1f kB, %.0f collective operations; %llu split bodies, %llu ghosts",
          comm.size(), whole.size(), contacts, static_cast<double>(sweeps) / steps, average_every,
          t[0] * ms, t[1] * ms, t[2] * ms, t[3] * ms, t[4] * ms, t[7] * ms, t[5] * ms, t[6] * ms,
          t[8] / steps, t[9] / steps / 1e3, t[10] / steps,
          static_cast<unsigned long long>(counts[0]), static_cast<unsigned long long>(counts[1]));
      if (serial > 0.0) {
        std::printf("; serial MoreauStepper %.1f ms, parallel / serial %.3f", 1e3 * serial,
                    t[0] / steps / serial);
      }
      std::printf("\n");
    }
  } catch (const std::exception& e) {
    parallel::abort_run(std::string("ch08_bench_parallel: ") + e.what(), 1);
  }
  return 0;
}
