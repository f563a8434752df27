/// \file
/// \brief Moreau's midpoint scheme through the real stepper, against the closed forms of
/// non-smooth mechanics (../shared/REFERENCES.md; Glocker 2001 for the cradle, Stewart 2000 for
/// Painlevé), conservation laws, and the identity of contacts under reordering.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <tuple>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/timestep/midpoint.hpp"
#include "grbd/timestep/stepper.hpp"
#include "pile.hpp"
#include "scenes.hpp"

namespace grbd::timestep {
namespace {

using demo::sphere_body;

constexpr double kG = 9.81;
constexpr double kEps = std::numeric_limits<double>::epsilon();

using demo::tight;
using demo::tilted_gravity;

// ---------------------------------------------------------------------------------------------
// The bouncing ball: impacts at t_k = t₁ (1 + 2ε + … + 2ε^(k−1)), rest after the Zeno time.

struct Bounce {
  std::vector<double> impacts;  // start time of each step with an approaching contact
  double rest_from = -1.0;      // from this time on u = 0 to round-off (−1: never)
  bool energy_increased = false;
  double worst_gain = 0.0;
};

Bounce bounce(double eps, double dt, double t_end, double overlap_recovery = 0.0,
              double look_ahead = 0.0) {
  BodySystem system;
  const double r = 0.1;
  const double h0 = 1.0;
  system.add(sphere_body(1, r, Vector3(0.0, 0.0, r + h0)));
  StaticGeometry statics;
  statics.add(demo::floor_object());
  const MaterialTable materials = demo::one_material(0.3, eps);
  StepSettings settings = tight(dt);
  settings.overlap_recovery = overlap_recovery;
  settings.look_ahead = look_ahead;
  MoreauStepper stepper(system, statics, materials, settings);
  Bounce result;
  double energy = mechanical_energy(system.inertia(), system.states(), stepper.settings().I_g);
  const double scale = std::abs(energy);
  bool resting = false;
  while (stepper.time() < t_end) {
    const double t = stepper.time();
    const double v_before = system.states()[0].u.z();
    const StepReport report = stepper.step();
    if (report.contacts > 0 && v_before < 0.0 && stepper.percussions()[0].x() > 0.0 &&
        system.states()[0].u.z() > 0.0) {
      result.impacts.push_back(t);
    }
    const double e = report.kinetic_energy + report.potential_energy;
    if (e > energy + 1e-13 * scale) {
      result.energy_increased = true;
      result.worst_gain = std::max(result.worst_gain, (e - energy) / scale);
    }
    energy = e;
    // At rest the velocity is zero to the round-off of the velocity change g Δt of one step
    // (the percussion m g Δt cancels it within a few ulps, ≈ 3·10⁻¹⁸ m/s here).
    const bool at_rest = system.states()[0].u.norm() <= 4.0 * kEps * kG * dt &&
                         system.states()[0].u.head<2>() == Vector2::Zero() &&
                         system.states()[0].u.tail<3>() == Vector3::Zero();
    if (at_rest && !resting) result.rest_from = stepper.time();
    if (!at_rest) result.rest_from = -1.0;
    resting = at_rest;
  }
  return result;
}

TEST(BouncingBall, ImpactTimesWithinKPlusOneStepsOfTheClosedFormAndRestAfterZeno) {
  const double dt = 1e-3;
  for (const double eps : {0.8, 0.5}) {
    const double zeno = bouncing_ball_zeno_time(1.0, kG, eps);
    const Bounce b = bounce(eps, dt, zeno + 0.5);
    ASSERT_GE(b.impacts.size(), 6u) << "eps " << eps;
    for (std::size_t k = 1; k <= 6; ++k) {
      const double expected = bouncing_ball_impact_time(static_cast<int>(k), 1.0, kG, eps);
      EXPECT_LE(std::abs(b.impacts[k - 1] - expected), double(k + 1) * dt)
          << "eps " << eps << ", impact " << k << ": " << b.impacts[k - 1] << " vs " << expected;
    }
    // At rest (u = 0 to round-off) soon after the Zeno time: once the flights are shorter than
    // Δt, the last closing velocity, at most g Δt, is restituted and reversed in turn (a
    // separating active contact takes ε = 1), shrinking by ε every two steps, so it reaches the
    // round-off ε_mach g Δt within 2 ln(ε_mach)/ln(ε) steps.
    ASSERT_GE(b.rest_from, 0.0) << "eps " << eps;
    const double settle = (2.0 * std::log(kEps) / std::log(eps) + 20.0) * dt;
    EXPECT_LE(b.rest_from, zeno + settle) << "eps " << eps;
    EXPECT_GE(b.rest_from, zeno - 2.0 * dt) << "eps " << eps;
    EXPECT_FALSE(b.energy_increased) << "eps " << eps << ": relative gain " << b.worst_gain;
  }
}

TEST(BouncingBall, MechanicalEnergyNeverIncreases) {
  for (const double eps : {0.0, 0.3, 1.0}) {
    const Bounce b = bounce(eps, 1e-3, 2.0);
    EXPECT_FALSE(b.energy_increased) << "eps " << eps << ": relative gain " << b.worst_gain;
  }
}

// ---------------------------------------------------------------------------------------------
// Block and sphere on an incline: gravity tilted by θ about y, the floor z = 0.

struct Slide {
  double x = 0.0;  // displacement along the slope after t_end
  double v = 0.0;  // velocity along the slope
  double omega_y = 0.0;
};

Slide incline(const BodyRecord& spec, double theta, double mu, double t_end, double dt = 1e-3) {
  BodySystem system;
  system.add(spec);
  StaticGeometry statics;
  statics.add(demo::floor_object());
  const MaterialTable materials = demo::one_material(mu);
  StepSettings settings = tight(dt);
  settings.I_g = tilted_gravity(theta);
  MoreauStepper stepper(system, statics, materials, settings);
  const double x0 = system.states()[0].q.x();
  while (stepper.time() < t_end - 0.5 * dt) stepper.step();
  return {system.states()[0].q.x() - x0, system.states()[0].u.x(), system.states()[0].u(4)};
}

TEST(Incline, ABlockSticksJustBelowTheFrictionAngleAndSlidesJustAbove) {
  const double mu = 0.5;
  const double theta_c = std::atan(mu);
  const double delta = 0.1 * std::numbers::pi / 180.0;
  const Vector3 h(0.1, 0.1, 0.05);
  const BodyRecord block = demo::box_body(1, h, Vector3(0.0, 0.0, h.z()));
  const double t = 1.0;
  const Slide stick = incline(block, theta_c - delta, mu, t);
  EXPECT_LE(std::abs(stick.x), 1e-12) << "creep below the friction angle";
  EXPECT_LE(std::abs(stick.v), 1e-12);
  const double theta = theta_c + delta;
  const double a = kG * (std::sin(theta) - mu * std::cos(theta));
  const Slide slide = incline(block, theta, mu, t);
  EXPECT_NEAR(slide.v, a * t, 1e-9 * a * t) << "a = g (sin θ − μ cos θ)";
  EXPECT_NEAR(slide.x, 0.5 * a * t * t, 1e-9 * a * t * t);
}

TEST(Incline, ASphereRollsIffFrictionSufficesElseSlides) {
  const double r = 0.05;
  const BodyRecord ball = sphere_body(1, r, Vector3(0.0, 0.0, r));
  const double theta = 20.0 * std::numbers::pi / 180.0;
  const double mu_roll = 2.0 / 7.0 * std::tan(theta);
  const double t = 1.0;
  // Rolling: a = 5/7 g sin θ, and ω R = v.
  const Slide roll = incline(ball, theta, 1.05 * mu_roll, t);
  const double a_roll = 5.0 / 7.0 * kG * std::sin(theta);
  EXPECT_NEAR(roll.v, a_roll * t, 1e-9 * a_roll * t);
  EXPECT_NEAR(roll.omega_y * r, roll.v, 1e-9 * roll.v);
  // Sliding: a = g (sin θ − μ cos θ), and the spin lags behind.
  const double mu = 0.95 * mu_roll;
  const Slide slip = incline(ball, theta, mu, t);
  const double a_slip = kG * (std::sin(theta) - mu * std::cos(theta));
  EXPECT_NEAR(slip.v, a_slip * t, 1e-9 * a_slip * t);
  EXPECT_LT(slip.omega_y * r, 0.99 * slip.v);
}

// ---------------------------------------------------------------------------------------------

TEST(BilliardBall, RollingStartsAtTwoV0Over7MuGWithFiveSeventhsOfTheSpeed) {
  const double r = 0.0286;  // a pool ball
  const double v0 = 2.0;
  const double mu = 0.2;
  const double dt = 1e-4;
  BodySystem system;
  Vector6 u0 = Vector6::Zero();
  u0(0) = v0;
  system.add(sphere_body(1, r, Vector3(0.0, 0.0, r), u0, 1700.0));
  StaticGeometry statics;
  statics.add(demo::floor_object());
  const MaterialTable materials = demo::one_material(mu);
  MoreauStepper stepper(system, statics, materials, tight(dt));
  const double t_star = 2.0 * v0 / (7.0 * mu * kG);
  double t_roll = -1.0;
  while (stepper.time() < 1.5 * t_star) {
    stepper.step();
    const Vector6& u = system.states()[0].u;
    const double slip = u(0) - u(4) * r;  // velocity of the contact point along x
    if (t_roll < 0.0 && std::abs(slip) <= 1e-9 * v0) t_roll = stepper.time();
  }
  ASSERT_GT(t_roll, 0.0);
  EXPECT_LE(std::abs(t_roll - t_star), dt) << "t* = 2 v0/(7 μ g)";
  EXPECT_NEAR(system.states()[0].u(0), 5.0 / 7.0 * v0, 1e-9 * v0);
}

// ---------------------------------------------------------------------------------------------
// Newton's cradle: N touching balls, the first moving; Moreau's simultaneous impact law
// (Glocker 2001) gives the striker (2 − N)/N v₀ and the others 2/N v₀ for ε = 1, v₀/N for all
// for ε = 0.

std::vector<double> cradle(int N, double eps) {
  BodySystem system;
  const double r = 0.0625;  // centres 2r i exact in binary: the balls touch, g_N = 0 exactly
  for (int i = 0; i < N; ++i) {
    Vector6 u = Vector6::Zero();
    if (i == 0) u(0) = 1.0;
    system.add(sphere_body(static_cast<GlobalId>(i + 1), r, Vector3(2.0 * r * i, 0.0, 1.0), u));
  }
  StaticGeometry statics;
  const MaterialTable materials = demo::one_material(0.0, eps);
  StepSettings settings = tight(1e-4);
  settings.I_g.setZero();
  MoreauStepper stepper(system, statics, materials, settings);
  const StepReport report = stepper.step();
  EXPECT_EQ(report.contacts, static_cast<std::size_t>(N - 1));
  std::vector<double> v;
  for (std::size_t i = 0; i < system.size(); ++i) v.push_back(system.states()[i].u.x());
  return v;
}

TEST(NewtonsCradle, SimultaneousImpactLawOfMoreau) {
  const std::vector<double> elastic = cradle(3, 1.0);
  EXPECT_NEAR(elastic[0], -1.0 / 3.0, 1e-10);
  EXPECT_NEAR(elastic[1], 2.0 / 3.0, 1e-10);
  EXPECT_NEAR(elastic[2], 2.0 / 3.0, 1e-10);
  for (const int N : {3, 5}) {
    const std::vector<double> plastic = cradle(N, 0.0);
    for (const double v : plastic) EXPECT_NEAR(v, 1.0 / N, 1e-10) << "N = " << N;
  }
  const std::vector<double> five = cradle(5, 1.0);
  EXPECT_NEAR(five[0], -3.0 / 5.0, 1e-10);
  for (int i = 1; i < 5; ++i) EXPECT_NEAR(five[static_cast<std::size_t>(i)], 2.0 / 5.0, 1e-10);
}

// ---------------------------------------------------------------------------------------------

TEST(SphereColumn, PercussionKMgDtAtTheKthContactFromTheTopAndNoDrift) {
  const int N = 8;
  const double r = 0.01;
  const double dt = 1e-3;
  BodySystem system;
  for (int i = 0; i < N; ++i) {
    system.add(sphere_body(static_cast<GlobalId>(i + 1), r, Vector3(0.0, 0.0, r + 2.0 * r * i)));
  }
  StaticGeometry statics;
  statics.add(demo::floor_object());
  const MaterialTable materials = demo::one_material(0.5);
  MoreauStepper stepper(system, statics, materials, tight(dt));
  const double m = system.inertia()[0].m;
  std::vector<Vector7> q0;
  for (const body::State& s : system.states()) q0.push_back(s.q);
  for (int step = 0; step < 1000; ++step) {
    const StepReport report = stepper.step();
    ASSERT_EQ(report.contacts, static_cast<std::size_t>(N));
    // The k-th contact from the top carries k m g Δt; find it by its key.
    for (std::size_t c = 0; c < report.contacts; ++c) {
      const ContactKey& key = stepper.keys()[c];
      // The contact below body with id j (floor: below id 1) carries the N − j + 1 bodies above.
      const GlobalId upper = (key.b & kStaticTag) ? key.a : std::max(key.a, key.b);
      const double k = double(N) - double(upper) + 1.0;
      EXPECT_NEAR(stepper.percussions()[c].x(), k * m * kG * dt, 1e-9 * k * m * kG * dt)
          << "step " << step << ", contact below body " << upper;
    }
  }
  for (std::size_t i = 0; i < system.size(); ++i) {
    EXPECT_LE((system.states()[i].q - q0[i]).norm(), 1e-12) << "body " << i << " drifted";
  }
}

// ---------------------------------------------------------------------------------------------
// Three spheres: two on the floor touching, one on top. The friction needed between the spheres
// is 2 − √3 and on the floor (2 − √3)/3.

double pyramid_sag(double mu_spheres, double mu_floor) {
  const double r = 0.05;
  BodySystem system;
  MaterialTable materials;
  const MaterialId ball = materials.add("ball");
  const MaterialId ground = materials.add("ground");
  materials.set_pair(ball, ball, {mu_spheres, 0.0, 0.0});
  materials.set_pair(ball, ground, {mu_floor, 0.0, 0.0});
  system.add(sphere_body(1, r, Vector3(-r, 0.0, r), Vector6::Zero(), 2500.0, ball));
  system.add(sphere_body(2, r, Vector3(r, 0.0, r), Vector6::Zero(), 2500.0, ball));
  system.add(
      sphere_body(3, r, Vector3(0.0, 0.0, r + std::sqrt(3.0) * r), Vector6::Zero(), 2500.0, ball));
  StaticGeometry statics;
  statics.add(demo::floor_object(0, ground));
  MoreauStepper stepper(system, statics, materials, tight(1e-3));
  const double z0 = system.states()[2].q.z();
  while (stepper.time() < 0.5) stepper.step();
  return z0 - system.states()[2].q.z();
}

TEST(ThreeSpheres, StayIffFrictionReachesTwoMinusRootThree) {
  const double need_spheres = 2.0 - std::sqrt(3.0);
  const double need_floor = need_spheres / 3.0;
  EXPECT_LE(pyramid_sag(1.02 * need_spheres, 1.02 * need_floor), 1e-10);
  EXPECT_GT(pyramid_sag(0.98 * need_spheres, 1.02 * need_floor), 1e-3);
  EXPECT_GT(pyramid_sag(1.02 * need_spheres, 0.98 * need_floor), 1e-3);
}

// ---------------------------------------------------------------------------------------------

struct RodRun {
  std::uint64_t non_converged = 0;
  int steps_with_contact = 0;
  double worst_gain = 0.0;  // largest relative energy increase of one step
  bool finite = true;
};

RodRun slide_painleve_rod(contact::Method method) {
  // The rod of demo::painleve_rod() in the Painlevé window, where the acceleration-level
  // problem may have no solution or two (Stewart 2000); the velocity-level step always has one.
  const BodyRecord rod = demo::painleve_rod();
  BodySystem system;
  system.add(rod);
  StaticGeometry statics;
  statics.add(demo::floor_object());
  const MaterialTable materials = demo::one_material(1.5);
  StepSettings settings;
  settings.dt = 1e-4;
  settings.method = method;
  settings.on_non_convergence = NonConvergence::count;
  MoreauStepper stepper(system, statics, materials, settings);
  RodRun run;
  double energy = 0.0;
  bool first = true;
  while (stepper.time() < 0.3) {
    const StepReport report = stepper.step();
    const double e = report.kinetic_energy + report.potential_energy;
    if (!first) run.worst_gain = std::max(run.worst_gain, (e - energy) / std::abs(energy));
    energy = e;
    first = false;
    if (report.contacts > 0) ++run.steps_with_contact;
    run.finite = run.finite && system.states()[0].q.allFinite() && system.states()[0].u.allFinite();
  }
  run.non_converged = stepper.non_converged_steps();
  return run;
}

TEST(Painleve, ARodSlidingOnARoughFloorKeepsGoing) {
  // APGD solves every step of the slide to its tolerance; the energy never grows beyond it.
  const RodRun apgd = slide_painleve_rod(contact::Method::apgd);
  EXPECT_TRUE(apgd.finite);
  EXPECT_GT(apgd.steps_with_contact, 100);
  EXPECT_EQ(apgd.non_converged, 0u);
  EXPECT_LT(apgd.worst_gain, 1e-7);
  // SOR's fixed point of this single, strongly coupled contact cycles in many steps: the stepper
  // counts them and goes on (NonConvergence::count), with a finite state throughout.
  const RodRun sor = slide_painleve_rod(contact::Method::sor);
  EXPECT_TRUE(sor.finite);
  EXPECT_GT(sor.steps_with_contact, 100);
  std::printf("Painleve rod: %llu of 3000 SOR steps stopped at max_iterations\n",
              static_cast<unsigned long long>(sor.non_converged));
}

// ---------------------------------------------------------------------------------------------

TEST(Conservation, MomentumOfCollidingSpheresWithoutGravityToRoundOff) {
  BodySystem system;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> x(0.0, 0.2);
  std::normal_distribution<double> v;
  for (GlobalId id = 1; id <= 200; ++id) {
    Vector6 u;
    u << v(rng), v(rng), v(rng), 10.0 * v(rng), 10.0 * v(rng), 10.0 * v(rng);
    system.add(sphere_body(id, 0.01, Vector3(x(rng), x(rng), x(rng)), u));
  }
  StaticGeometry statics;
  const MaterialTable materials = demo::one_material(0.4, 0.5, 0.0);
  StepSettings settings = tight(1e-3);
  settings.I_g.setZero();
  settings.solver.max_iterations = 1000;
  settings.on_non_convergence = NonConvergence::count;
  MoreauStepper stepper(system, statics, materials, settings);
  const auto momentum = [&] {
    Vector3 p = Vector3::Zero();
    for (std::size_t i = 0; i < system.size(); ++i) {
      p += system.inertia()[i].m * system.states()[i].u.head<3>();
    }
    return p;
  };
  const Vector3 p0 = momentum();
  double scale = 0.0;
  for (std::size_t i = 0; i < system.size(); ++i) {
    scale += system.inertia()[i].m * system.states()[i].u.head<3>().norm();
  }
  std::size_t contacts = 0;
  for (int step = 0; step < 100; ++step) contacts += stepper.step().contacts;
  EXPECT_GT(contacts, 100u);
  EXPECT_LE((momentum() - p0).norm(), 1e-13 * scale);
}

// ---------------------------------------------------------------------------------------------
// Contacts keyed by identity: the same run with the bodies stored in another order, or reordered
// between steps, gives the same iterations and bit-identical percussions and states.

TEST(Identity, PermutingTheBodiesBetweenStepsChangesNothing) {
  const auto setup = [](BodySystem& system, StaticGeometry& statics) {
    demo::add_open_box(statics, 0.12, 0.12);
    demo::add_sphere_lattice(system, 4, 4, 4, 0.01);
  };
  BodySystem a;
  BodySystem b;
  StaticGeometry statics;
  StaticGeometry statics_b;
  setup(a, statics);
  setup(b, statics_b);
  const MaterialTable materials = demo::one_material(0.5, 0.2);
  StepSettings settings;
  settings.dt = 1e-3;
  settings.solver.max_iterations = 50;
  MoreauStepper sa(a, statics, materials, settings);
  MoreauStepper sb(b, statics_b, materials, settings);
  std::mt19937 rng(17);
  std::vector<std::int32_t> order(b.size());
  std::size_t warm = 0;
  for (int step = 0; step < 150; ++step) {
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    b.permute(order);
    const StepReport ra = sa.step();
    const StepReport rb = sb.step();
    ASSERT_EQ(ra.contacts, rb.contacts) << "step " << step;
    ASSERT_EQ(ra.iterations, rb.iterations) << "step " << step;
    ASSERT_EQ(ra.warm_started, rb.warm_started) << "step " << step;
    warm += ra.warm_started;
    for (std::size_t c = 0; c < ra.contacts; ++c) {
      ASSERT_EQ(sa.keys()[c], sb.keys()[c]);
      ASSERT_EQ(sa.percussions()[c], sb.percussions()[c]) << "step " << step << " contact " << c;
    }
  }
  EXPECT_GT(warm, 1000u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::size_t j = b.index_of(a.ids()[i]);
    ASSERT_EQ(a.states()[i].q, b.states()[j].q);
    ASSERT_EQ(a.states()[i].u, b.states()[j].u);
  }
}

TEST(Identity, SameInputGivesBitIdenticalOutputAndReorderingOrACandidateListKeepsIt) {
  const auto run = [](int reorder_interval, double skin = 0.0) {
    BodySystem system;
    StaticGeometry statics;
    demo::add_open_box(statics, 0.12, 0.12);
    demo::add_sphere_lattice(system, 4, 4, 4, 0.01, 3);
    const MaterialTable materials = demo::one_material(0.5, 0.2);
    StepSettings settings;
    settings.dt = 1e-3;
    settings.reorder_interval = reorder_interval;
    settings.skin = skin;
    MoreauStepper stepper(system, statics, materials, settings);
    int reordered = 0;
    for (int step = 0; step < 100; ++step) {
      reordered += stepper.reorder_if_due() ? 1 : 0;  // the driver's call, between steps
      stepper.step();
    }
    EXPECT_EQ(reordered, reorder_interval > 0 ? 99 / reorder_interval : 0);
    std::vector<std::pair<GlobalId, body::State>> out;
    for (std::size_t i = 0; i < system.size(); ++i) {
      out.emplace_back(system.ids()[i], system.states()[i]);
    }
    std::sort(out.begin(), out.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    return out;
  };
  const auto first = run(0);
  const auto again = run(0);
  const auto reordered = run(7);
  const auto listed = run(0, 0.002);            // a skin of a fifth of the radius
  const auto listed_reordered = run(7, 0.002);  // reordering rebuilds the list
  for (std::size_t i = 0; i < first.size(); ++i) {
    ASSERT_EQ(first[i].second.q, again[i].second.q);
    ASSERT_EQ(first[i].second.q, reordered[i].second.q);
    ASSERT_EQ(first[i].second.u, reordered[i].second.u);
    ASSERT_EQ(first[i].second.q, listed[i].second.q);
    ASSERT_EQ(first[i].second.u, listed[i].second.u);
    ASSERT_EQ(first[i].second.q, listed_reordered[i].second.q);
  }
}

// ---------------------------------------------------------------------------------------------
// The hooks of a step (StepHooks): where chapter 8's parallel engine takes part. Each is checked
// against what the serial step computes without it.

// A pile of 4 × 4 × 4 spheres in an open box, 60 steps: the reference of the hook tests.
struct PileRun {
  BodySystem system;
  StaticGeometry statics;
  MaterialTable materials = demo::one_material(0.5, 0.2);
  StepSettings settings;
  PileRun() {
    demo::add_open_box(statics, 0.12, 0.12);
    demo::add_sphere_lattice(system, 4, 4, 4, 0.01, 3);
    settings.dt = 1e-3;
    settings.solver.abs_tol = 0.0;  // a criterion that does not change when Λ is scaled
  }
};

TEST(StepHooks, AHookThatDoublesEveryMassDoublesThePercussionsAndKeepsTheMotion) {
  // after_assembly halves every body's inverse mass (what a split body's copy does to its share
  // of a body): under gravity and contacts alone, doubled masses take doubled percussions and
  // move exactly as before. Scaling by 2 is exact in binary floating point, so the motion must
  // agree bit for bit and every percussion be exactly twice the reference's.
  PileRun plain, hooked;
  StepHooks hooks;
  int called = 0;
  hooks.after_assembly = [&](contact::CompactProblem& problem, contact::ContactSolution&) {
    for (contact::WorldInverseMass& w : problem.M_inv) {
      w.inv_m *= 0.5;
      w.I_Theta_inv *= 0.5;
    }
    ++called;
  };
  MoreauStepper a(plain.system, plain.statics, plain.materials, plain.settings);
  MoreauStepper b(hooked.system, hooked.statics, hooked.materials, hooked.settings, hooks);
  std::size_t contacts = 0;
  for (int step = 0; step < 60; ++step) {
    const StepReport ra = a.step();
    const StepReport rb = b.step();
    ASSERT_EQ(ra.contacts, rb.contacts) << "step " << step;
    ASSERT_EQ(ra.iterations, rb.iterations) << "step " << step;
    for (std::size_t k = 0; k < ra.contacts; ++k) {
      ASSERT_EQ(b.percussions()[k], 2.0 * a.percussions()[k]) << "step " << step;
    }
    contacts += rb.contacts;
  }
  EXPECT_EQ(called, 60);
  EXPECT_GT(contacts, 1000u);
  for (std::size_t i = 0; i < hooked.system.size(); ++i) {
    ASSERT_EQ(hooked.system.states()[i].q, plain.system.states()[i].q) << "body " << i;
    ASSERT_EQ(hooked.system.states()[i].u, plain.system.states()[i].u) << "body " << i;
  }
}

TEST(StepHooks, ContactsDroppedAfterDetectionAreNotSolved) {
  // after_detection removes every contact of body 0 (a process that does not solve them): body 0
  // then falls freely through its neighbours and the floor, u_z = −g t exactly as for a body
  // alone, while the hook sees the contacts in canonical order, one key per contact.
  PileRun run;
  const GlobalId id = run.system.ids()[0];
  StepHooks hooks;
  std::size_t dropped = 0;
  hooks.after_detection = [&](const BodySystem& system, std::vector<DetectedContact>& contacts,
                              std::vector<ContactKey>& keys) {
    EXPECT_EQ(contacts.size(), keys.size());
    std::size_t kept = 0;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      if (keys[k].a == id || keys[k].b == id) {
        ++dropped;
        continue;
      }
      contacts[kept] = contacts[k];
      keys[kept] = keys[k];
      ++kept;
    }
    contacts.resize(kept);
    keys.resize(kept);
    (void)system;
  };
  MoreauStepper stepper(run.system, run.statics, run.materials, run.settings, hooks);
  double v = 0.0;
  for (int step = 0; step < 60; ++step) {
    stepper.step();
    v -= kG * run.settings.dt;
    const std::size_t i = run.system.index_of(id);
    EXPECT_NEAR(run.system.states()[i].u.z(), v, 1e-12) << "step " << step;
  }
  EXPECT_GT(dropped, 0u);
  for (const ContactKey& key : stepper.keys()) EXPECT_TRUE(key.a != id && key.b != id);
}

TEST(StepHooks, TheSolverHooksAreReachedAndAVelocityHookKeepsTheResult) {
  // The solver's own hooks through the step: velocities_between_sweeps runs once per SOR
  // iteration; one that changes nothing leaves the run bit-identical to a run without hooks,
  // and reduce_report gets the finished report once per step, last.
  PileRun plain, hooked;
  StepHooks hooks;
  long sweeps = 0;
  int reports = 0;
  hooks.solver.velocities_between_sweeps = [&](int, std::span<Vector6> u) {
    EXPECT_EQ(u.size(), hooked.system.size());
    ++sweeps;
  };
  hooks.reduce_report = [&](StepReport& report) {
    ++reports;
    EXPECT_GT(report.seconds.total, 0.0);  // the stages are done and timed
    report.contacts += 1000;               // what the driver returns is the step's report
  };
  MoreauStepper a(plain.system, plain.statics, plain.materials, plain.settings);
  MoreauStepper b(hooked.system, hooked.statics, hooked.materials, hooked.settings, hooks);
  long iterations = 0;
  for (int step = 0; step < 60; ++step) {
    const StepReport ra = a.step();
    const StepReport rb = b.step();
    EXPECT_EQ(rb.contacts, ra.contacts + 1000);
    EXPECT_EQ(rb.iterations, ra.iterations);
    iterations += rb.contacts > 1000 ? rb.iterations : 0;
  }
  EXPECT_EQ(reports, 60);
  EXPECT_EQ(sweeps, iterations);
  EXPECT_GT(sweeps, 60);
  for (std::size_t i = 0; i < plain.system.size(); ++i) {
    ASSERT_EQ(hooked.system.states()[i].q, plain.system.states()[i].q);
    ASSERT_EQ(hooked.system.states()[i].u, plain.system.states()[i].u);
  }
  // For JOR and APGD, which recompute u from Λ, a velocity hook is refused by name.
  StepSettings jor = plain.settings;
  jor.method = contact::Method::jor;
  try {
    MoreauStepper refused(plain.system, plain.statics, plain.materials, jor, hooks);
    FAIL() << "a velocity hook for JOR was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("velocities_between_sweeps is for SOR only"),
              std::string::npos)
        << e.what();
  }
}

TEST(StepHooks, AHookThatBreaksTheShapeOfTheStepIsAnError) {
  PileRun run;
  StepHooks hooks;
  hooks.after_detection = [](const BodySystem&, std::vector<DetectedContact>& contacts,
                             std::vector<ContactKey>&) {
    if (!contacts.empty()) contacts.pop_back();  // keys no longer match
  };
  MoreauStepper stepper(run.system, run.statics, run.materials, run.settings, hooks);
  bool refused = false;
  for (int step = 0; step < 20 && !refused; ++step) {
    try {
      stepper.step();
    } catch (const InvalidArgument& e) {
      refused = std::string(e.what()).find("one key per contact") != std::string::npos;
    }
  }
  EXPECT_TRUE(refused);
}

TEST(StepHooks, TheActiveSetToleranceIsFixedOnceWhateverBodiesArePresent) {
  // Without tolerance_radius the smallest bounding radius of the first bodies, kept when smaller
  // bodies arrive later; with it, the settings' length from the start.
  PileRun run;
  const double r = run.system.bounding_radii()[0];
  MoreauStepper stepper(run.system, run.statics, run.materials, run.settings);
  EXPECT_EQ(stepper.active_set_tolerance(), run.settings.contact_tolerance * r);
  run.system.add(sphere_body(9999, 0.25 * r, Vector3(0.0, 0.0, 0.2)));
  stepper.step();
  EXPECT_EQ(stepper.active_set_tolerance(), run.settings.contact_tolerance * r);
  StepSettings given = run.settings;
  given.tolerance_radius = 0.1 * r;
  MoreauStepper fixed(run.system, run.statics, run.materials, given);
  EXPECT_EQ(fixed.active_set_tolerance(), given.contact_tolerance * 0.1 * r);
}

// ---------------------------------------------------------------------------------------------

TEST(Stepper, RefusesBadSettingsMissingMaterialPairsAndUnsupportedShapePairs) {
  BodySystem system;
  system.add(sphere_body(1, 0.1, Vector3(0.0, 0.0, 1.0)));
  StaticGeometry statics;
  statics.add(demo::floor_object(0, 1));
  MaterialTable materials;
  materials.add("ball");
  materials.add("floor");
  materials.set_pair(0, 0, {0.5, 0.0, 0.0});
  try {
    MoreauStepper stepper(system, statics, materials);
    ADD_FAILURE() << "a missing pair was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("\"ball\" and \"floor\""), std::string::npos) << e.what();
  }
  materials.set_pair(0, 1, {0.5, 0.0, 0.0});
  StepSettings bad;
  bad.dt = 0.0;
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad = {};
  bad.drift_correction = 2.0;
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad = {};
  bad.overlap_recovery = -0.1;
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad = {};
  bad.max_recovery_speed = 0.0;
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad.max_recovery_speed = std::nan("");
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad = {};
  bad.look_ahead = -1.0;
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad = {};
  bad.look_ahead_reach = 1.0;  // a reach without a look-ahead to extend
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad.look_ahead = 0.5;  // shorter than the look-ahead
  bad.look_ahead_reach = 0.2;
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad.look_ahead_reach = std::numeric_limits<double>::infinity();
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  bad = {};
  bad.skin = -1e-3;
  EXPECT_THROW(MoreauStepper(system, statics, materials, bad), InvalidArgument);
  materials.set_pair(1, 1, {0.5, 0.0, 0.0});
  system.add(demo::box_body(2, Vector3(0.1, 0.1, 0.1), Vector3(1.0, 0.0, 1.0)));
  system.add(demo::box_body(3, Vector3(0.1, 0.1, 0.1), Vector3(2.0, 0.0, 1.0)));
  try {
    MoreauStepper stepper(system, statics, materials);
    ADD_FAILURE() << "two dynamic boxes were accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("box"), std::string::npos) << e.what();
  }
}

