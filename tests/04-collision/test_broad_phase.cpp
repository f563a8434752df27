// Chapter 4: the broad phase — the Morton code of a grid cell (Exercise 4.6), the Morton order
// of a point set, and the cell grid, checked pair for pair against the brute-force test of all
// N(N − 1)/2 pairs.
//
// Independent references: a bit-by-bit interleaving written out in the test; hand-computed codes;
// brute_force_pairs (a double loop over all pairs) on seeded random sets of many kinds.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "grbd/collision/broad_phase.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/random.hpp"

namespace {

using grbd::Vector3;
using grbd::collision::brute_force_pairs;
using grbd::collision::CellGrid;
using grbd::collision::IndexPair;
using grbd::collision::morton_code;
using grbd::collision::morton_order;
using grbd::test::Random;

/// Bit b of i, j, k to bit 3b, 3b + 1, 3b + 2, one bit at a time.
std::uint64_t reference_morton(std::uint32_t i, std::uint32_t j, std::uint32_t k) {
  std::uint64_t code = 0;
  for (int b = 0; b < 21; ++b) {
    code |= std::uint64_t{(i >> b) & 1u} << (3 * b);
    code |= std::uint64_t{(j >> b) & 1u} << (3 * b + 1);
    code |= std::uint64_t{(k >> b) & 1u} << (3 * b + 2);
  }
  return code;
}

struct Spheres {
  std::vector<Vector3> centres;
  std::vector<double> radii;
};

/// Checks that the grid finds exactly the brute-force pairs, each once with i < j.
void expect_same_pairs_as_brute_force(const Spheres& s, double margin) {
  CellGrid grid;
  grid.build(s.centres, s.radii, margin);
  std::vector<IndexPair> pairs;
  grid.find_pairs(pairs);
  for (const auto& [i, j] : pairs) {
    ASSERT_LT(i, j);
    ASSERT_GE(i, 0);
    ASSERT_LT(j, static_cast<std::int32_t>(s.centres.size()));
  }
  std::vector<IndexPair> sorted = pairs;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "duplicate pair";
  const std::vector<IndexPair> reference = brute_force_pairs(s.centres, s.radii, margin);
  EXPECT_TRUE(std::is_sorted(reference.begin(), reference.end()));
  EXPECT_EQ(sorted, reference) << "N = " << s.centres.size() << ", margin = " << margin;
}

Spheres uniform_spheres(Random& random, int n, double box, double r_lo, double r_hi) {
  Spheres s;
  for (int i = 0; i < n; ++i) {
    s.centres.push_back(random.vector3(0.0, box));
    s.radii.push_back(random.uniform(r_lo, r_hi));
  }
  return s;
}

// ---- Exercise 4.6: morton_code ------------------------------------------------------------

TEST(Exercise4_6, KnownValues) {
  EXPECT_EQ(morton_code(0, 0, 0), 0u);
  EXPECT_EQ(morton_code(1, 0, 0), 1u);
  EXPECT_EQ(morton_code(0, 1, 0), 2u);
  EXPECT_EQ(morton_code(0, 0, 1), 4u);
  EXPECT_EQ(morton_code(1, 1, 1), 7u);
  EXPECT_EQ(morton_code(2, 0, 0), 8u);
  EXPECT_EQ(morton_code(3, 5, 6), 0b110'101'011u);  // bits (k j i) per level: 110, 101, 011
  constexpr std::uint32_t kMax = (std::uint32_t{1} << 21) - 1;
  EXPECT_EQ(morton_code(kMax, 0, 0), 0x1249249249249249ULL);
  EXPECT_EQ(morton_code(0, kMax, 0), 0x1249249249249249ULL << 1);
  EXPECT_EQ(morton_code(0, 0, kMax), 0x1249249249249249ULL << 2);
  EXPECT_EQ(morton_code(kMax, kMax, kMax), 0x7fffffffffffffffULL);
}

TEST(Exercise4_6, MatchesBitByBitInterleaving) {
  Random random(460);
  std::uniform_int_distribution<std::uint32_t> coordinate(0, (1u << 21) - 1);
  for (int n = 0; n < 2000; ++n) {
    const std::uint32_t i = coordinate(random.engine());
    const std::uint32_t j = coordinate(random.engine());
    const std::uint32_t k = coordinate(random.engine());
    ASSERT_EQ(morton_code(i, j, k), reference_morton(i, j, k)) << i << ", " << j << ", " << k;
  }
  for (int b = 0; b < 21; ++b) {  // every single bit of every coordinate
    const std::uint32_t v = 1u << b;
    EXPECT_EQ(morton_code(v, 0, 0), std::uint64_t{1} << (3 * b));
    EXPECT_EQ(morton_code(0, v, 0), std::uint64_t{1} << (3 * b + 1));
    EXPECT_EQ(morton_code(0, 0, v), std::uint64_t{1} << (3 * b + 2));
  }
}

TEST(Exercise4_6, VisitsTheCellsOfABlockInZOrder) {
  // The Z-order walk of an 8 × 8 × 8 block visits every cell once, each code one more than the
  // last, and each octant of 4 × 4 × 4 cells before the next.
  constexpr std::uint32_t kSide = 8;
  std::vector<int> visits(kSide * kSide * kSide, 0);
  for (std::uint32_t k = 0; k < kSide; ++k) {
    for (std::uint32_t j = 0; j < kSide; ++j) {
      for (std::uint32_t i = 0; i < kSide; ++i) {
        const std::uint64_t code = morton_code(i, j, k);
        ASSERT_LT(code, visits.size());
        ++visits[code];
        const std::uint64_t octant = code / 64;
        EXPECT_EQ(octant, (i / 4) + 2 * (j / 4) + 4 * (k / 4));
      }
    }
  }
  EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](int v) { return v == 1; }));
  // Monotone along each axis: moving to a larger coordinate never decreases the code.
  Random random(461);
  std::uniform_int_distribution<std::uint32_t> coordinate(0, (1u << 21) - 2);
  for (int n = 0; n < 1000; ++n) {
    const std::uint32_t i = coordinate(random.engine());
    const std::uint32_t j = coordinate(random.engine());
    const std::uint32_t k = coordinate(random.engine());
    EXPECT_LT(morton_code(i, j, k), morton_code(i + 1, j, k));
    EXPECT_LT(morton_code(i, j, k), morton_code(i, j + 1, k));
    EXPECT_LT(morton_code(i, j, k), morton_code(i, j, k + 1));
  }
}

