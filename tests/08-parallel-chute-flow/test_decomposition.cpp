// Chapter 8: the Cartesian decomposition. References: the subdomain boxes themselves (every
// position lies in the half-open box of exactly one rank, the one owner_of names), brute-force
// distances for the overlap, and the interface areas of every factorisation for grid_dims.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/parallel/balance.hpp"
#include "grbd/parallel/bisection.hpp"
#include "grbd/parallel/decomposition.hpp"
#include "grbd/timestep/contacts.hpp"

namespace grbd::parallel {
namespace {

// Whether x lies in the half-open box [min, max) of a subdomain, closed at the domain's far side.
bool holds(const CartesianGrid& grid, int rank, const Vector3& x) {
  const Box box = grid.subdomain(rank);
  for (int d = 0; d < 3; ++d) {
    const bool last = box.max()[d] == grid.domain().max()[d];
    if (x[d] < box.min()[d] || (last ? x[d] > box.max()[d] : x[d] >= box.max()[d])) return false;
  }
  return true;
}

TEST(Exercise8_1, EveryPositionInTheDomainHasExactlyTheOwnerWhoseBoxHoldsIt) {
  const CartesianGrid grid(Box(Vector3(-0.3, 0.0, 1.0), Vector3(0.7, 0.2, 1.3)), {5, 3, 2});
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 20000; ++k) {
    const Vector3 x =
        grid.domain().min() + Vector3(u(rng), u(rng), u(rng)).cwiseProduct(grid.domain().sizes());
    const int owner = grid.owner_of(x);
    ASSERT_GE(owner, 0);
    ASSERT_LT(owner, grid.size());
    int holders = 0;
    for (int r = 0; r < grid.size(); ++r) holders += holds(grid, r, x) ? 1 : 0;
    ASSERT_EQ(holders, 1);
    ASSERT_TRUE(holds(grid, owner, x)) << "x = " << x.transpose();
  }
}

TEST(Exercise8_1, BoundariesGoToTheCellAboveAndOutsidePositionsToTheNearestCell) {
  const CartesianGrid grid(Box(Vector3(0, 0, 0), Vector3(4, 2, 1)), {4, 2, 1});
  // On the interior boundary x = 1 (exactly b^x_1): the cell above.
  EXPECT_EQ(grid.owner_of(Vector3(1.0, 0.5, 0.5)), grid.rank_of({1, 0, 0}));
  EXPECT_EQ(grid.owner_of(Vector3(std::nextafter(1.0, 0.0), 0.5, 0.5)), grid.rank_of({0, 0, 0}));
  EXPECT_EQ(grid.owner_of(Vector3(3.0, 1.0, 0.5)), grid.rank_of({3, 1, 0}));
  // Outside: clamped, axis by axis.
  EXPECT_EQ(grid.owner_of(Vector3(-5.0, 0.5, 0.5)), grid.rank_of({0, 0, 0}));
  EXPECT_EQ(grid.owner_of(Vector3(9.0, 7.0, -3.0)), grid.rank_of({3, 1, 0}));
  EXPECT_EQ(grid.owner_of(Vector3(4.0, 2.0, 1.0)), grid.rank_of({3, 1, 0}));  // far corner
  // Every cell's centre belongs to its rank.
  for (int r = 0; r < grid.size(); ++r) EXPECT_EQ(grid.owner_of(grid.subdomain(r).center()), r);
}

TEST(Exercise8_1, PeriodicAxesWrapBeforeTheOwnerIsFound) {
  const CartesianGrid grid(Box(Vector3(0, 0, 0), Vector3(3, 1, 1)), {3, 1, 1},
                           {true, false, false});
  EXPECT_EQ(grid.owner_of(Vector3(-0.5, 0.5, 0.5)), 2);  // one period back: x = 2.5
  EXPECT_EQ(grid.owner_of(Vector3(3.0, 0.5, 0.5)), 0);   // x = L is x = 0
  EXPECT_EQ(grid.owner_of(Vector3(7.2, 0.5, 0.5)), 1);   // two periods on: x = 1.2
  // −10⁻¹⁷ + 3 rounds to 3 = L, which is 0: wrapping never leaves a position on the far side.
  EXPECT_EQ(grid.wrap(Vector3(-1e-17, 0.5, 0.5)).x(), 0.0);
  EXPECT_EQ(grid.owner_of(Vector3(-1e-17, 0.5, 0.5)), 0);
  EXPECT_EQ(grid.wrap(Vector3(-0.5, 9.0, 0.5)), Vector3(2.5, 9.0, 0.5));  // y is not periodic
}

TEST(Exercise8_2, ASphereOverlapsABoxWhenItsDistanceToTheBoxIsAtMostItsReach) {
  const Box box(Vector3(0, 0, 0), Vector3(1, 2, 3));
  EXPECT_TRUE(overlaps(Vector3(0.5, 0.5, 0.5), 0.0, box));     // inside
  EXPECT_TRUE(overlaps(Vector3(-0.25, 1.0, 1.0), 0.25, box));  // touching a face
  EXPECT_FALSE(overlaps(Vector3(-0.25, 1.0, 1.0), 0.2499, box));
  EXPECT_TRUE(overlaps(Vector3(-3.0, -4.0, 1.0), 5.0, box));  // touching an edge: 3-4-5
  EXPECT_FALSE(overlaps(Vector3(-3.0, -4.0, 1.0), 4.999, box));
  EXPECT_TRUE(overlaps(Vector3(2.0, 4.0, 5.0), 3.0, box));  // the far corner: (1, 2, 2) away
  EXPECT_FALSE(overlaps(Vector3(2.0, 4.0, 5.0), 2.999, box));
  // Against the distance to a dense sampling of the box's surface and inside.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 4.0);
  for (int k = 0; k < 2000; ++k) {
    const Vector3 c(u(rng), u(rng), u(rng));
    double distance = 0.0;
    for (int d = 0; d < 3; ++d) {
      const double outside = std::max({box.min()[d] - c[d], 0.0, c[d] - box.max()[d]});
      distance += outside * outside;
    }
    distance = std::sqrt(distance);
    EXPECT_EQ(overlaps(c, distance * (1 + 1e-12) + 1e-300, box), true);
    if (distance > 0.0) {
      EXPECT_EQ(overlaps(c, distance * (1 - 1e-12), box), false);
    }
  }
}

TEST(GridDims, CutsTheDomainWhereTheInterfacesAreSmallest) {
  EXPECT_EQ(grid_dims(1, Vector3(1, 1, 1)), (std::array<int, 3>{1, 1, 1}));
  EXPECT_EQ(grid_dims(8, Vector3(1, 1, 1)), (std::array<int, 3>{2, 2, 2}));
  EXPECT_EQ(grid_dims(7, Vector3(1, 5, 1)), (std::array<int, 3>{1, 7, 1}));     // a prime: one axis
  EXPECT_EQ(grid_dims(4, Vector3(10, 1, 0.1)), (std::array<int, 3>{4, 1, 1}));  // a chute
  // Against every factorisation: no other has smaller interfaces.
  for (int p = 1; p <= 64; ++p) {
    const Vector3 L(3.0, 1.0, 0.4);
    const auto area = [&](int nx, int ny, int nz) {
      return (nx - 1) * L.y() * L.z() + (ny - 1) * L.x() * L.z() + (nz - 1) * L.x() * L.y();
    };
    const std::array<int, 3> d = grid_dims(p, L);
    ASSERT_EQ(d[0] * d[1] * d[2], p);
    for (int nx = 1; nx <= p; ++nx) {
      for (int ny = 1; nx * ny <= p; ++ny) {
        if (p % (nx * ny) != 0) continue;
        EXPECT_LE(area(d[0], d[1], d[2]), area(nx, ny, p / (nx * ny)) * (1 + 1e-12));
      }
    }
  }
  EXPECT_THROW(grid_dims(0, Vector3(1, 1, 1)), InvalidArgument);
  EXPECT_THROW(grid_dims(2, Vector3(1, 0, 1)), InvalidArgument);
}

TEST(CartesianGrid, NeighboursAreTheSubdomainsWithinReachThroughPeriodicImagesToo) {
  const CartesianGrid line(Box(Vector3(0, 0, 0), Vector3(4, 1, 1)), {4, 1, 1});
  EXPECT_EQ(line.neighbours(0, 0.1), (std::vector<int>{1}));
  EXPECT_EQ(line.neighbours(1, 0.1), (std::vector<int>{0, 2}));
  EXPECT_EQ(line.neighbours(0, 1.5), (std::vector<int>{1, 2}));
  const CartesianGrid ring(Box(Vector3(0, 0, 0), Vector3(4, 1, 1)), {4, 1, 1},
                           {true, false, false});
  EXPECT_EQ(ring.neighbours(0, 0.1), (std::vector<int>{1, 3}));
  const CartesianGrid one(Box(Vector3(0, 0, 0), Vector3(4, 1, 1)), {1, 1, 1}, {true, false, false});
  EXPECT_EQ(one.neighbours(0, 0.1), (std::vector<int>{0}));  // its own image
  const CartesianGrid square(Box(Vector3(0, 0, 0), Vector3(2, 2, 1)), {2, 2, 1});
  EXPECT_EQ(square.neighbours(0, 0.0), (std::vector<int>{1, 2, 3}));  // the corner touches
  EXPECT_THROW(CartesianGrid(Box(Vector3(0, 0, 0), Vector3(1, 1, 1)), {0, 1, 1}), InvalidArgument);
  EXPECT_THROW(CartesianGrid(Box(Vector3(0, 0, 0), Vector3(1, 0, 1)), {1, 1, 1}), InvalidArgument);
  EXPECT_THROW(line.cell_of(4), InvalidArgument);
}

// Exercise 8.3: split a dense random packing among the six subdomains of a 3 × 2 × 1 grid; each
// part holds its owned bodies and, as ghosts, every body that reaches its subdomain within
// r + r_max + margin (what BodyExchange::borders sends). Each part detects its contacts and keeps
// those it solves: together the parts keep every contact of the whole system exactly once, with
// the same geometry bit for bit.
TEST(Exercise8_3, EveryContactIsSolvedByExactlyOneProcess) {
  const Box domain(Vector3(0, 0, 0), Vector3(0.3, 0.2, 0.1));
  const CartesianGrid grid(domain, {3, 2, 1});
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  timestep::BodySystem full;
  timestep::StaticGeometry statics;
  timestep::StaticObject floor;
  floor.id = 0;
  floor.shape = collision::HalfSpace{Vector3::UnitZ(), 0.0};
  statics.add(floor);
  const double r_max = 0.012;
  for (timestep::GlobalId id = 1; id <= 900; ++id) {
    timestep::BodyRecord b;
    b.id = id;
    const double r = 0.008 + 0.004 * u(rng);
    b.shape = collision::Sphere{r};
    b.inertia = {1.0, Vector3::Constant(0.4 * r * r)};
    b.flags = id % 50 == 0 ? 0 : timestep::kDynamic;  // a few fixed beads
    b.state.q << 0.3 * u(rng), 0.2 * u(rng), r * (0.9 + 6.0 * u(rng)), 1.0, 0.0, 0.0, 0.0;
    b.state.u.setZero();
    full.add(b);
  }
  const double margin = 1e-3;
  timestep::ContactDetector detector;
  std::vector<timestep::DetectedContact> all;
  std::vector<timestep::ContactKey> all_keys;
  detector.detect(full, statics, margin, all, all_keys);
  ASSERT_GT(all.size(), 500u);
  std::map<timestep::ContactKey, int> solved;
  for (int p = 0; p < grid.size(); ++p) {
    const Box box = grid.subdomain(p);
    timestep::BodySystem part;
    for (std::size_t i = 0; i < full.size(); ++i) {
      if (grid.owner_of(full.states()[i].q.head<3>()) == p) part.add(full.record(i));
    }
    for (std::size_t i = 0; i < full.size(); ++i) {
      const Vector3 c = full.states()[i].q.head<3>();
      if (grid.owner_of(c) != p && overlaps(c, full.bounding_radii()[i] + r_max + margin, box)) {
        part.add_ghost(full.record(i));
      }
    }
    std::vector<timestep::DetectedContact> found;
    std::vector<timestep::ContactKey> keys;
    detector.detect(part, statics, margin, found, keys);
    for (std::size_t k = 0; k < found.size(); ++k) {
      if (!solves_contact(part, found[k])) continue;
      ++solved[keys[k]];
      const auto it = std::find(all_keys.begin(), all_keys.end(), keys[k]);
      ASSERT_NE(it, all_keys.end());
      const timestep::DetectedContact& reference =
          all[static_cast<std::size_t>(it - all_keys.begin())];
      EXPECT_EQ(found[k].geometry.g_N, reference.geometry.g_N);
      EXPECT_EQ(found[k].geometry.I_n, reference.geometry.I_n);
    }
  }
  EXPECT_EQ(solved.size(), all_keys.size());
  for (const auto& [key, times] : solved) {
    EXPECT_EQ(times, 1) << "contact " << key.a << "–" << key.b;
  }
}

}  // namespace
}  // namespace grbd::parallel