// A blow-up is an error, not data: a step that leaves a state or an energy outside the doubles
// throws, naming the step, the time and the body's id, whether or not the body has a contact.
TEST(Stepper, AStepThatBlowsUpThrowsNamingStepTimeAndBody) {
  const auto message_of_first_step = [](BodyRecord spec, double dt, bool with_floor) {
    BodySystem system;
    system.add(sphere_body(5, 0.1, Vector3(3.0, 0.0, 1.0)));  // a quiet neighbour
    system.add(spec);
    StaticGeometry statics;
    if (with_floor) statics.add(demo::floor_object());
    const MaterialTable materials = demo::one_material(0.5);
    MoreauStepper stepper(system, statics, materials, tight(dt));
    try {
      stepper.step();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  BodyRecord spin = sphere_body(7, 0.1, Vector3(0.0, 0.0, 1.0));
  spin.state.u << 0.0, 0.0, 0.0, 1e308, 1e308, 0.0;  // |ω| overflows in the exponential map
  EXPECT_EQ(message_of_first_step(spin, 1.0, false).rfind(
                "MoreauStepper: step 1 (t = 1 s): body 7 blew up", 0),
            0U) << message_of_first_step(spin, 1.0, false);
  BodyRecord fast = sphere_body(9, 0.1, Vector3(0.0, 0.0, 1.0));
  fast.state.u << 1e308, 0.0, 0.0, 0.0, 0.0, 0.0;  // finite, but q overflows in Δt = 10 s
  const std::string m = message_of_first_step(fast, 10.0, true);
  EXPECT_EQ(m.rfind("MoreauStepper: step 1 (t = 10 s): body 9 blew up", 0), 0U) << m;
  // Every body finite, but the system's energy overflows: named as such.
  BodyRecord heavy = sphere_body(11, 0.1, Vector3(0.0, 0.0, 1.0));
  heavy.state.u << 1e154, 1e154, 1e154, 0.0, 0.0, 0.0;
  heavy.inertia.m = 1e10;
  heavy.inertia.K_Theta = Vector3::Constant(1e8);
  EXPECT_NE(message_of_first_step(heavy, 1e-6, false).find("kinetic energy inf"),
            std::string::npos);
}

TEST(Stepper, AStateSetFromOutsideThatIsNotFiniteIsNamedByItsId) {
  BodySystem system;
  system.add(sphere_body(3, 0.1, Vector3(0.0, 0.0, 1.0)));
  system.add(sphere_body(4, 0.1, Vector3(1.0, 0.0, 1.0)));
  StaticGeometry statics;
  const MaterialTable materials = demo::one_material(0.5);
  MoreauStepper stepper(system, statics, materials, tight(1e-3));
  system.states()[system.index_of(4)].q[2] = -std::numeric_limits<double>::infinity();
  try {
    stepper.step();
    ADD_FAILURE() << "an infinite position was stepped";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("MoreauStepper: step 1 (t = 0.001 s): ", 0), 0U) << m;
    EXPECT_NE(m.find("body 4 blew up at the midpoint"), std::string::npos) << m;
  }
  EXPECT_THROW(stepper.set_clock(-5.0, 0), InvalidArgument);
}

TEST(Stepper, RefusesBodiesWhoseMassOrInertiaHasNoFiniteInverse) {
  BodySystem system;
  BodyRecord tiny = sphere_body(1, 0.1, Vector3(0.0, 0.0, 1.0));
  tiny.inertia.m = 5e-324;  // positive and finite, but 1/m = inf
  EXPECT_THROW(system.add(tiny), InvalidArgument);
  tiny = sphere_body(1, 0.1, Vector3(0.0, 0.0, 1.0));
  tiny.inertia.K_Theta = Vector3::Constant(1e-310);
  EXPECT_THROW(system.add(tiny), InvalidArgument);
}

TEST(Stepper, ReportsEnergiesPenetrationAndStageTimes) {
  BodySystem system;
  system.add(sphere_body(1, 0.1, Vector3(0.0, 0.0, 0.09)));  // 1 cm into the floor
  StaticGeometry statics;
  statics.add(demo::floor_object());
  const MaterialTable materials = demo::one_material(0.5);
  MoreauStepper stepper(system, statics, materials, tight(1e-3));
  const StepReport r = stepper.step();
  EXPECT_EQ(r.step, 1u);
  EXPECT_DOUBLE_EQ(r.t, 1e-3);
  EXPECT_EQ(r.contacts, 1u);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.max_penetration, 0.01, 1e-12);
  EXPECT_NEAR(r.mean_penetration, 0.01, 1e-12);  // one contact: the mean is the largest
  EXPECT_NEAR(r.potential_energy, system.inertia()[0].m * kG * system.states()[0].q.z(), 1e-12);
  EXPECT_GE(r.seconds.total, r.seconds.solve);
  EXPECT_GE(r.seconds.solve, 0.0);
}