TEST(Exercise4_6, RefusesCoordinatesOutOfRange) {
  constexpr std::uint32_t kLimit = std::uint32_t{1} << 21;
  EXPECT_NO_THROW(morton_code(kLimit - 1, kLimit - 1, kLimit - 1));
  EXPECT_THROW(morton_code(kLimit, 0, 0), grbd::InvalidArgument);
  EXPECT_THROW(morton_code(0, kLimit, 0), grbd::InvalidArgument);
  EXPECT_THROW(morton_code(0, 0, 0xffffffffu), grbd::InvalidArgument);
}

// ---- morton_order ---------------------------------------------------------------------------

TEST(MortonOrder, IsAPermutationSortedByCode) {
  Random random(462);
  std::vector<Vector3> centres;
  for (int n = 0; n < 3000; ++n) centres.push_back(random.vector3(-5.0, 7.0));
  const double h = 0.37;
  const std::vector<std::int32_t> order = morton_order(centres, h);
  ASSERT_EQ(order.size(), centres.size());
  std::vector<std::int32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::int32_t> identity(centres.size());
  std::iota(identity.begin(), identity.end(), 0);
  EXPECT_EQ(sorted, identity);

  Vector3 lo = centres.front();
  for (const Vector3& c : centres) lo = lo.cwiseMin(c);
  const auto code = [&](std::int32_t n) {
    const Vector3 t = (centres[n] - lo) / h;
    return morton_code(static_cast<std::uint32_t>(std::floor(t.x())),
                       static_cast<std::uint32_t>(std::floor(t.y())),
                       static_cast<std::uint32_t>(std::floor(t.z())));
  };
  for (std::size_t m = 1; m < order.size(); ++m) {
    const std::uint64_t a = code(order[m - 1]), b = code(order[m]);
    ASSERT_LE(a, b);
    if (a == b) {
      ASSERT_LT(order[m - 1], order[m]);  // ties broken by index
    }
  }
}

