// Chapter 7: the generators. Lattice, packing and inflow place bodies without overlaps inside
// their regions, reproducibly from their seeds, and never inside static geometry; the inflow
// keeps its rate; the outlet removes what leaves the domain.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"

namespace {

using grbd::Vector3;
using grbd::scene::parse_scene;
using grbd::scene::Scene;
using grbd::scene::SceneError;
using grbd::scene::Simulation;

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string scene_text(const std::string& group, const std::string& extra = "") {
  return R"([simulation]
dt = 1e-3
end_time = 0.1
gravity = [0, 0, 0]
)" + extra +
         R"(
[[material]]
name = "glass"

[default_contact]
mu = 0.5

[[bodies]]
density = 2500
material = "glass"
)" + group;
}

// Smallest gap |c_i − c_j| − r_i − r_j over all pairs, and whether every body is in `lo`…`hi`.
struct Placement {
  double min_gap = INFINITY;
  bool inside = true;
};

Placement check(const Simulation& sim, const Vector3& lo, const Vector3& hi) {
  Placement out;
  const auto states = sim.system().states();
  const auto radii = sim.system().bounding_radii();
  for (std::size_t i = 0; i < states.size(); ++i) {
    const Vector3 c = states[i].q.head<3>();
    out.inside = out.inside && ((c.array() - radii[i]) >= lo.array() - 1e-12).all() &&
                 ((c.array() + radii[i]) <= hi.array() + 1e-12).all();
    for (std::size_t j = i + 1; j < states.size(); ++j) {
      out.min_gap = std::min(out.min_gap, (c - states[j].q.head<3>()).norm() - radii[i] - radii[j]);
    }
  }
  return out;
}

TEST(Generators, LatticeFillsTheRegionWithoutOverlapsAndJitterStaysInTheGap) {
  const Scene scene =
      parse_scene(scene_text(R"(radius = { distribution = "uniform", min = 0.004, max = 0.005 }
[bodies.generator]
kind = "lattice"
region = { min = [0, 0, 0], max = [0.1, 0.05, 0.032] }
jitter = 1.0
random_orientation = true
)"),
                  "lattice.toml");
  Simulation sim(scene);
  // Spacing 2 r_max = 0.01: 10 × 5 × 3 sites.
  EXPECT_EQ(sim.system().size(), 150U);
  const Placement p = check(sim, Vector3(0, 0, 0), Vector3(0.1, 0.05, 0.032));
  EXPECT_TRUE(p.inside);
  EXPECT_GE(p.min_gap, 0.0);
  for (const auto& x : sim.system().states()) EXPECT_NEAR(x.q.tail<4>().norm(), 1.0, 1e-15);
  // Reproducible: the same scene gives the same bodies, bit for bit.
  Simulation again(scene);
  for (std::size_t i = 0; i < sim.system().size(); ++i) {
    EXPECT_EQ(sim.system().states()[i].q, again.system().states()[i].q);
    EXPECT_EQ(sim.system().inertia()[i].m, again.system().inertia()[i].m);
  }
  // Without jitter the centres are the cell centres of the lattice.
  const Scene exact = parse_scene(scene_text(R"(radius = 0.005
[bodies.generator]
kind = "lattice"
region = { min = [0, 0, 0], max = [0.1, 0.05, 0.032] }
count = 7
)"),
                                  "lattice.toml");
  Simulation plain(exact);
  ASSERT_EQ(plain.system().size(), 7U);
  for (std::size_t k = 0; k < 7; ++k) {
    EXPECT_EQ(plain.system().states()[k].q.head<3>(),
              Vector3((static_cast<double>(k) + 0.5) * 0.01, 0.005, 0.005));
  }
}