// Jacobi (JOR) with the default options is safe: its spectral r-factors make it a contraction,
// so it never diverges and every iteration brings it closer. But it is slow: the error of Jacobi
// falls by about 1 − λ_min/λ_max of G per iteration, and on a small settled pile of spheres it
// needs more than the default cap of 1000 iterations, where Gauss–Seidel (SOR) with per-contact
// r-factors needs a few dozen from zero (chapter 6, "Which solver").
TEST(SolverChoice, JorWithDefaultOptionsIsSafeButSlowOnAPile) {
  BodySystem system;
  StaticGeometry statics;
  demo::fcc_pile(system, statics, 3, 3, 3);
  const MaterialTable materials = demo::glass_materials();
  StepSettings settings;
  settings.dt = 2e-4;
  MoreauStepper stepper(system, statics, materials, settings);
  for (int k = 0; k < 20; ++k) stepper.step();
  const contact::CompactProblem problem = stepper.problem();
  ASSERT_GT(problem.contacts.size(), 2 * system.size());

  const auto solve = [&](contact::Method method, int max_iterations) {
    contact::SolverOptions options;  // the defaults but for the cap
    options.max_iterations = max_iterations;
    contact::ContactSolver solver(method, options);
    contact::ContactSolution solution;  // from Λ = 0
    return solver.solve(problem, solution);
  };
  const contact::SolverResult capped = solve(contact::Method::jor, 1000);
  EXPECT_FALSE(capped.diverged) << describe(capped);
  EXPECT_FALSE(capped.converged) << describe(capped);
  EXPECT_EQ(capped.iterations, 1000);
  EXPECT_LT(capped.residual, 0.1 * capped.norm_c) << describe(capped);

  const contact::SolverResult jor = solve(contact::Method::jor, 100000);
  const contact::SolverResult sor = solve(contact::Method::sor, 100000);
  ASSERT_TRUE(jor.converged) << describe(jor);
  ASSERT_TRUE(sor.converged) << describe(sor);
  std::printf("3 x 3 x 3 pile, %zu contacts, from zero: JOR %d iterations, SOR %d\n",
              problem.contacts.size(), jor.iterations, sor.iterations);
  EXPECT_GT(jor.iterations, 1000);
  EXPECT_LT(10 * sor.iterations, jor.iterations);
}