TEST(MortonOrder, EmptyAndDegenerateSets) {
  EXPECT_TRUE(morton_order({}, 1.0).empty());
  const std::vector<Vector3> same(5, Vector3(1.0, 2.0, 3.0));
  EXPECT_EQ(morton_order(same, 1.0), (std::vector<std::int32_t>{0, 1, 2, 3, 4}));
  // A box far wider than 2²¹ cells: the cells grow, the order stays along the line.
  const std::vector<Vector3> line{{3e9, 0, 0}, {-3e9, 0, 0}, {0, 0, 0}};
  EXPECT_EQ(morton_order(line, 1e-3), (std::vector<std::int32_t>{1, 2, 0}));
}

TEST(MortonOrder, RefusesInvalidInput) {
  const std::vector<Vector3> centres{{0, 0, 0}, {1, 1, 1}};
  EXPECT_THROW(morton_order(centres, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(morton_order(centres, -1.0), grbd::InvalidArgument);
  EXPECT_THROW(morton_order(centres, std::numeric_limits<double>::infinity()),
               grbd::InvalidArgument);
  const std::vector<Vector3> bad{{0, 0, 0}, {std::nan(""), 0, 0}};
  EXPECT_THROW(morton_order(bad, 1.0), grbd::InvalidArgument);
}

// ---- CellGrid against brute force ---------------------------------------------------------

TEST(CellGrid, UniformRandomSetsMatchBruteForce) {
  Random random(463);
  for (const int n : {3, 10, 100, 1000}) {
    for (const double margin : {0.0, 0.05, 0.3}) {
      const double box = 2.0 * std::cbrt(static_cast<double>(n));  // several neighbours each
      expect_same_pairs_as_brute_force(uniform_spheres(random, n, box, 0.4, 0.6), margin);
    }
  }
}

TEST(CellGrid, PolydisperseRadiiMatchBruteForce) {
  Random random(464);
  for (const double margin : {0.0, 0.1}) {
    expect_same_pairs_as_brute_force(uniform_spheres(random, 1500, 16.0, 0.2, 0.6), margin);
    // Mostly small spheres and a few large ones: the cells are sized by the largest.
    Spheres s = uniform_spheres(random, 1500, 16.0, 0.1, 0.15);
    for (int n = 0; n < 20; ++n) s.radii[7 * n] = 1.2;
    expect_same_pairs_as_brute_force(s, margin);
  }
}

TEST(CellGrid, ClusteredSetsMatchBruteForce) {
  Random random(465);
  Spheres s;
  std::normal_distribution<double> normal(0.0, 0.7);
  for (int cluster = 0; cluster < 8; ++cluster) {
    const Vector3 centre = random.vector3(-50.0, 50.0);
    for (int n = 0; n < 150; ++n) {
      s.centres.push_back(centre + Vector3(normal(random.engine()), normal(random.engine()),
                                           normal(random.engine())));
      s.radii.push_back(random.uniform(0.1, 0.3));
    }
  }
  for (const double margin : {0.0, 0.02}) expect_same_pairs_as_brute_force(s, margin);
}

TEST(CellGrid, AllSpheresInOneCell) {
  Random random(466);
  Spheres s = uniform_spheres(random, 300, 0.5, 0.5, 1.0);
  CellGrid grid;
  grid.build(s.centres, s.radii, 0.0);
  EXPECT_EQ(grid.cells(), Eigen::Vector3i(1, 1, 1));
  expect_same_pairs_as_brute_force(s, 0.0);
  std::vector<IndexPair> pairs;
  grid.find_pairs(pairs);
  EXPECT_EQ(pairs.size(), 300u * 299u / 2u);  // all overlap
  // All at the very same point.
  const Spheres same{std::vector<Vector3>(50, Vector3(1.0, -2.0, 3.0)),
                     std::vector<double>(50, 0.1)};
  expect_same_pairs_as_brute_force(same, 0.0);
}

TEST(CellGrid, CollinearAndPlanarSetsMatchBruteForce) {
  Random random(467);
  Spheres line, plane, diagonal;
  for (int n = 0; n < 800; ++n) {
    line.centres.emplace_back(random.uniform(0.0, 300.0), 2.0, -1.0);
    line.radii.push_back(random.uniform(0.2, 0.5));
    plane.centres.emplace_back(random.uniform(0.0, 30.0), 4.0, random.uniform(0.0, 30.0));
    plane.radii.push_back(random.uniform(0.2, 0.5));
    const double t = random.uniform(0.0, 200.0);
    diagonal.centres.emplace_back(t, t, t);
    diagonal.radii.push_back(random.uniform(0.2, 0.5));
  }
  for (const double margin : {0.0, 0.1}) {
    expect_same_pairs_as_brute_force(line, margin);
    expect_same_pairs_as_brute_force(plane, margin);
    expect_same_pairs_as_brute_force(diagonal, margin);
  }
}

TEST(CellGrid, SparseSetsKeepTheGridSmall) {
  // Tiny spheres spread over a huge box: the cells grow so that their number stays O(N).
  Random random(468);
  const Spheres s = uniform_spheres(random, 500, 1e6, 1e-3, 2e-3);
  CellGrid grid;
  grid.build(s.centres, s.radii, 0.0);
  const Eigen::Vector3i d = grid.cells();
  EXPECT_LE(static_cast<double>(d.x()) * d.y() * d.z(), 2.0 * 500 + 64);
  EXPECT_GE(grid.cell_size(), 4e-3);
  expect_same_pairs_as_brute_force(s, 0.0);
  // Two clusters far apart: most of the box is empty.
  Spheres two = uniform_spheres(random, 400, 5.0, 0.3, 0.5);
  for (int n = 0; n < 200; ++n) two.centres[n] += Vector3(1e5, -1e5, 3e4);
  expect_same_pairs_as_brute_force(two, 0.05);
}

TEST(CellGrid, SmallSets) {
  expect_same_pairs_as_brute_force({}, 0.0);
  expect_same_pairs_as_brute_force({{Vector3(1, 2, 3)}, {0.5}}, 0.0);
  expect_same_pairs_as_brute_force({{Vector3(0, 0, 0), Vector3(0.9, 0, 0)}, {0.5, 0.5}}, 0.0);
  expect_same_pairs_as_brute_force({{Vector3(0, 0, 0), Vector3(1.1, 0, 0)}, {0.5, 0.5}}, 0.0);
  expect_same_pairs_as_brute_force({{Vector3(0, 0, 0), Vector3(1.1, 0, 0)}, {0.5, 0.5}}, 0.2);
  CellGrid grid;
  std::vector<IndexPair> pairs{{3, 4}};
  grid.build({}, {}, 0.0);
  grid.find_pairs(pairs);
  EXPECT_TRUE(pairs.empty());
  grid.build(std::vector<Vector3>{{0, 0, 0}, {0.5, 0, 0}}, std::vector<double>{0.3, 0.3}, 0.0);
  grid.find_pairs(pairs);
  EXPECT_EQ(pairs, (std::vector<IndexPair>{{0, 1}}));
}

TEST(CellGrid, ExactlyTouchingSpheresAreNotAPair) {
  // Centres 2 apart on a line, radius 1: |c_i − c_j| = r_i + r_j exactly (all numbers exact),
  // so the strict test excludes every pair; any margin > 0 includes the neighbours.
  Spheres chain;
  for (int n = 0; n < 20; ++n) {
    chain.centres.emplace_back(2.0 * n, 0.0, 0.0);
    chain.radii.push_back(1.0);
  }
  CellGrid grid;
  std::vector<IndexPair> pairs;
  grid.build(chain.centres, chain.radii, 0.0);
  grid.find_pairs(pairs);
  EXPECT_TRUE(pairs.empty());
  expect_same_pairs_as_brute_force(chain, 0.0);
  grid.build(chain.centres, chain.radii, 0.25);
  grid.find_pairs(pairs);
  EXPECT_EQ(pairs.size(), 19u);
  expect_same_pairs_as_brute_force(chain, 0.25);
  // Margin that closes the gap exactly: centres 3 apart, radii 1, margin 1.
  Spheres gap{{Vector3(0, 0, 0), Vector3(0, 3, 0), Vector3(0, 3, 3)}, {1.0, 1.0, 1.0}};
  EXPECT_TRUE(brute_force_pairs(gap.centres, gap.radii, 1.0).empty());
  expect_same_pairs_as_brute_force(gap, 1.0);
  // A simple cubic lattice at the touching distance, with and without a margin: the boundary
  // distance occurs along every axis and across cells.
  Spheres lattice;
  for (int k = 0; k < 6; ++k) {
    for (int j = 0; j < 6; ++j) {
      for (int i = 0; i < 6; ++i) {
        lattice.centres.emplace_back(0.5 * i, 0.5 * j, 0.5 * k);
        lattice.radii.push_back(0.25);
      }
    }
  }
  expect_same_pairs_as_brute_force(lattice, 0.0);
  expect_same_pairs_as_brute_force(lattice, 0.125);  // adds the neighbours along the axes only
  EXPECT_EQ(brute_force_pairs(lattice.centres, lattice.radii, 0.125).size(), 3u * 6 * 6 * 5);
}

TEST(CellGrid, ReusedGridGivesTheSameAnswer) {
  Random random(469);
  CellGrid grid;
  std::vector<IndexPair> pairs;
  for (const int n : {500, 20, 800}) {
    const Spheres s = uniform_spheres(random, n, 10.0, 0.3, 0.6);
    grid.build(s.centres, s.radii, 0.01);
    grid.find_pairs(pairs);
    std::sort(pairs.begin(), pairs.end());
    EXPECT_EQ(pairs, brute_force_pairs(s.centres, s.radii, 0.01));
  }
}

TEST(CellGrid, RefusesInvalidInput) {
  const std::vector<Vector3> centres{{0, 0, 0}, {1, 0, 0}};
  const std::vector<double> radii{0.5, 0.5};
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CellGrid grid;
  EXPECT_THROW(grid.build(centres, std::vector<double>{0.5}, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(grid.build(centres, std::vector<double>{0.5, 0.0}, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(grid.build(centres, std::vector<double>{-0.5, 0.5}, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(grid.build(centres, std::vector<double>{0.5, nan}, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(grid.build(centres, std::vector<double>{inf, 0.5}, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(grid.build(centres, radii, -0.1), grbd::InvalidArgument);
  EXPECT_THROW(grid.build(centres, radii, nan), grbd::InvalidArgument);
  EXPECT_THROW(grid.build(centres, radii, inf), grbd::InvalidArgument);
  const std::vector<Vector3> bad{{0, 0, 0}, {inf, 0, 0}};
  EXPECT_THROW(grid.build(bad, radii, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(brute_force_pairs(bad, radii, 0.0), grbd::InvalidArgument);
  EXPECT_THROW(brute_force_pairs(centres, radii, -1.0), grbd::InvalidArgument);
  EXPECT_THROW(brute_force_pairs(centres, std::vector<double>{1.0}, 0.0), grbd::InvalidArgument);
}

}  // namespace

namespace {

// Regression (issue 11): finite centres at ±1e308 made the extent of the grid infinite; the cell
// size became ∞, (x − origin)/h NaN, and its conversion to int undefined (then std::length_error).
// Reference: a grid over the centres exists only when their differences are finite; both the
// grid and the Morton order refuse the set with grbd::InvalidArgument naming the axis.
TEST(CellGrid, RefusesCentresWhoseExtentOverflows) {
  const std::vector<Vector3> centres{{-1e308, 0, 0}, {1e308, 0, 0}, {0, 0, 0}};
  const std::vector<double> radii{0.5, 0.5, 0.5};
  CellGrid grid;
  for (const auto& call : {std::function<void()>([&] { grid.build(centres, radii, 0.0); }),
                           std::function<void()>([&] { morton_order(centres, 1.0); })}) {
    try {
      call();
      ADD_FAILURE() << "centres at ±1e308 were accepted";
    } catch (const grbd::InvalidArgument& error) {
      EXPECT_NE(std::string(error.what()).find("axis 0"), std::string::npos) << error.what();
      EXPECT_NE(std::string(error.what()).find("largest double"), std::string::npos)
          << error.what();
    }
  }
}

// The largest finite extent still works (no overflow in the cell coordinates): two touching
// spheres at x ≈ 1.7e308 and one at the origin, compared with brute force.
TEST(CellGrid, LargestFiniteExtentMatchesBruteForce) {
  const double far = 1.7e308;
  const std::vector<Vector3> centres{{0, 0, 0}, {far, 0, 0}, {far, 0.5, 0}, {far, 0, -1e300}};
  const std::vector<double> radii{1.0, 1.0, 1.0, 1.0};
  CellGrid grid;
  grid.build(centres, radii, 0.0);
  std::vector<IndexPair> pairs;
  grid.find_pairs(pairs);
  std::sort(pairs.begin(), pairs.end());
  std::vector<IndexPair> reference = brute_force_pairs(centres, radii, 0.0);
  std::sort(reference.begin(), reference.end());
  EXPECT_EQ(pairs, reference);
  EXPECT_EQ(reference.size(), 1U);
  const std::vector<std::int32_t> order = morton_order(centres, 1.0);
  EXPECT_EQ(std::set<std::int32_t>(order.begin(), order.end()).size(), centres.size());
}

}  // namespace
