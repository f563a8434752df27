// Chapter 7: the chapter's experiments at reduced size, from the scene files of its folder. The
// silo of silo.toml with a third of its beads: the walls and the floor carry the weight of the
// fill, the walls carry a part of it by friction, and never more than Coulomb's μ_w allows. The
// discharge of beverloo.toml over 0.3 s: the steady mass flow rate is Beverloo's
// (Beverloo, Leniger and van de Velde 1961, C = 0.58, k = 1.5) within 20 %. The heap of
// repose.toml on a table half as long: it comes to rest, the table carries its weight, and its
// angle grows with the friction between the beads (Zhou et al. 2001).

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "grbd/scene/measure.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"

namespace {

using grbd::Vector3;

const std::string kScenes = GRBD_CH07_SCENE_DIR;

TEST(Experiments, JanssensSiloCarriesItsWeightOnWallsAndFloor) {
  grbd::scene::Scene scene = grbd::scene::load_scene(kScenes + "/silo.toml");
  scene.groups.at(0).generator.count = 600;
  scene.groups.at(0).generator.region.max.z() = 0.085;
  scene.end_time = 0.4;
  grbd::scene::Simulation sim(scene);
  while (!sim.finished()) sim.step();

  const double g = 9.81;
  double weight = 0.0;
  for (std::size_t i = 0; i < sim.system().size(); ++i) weight += sim.system().inertia()[i].m * g;
  const auto& problem = sim.stepper().problem();
  const auto Lambda = sim.stepper().percussions();
  const double dt = scene.settings.dt;
  double mu_w = 0.0;
  for (const auto& c : scene.contacts) {
    if (c.a != c.b) mu_w = c.law.mu;
  }
  double floor = 0.0, walls = 0.0, wall_normal = 0.0;
  for (std::size_t c = 0; c < problem.contacts.size(); ++c) {
    const auto& contact = problem.contacts[c];
    if (contact.body_b != grbd::collision::kStatic) continue;
    const Vector3 F = grbd::scene::contact_force(contact, Lambda[c], dt);
    if (std::abs(contact.n.z()) > 0.5) {
      floor += F.z();
    } else {
      walls += F.z();
      wall_normal += Lambda[c][0] / dt;
      // Coulomb at every wall contact: |F_T| ≤ μ_w F_N.
      EXPECT_LE(std::hypot(Lambda[c][1], Lambda[c][2]), mu_w * Lambda[c][0] * (1.0 + 1e-9) + 1e-15);
    }
  }
  // At rest the static geometry carries the weight (to the solver's tolerance).
  EXPECT_NEAR((floor + walls) / weight, 1.0, 0.01);
  // The walls carry a part by friction, at most μ_w of their normal force.
  EXPECT_GT(walls / weight, 0.05);
  EXPECT_LT(floor / weight, 0.95);
  EXPECT_LE(walls / wall_normal, mu_w * (1.0 + 1e-9));
  EXPECT_GT(walls / wall_normal, 0.0);
}

TEST(Experiments, BeverlooDischargeFlowsAtBeverloosRate) {
  // The measurement (Exercise 7.4) first: a student build without it stops here, not after the
  // 20 s of the run.
  ASSERT_EQ(grbd::scene::steady_rate(std::vector<double>{0, 1, 2, 3},
                                     std::vector<double>{0, 2, 4, 6}, 0.0, 2)
                .rate,
            2.0);
  grbd::scene::Scene scene = grbd::scene::load_scene(kScenes + "/beverloo.toml");
  scene.end_time = 0.3;
  const double D = 0.026;  // the scene's orifice
  grbd::scene::Simulation sim(scene);
  std::vector<double> t, m;
  double rho_b = 0.0;
  int samples = 0;
  const grbd::scene::Slices slab{0.035, 0.025, 1, 0.064 * 0.064};
  while (!sim.finished()) {
    sim.step();
    sim.created().clear();
    t.push_back(sim.stepper().time());
    m.push_back(sim.mass_removed());
    if (t.back() >= 0.15 && sim.stepper().steps() % 10 == 0) {
      rho_b += grbd::scene::slice_masses(sim, slab)[0] / (slab.area * slab.h);
      ++samples;
    }
  }
  rho_b /= samples;
  EXPECT_GT(rho_b, 1300.0);  // a packing fraction above 0.52
  EXPECT_LT(rho_b, 1600.0);  // and below 0.64
  const grbd::scene::Rate W = grbd::scene::steady_rate(t, m, 0.15);
  const double beverloo = grbd::scene::beverloo_rate(0.58, 1.5, rho_b, 9.81, D, 0.004);
  EXPECT_NEAR(W.rate / beverloo, 1.0, 0.2)
      << "W = " << W.rate << " ± " << W.error << " kg/s, Beverloo " << beverloo << " kg/s";
  EXPECT_LT(W.error, 0.1 * W.rate);
}

struct Heap {
  double rest = -1.0;      // when every bead was at rest [s]
  double angle = 0.0;      // of its flanks [degrees]
  double weight = 0.0;     // of the beads on the table [N]
  double supported = 0.0;  // the vertical force of the fixed beads and the table on them [N]
};

Heap pour_heap(double mu) {
  grbd::scene::Scene scene = grbd::scene::load_scene(kScenes + "/repose.toml");
  const double L = 0.04;  // half the chapter's table
  for (auto& s : scene.statics) {
    if (s.name == "table") std::get<grbd::collision::Box>(s.shape).half_extents.x() = L;
  }
  scene.groups.at(0).generator.region.min.x() = -L;
  scene.groups.at(0).generator.region.max.x() = L;
  scene.groups.at(1).generator.stop = 0.5;  // 400 beads
  scene.end_time = 3.0;
  for (auto& c : scene.contacts) {
    if (c.a == "glass" && c.b == "glass") c.law.mu = mu;
  }
  grbd::scene::Simulation sim(scene);
  Heap heap;
  while (!sim.finished()) {
    const auto report = sim.step();
    sim.created().clear();
    if (report.t > 0.5 && report.step % 25 == 0 && grbd::scene::at_rest(sim.system(), 1e-3)) {
      heap.rest = report.t;
      break;
    }
  }
  const double d = 0.004;
  heap.angle = grbd::scene::fit_flanks(grbd::scene::heap_surface(sim.system(), L, d), 3.0 * d,
                                       L - 2.0 * d)
                   .angle;
  const auto& problem = sim.stepper().problem();
  const auto Lambda = sim.stepper().percussions();
  for (std::size_t c = 0; c < problem.contacts.size(); ++c) {
    // The fixed beads and the table are a static side of their contacts; the force on side a is
    // F, on side b −F.
    const auto& contact = problem.contacts[c];
    const double F_z = grbd::scene::contact_force(contact, Lambda[c], scene.settings.dt).z();
    if (contact.body_b == grbd::collision::kStatic) heap.supported += F_z;
    if (contact.body_a == grbd::collision::kStatic) heap.supported -= F_z;
  }
  for (std::size_t i = 0; i < sim.system().size(); ++i) {
    if (sim.system().dynamic(i)) heap.weight += sim.system().inertia()[i].m * 9.81;
  }
  return heap;
}

TEST(Experiments, AHeapComesToRestAtAnAngleThatGrowsWithFriction) {
  const Heap smooth = pour_heap(0.0);
  const Heap rough = pour_heap(0.5);
  std::cout << "heap: mu = 0: " << smooth.angle << " degrees, at rest at " << smooth.rest
            << " s, supported/weight " << smooth.supported / smooth.weight << "; mu = 0.5: "
            << rough.angle << " degrees, at rest at " << rough.rest << " s, supported/weight "
            << rough.supported / rough.weight << '\n';
  for (const Heap& heap : {smooth, rough}) {
    EXPECT_GT(heap.rest, 0.5) << "still moving after 3 s";
    // At rest, the table and its beads carry the heap's weight (the solver's tolerance).
    EXPECT_NEAR(heap.supported / heap.weight, 1.0, 1e-3);
  }
  // Frictionless beads still stand on the rough base; friction steepens the heap by several
  // degrees (the chapter's demo: 11.8 and 21.6 degrees on the full table).
  EXPECT_GT(smooth.angle, 3.0);
  EXPECT_GT(rough.angle, smooth.angle + 5.0)
      << "mu = 0: " << smooth.angle << " degrees, mu = 0.5: " << rough.angle << " degrees";
  EXPECT_LT(rough.angle, 35.0);
}

}  // namespace
