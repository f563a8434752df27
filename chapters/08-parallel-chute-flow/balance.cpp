// Chapter 8 demo: the load of a heap in a corner, shared by a grid and by a bisection tree.
//
// The domain is a box 0.4 m × 0.4 m in plan and 0.1 m high. 20 000 bodies of equal weight: half
// fill a cone heaped against the corner x = y = 0 (height 0.1 m at the corner, falling to 0 at
// 0.15 m from it), half a layer 1 cm deep over the whole floor — a load uneven along x and along y
// at once, as a heap poured into a corner, or a chute's reservoir behind its gate. P processes
// share it three ways: the even grid of grid_dims(), the grid balanced by weighted quantiles along
// each axis (balanced_grid), and the tree of recursive coordinate bisection balanced by weight
// (BisectionTree::balanced). For each the demo reports the most loaded process's bodies over the
// mean and the share of bodies that reach within 1 cm of another process's subdomain (ghosts
// somewhere: what each step's exchange carries).
//
// Output in the data directory: balance.csv (x, y of every body, its owner under the balanced grid
// and under the tree, P = 4), cuts.csv (layout, rank, x_min, y_min, x_max, y_max of the
// subdomains, P = 4) and values.txt (key = value, read by the book): p<P>.<layout>.imbalance (most
// loaded over mean) and p<P>.<layout>.ghost_percent for P = 4, 8, 16 and layout even, grid, tree.
//
// Usage: `ch08_balance <data directory>`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "grbd/parallel/balance.hpp"
#include "grbd/parallel/bisection.hpp"
#include "grbd/parallel/decomposition.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Vector3;
using grbd::parallel::Box;
using grbd::parallel::Partition;

// Half the bodies uniform in a cone heaped against the corner, half in a layer over the floor.
std::vector<Vector3> heap(int n) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vector3> centres;
  while (static_cast<int>(centres.size()) < n / 2) {
    const Vector3 c(0.15 * u(rng), 0.15 * u(rng), 0.1 * u(rng));
    if (c.z() < 0.1 * (1.0 - std::hypot(c.x(), c.y()) / 0.15)) centres.push_back(c);
  }
  while (static_cast<int>(centres.size()) < n) {
    centres.emplace_back(0.4 * u(rng), 0.4 * u(rng), 0.01 * u(rng));
  }
  return centres;
}

struct Measure {
  double imbalance = 0.0;      // most loaded over mean
  double ghost_percent = 0.0;  // bodies within reach of another subdomain [%]
};

Measure measure(const Partition& partition, const std::vector<Vector3>& centres, double reach) {
  std::vector<int> load(static_cast<std::size_t>(partition.size()), 0);
  int ghosts = 0;
  for (const Vector3& c : centres) {
    const int owner = partition.owner_of(c);
    ++load[static_cast<std::size_t>(owner)];
    for (int r = 0; r < partition.size(); ++r) {
      if (r != owner && grbd::parallel::overlaps(c, reach, partition.owned_region(r))) {
        ++ghosts;
        break;
      }
    }
  }
  const double mean = static_cast<double>(centres.size()) / partition.size();
  return {*std::max_element(load.begin(), load.end()) / mean,
          100.0 * ghosts / static_cast<double>(centres.size())};
}

void run(const std::string& dir) {
  const Box domain(Vector3(0.0, 0.0, 0.0), Vector3(0.4, 0.4, 0.1));
  const std::array<bool, 3> open{false, false, false};
  const std::vector<Vector3> centres = heap(20000);
  const std::vector<double> weights(centres.size(), 1.0);
  const double reach = 0.01;
  const grbd::Communicator& self = grbd::self_communicator();
  const char* names[3] = {"even", "grid", "tree"};

  grbd::demo::OutputFile values(std::filesystem::path(dir) / "values.txt");
  char line[256];
  std::printf(
      "ch08_balance: 20 000 bodies heaped in a corner of a 0.4 × 0.4 × 0.1 m box; most "
      "loaded process over the mean (bodies with ghosts, reach 1 cm):\n");
  for (const int p : {4, 8, 16}) {
    const grbd::parallel::CartesianGrid even(domain, grbd::parallel::grid_dims(p, domain.sizes()));
    const std::unique_ptr<Partition> layouts[3] = {
        even.clone(), even.rebalanced(self, centres, weights),
        grbd::parallel::BisectionTree(domain, p, open).rebalanced(self, centres, weights)};
    std::printf("  P = %2d:", p);
    for (int k = 0; k < 3; ++k) {
      const Measure m = measure(*layouts[k], centres, reach);
      std::snprintf(line, sizeof line, "p%d.%s.imbalance = %.2f\np%d.%s.ghost_percent = %.1f\n", p,
                    names[k], m.imbalance, p, names[k], m.ghost_percent);
      values << line;
      std::printf("  %s %.2f (%.1f %%)", names[k], m.imbalance, m.ghost_percent);
    }
    std::printf("\n");
    if (p != 4) continue;
    grbd::demo::OutputFile csv(std::filesystem::path(dir) / "balance.csv",
                               "x_m,y_m,owner_grid,owner_tree");
    for (const Vector3& c : centres) {
      csv << c.x() << ',' << c.y() << ',' << layouts[1]->owner_of(c) << ','
          << layouts[2]->owner_of(c) << '\n';
    }
    csv.finish();
    grbd::demo::OutputFile cuts(std::filesystem::path(dir) / "cuts.csv",
                                "layout,rank,x_min_m,y_min_m,x_max_m,y_max_m");
    for (int k = 1; k < 3; ++k) {
      for (int r = 0; r < p; ++r) {
        const Box box = layouts[k]->subdomain(r);
        cuts << k << ',' << r << ',' << box.min().x() << ',' << box.min().y() << ','
             << box.max().x() << ',' << box.max().y() << '\n';
      }
    }
    cuts.finish();
  }
  values.finish();
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch08_balance", {"<data directory>"},
          "writes balance.csv, cuts.csv and values.txt into the existing directory")) {
    return *exit_code;
  }
  try {
    run(argv[1]);
  } catch (...) {
    return grbd::demo::report_exception("ch08_balance", "the exercises of chapter 8");
  }
  return 0;
}