TEST(DriftCorrection, OffKeepsOverlapsOnRemovesThemGeometricallyWithoutVelocity) {
  // One sphere 0.1 mm into the floor: with β the overlap shrinks by the factor 1 − β per step.
  const auto single = [](double beta, int steps) {
    BodySystem system;
    StaticGeometry statics;
    statics.add(demo::floor_object());
    system.add(sphere_body(1, 0.01, Vector3(0.0, 0.0, 0.0099)));
    const MaterialTable materials = demo::one_material(0.5);
    StepSettings settings = tight(1e-3);
    settings.drift_correction = beta;
    MoreauStepper stepper(system, statics, materials, settings);
    for (int step = 0; step < steps; ++step) stepper.step();
    return std::pair{0.01 - system.states()[0].q.z(), system.states()[0].u.norm()};
  };
  const auto [off, off_speed] = single(0.0, 50);
  EXPECT_NEAR(off, 1e-4, 1e-12) << "the velocity-level scheme keeps the overlap";
  EXPECT_LT(off_speed, 1e-15);
  const auto [on, on_speed] = single(0.2, 50);
  EXPECT_NEAR(on, 1e-4 * std::pow(0.8, 50), 1e-12);
  EXPECT_LT(on_speed, 1e-15) << "positions only";
  // A column of five: every overlap shrinks, none grows.
  BodySystem system;
  StaticGeometry statics;
  statics.add(demo::floor_object());
  for (int i = 0; i < 5; ++i) {
    system.add(sphere_body(static_cast<GlobalId>(i + 1), 0.01,
                           Vector3(0.0, 0.0, 0.0099 + 0.0198 * i)));  // overlaps of 0.2 mm
  }
  const MaterialTable materials = demo::one_material(0.5);
  StepSettings settings = tight(1e-3);
  settings.drift_correction = 0.2;
  MoreauStepper stepper(system, statics, materials, settings);
  double previous = stepper.step().max_penetration;
  EXPECT_NEAR(previous, 2e-4, 1e-12);
  for (int step = 0; step < 300; ++step) {
    const double now = stepper.step().max_penetration;
    EXPECT_LE(now, previous * (1.0 + 1e-12)) << "step " << step;
    previous = now;
  }
  EXPECT_LT(previous, 5e-5);  // the overlaps diffuse through the column: 300 steps remove 3/4
}