// A region that holds a whole number of sites holds them all, though the quotient of extent and
// spacing falls short of it in doubles ((0.18 − 0.1) / 0.004 = 19.999999999999996).
TEST(Generators, ALatticeCountsItsSitesWithATolerance) {
  const Scene scene = parse_scene(scene_text(R"(radius = 0.002
[bodies.generator]
kind = "lattice"
region = { min = [0.1, 0, 0], max = [0.18, 0.004, 0.004] }
spacing = 0.004
)"),
                                  "row.toml");
  volatile double lo = 0.1, hi = 0.18;  // evaluated at run time, as the generator does
  ASSERT_LT((hi - lo) / 0.004, 20.0);
  Simulation sim(scene);
  EXPECT_EQ(sim.system().size(), 20U);
  const Placement p = check(sim, Vector3(0.1, 0, 0), Vector3(0.18, 0.004, 0.004));
  EXPECT_TRUE(p.inside);
  EXPECT_GE(p.min_gap, -1e-15);
}

TEST(Generators, PackingPlacesEveryBodyWithoutOverlapOrRefusesClearly) {
  const Scene scene =
      parse_scene(scene_text(R"(radius = { distribution = "uniform", min = 0.003, max = 0.006 }
[bodies.generator]
kind = "packing"
region = { min = [0, 0, 0], max = [0.1, 0.1, 0.1] }
count = 800
seed = 5
)"),
                  "packing.toml");
  Simulation sim(scene);
  ASSERT_EQ(sim.system().size(), 800U);
  const Placement p = check(sim, Vector3::Zero(), Vector3::Constant(0.1));
  EXPECT_TRUE(p.inside);
  EXPECT_GE(p.min_gap, 0.0);
  // The ids are 0 … 799 and the radii follow the distribution's bounds.
  for (std::size_t i = 0; i < 800; ++i) {
    EXPECT_LT(sim.system().ids()[i], 800U);
    EXPECT_GE(sim.system().bounding_radii()[i], 0.003);
    EXPECT_LE(sim.system().bounding_radii()[i], 0.006);
  }
  // 60 % of the region is beyond random sequential addition: refused before any attempt.
  const Scene dense = parse_scene(scene_text(R"(radius = 0.01
[bodies.generator]
kind = "packing"
region = { min = [0, 0, 0], max = [0.1, 0.1, 0.1] }
count = 150
)"),
                                  "dense.toml");
  try {
    Simulation s(dense);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(
        std::string(e.what()).find("dense.toml: bodies[0] (bodies[0]): generator: 150 bounding "
                                   "spheres fill 0.628"),
        std::string::npos)
        << e.what();
  }
}

TEST(Generators, InflowKeepsItsRateWithoutOverlapsAndStopsAtItsCount) {
  // 2000 bodies/s for 0.05 s: floor(2000 (t + Δt)) bodies by the end of each step, at most 60.
  const Scene scene = parse_scene(scene_text(R"(radius = 0.002
velocity = [0, 0, -1]
[bodies.generator]
kind = "inflow"
region = { min = [0, 0, 0], max = [0.1, 0.1, 0.02] }
rate = 2000
count = 60
random_orientation = true
)"),
                                  "inflow.toml");
  Simulation sim(scene);
  EXPECT_EQ(sim.system().size(), 0U);
  for (int k = 1; k <= 50; ++k) {
    sim.step();
    const auto expected = std::min<std::uint64_t>(
        60, static_cast<std::uint64_t>(std::floor(2000.0 * k * 1e-3 + 1e-6)));
    ASSERT_EQ(sim.bodies_created(), expected) << "step " << k;
    EXPECT_EQ(sim.inflow_backlog(), 0U);
  }
  EXPECT_EQ(sim.system().size(), 60U);
  // They fall at 1 m/s without gravity: created without overlaps, they never touch.
  const Placement p = check(sim, Vector3(-1, -1, -1), Vector3(1, 1, 1));
  EXPECT_GE(p.min_gap, 0.0);
}

