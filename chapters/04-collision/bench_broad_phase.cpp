// Chapter 4: the cost of the broad phase per body on dense sphere packings of N = 10³ … 10⁶.
//
// The packing: the first N sites of a face-centred cubic lattice of nearest-neighbour distance
// 2.1 r (filled layer by layer), each centre jittered by up to ±0.1 r per axis, radii uniform
// in [0.9, 1.1] r: volume fraction ≈ 0.64 (random close packing), every sphere near-touching
// its twelve lattice neighbours, of which a few are closer than r_i + r_j + margin
// (margin = 0.05 r); the counter pairs_per_body reports how many.
//
// Three variants, all with the same CellGrid reused from iteration to iteration (as a time
// stepper would):
//   BM_detect/random   build + find_pairs, bodies stored in random order
//   BM_detect/morton   build + find_pairs, bodies stored in Morton (Z-) order of their cells
//   BM_build/random    build only, random order
// items_per_second is bodies per second; the counter ns_per_body is its inverse in nanoseconds
// (CPU time of the benchmark thread per body per detection), pairs_per_body the pairs found.
//
// Run: ch04_bench_broad_phase [--benchmark_filter=...] (or the target
// run_ch04_bench_broad_phase).

#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "grbd/collision/broad_phase.hpp"
#include "grbd/core/types.hpp"

namespace {

using grbd::Vector3;
using grbd::collision::CellGrid;
using grbd::collision::IndexPair;

constexpr double kRadius = 1.0;             // r [m]
constexpr double kMargin = 0.05 * kRadius;  // [m]

struct Packing {
  std::vector<Vector3> centres;
  std::vector<double> radii;
};

/// N spheres on a jittered FCC lattice (see the file comment), in random order.
Packing dense_packing(std::int64_t n) {
  std::mt19937_64 engine(20260404);
  std::uniform_real_distribution<double> jitter(-0.1 * kRadius, 0.1 * kRadius);
  std::uniform_real_distribution<double> radius(0.9 * kRadius, 1.1 * kRadius);
  const double a = 2.1 * kRadius * std::sqrt(2.0);  // cubic cell edge of the FCC lattice
  const auto m = static_cast<std::int64_t>(std::ceil(std::cbrt(static_cast<double>(n) / 4.0)));
  const Vector3 basis[4] = {{0.0, 0.0, 0.0}, {0.5, 0.5, 0.0}, {0.5, 0.0, 0.5}, {0.0, 0.5, 0.5}};
  Packing p;
  p.centres.reserve(static_cast<std::size_t>(n));
  for (std::int64_t k = 0; k < m && std::ssize(p.centres) < n; ++k) {
    for (std::int64_t j = 0; j < m && std::ssize(p.centres) < n; ++j) {
      for (std::int64_t i = 0; i < m && std::ssize(p.centres) < n; ++i) {
        for (const Vector3& b : basis) {
          if (std::ssize(p.centres) == n) break;
          const Vector3 site = a * (Vector3(double(i), double(j), double(k)) + b);
          p.centres.push_back(site + Vector3(jitter(engine), jitter(engine), jitter(engine)));
        }
      }
    }
  }
  std::shuffle(p.centres.begin(), p.centres.end(), engine);
  for (std::int64_t i = 0; i < n; ++i) p.radii.push_back(radius(engine));
  return p;
}

/// The same packing with the bodies renumbered in Morton order of cells of edge 2 r_max + margin.
Packing morton_sorted(const Packing& p) {
  const double r_max = *std::max_element(p.radii.begin(), p.radii.end());
  const std::vector<std::int32_t> order =
      grbd::collision::morton_order(p.centres, 2.0 * r_max + kMargin);
  Packing sorted;
  for (const std::int32_t i : order) {
    sorted.centres.push_back(p.centres[i]);
    sorted.radii.push_back(p.radii[i]);
  }
  return sorted;
}

/// CPU time of this thread [ns]: unlike the wall clock, it does not count the time that other
/// processes of a loaded machine take.
double thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

void report(benchmark::State& state, std::int64_t n, std::size_t pairs, double cpu_ns) {
  const auto bodies = static_cast<std::int64_t>(state.iterations()) * n;
  state.SetItemsProcessed(bodies);
  state.counters["ns_per_body"] = cpu_ns / static_cast<double>(bodies);
  state.counters["pairs_per_body"] = static_cast<double>(pairs) / static_cast<double>(n);
}

void BM_detect(benchmark::State& state, bool morton) {
  const std::int64_t n = state.range(0);
  const Packing random_order = dense_packing(n);
  const Packing p = morton ? morton_sorted(random_order) : random_order;
  CellGrid grid;
  std::vector<IndexPair> pairs;
  const double start = thread_cpu_ns();
  for (auto _ : state) {
    grid.build(p.centres, p.radii, kMargin);
    grid.find_pairs(pairs);
    benchmark::DoNotOptimize(pairs.data());
    benchmark::ClobberMemory();
  }
  const double cpu_ns = thread_cpu_ns() - start;
  report(state, n, pairs.size(), cpu_ns);
}

void BM_build(benchmark::State& state) {
  const std::int64_t n = state.range(0);
  const Packing p = dense_packing(n);
  CellGrid grid;
  const double start = thread_cpu_ns();
  for (auto _ : state) {
    grid.build(p.centres, p.radii, kMargin);
    benchmark::ClobberMemory();
  }
  const double cpu_ns = thread_cpu_ns() - start;
  std::vector<IndexPair> pairs;
  grid.find_pairs(pairs);
  report(state, n, pairs.size(), cpu_ns);
}

void sizes(benchmark::internal::Benchmark* b) {
  b->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);
}

BENCHMARK_CAPTURE(BM_detect, random, false)->Apply(sizes);
BENCHMARK_CAPTURE(BM_detect, morton, true)->Apply(sizes);
BENCHMARK(BM_build)->Name("BM_build/random")->Apply(sizes);

}  // namespace

BENCHMARK_MAIN();