// ---------------------------------------------------------------------------------------------
// The gap-aware normal law (chapter 6, "The gap-aware normal law"): γ_N,E ≥ max(−ε_N γ_N,S, v_R),
// v_R = min(β_g 2|g_N(q_M)|/Δt, v_max) for a contact overlapping at the midpoint.

// The closed-form cases of the gap-aware law: spheres of radius r overlapping by δ₀ = (N − ½)
// v_max Δt, β_g = 1, on the floor.
struct GapCase {
  double r = 0.01;
  double dt = 1e-3;
  int N = 10;
  double delta0 = 1e-4;
  double v_max() const { return delta0 / ((N - 0.5) * dt); }
  StepSettings settings() const {
    StepSettings s = tight(dt);
    s.overlap_recovery = 1.0;
    s.max_recovery_speed = v_max();
    return s;
  }
};

// A sphere at rest δ₀ = (N − ½) v_max Δt into the floor, β_g = 1: while the uncapped recovery
// exceeds the cap, each step leaves the contact opening at exactly v_max (gravity keeps the law
// binding), so the midpoint overlap of step k is δ₀ − (k − 1) v_max Δt; step N ends with the
// overlap gone, step N + 1 has no overlap, and from then on the energy above rest never exceeds
// the bound ½ m v_max² (the hop of a body the law pushed out).
TEST(GapLaw, ASphereInTheFloorRisesAtTheCapLeavesInThePredictedStepAndGainsAtMostHalfMVSquared) {
  const GapCase gap;
  const auto [r, dt, N, delta0] = std::tuple{gap.r, gap.dt, gap.N, gap.delta0};
  const double v_max = gap.v_max();
  BodySystem system;
  StaticGeometry statics;
  statics.add(demo::floor_object());
  system.add(sphere_body(1, r, Vector3(0.0, 0.0, r - delta0)));
  const MaterialTable materials = demo::one_material(0.5);
  MoreauStepper stepper(system, statics, materials, gap.settings());
  const double m = system.inertia()[0].m;
  for (int k = 1; k <= N; ++k) {
    const StepReport report = stepper.step();
    ASSERT_EQ(report.contacts, 1u) << "step " << k;
    EXPECT_NEAR(report.max_penetration, delta0 - (k - 1) * v_max * dt, 1e-12) << "step " << k;
    EXPECT_NEAR(system.states()[0].u.z(), v_max, 1e-9 * v_max) << "step " << k;
  }
  EXPECT_NEAR(system.states()[0].q.z(), r, 1e-12) << "the overlap is gone after N steps";
  EXPECT_EQ(stepper.step().max_penetration, 0.0) << "step N + 1 overlaps no more";
  // Without the law the overlap stays (Penetration drift); with it, the hops that follow gain
  // nothing beyond ½ m v_max² and never overlap by more than a landing's (v_max + g Δt) Δt.
  const double bound = 0.5 * m * v_max * v_max;
  for (int k = 0; k < 2000; ++k) {
    const StepReport report = stepper.step();
    const double above_rest = report.kinetic_energy + report.potential_energy - m * kG * r;
    ASSERT_LE(above_rest, bound * (1.0 + 1e-9)) << "step " << k;
    ASSERT_LE(report.max_penetration, (v_max + kG * dt) * dt) << "step " << k;
  }
}