TEST(Generators, AFullInflowRegionOwesItsBodiesAndDeliversThemLater) {
  // A region that holds one body of radius 0.01 at a time; they leave at 1 m/s.
  const Scene scene = parse_scene(scene_text(R"(radius = 0.01
velocity = [0, 0, -1]
[bodies.generator]
kind = "inflow"
region = { min = [0, 0, 0], max = [0.02, 0.02, 0.021] }
rate = 1000
)"),
                                  "full.toml");
  Simulation sim(scene);
  sim.step();
  EXPECT_EQ(sim.bodies_created(), 1U);
  sim.step();
  EXPECT_EQ(sim.bodies_created(), 1U);  // the first still fills the region
  EXPECT_EQ(sim.inflow_backlog(), 1U);
  for (int k = 0; k < 40; ++k) sim.step();
  EXPECT_GT(sim.bodies_created(), 1U);
  const Placement p = check(sim, Vector3(-1, -1, -1), Vector3(1, 1, 1));
  EXPECT_GE(p.min_gap, 0.0);
}

// What a generator refuses to start with: a body inside static geometry or inside another body.
std::string refusal(const std::string& text, const std::string& file) {
  try {
    const Scene scene = parse_scene(text, file);
    Simulation sim(scene);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

// A table top: the box 0 ≤ x, y ≤ 0.1, 0.02 ≤ z ≤ 0.04.
const std::string kTable = R"(
[[static]]
name = "table"
shape = "box"
half_extents = [0.05, 0.05, 0.01]
position = [0.05, 0.05, 0.03]
material = "glass"
)";

// The gap between a sphere (c, r) and the table, by the closest point of the box (clamping).
double table_gap(const Vector3& c, double r) {
  const Vector3 lo(0.0, 0.0, 0.02), hi(0.1, 0.1, 0.04);
  const Vector3 closest = c.cwiseMax(lo).cwiseMin(hi);
  return (c - closest).norm() - r;  // > 0 only outside; a centre inside gives −r or less
}

TEST(Generators, LatticesAndListsNeverStartInsideStaticGeometryOrOtherBodies) {
  // Lattice sites 0.01 apart from z = 0.005: the layer z = 0.015 touches the table's underside
  // (allowed), the layer z = 0.025 has its centres inside the table, 0.005 from its faces x = 0
  // and z = 0.02: pushed out by 0.005 + r = 0.01.
  const std::string lattice = R"(radius = 0.005
[bodies.generator]
kind = "lattice"
region = { min = [0, 0, 0], max = [0.1, 0.1, 0.1] }
)";
  EXPECT_NE(refusal(scene_text(lattice, kTable), "table.toml")
                .find("table.toml: bodies[0] (bodies[0]): generator: the body at (0.005, 0.005, "
                      "0.025) m overlaps static[0] (table) by 0.01 m"),
            std::string::npos)
      << refusal(scene_text(lattice, kTable), "table.toml");
  // Two layers below the table are fine: they touch it.
  const std::string below = replace_all(lattice, "max = [0.1, 0.1, 0.1]", "max = [0.1, 0.1, 0.02]");
  EXPECT_EQ(refusal(scene_text(below, kTable), "below.toml"), "no error");
  // A second lattice (spacing 0.008) in the same region as the first: its first body, at
  // (0.004, 0.004, 0.004), overlaps the first one's.
  const std::string twice = below + R"(
[[bodies]]
name = "again"
density = 2500
material = "glass"
radius = 0.004
[bodies.generator]
kind = "lattice"
region = { min = [0, 0, 0], max = [0.1, 0.1, 0.02] }
)";
  EXPECT_NE(refusal(scene_text(twice), "twice.toml")
                .find("twice.toml: bodies[1] (again): generator: the body at (0.004, 0.004, "
                      "0.004) m overlaps the body with id 0, made before it"),
            std::string::npos)
      << refusal(scene_text(twice), "twice.toml");
  // A list whose second position is 0.009 from its first, with radii 0.005.
  const std::string list = R"(radius = 0.005