namespace grbd::parallel {
namespace {

// A grid with boundaries of its own (a balanced grid's): the cells are where the boundaries say,
// and boundaries that do not increase from the domain's min to its max are refused.
TEST(CartesianGrid, TakesBoundariesThatIncreaseAcrossTheDomain) {
  const Box domain(Vector3(0, 0, 0), Vector3(2, 1, 1));
  const CartesianGrid grid(domain,
                           {std::vector<double>{0.0, 0.1, 0.3, 2.0}, {0.0, 1.0}, {0.0, 1.0}});
  EXPECT_EQ(grid.dims(), (std::array<int, 3>{3, 1, 1}));
  EXPECT_EQ(grid.owner_of(Vector3(0.05, 0.5, 0.5)), 0);
  EXPECT_EQ(grid.owner_of(Vector3(0.1, 0.5, 0.5)), 1);  // on a boundary: the cell above
  EXPECT_EQ(grid.owner_of(Vector3(1.9, 0.5, 0.5)), 2);
  EXPECT_EQ(grid.owner_of(Vector3(-5.0, 0.5, 0.5)), 0);  // outside: the nearest cell
  EXPECT_DOUBLE_EQ(grid.subdomain(1).min().x(), 0.1);
  EXPECT_DOUBLE_EQ(grid.subdomain(1).max().x(), 0.3);
  for (const std::vector<double>& bad :
       {std::vector<double>{0.0, 0.3, 0.3, 2.0}, std::vector<double>{0.0, 0.5, 0.3, 2.0},
        std::vector<double>{0.1, 0.5, 2.0}, std::vector<double>{0.0, 0.5, 2.5},
        std::vector<double>{0.0}}) {
    EXPECT_THROW(CartesianGrid(domain, {bad, {0.0, 1.0}, {0.0, 1.0}}), InvalidArgument);
  }
}

}  // namespace
}  // namespace grbd::parallel