// A column of five spheres overlapping by δ₀ each: every contact binds at the cap, so every
// overlap shrinks by v_max Δt a step, all at once, and all are gone after N steps.
TEST(GapLaw, AColumnOfOverlapsOpensContactByContactAtTheCap) {
  GapCase gap;
  gap.delta0 = 2e-4;
  const auto [r, dt, N, delta0] = std::tuple{gap.r, gap.dt, gap.N, gap.delta0};
  const double v_max = gap.v_max();
  BodySystem system;
  StaticGeometry statics;
  statics.add(demo::floor_object());
  for (int i = 0; i < 5; ++i) {
    system.add(sphere_body(static_cast<GlobalId>(i + 1), r,
                           Vector3(0.0, 0.0, r - delta0 + (2.0 * r - delta0) * i)));
  }
  const MaterialTable materials = demo::one_material(0.5);
  MoreauStepper stepper(system, statics, materials, gap.settings());
  for (int k = 1; k <= N; ++k) {
    const StepReport report = stepper.step();
    ASSERT_EQ(report.contacts, 5u) << "step " << k;
    EXPECT_NEAR(report.max_penetration, delta0 - (k - 1) * v_max * dt, 1e-11) << "step " << k;
    EXPECT_NEAR(report.mean_penetration, delta0 - (k - 1) * v_max * dt, 1e-11) << "step " << k;
    for (int i = 0; i < 5; ++i) {
      EXPECT_NEAR(system.states()[static_cast<std::size_t>(i)].u.z(), (i + 1) * v_max, 1e-8 * v_max)
          << "step " << k << ", sphere " << i + 1;
    }
  }
  EXPECT_EQ(stepper.step().max_penetration, 0.0);
}

