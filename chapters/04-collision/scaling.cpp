// Chapter 4 demo: how the broad phase scales. For N = 10³, 10⁴, 10⁵ and 10⁶ spheres it times one
// broad-phase pass, grbd::collision::CellGrid::build followed by find_pairs, once with the spheres
// stored in random order and once after sorting them along the Morton (Z-order) curve with
// grbd::collision::morton_order, and reports the time per sphere. A flat line over N is linear
// scaling.
//
// The spheres: radii uniform in [0.8, 1] r_max with r_max = 1 mm, centres uniform in a cube sized
// for a solid fraction of 0.55 (the sum of the sphere volumes over the cube's volume), seeded. This
// is as dense as a random loose packing; the spheres may overlap, which the broad phase does not
// care about. The margin is 0.1 r_max, so the grid's cells have the edge h = 2.1 r_max.
//
// Every time is the best of several repetitions (many for small N, three for N = 10⁶), measured
// as the CPU time of this thread around build + find_pairs; the first pass allocates the grid and
// the pair vector, the best one reuses them, as a time step of a simulation does. Timings are
// measured, never asserted: they depend on the machine and on what else it runs. The program
// checks (and prints) that both orders find the same number of pairs and, for N = 10³, that the
// grid finds exactly the pairs of brute_force_pairs.
//
// Output: `scaling.csv` in the data directory, one row per N, with the columns
//
//   N                           number of spheres
//   ns_per_body_random          best time of build + find_pairs divided by N, random order [ns]
//   ns_per_body_morton          the same after Morton reordering [ns]
//   pairs_per_body              candidate pairs found divided by N
//   morton_order_ns_per_body    best time of morton_order plus applying the permutation, / N [ns]
//   cells                       number of grid cells
//   build_ns_random             best time of build alone divided by N, random order [ns]
//   pairs_ns_random             best time of find_pairs alone divided by N, random order [ns]
//   build_ns_morton             the same two after Morton reordering [ns]
//   pairs_ns_morton
//
// (The best of the sum is at least the sum of the bests, so the parts add up to a little less than
// the total.)
//
// The numbers the chapter quotes also go to `values.txt` (key = value lines read by the book at
// build time: \demo{ch04_scaling/values.txt#KEY} in chapter.md): for every N, with the prefix
// N<N>., pairs (per sphere), cells, random, random_build, morton, morton_build, reordering (the
// times per sphere of the table, ns) and pass (the best time of one pass in random order, s);
// for N = 10⁶ spheres_per_cell and half_shell_tests (13.5 cells' worth of spheres, the number of
// distance tests per sphere).
//
// Usage: `ch04_scaling <data directory>`.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "grbd/collision/broad_phase.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Vector3;
namespace collision = grbd::collision;
/// The CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID). Unlike wall time it does not
/// count the time the core spends on other processes, which matters because the figures are
/// drawn while the rest of the project compiles; caches and memory bandwidth are still shared.
struct ThreadCpuClock {
  using duration = std::chrono::nanoseconds;
  using rep = duration::rep;
  using period = duration::period;
  using time_point = std::chrono::time_point<ThreadCpuClock>;
  static constexpr bool is_steady = true;
  static time_point now() noexcept {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return time_point(duration(static_cast<rep>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec));
  }
};
using Clock = ThreadCpuClock;

constexpr double kRadiusMax = 1e-3;              // r_max [m]
constexpr double kRadiusMin = 0.8 * kRadiusMax;  // [m]
constexpr double kMargin = 0.1 * kRadiusMax;     // [m]
constexpr double kSolidFraction = 0.55;

struct Spheres {
  std::vector<Vector3> centres;
  std::vector<double> radii;
};