namespace grbd::parallel {
namespace {

// Recursive coordinate bisection: the leaves tile the domain, and owner_of agrees with them.
TEST(BisectionTree, LeavesTileTheDomainAndOwnEveryPositionOnce) {
  const Box domain(Vector3(-1, 0, 0), Vector3(2, 1, 0.5));
  for (const int p : {1, 2, 3, 5, 7, 12}) {
    const grbd::parallel::BisectionTree tree(domain, p);
    ASSERT_EQ(tree.size(), p);
    double volume = 0.0;
    for (int r = 0; r < p; ++r) volume += tree.subdomain(r).volume();
    EXPECT_NEAR(volume, domain.volume(), 1e-12);
    std::mt19937_64 random(p);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 2000; ++k) {
      const Vector3 x(-1 + 3 * u(random), u(random), 0.5 * u(random));
      const int owner = tree.owner_of(x);
      int holders = 0;
      for (int r = 0; r < p; ++r) {
        const Box& b = tree.subdomain(r);
        holders += (x.array() >= b.min().array()).all() && (x.array() < b.max().array()).all();
      }
      EXPECT_EQ(holders, 1);
      const Box& b = tree.subdomain(owner);
      EXPECT_TRUE((x.array() >= b.min().array()).all() && (x.array() < b.max().array()).all());
      // A position outside the domain belongs to the leaf whose owned region holds it.
      const Vector3 out(x.x() + 5.0, x.y(), x.z() - 3.0);
      const Box region = tree.owned_region(tree.owner_of(out));
      EXPECT_TRUE((out.array() >= region.min().array()).all() &&
                  (out.array() <= region.max().array()).all());
    }
  }
  EXPECT_THROW(grbd::parallel::BisectionTree(domain, 0), grbd::InvalidArgument);
  EXPECT_THROW(grbd::parallel::BisectionTree(Box(Vector3(0, 0, 0), Vector3(1, 0, 1)), 2),
               grbd::InvalidArgument);
}

// Two positions within the reach of each other have owners that are neighbours (or the same),
// also through the periodic boundary; neighbourhood is symmetric.
TEST(BisectionTree, OwnersOfPositionsWithinReachAreNeighbours) {
  const Box domain(Vector3(0, 0, 0), Vector3(1, 1, 1));
  const grbd::parallel::BisectionTree tree(domain, 9, {true, false, false});
  const double reach = 0.05;
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 5000; ++k) {
    const Vector3 x(u(random), u(random), u(random));
    Vector3 step(u(random) - 0.5, u(random) - 0.5, u(random) - 0.5);
    const Vector3 y = x + reach * u(random) * step.normalized();
    const int a = tree.owner_of(x), b = tree.owner_of(y);  // y may cross x = 0 or 1: wrapped
    if (a == b) continue;
    const std::vector<int> n = tree.neighbours(a, reach);
    EXPECT_TRUE(std::binary_search(n.begin(), n.end(), b)) << a << " " << b;
  }
  for (int r = 0; r < tree.size(); ++r) {
    for (const int s : tree.neighbours(r, reach)) {
      const std::vector<int> back = tree.neighbours(s, reach);
      EXPECT_TRUE(std::binary_search(back.begin(), back.end(), r));
    }
  }
}