// Impacts: the overlap at the midpoint of a first contact is less than |γ_N,S| Δt, so with
// β_g ≤ ε_N/2 the recovery speed stays below the restituted one and the law leaves the bouncing
// ball's impacts exactly as Moreau's law gives them (t_k of the closed form, Bouncing ball).
TEST(GapLaw, WithBetaAtMostHalfEpsilonTheBouncingBallsImpactsAreUnchanged) {
  const double dt = 1e-3;
  const double eps = 0.8;
  const double zeno = bouncing_ball_zeno_time(1.0, kG, eps);
  const Bounce off = bounce(eps, dt, zeno - 0.05);
  const Bounce on = bounce(eps, dt, zeno - 0.05, 0.5 * eps);
  ASSERT_GE(off.impacts.size(), 8u);
  EXPECT_EQ(on.impacts, off.impacts);
  EXPECT_FALSE(on.energy_increased) << "relative gain " << on.worst_gain;
}

// The look-ahead (The gap-aware normal law): a ball falling onto the floor at v with a look-ahead
// longer than v Δt is stopped by the step whose midpoint sees it still apart, so that the next
// midpoint finds it touching: with ε_N = 0 it never overlaps (to round-off), where Moreau's
// active set lets it in by up to v Δt; the energy never rises.
TEST(GapLaw, WithALookAheadAFallingBallLandsWithoutOverlap) {
  const auto land = [](double look_ahead) {
    BodySystem system;
    const double r = 0.1;
    system.add(sphere_body(1, r, Vector3(0.0, 0.0, r + 0.1)));
    StaticGeometry statics;
    statics.add(demo::floor_object());
    const MaterialTable materials = demo::one_material(0.3, 0.0);
    StepSettings settings = tight(1e-3);
    settings.look_ahead = look_ahead;
    MoreauStepper stepper(system, statics, materials, settings);
    double overlap = 0.0;
    double energy = std::numeric_limits<double>::infinity();
    bool rose = false;
    for (int k = 0; k < 400; ++k) {
      const StepReport report = stepper.step();
      overlap = std::max(overlap, report.max_penetration);
      const double e = report.kinetic_energy + report.potential_energy;
      rose = rose || e > energy + 1e-12 * std::abs(energy);
      energy = e;
    }
    return std::tuple{overlap, rose, system.states()[0].u.norm()};
  };
  const auto [moreau, moreau_rose, moreau_speed] = land(0.0);
  EXPECT_GT(moreau, 1e-4) << "Moreau's active set admits the ball overlapping";
  const auto [ahead, ahead_rose, ahead_speed] = land(0.02);  // 2 mm > v Δt = 1.4 mm
  EXPECT_LT(ahead, 1e-14) << "the look-ahead stops it touching";
  EXPECT_FALSE(ahead_rose);
  EXPECT_FALSE(moreau_rose);
  EXPECT_LT(ahead_speed, 1e-12) << "at rest";
}

// The look-ahead acts on inelastic pairs only: a restituted pair (ε_N = 0.8) must hit to rebound,
// so with a look-ahead as long as a step's fall (2 cm against v Δt ≤ 4.5 mm) the bouncing ball's
// impacts are those of Moreau's law to the step, and its energy never rises.
TEST(GapLaw, TheLookAheadLeavesARestitutedPairToMoreausLaw) {
  const double dt = 1e-3;
  const double eps = 0.8;
  const double zeno = bouncing_ball_zeno_time(1.0, kG, eps);
  const Bounce off = bounce(eps, dt, zeno - 0.05);
  const Bounce on = bounce(eps, dt, zeno - 0.05, 0.0, 0.2);
  ASSERT_GE(off.impacts.size(), 8u);
  EXPECT_EQ(on.impacts, off.impacts);
  EXPECT_FALSE(on.energy_increased) << "relative gain " << on.worst_gain;
}

