// Chapter 7: what the output costs a run, measured against the run's own steps in the same
// benchmark run (this machine is shared: a ratio is what stays comparable).
//
//   BM_output/N/P   N spheres of radius 1 mm in a simple-cubic lattice of touching spheres on a
//                   floor (about 3 contacts per sphere, SOR with at most 100 iterations and warm
//                   start), P = 0 double, 1 float32 records, 2 double records with their
//                   contacts ([output] contacts). Each iteration is one step and one
//                   record, timed apart. Counters:
//                   step_ms      wall time of a step
//                   record_ms    wall time of a record (write, flush, count, XDMF)
//                   record_MB    bytes a record adds to the file
//                   overhead_per_100   record_ms / (100 step_ms + record_ms): the share of the
//                                run's time that output takes at one record every 100 steps
//
// Run: grbd bench ch07 (or ch07_bench_output, or the target run_ch07_bench_output).

#include <benchmark/benchmark.h>

#include <unistd.h>
#include <chrono>
#include <filesystem>
#include <string>

#include "grbd/io/output.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"

namespace {

std::string lattice_scene(std::int64_t n, bool float32, bool contacts) {
  // A square base of side k spheres holds the lattice in ⌈n / k²⌉ layers.
  std::int64_t k = 1;
  while (k * k * k < n) ++k;
  const double side = 0.002 * static_cast<double>(k);
  const double height = 0.002 * static_cast<double>((n + k * k - 1) / (k * k) + 1);
  return R"([simulation]
dt = 1e-3
end_time = 1.0
gravity = [0, 0, -9.81]

[solver]
max_iterations = 100
tolerance = 1e-6

[[material]]
name = "glass"

[default_contact]
mu = 0.5

[[static]]
shape = "half_space"
normal = [0, 0, 1]
material = "glass"

[[bodies]]
radius = 0.001
density = 2500
material = "glass"

[bodies.generator]
kind = "lattice"
count = )" +
         std::to_string(n) + "\nregion = { min = [0, 0, 0], max = [" + std::to_string(side) + ", " +
         std::to_string(side) + ", " + std::to_string(height) + "] }\n\n[output]\nprecision = \"" +
         (float32 ? "float" : "double") + "\"\ncontacts = " + (contacts ? "true" : "false") +
         "\n";
}

void BM_output(benchmark::State& state) {
  const std::int64_t n = state.range(0);
  const bool float32 = state.range(1) == 1;
  const bool contacts = state.range(1) == 2;
  const grbd::scene::Scene scene =
      grbd::scene::parse_scene(lattice_scene(n, float32, contacts), "bench_output.toml");
  grbd::scene::Simulation sim(scene);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("grbd_bench_output_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "bench.h5";
  double step = 0.0, record = 0.0;
  std::uintmax_t bytes = 0;
  {
    grbd::io::OutputFile output(file, scene);
    output.write_record(sim);  // the first record also writes the body table
    sim.step();                // the contacts form
    std::uintmax_t size = std::filesystem::file_size(file);
    using Clock = std::chrono::steady_clock;
    for (auto _ : state) {
      const auto t0 = Clock::now();
      const grbd::timestep::StepReport report = sim.step();
      const auto t1 = Clock::now();
      output.add_step(report, sim.system().size());
      output.write_record(sim);
      const auto t2 = Clock::now();
      step += std::chrono::duration<double>(t1 - t0).count();
      record += std::chrono::duration<double>(t2 - t1).count();
      state.SetIterationTime(std::chrono::duration<double>(t2 - t0).count());
    }
    output.close(sim);
    bytes = std::filesystem::file_size(file) - size;
  }
  std::filesystem::remove_all(dir);
  const auto iterations = static_cast<double>(state.iterations());
  state.counters["step_ms"] = 1e3 * step / iterations;
  state.counters["record_ms"] = 1e3 * record / iterations;
  state.counters["record_MB"] = 1e-6 * static_cast<double>(bytes) / iterations;
  state.counters["overhead_per_100"] = record / (100.0 * step + record);
  state.counters["contacts"] = static_cast<double>(sim.stepper().problem().contacts.size());
}

}  // namespace

BENCHMARK(BM_output)
    ->Args({10000, 0})
    ->Args({100000, 0})
    ->Args({100000, 1})
    ->Args({100000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);

BENCHMARK_MAIN();