// N spheres with radii uniform in [r_min, r_max] and centres uniform in a cube of solid fraction
// kSolidFraction, in the (random) order in which they were drawn.
Spheres random_spheres(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> radius(kRadiusMin, kRadiusMax);
  Spheres s;
  s.radii.resize(n);
  double volume = 0.0;
  for (double& r : s.radii) {
    r = radius(rng);
    volume += 4.0 / 3.0 * std::numbers::pi * r * r * r;
  }
  const double side = std::cbrt(volume / kSolidFraction);
  std::uniform_real_distribution<double> coordinate(0.0, side);
  s.centres.resize(n);
  for (Vector3& c : s.centres) {
    c = Vector3(coordinate(rng), coordinate(rng), coordinate(rng));
  }
  return s;
}

// The spheres in the order `order` (order[n] is the index of the n-th sphere).
Spheres permuted(const Spheres& s, const std::vector<std::int32_t>& order) {
  Spheres out;
  out.centres.resize(order.size());
  out.radii.resize(order.size());
  for (std::size_t n = 0; n < order.size(); ++n) {
    out.centres[n] = s.centres[static_cast<std::size_t>(order[n])];
    out.radii[n] = s.radii[static_cast<std::size_t>(order[n])];
  }
  return out;
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct GridTiming {
  double best_s = std::numeric_limits<double>::infinity();        // best time of build + find_pairs
  double best_build_s = std::numeric_limits<double>::infinity();  // best time of build alone
  double best_pairs_s = std::numeric_limits<double>::infinity();  // best time of find_pairs alone
  std::size_t pairs = 0;
  std::int64_t cells = 0;
  double cell_size = 0.0;
};

GridTiming time_grid(const Spheres& s, int repetitions) {
  collision::CellGrid grid;
  std::vector<collision::IndexPair> pairs;
  GridTiming t;
  for (int rep = 0; rep < repetitions; ++rep) {
    const Clock::time_point start = Clock::now();
    grid.build(s.centres, s.radii, kMargin);
    const Clock::time_point built = Clock::now();
    grid.find_pairs(pairs);
    const Clock::time_point end = Clock::now();
    t.best_s = std::min(t.best_s, std::chrono::duration<double>(end - start).count());
    t.best_build_s = std::min(t.best_build_s, std::chrono::duration<double>(built - start).count());
    t.best_pairs_s = std::min(t.best_pairs_s, std::chrono::duration<double>(end - built).count());
  }
  t.pairs = pairs.size();
  t.cells = static_cast<std::int64_t>(grid.cells().cast<std::int64_t>().prod());
  t.cell_size = grid.cell_size();
  return t;
}

// Repetitions for N spheres: about two million sphere-passes per measurement, at least three.
int repetitions_for(std::size_t n) { return std::max(3, static_cast<int>(2'000'000 / n)); }

// The 1-minute load average, or −1 where /proc/loadavg cannot be read: timings taken on a loaded
// machine are slower, and the chapter says which kind its table is.
double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = -1.0;
  if (!(in >> load)) {
    return -1.0;
  }
  return load;
}