// The look-ahead's reach (The gap-aware normal law): two balls closing head-on at 2 m/s, 2 mm a
// step, with a look-ahead of 0.1 mm. Without a reach the first midpoint within the look-ahead
// finds them already overlapping, by up to 2 mm less the look-ahead; with a reach of 5 mm the step
// whose free velocities close the gap to the look-ahead takes them in, and they meet touching
// (to round-off) and stop along the line of centres, an inelastic impact, while their common
// sliding across it is untouched. A pair within the reach that moves apart stays out of the
// active set.
TEST(GapLaw, TheReachCatchesAPairClosingByMoreThanTheLookAheadAStep) {
  const double r = 0.1;
  const auto collide = [&](double reach, double speed) {
    BodySystem system;
    system.add(sphere_body(1, r, Vector3(-r - 0.0253, 0.0, 0.0)));
    system.add(sphere_body(2, r, Vector3(r + 0.0253, 0.0, 0.0)));
    system.states()[0].u(0) = speed;
    system.states()[1].u(0) = -speed;
    system.states()[0].u(1) = system.states()[1].u(1) = 0.5;  // sliding past along y as well
    StaticGeometry statics;
    const MaterialTable materials = demo::one_material(0.0, 0.0);
    StepSettings settings = tight(1e-3);
    settings.I_g.setZero();
    settings.look_ahead = 0.001;  // 0.1 mm
    settings.look_ahead_reach = reach;
    MoreauStepper stepper(system, statics, materials, settings);
    double overlap = 0.0;
    std::size_t contacts = 0;
    for (int k = 0; k < 40; ++k) {
      const StepReport report = stepper.step();
      overlap = std::max(overlap, report.max_penetration);
      contacts = std::max(contacts, report.contacts);
    }
    const double momentum = (system.states()[0].u + system.states()[1].u).head<3>().norm();
    return std::tuple{overlap, contacts, momentum, system.states()[0].u(0)};
  };
  const auto [off, off_contacts, off_momentum, off_speed] = collide(0.0, 1.0);
  EXPECT_GT(off, 1e-4) << "the look-ahead alone lets the pair in";
  const auto [on, on_contacts, on_momentum, on_speed] = collide(0.05, 1.0);
  EXPECT_EQ(on_contacts, 1u);
  EXPECT_LT(on, 1e-14) << "the reach takes the pair in before it overlaps";
  EXPECT_NEAR(on_momentum, 1.0, 1e-12) << "the sliding along y is untouched (mu = 0)";
  EXPECT_LT(std::abs(on_speed), 1e-12) << "an inelastic impact: the pair stops along x";
  EXPECT_LT(std::abs(off_speed), 1e-12);
  // Moving apart within the reach: never active.
  const auto [apart, apart_contacts, apart_momentum, apart_speed] = collide(1.0, -1.0);
  EXPECT_EQ(apart_contacts, 0u);
  EXPECT_EQ(apart, 0.0);
}

// The criterion's reference with the look-ahead (The gap-aware normal law): a sphere resting on
// the floor and one hovering 5 mm above it, within the look-ahead. The hovering one's gap rate
// g/Δt = 5 m/s is a length over a step, not a velocity of the motion: the reference of the
// natural residual is that of the free contact velocities alone, −gΔt for each (√2 g Δt), where
// with the gap rate it would be 5 m/s and the tolerance 500 times looser.
TEST(GapLaw, TheLookAheadsGapRatesAreNotPartOfTheCriterionsReference) {
  const double r = 0.1;
  const double dt = 1e-3;
  BodySystem system;
  system.add(sphere_body(1, r, Vector3(0.0, 0.0, r)));
  system.add(sphere_body(2, r, Vector3(1.0, 0.0, r + 0.005 + 0.5 * dt * dt * kG)));
  StaticGeometry statics;
  statics.add(demo::floor_object());
  const MaterialTable materials = demo::one_material(0.3, 0.0);
  StepSettings settings = tight(dt);
  settings.look_ahead = 0.1;  // 1 cm
  MoreauStepper stepper(system, statics, materials, settings);
  const StepReport report = stepper.step();
  ASSERT_EQ(report.contacts, 2u);
  EXPECT_NEAR(stepper.problem().reference_norm, std::sqrt(2.0) * kG * dt, 1e-12);
  settings.look_ahead = 0.0;  // Moreau's law: the solver's own ‖c‖
  BodySystem moreau_system;
  moreau_system.add(sphere_body(1, r, Vector3(0.0, 0.0, r)));
  MoreauStepper moreau(moreau_system, statics, materials, settings);
  moreau.step();
  EXPECT_EQ(moreau.problem().reference_norm, 0.0);
}

// The overlaps' histogram (Accuracy of a step): bins of 10^(1/20) from 1e-8 r to r, quantiles
// read as the upper edge of their bin — never below the exact quantile, at most 12 % above it —
// and counts that add exactly (over steps, over processes).
TEST(OverlapHistogram, BinsQuantilesAndSumsAgainstTheSortedOverlaps) {
  using H = OverlapHistogram;
  EXPECT_EQ(H::bin(0.0), 0);
  EXPECT_EQ(H::bin(0.9e-8), 0);
  EXPECT_EQ(H::bin(std::nan("")), 0);
  EXPECT_EQ(H::bin(1e-8), 1);
  EXPECT_EQ(H::bin(0.999), H::kBins - 2);
  EXPECT_EQ(H::bin(1.0), H::kBins - 1);
  EXPECT_NEAR(H::upper_edge(H::kBins - 2), 1.0, 1e-15);
  EXPECT_EQ(H::upper_edge(H::kBins - 1), std::numeric_limits<double>::infinity());
  for (int b = 1; b < H::kBins - 1; ++b) {  // every bin holds what its edges say
    const double lo = H::upper_edge(b - 1) * (b == 1 ? 1.0 : 1.0 + 1e-12);
    EXPECT_EQ(H::bin(lo), b) << b;
    EXPECT_EQ(H::bin(H::upper_edge(b) * (1.0 - 1e-12)), b) << b;
  }
  std::mt19937_64 rng(3);
  std::lognormal_distribution<double> overlap(std::log(1e-3), 1.5);
  const double r = 1e-3;
  std::vector<double> all;
  H first, second;
  for (int k = 0; k < 20000; ++k) {
    const double d = r * std::min(overlap(rng), 0.5);
    all.push_back(d);
    (k % 3 == 0 ? first : second).add(d, r);
  }
  H both = first;
  both.add(second);
  EXPECT_EQ(both.count(), all.size());
  std::sort(all.begin(), all.end());
  for (const double p : {0.5, 0.9, 0.99, 0.999}) {
    const double exact = all[static_cast<std::size_t>(std::ceil(p * all.size())) - 1] / r;
    const double read = both.quantile(p);
    EXPECT_GE(read, exact) << p;
    EXPECT_LE(read, exact * std::pow(10.0, 1.0 / H::kPerDecade) * (1.0 + 1e-12)) << p;
  }
  EXPECT_EQ(H{}.quantile(0.99), 0.0);
}

}  // namespace
}  // namespace grbd::timestep