// Bodies crowded into one corner: the bisection balances the weight to within a few bodies on
// every process, where the tensor grid of per-axis quantiles cannot (its cuts along x and y are
// shared by all rows and columns).
TEST(BisectionTree, BalancesALoadThatIsUnevenInTwoDirections) {
  const Box domain(Vector3(0, 0, 0), Vector3(1, 1, 0.1));
  std::vector<Vector3> centres;
  std::vector<double> weights;
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    // Half the bodies uniform, half crowded into the corner x, y < 0.2.
    const double s = i % 2 == 0 ? 1.0 : 0.2;
    centres.emplace_back(s * u(random), s * u(random), 0.1 * u(random));
    weights.push_back(1.0);
  }
  const int p = 4;
  const auto tree = grbd::parallel::BisectionTree::balanced(
      grbd::self_communicator(), domain, p, {false, false, false}, centres, weights);
  const CartesianGrid grid = grbd::parallel::balanced_grid(
      grbd::self_communicator(), domain, {2, 2, 1}, {false, false, false}, centres, weights);
  std::vector<double> by_tree(p), by_grid(p);
  for (std::size_t i = 0; i < centres.size(); ++i) {
    by_tree[static_cast<std::size_t>(tree.owner_of(centres[i]))] += weights[i];
    by_grid[static_cast<std::size_t>(grid.owner_of(centres[i]))] += weights[i];
  }
  const double mean = 20000.0 / p;
  for (const double w : by_tree) EXPECT_NEAR(w, mean, 3.0);
  EXPECT_GT(*std::max_element(by_grid.begin(), by_grid.end()) / mean, 1.3);
  EXPECT_THROW(grbd::parallel::BisectionTree::balanced(grbd::self_communicator(), domain, p,
                                                       {false, false, false}, centres,
                                                       std::vector<double>(3, 1.0)),
               grbd::InvalidArgument);
}

}  // namespace
}  // namespace grbd::parallel