void run(const std::filesystem::path& dir) {
  grbd::demo::OutputFile out(
      dir / "scaling.csv",
      "N,ns_per_body_random,ns_per_body_morton,pairs_per_body,morton_order_ns_per_body,cells,"
      "build_ns_random,pairs_ns_random,build_ns_morton,pairs_ns_morton");
  std::printf("ch04_scaling: %u hardware threads, load average %.2f at the start\n",
              std::thread::hardware_concurrency(), load_average());
  std::printf("%9s %14s %14s %10s %14s %10s\n", "N", "random ns/body", "morton ns/body",
              "pairs/body", "sort ns/body", "cells");

  grbd::demo::Values values;
  const std::size_t sizes[] = {1'000, 10'000, 100'000, 1'000'000};
  for (const std::size_t n : sizes) {
    const Spheres spheres = random_spheres(n, 20261121 + n);
    const int repetitions = repetitions_for(n);
    const GridTiming random = time_grid(spheres, repetitions);

    // The reordering a simulation would do every few steps: sort and apply the permutation.
    double sort_s = std::numeric_limits<double>::infinity();
    Spheres sorted;
    for (int rep = 0; rep < std::max(3, repetitions / 10); ++rep) {
      const Clock::time_point start = Clock::now();
      const std::vector<std::int32_t> order =
          collision::morton_order(spheres.centres, random.cell_size);
      sorted = permuted(spheres, order);
      sort_s = std::min(sort_s, seconds_since(start));
    }
    const GridTiming morton = time_grid(sorted, repetitions);

    const double per_body = 1e9 / static_cast<double>(n);
    out << n << ',' << random.best_s * per_body << ',' << morton.best_s * per_body << ','
        << static_cast<double>(random.pairs) / static_cast<double>(n) << ',' << sort_s * per_body
        << ',' << random.cells << ',' << random.best_build_s * per_body << ','
        << random.best_pairs_s * per_body << ',' << morton.best_build_s * per_body << ','
        << morton.best_pairs_s * per_body << '\n';
    std::printf(
        "%9zu %14.1f %14.1f %10.3f %14.1f %10lld  (%d repetitions; build/pairs %.1f/%.1f "
        "random, %.1f/%.1f Morton)\n",
        n, random.best_s * per_body, morton.best_s * per_body,
        static_cast<double>(random.pairs) / static_cast<double>(n), sort_s * per_body,
        static_cast<long long>(random.cells), repetitions, random.best_build_s * per_body,
        random.best_pairs_s * per_body, morton.best_build_s * per_body,
        morton.best_pairs_s * per_body);
    std::string key = "N";  // (not "N" + std::to_string(n): GCC 12 warns falsely, -Wrestrict)
    key += std::to_string(n);
    key += '.';
    values.set(key + "pairs", "%.2f", static_cast<double>(random.pairs) / static_cast<double>(n));
    values.set(key + "cells", "%lld", static_cast<long long>(random.cells));
    values.set(key + "random", "%.0f", random.best_s * per_body);
    values.set(key + "random_build", "%.0f", random.best_build_s * per_body);
    values.set(key + "morton", "%.0f", morton.best_s * per_body);
    values.set(key + "morton_build", "%.0f", morton.best_build_s * per_body);
    values.set(key + "reordering", "%.0f", sort_s * per_body);
    values.set(key + "pass", "%.2g", random.best_s);
    if (n == 1'000'000) {
      const double per_cell = static_cast<double>(n) / static_cast<double>(random.cells);
      values.set("spheres_per_cell", "%.1f", per_cell);
      values.set("half_shell_tests", "%.0f", 13.5 * per_cell);
    }
    if (random.pairs != morton.pairs) {
      std::printf("  note: %zu pairs in random order, %zu after reordering\n", random.pairs,
                  morton.pairs);
    }
    if (n == 1'000) {
      std::vector<collision::IndexPair> grid_pairs;
      collision::CellGrid grid;
      grid.build(spheres.centres, spheres.radii, kMargin);
      grid.find_pairs(grid_pairs);
      std::sort(grid_pairs.begin(), grid_pairs.end());
      const bool same =
          grid_pairs == collision::brute_force_pairs(spheres.centres, spheres.radii, kMargin);
      std::printf("  N = 1000: the grid's pairs %s the brute-force pairs\n",
                  same ? "equal" : "DIFFER FROM");
    }
  }
  out.finish();
  values.write(dir / "values.txt");
  std::printf("ch04_scaling: load average %.2f at the end; wrote %s\n", load_average(),
              out.path().string().c_str());
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code =
          grbd::demo::check_arguments(argc, argv, "ch04_scaling", {"<data directory>"},
                                      "writes scaling.csv and values.txt into the existing directory")) {
    return *exit_code;
  }
  try {
    run(argv[1]);
  } catch (...) {
    return grbd::demo::report_exception("ch04_scaling", "the exercises of chapter 4");
  }
  return 0;
}