positions = [[0.5, 0.5, 0.5], [0.509, 0.5, 0.5]]
)";
  EXPECT_NE(refusal(scene_text(list), "list.toml")
                .find("list.toml: bodies[0] (bodies[0]): generator: the body at (0.509, 0.5, 0.5) "
                      "m overlaps the body with id 0"),
            std::string::npos)
      << refusal(scene_text(list), "list.toml");
}

TEST(Generators, PackingAndInflowPlaceNothingInsideStaticGeometry) {
  // Random packing in a region the table cuts through: every sphere clear of the box.
  const Scene packing = parse_scene(scene_text(R"(radius = 0.004
[bodies.generator]
kind = "packing"
region = { min = [0, 0, 0], max = [0.1, 0.1, 0.1] }
count = 300
seed = 11
)",
                                               kTable),
                                    "packing.toml");
  Simulation sim(packing);
  ASSERT_EQ(sim.system().size(), 300U);
  double gap = INFINITY;
  for (const auto& x : sim.system().states()) gap = std::min(gap, table_gap(x.q.head<3>(), 0.004));
  EXPECT_GE(gap, 0.0);
  // An inflow whose region reaches 0.01 below a floor at z = 0.01: every body above the floor.
  const Scene inflow = parse_scene(scene_text(R"(radius = 0.002
[bodies.generator]
kind = "inflow"
region = { min = [0, 0, 0], max = [0.1, 0.1, 0.02] }
rate = 2000
count = 60
)",
                                              R"(
[[static]]
name = "floor"
shape = "half_space"
normal = [0, 0, 1]
point = [0, 0, 0.01]
material = "glass"
)"),
                                   "inflow.toml");
  Simulation flow(inflow);
  for (int k = 0; k < 30; ++k) flow.step();
  ASSERT_EQ(flow.system().size(), 60U);
  for (const auto& x : flow.system().states()) EXPECT_GE(x.q[2] - 0.01, 0.002 - 1e-12);
}

TEST(Generators, TheOutletRemovesWhatLeavesTheDomain) {
  const Scene scene =
      parse_scene(scene_text(R"(radius = 0.001
[bodies.generator]
kind = "lattice"
region = { min = [0, 0, 0], max = [0.01, 0.01, 0.01] }
)",
                             "domain = { min = [-1, -1, -0.0021], max = [1, 1, 1] }\n"),
                  "outlet.toml");
  grbd::scene::Scene falling = scene;
  falling.settings.I_g = Vector3(0, 0, -9.81);
  Simulation sim(falling);
  EXPECT_EQ(sim.system().size(), 125U);
  // z_k = 0.001 + 0.002 k falls below −0.0021 when ½ g t² > 0.0031 + 0.002 k.
  for (int step = 1; step <= 40; ++step) sim.step();
  const double t = 0.04;
  const double drop = 0.5 * 9.81 * t * t;  // the midpoint scheme is exact for constant g
  std::size_t left = 0;
  for (int k = 0; k < 5; ++k) left += (0.001 + 0.002 * k - drop < -0.0021) ? 25 : 0;
  EXPECT_EQ(sim.bodies_removed(), left);
  EXPECT_EQ(sim.system().size(), 125U - left);
  EXPECT_GT(left, 0U);
  // Every body has the same mass (4/3) π r³ ρ: the outlet's mass is that times the count.
  const double m = sim.system().inertia()[0].m;
  EXPECT_NEAR(sim.mass_removed(), static_cast<double>(left) * m, 1e-12 * m * 125.0);
}

TEST(Generators, MassOrDensityGiveTheBodysInertia) {
  const Scene by_mass =
      parse_scene(replace_all(scene_text("radius = 0.01\npositions = [[0, 0, 0]]\n"),
                              "density = 2500", "mass = 0.2"),
                  "mass.toml");
  Simulation sim(by_mass);
  EXPECT_DOUBLE_EQ(sim.system().inertia()[0].m, 0.2);
  // Θ = (2/5) m r².
  EXPECT_NEAR(sim.system().inertia()[0].K_Theta.x(), 0.4 * 0.2 * 1e-4, 1e-18);
}

}  // namespace
