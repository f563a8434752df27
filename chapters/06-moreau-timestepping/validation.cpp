// Chapter 6 demo: Moreau's midpoint scheme, through the real MoreauStepper, against the closed
// forms of non-smooth mechanics (../shared/REFERENCES.md), and a settling pile with and without
// warm start.
//
// Cases (every one a BodySystem, a StaticGeometry and a MaterialTable stepped by MoreauStepper):
//   bouncing ball  a sphere (r = 0.1 m) dropped from a gap of 1 m onto the floor, ε_N = 0.8 and
//                  0.5, Δt = 1 ms: impact times against t_k = t₁(1 + 2ε + … + 2ε^(k−1)), the
//                  Zeno time t₁(1 + ε)/(1 − ε), the energy after each step
//   incline        a block (μ = 0.5) on a slope at θ_c ∓ 0.1°, θ_c = atan μ, Δt = 1 ms, 1 s:
//                  at rest below, a = g(sin θ − μ cos θ) above; also a sphere at 20° with
//                  μ = 1.05 and 0.95 × (2/7) tan θ: rolls with a = (5/7) g sin θ, or slides
//   billiard       a pool ball launched sliding at v₀ = 2 m/s without spin, μ = 0.2, Δt = 0.1 ms:
//                  rolling from t* = 2v₀/(7μg) at (5/7)v₀
//   cradle         3 and 5 touching balls, the first moving at v₀, ε_N = 1 and 0, one step
//   midpoint       the exp-map half step against "add and normalise" for |ω|Δt = 0.02 and 0.01
//   Painlevé rod   a rod sliding on a rough floor (μ = 1.5 > 4/3) with APGD and with SOR
//   pile           216 glass spheres (r = 1 mm, μ = 0.5) dropped from a jittered lattice into an
//                  open box, settling for 0.3 s at Δt = 0.2 ms with the default solver options
//                  (SOR, percussion change ≤ 10⁻⁶ relative, at most 1000 iterations), with and
//                  without warm start
// The closed-form cases use tight solver tolerances (rel_tol 1e-12), the pile the defaults.
//
// Output, in the data directory:
//   bouncing_ball.csv  t, then per ε (0.8, 0.5): gap of the ball, closed-form gap, energy above
//                      rest relative to the start
//   impacts.csv        k, then per ε: closed-form and measured time of impact k
//   zeno.csv           ε, closed-form Zeno time, time from which the ball rests
//   incline.csv        t, velocity along the slope at θ_c − 0.1° and θ_c + 0.1°, closed form
//   billiard.csv       t, v, ω R, slip v − ω R
//   pile.csv           step, t, then per run (warm, cold): kinetic energy, contacts, iterations,
//                      converged, largest penetration, natural-map residual ‖F‖
//   validation.txt     the summary lines the demo prints: measured errors against the closed forms
//   values.txt         key = value lines that the chapter quotes (\demo{…} in chapter.md)
//
// Usage: ch06_validation <data directory>.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "grbd/kinematics/rotation.hpp"
#include "grbd/timestep/midpoint.hpp"
#include "grbd/timestep/stepper.hpp"
#include "grbd_demo/demo.hpp"
#include "scenes.hpp"

namespace {

using namespace grbd;
using timestep::BodyRecord;
using timestep::BodySystem;
using timestep::GlobalId;
using timestep::MaterialTable;
using timestep::MoreauStepper;
using timestep::OverlapHistogram;
using timestep::StaticGeometry;
using timestep::StepReport;
using timestep::StepSettings;

constexpr const char* kProgram = "ch06_validation";
constexpr double kG = 9.81;

/// The summary: printed and kept for validation.txt.
std::string summary;

/// Values the chapter's text quotes (`\demo{ch06_validation/values.txt#KEY}` in chapter.md).
demo::Values values;

void value(const char* key, const char* format, auto... args) { values.set(key, format, args...); }

using demo::tex_power;

void say(const char* format, auto... args) {
  char line[512];
  std::snprintf(line, sizeof line, format, args...);
  summary += line;
  std::cout << line << std::flush;
}

using demo::half_space;
using demo::one_material;
using demo::tight;
using demo::tilted_gravity;

// ---------------------------------------------------------------------------------------------
// The bouncing ball.

struct BallRun {
  std::vector<double> t, gap, exact, energy;
  std::vector<double> impacts;  // start time of each step that reverses an approaching contact
  double rest_from = -1.0;      // from this time on the ball rests (u = 0 to round-off)
  double worst_gain = 0.0;      // largest relative increase of the energy in one step
};

/// The closed-form gap of the ball at time t: free fall to t₁, then arcs leaving impact k with
/// ε^k √(2 g h₀), and rest after the Zeno time.
double exact_gap(double t, double h0, double eps) {
  const double t1 = timestep::bouncing_ball_impact_time(1, h0, kG, eps);
  if (t < t1) return h0 - 0.5 * kG * t * t;
  if (t >= timestep::bouncing_ball_zeno_time(h0, kG, eps)) return 0.0;
  double t_k = t1;
  double v_k = kG * t1;
  for (int k = 1;; ++k) {
    v_k *= eps;
    const double t_next = t_k + 2.0 * v_k / kG;
    if (t < t_next) {
      const double s = t - t_k;
      return v_k * s - 0.5 * kG * s * s;
    }
    t_k = t_next;
    if (k > 2000) return 0.0;
  }
}

BallRun bouncing_ball(double eps, double dt, double t_end) {
  const double r = 0.1;
  const double h0 = 1.0;
  BodySystem system;
  system.add(demo::sphere_body(1, r, Vector3(0.0, 0.0, r + h0)));
  StaticGeometry statics;
  statics.add(half_space(0, Vector3::UnitZ(), 0.0));
  const MaterialTable materials = one_material(0.3, eps);
  MoreauStepper stepper(system, statics, materials, tight(dt));
  const double m = system.inertia()[0].m;
  const double e_rest = m * kG * r;
  const double e0 =
      timestep::mechanical_energy(system.inertia(), system.states(), stepper.settings().I_g) -
      e_rest;
  BallRun run;
  run.t.push_back(0.0);
  run.gap.push_back(h0);
  run.exact.push_back(h0);
  run.energy.push_back(1.0);
  double energy = e0;
  bool resting = false;
  const double eps_mach = std::numeric_limits<double>::epsilon();
  while (stepper.time() < t_end - 0.5 * dt) {
    const double t = stepper.time();
    const double v_before = system.states()[0].u.z();
    const StepReport report = stepper.step();
    if (report.contacts > 0 && v_before < 0.0 && stepper.percussions()[0].x() > 0.0 &&
        system.states()[0].u.z() > 0.0) {
      run.impacts.push_back(t);
    }
    const double e = report.kinetic_energy + report.potential_energy - e_rest;
    run.worst_gain = std::max(run.worst_gain, (e - energy) / e0);
    energy = e;
    const Vector6& u = system.states()[0].u;
    const bool at_rest = u.norm() <= 4.0 * eps_mach * kG * dt;
    if (at_rest && !resting) run.rest_from = stepper.time();
    if (!at_rest) run.rest_from = -1.0;
    resting = at_rest;
    run.t.push_back(stepper.time());
    run.gap.push_back(system.states()[0].q.z() - r);
    run.exact.push_back(exact_gap(stepper.time(), h0, eps));
    run.energy.push_back(e / e0);
  }
  return run;
}

void bouncing_balls(const std::filesystem::path& dir) {
  const double dt = 1e-3;
  const double t_end = 4.5;
  const double epsilons[2] = {0.8, 0.5};
  BallRun runs[2];
  for (int i = 0; i < 2; ++i) runs[i] = bouncing_ball(epsilons[i], dt, t_end);

  demo::OutputFile out(dir / "bouncing_ball.csv",
                       "t,gap_0.8,exact_0.8,energy_0.8,gap_0.5,exact_0.5,energy_0.5");
  char row[256];
  for (std::size_t k = 0; k < runs[0].t.size(); ++k) {
    std::snprintf(row, sizeof row, "%.4f,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e\n", runs[0].t[k],
                  runs[0].gap[k], runs[0].exact[k], runs[0].energy[k], runs[1].gap[k],
                  runs[1].exact[k], runs[1].energy[k]);
    out << row;
  }
  out.finish();

  constexpr int kImpacts = 8;
  demo::OutputFile impacts(dir / "impacts.csv",
                           "k,closed_0.8,measured_0.8,closed_0.5,measured_0.5");
  for (int k = 1; k <= kImpacts; ++k) {
    impacts << k;
    for (int i = 0; i < 2; ++i) {
      const double closed = timestep::bouncing_ball_impact_time(k, 1.0, kG, epsilons[i]);
      impacts << ',' << closed << ',';
      if (k <= static_cast<int>(runs[i].impacts.size())) impacts << runs[i].impacts[k - 1];
    }
    impacts << '\n';
  }
  impacts.finish();

  demo::OutputFile zeno(dir / "zeno.csv", "eps,zeno,rest_from");
  for (int i = 0; i < 2; ++i) {
    const double eps = epsilons[i];
    const BallRun& run = runs[i];
    const double t_zeno = timestep::bouncing_ball_zeno_time(1.0, kG, eps);
    zeno << eps << ',' << t_zeno << ',' << run.rest_from << '\n';
    // Error of impact k in steps, against the bound (k + 1) Δt of the tests.
    double worst = 0.0;
    int worst_k = 0;
    const int n = std::min<int>(kImpacts, static_cast<int>(run.impacts.size()));
    for (int k = 1; k <= n; ++k) {
      const double err =
          std::abs(run.impacts[k - 1] - timestep::bouncing_ball_impact_time(k, 1.0, kG, eps)) / dt;
      if (err > worst) {
        worst = err;
        worst_k = k;
      }
    }
    const std::string ball = eps == 0.8 ? "ball.eps08." : "ball.eps05.";
    value((ball + "worst").c_str(), "%.1f", worst);
    value((ball + "worst_impact").c_str(), "%d", worst_k);
    value((ball + "zeno").c_str(), "%.4f", t_zeno);
    value((ball + "rest_from").c_str(), "%.4f", run.rest_from);
    value((ball + "rest_after_zeno").c_str(), "%.2f", run.rest_from - t_zeno);
    value((ball + "gain").c_str(), "%s", tex_power(std::max(run.worst_gain, 1e-300)).c_str());
    say("bouncing ball, eps = %.1f: %zu impacts measured; impacts 1-%d within %.2f dt of the "
        "closed form (worst: impact %d); Zeno time %.4f s, at rest (|u| <= 4 eps_mach g dt) from "
        "%.4f s; largest energy gain of one step %.1e of E0\n",
        eps, run.impacts.size(), n, worst, worst_k, t_zeno, run.rest_from,
        std::max(run.worst_gain, 0.0));
  }
  zeno.finish();
}

// ---------------------------------------------------------------------------------------------
// Block and sphere on an incline: gravity tilted by θ about y, the floor z = 0.

/// Steps `spec` on the floor with gravity tilted by θ until t_end; returns the velocities along
/// the slope after each step, and the final displacement and spin.
struct Slide {
  std::vector<double> v;
  double x = 0.0;
  double omega_y = 0.0;
};

Slide slide(const BodyRecord& spec, double theta, double mu, double t_end, double dt) {
  BodySystem system;
  system.add(spec);
  StaticGeometry statics;
  statics.add(half_space(0, Vector3::UnitZ(), 0.0));
  const MaterialTable materials = one_material(mu);
  StepSettings settings = tight(dt);
  settings.I_g = tilted_gravity(theta);
  MoreauStepper stepper(system, statics, materials, settings);
  const double x0 = system.states()[0].q.x();
  Slide s;
  s.v.push_back(0.0);
  while (stepper.time() < t_end - 0.5 * dt) {
    stepper.step();
    s.v.push_back(system.states()[0].u.x());
  }
  s.x = system.states()[0].q.x() - x0;
  s.omega_y = system.states()[0].u(4);
  return s;
}

void inclines(const std::filesystem::path& dir) {
  const double mu = 0.5;
  const double theta_c = std::atan(mu);
  const double delta = 0.1 * std::numbers::pi / 180.0;
  const double dt = 1e-3;
  const double t_end = 1.0;
  const Vector3 h(0.1, 0.1, 0.05);
  const BodyRecord block = demo::box_body(1, h, Vector3(0.0, 0.0, h.z()));
  const Slide below = slide(block, theta_c - delta, mu, t_end, dt);
  const double theta = theta_c + delta;
  const double a = kG * (std::sin(theta) - mu * std::cos(theta));
  const Slide above = slide(block, theta, mu, t_end, dt);

  demo::OutputFile out(dir / "incline.csv", "t,v_below,v_above,closed_above");
  double worst_below = 0.0;
  double worst_above = 0.0;
  char row[160];
  for (std::size_t k = 0; k < above.v.size(); ++k) {
    const double t = static_cast<double>(k) * dt;
    worst_below = std::max(worst_below, std::abs(below.v[k]));
    if (k > 0) worst_above = std::max(worst_above, std::abs(above.v[k] - a * t) / (a * t));
    std::snprintf(row, sizeof row, "%.4f,%.6e,%.6e,%.6e\n", t, below.v[k], above.v[k], a * t);
    out << row;
  }
  out.finish();
  value("incline.below_x", "%s", tex_power(std::abs(below.x)).c_str());
  value("incline.below_v", "%s", tex_power(worst_below).c_str());
  value("incline.a", "%.5f", a);
  value("incline.v_error", "%s", tex_power(worst_above).c_str());
  value("incline.x_error", "%s",
        tex_power(std::abs(above.x - 0.5 * a * t_end * t_end) / (0.5 * a * t_end * t_end)).c_str());
  say("block on an incline, mu = %.1f, theta_c = %.4f deg: at theta_c - 0.1 deg after %.0f s "
      "|x| = %.1e m, max |v| = %.1e m/s; at theta_c + 0.1 deg a = g(sin - mu cos) = %.5f m/s^2, "
      "largest relative error of v = a t %.1e, of x = a t^2/2 %.1e\n",
      mu, theta_c * 180.0 / std::numbers::pi, t_end, std::abs(below.x), worst_below, a, worst_above,
      std::abs(above.x - 0.5 * a * t_end * t_end) / (0.5 * a * t_end * t_end));

  // A sphere at 20°: rolls iff μ ≥ (2/7) tan θ.
  const double r = 0.05;
  const double theta_s = 20.0 * std::numbers::pi / 180.0;
  const double mu_roll = 2.0 / 7.0 * std::tan(theta_s);
  const BodyRecord ball = demo::sphere_body(1, r, Vector3(0.0, 0.0, r));
  const Slide roll = slide(ball, theta_s, 1.05 * mu_roll, t_end, dt);
  const double a_roll = 5.0 / 7.0 * kG * std::sin(theta_s);
  const Slide slip = slide(ball, theta_s, 0.95 * mu_roll, t_end, dt);
  const double a_slip = kG * (std::sin(theta_s) - 0.95 * mu_roll * std::cos(theta_s));
  value("sphere.roll_error", "%s",
        tex_power(std::abs(roll.v.back() - a_roll * t_end) / (a_roll * t_end)).c_str());
  value("sphere.roll_slip", "%s",
        tex_power(std::abs(roll.omega_y * r - roll.v.back()) / roll.v.back()).c_str());
  value("sphere.slide_error", "%s",
        tex_power(std::abs(slip.v.back() - a_slip * t_end) / (a_slip * t_end)).c_str());
  value("sphere.slide_spin", "%.3f", slip.omega_y * r / slip.v.back());
  say("sphere on a 20 deg incline: mu = 1.05 (2/7) tan theta rolls, v(1 s) relative error to "
      "(5/7) g sin theta t %.1e, |omega R - v|/v = %.1e; mu = 0.95 (2/7) tan theta slides, "
      "relative error to g(sin - mu cos) t %.1e, omega R/v = %.3f\n",
      std::abs(roll.v.back() - a_roll * t_end) / (a_roll * t_end),
      std::abs(roll.omega_y * r - roll.v.back()) / roll.v.back(),
      std::abs(slip.v.back() - a_slip * t_end) / (a_slip * t_end),
      slip.omega_y * r / slip.v.back());
}

// ---------------------------------------------------------------------------------------------

void billiard(const std::filesystem::path& dir) {
  const double r = 0.0286;
  const double v0 = 2.0;
  const double mu = 0.2;
  const double dt = 1e-4;
  BodySystem system;
  Vector6 u0 = Vector6::Zero();
  u0(0) = v0;
  system.add(demo::sphere_body(1, r, Vector3(0.0, 0.0, r), u0, 1700.0));
  StaticGeometry statics;
  statics.add(half_space(0, Vector3::UnitZ(), 0.0));
  const MaterialTable materials = one_material(mu);
  MoreauStepper stepper(system, statics, materials, tight(dt));
  const double t_star = 2.0 * v0 / (7.0 * mu * kG);
  double t_roll = -1.0;
  demo::OutputFile out(dir / "billiard.csv", "t,v,omega_R,slip");
  out << "0," << v0 << ",0," << v0 << '\n';
  char row[160];
  int step = 0;
  while (stepper.time() < 1.5 * t_star) {
    stepper.step();
    const Vector6& u = system.states()[0].u;
    const double slip = u(0) - u(4) * r;
    if (t_roll < 0.0 && std::abs(slip) <= 1e-9 * v0) t_roll = stepper.time();
    if (++step % 10 == 0) {
      std::snprintf(row, sizeof row, "%.5f,%.9e,%.9e,%.6e\n", stepper.time(), u(0), u(4) * r, slip);
      out << row;
    }
  }
  out.finish();
  value("billiard.t_roll", "%.5f", t_roll);
  value("billiard.t_star", "%.5f", t_star);
  value("billiard.steps_late", "%.2f", std::abs(t_roll - t_star) / dt);
  value("billiard.speed_error", "%s",
        tex_power(std::abs(system.states()[0].u(0) - 5.0 / 7.0 * v0) / (5.0 / 7.0 * v0)).c_str());
  say("billiard ball, v0 = %.1f m/s, mu = %.1f, dt = %.0e s: rolling from t = %.5f s, "
      "t* = 2 v0/(7 mu g) = %.5f s (error %.2f dt); speed %.12f m/s, (5/7) v0 = %.12f m/s "
      "(relative error %.1e)\n",
      v0, mu, dt, t_roll, t_star, std::abs(t_roll - t_star) / dt, system.states()[0].u(0),
      5.0 / 7.0 * v0, std::abs(system.states()[0].u(0) - 5.0 / 7.0 * v0) / (5.0 / 7.0 * v0));
}

// ---------------------------------------------------------------------------------------------

void cradle(const std::filesystem::path& dir) {
  demo::OutputFile out(dir / "cradle.csv", "N,eps,ball,v,closed");
  for (const int N : {3, 5}) {
    for (const double eps : {1.0, 0.0}) {
      BodySystem system;
      const double r = 0.0625;  // centres 2 r i exact in binary: g_N = 0 exactly
      for (int i = 0; i < N; ++i) {
        Vector6 u = Vector6::Zero();
        if (i == 0) u(0) = 1.0;
        system.add(demo::sphere_body(static_cast<GlobalId>(i + 1), r,
                                     Vector3(2.0 * r * i, 0.0, 1.0), u));
      }
      StaticGeometry statics;
      const MaterialTable materials = one_material(0.0, eps);
      StepSettings settings = tight(1e-4);
      settings.I_g.setZero();
      MoreauStepper stepper(system, statics, materials, settings);
      stepper.step();
      double worst = 0.0;
      std::string velocities;
      char field[64];
      for (int i = 0; i < N; ++i) {
        const double v = system.states()[system.index_of(static_cast<GlobalId>(i + 1))].u.x();
        const double closed = eps == 1.0 ? (i == 0 ? (2.0 - N) / N : 2.0 / N) : 1.0 / N;
        worst = std::max(worst, std::abs(v - closed));
        out << N << ',' << eps << ',' << i + 1 << ',' << v << ',' << closed << '\n';
        std::snprintf(field, sizeof field, "%s%.4f", i ? ", " : "", v);
        velocities += field;
      }
      const std::string cradle = "cradle.N" + std::to_string(N) + (eps == 1.0 ? ".eps1." : ".eps0.");
      value((cradle + "velocities").c_str(), "%s", velocities.c_str());
      value((cradle + "error").c_str(), "%s", tex_power(worst).c_str());
      say("Newton's cradle, N = %d, eps = %.0f: v/v0 = (%s), largest error to the simultaneous "
          "impact law %.1e\n",
          N, eps, velocities.c_str(), worst);
    }
  }
  out.finish();
}

// ---------------------------------------------------------------------------------------------

void half_steps() {
  // One body spinning at |ω| = 1 rad/s about an oblique axis, moving at 1 m/s.
  Vector7 q;
  q << 0.0, 0.0, 0.0,
      kinematics::quaternion_from_axis_angle(Vector3(1.0, 2.0, 2.0).normalized(), 0.7).coeffs();
  Vector6 u;
  u << 1.0, 0.0, 0.0, Vector3(0.0, 0.6, 0.8);
  double d[2];
  const double dts[2] = {0.04, 0.02};
  for (int i = 0; i < 2; ++i) {
    d[i] = (timestep::half_step(q, u, dts[i]) - timestep::half_step_add_normalize(q, u, dts[i]))
               .norm();
  }
  say("half step: exp map vs add-and-normalise for |omega| dt/2 = %.2f and %.2f: |dq| = %.2e "
      "and %.2e, ratio %.2f (third order: 8)\n",
      0.5 * dts[0], 0.5 * dts[1], d[0], d[1], d[0] / d[1]);
}

// ---------------------------------------------------------------------------------------------

void painleve() {
  for (const contact::Method method : {contact::Method::apgd, contact::Method::sor}) {
    const BodyRecord rod = demo::painleve_rod();
    BodySystem system;
    system.add(rod);
    StaticGeometry statics;
    statics.add(half_space(0, Vector3::UnitZ(), 0.0));
    const MaterialTable materials = one_material(1.5);
    StepSettings settings;
    settings.dt = 1e-4;
    settings.method = method;
    MoreauStepper stepper(system, statics, materials, settings);
    int with_contact = 0;
    double worst_gain = 0.0;
    double energy = 0.0;
    bool first = true;
    while (stepper.time() < 0.3 - 0.5 * settings.dt) {
      const StepReport report = stepper.step();
      const double e = report.kinetic_energy + report.potential_energy;
      if (!first) worst_gain = std::max(worst_gain, (e - energy) / std::abs(energy));
      energy = e;
      first = false;
      if (report.contacts > 0) ++with_contact;
    }
    const std::string key = method == contact::Method::apgd ? "painleve.apgd." : "painleve.sor.";
    value((key + "capped").c_str(), "%llu",
          static_cast<unsigned long long>(stepper.non_converged_steps()));
    value((key + "with_contact").c_str(), "%d", with_contact);
    value((key + "gain").c_str(), "%s", tex_power(std::max(worst_gain, 1e-300)).c_str());
    say("Painleve rod (mu = 1.5 > 4/3), %s: %llu steps, %d with contact, %llu stopped at "
        "max_iterations; largest energy gain of one step %.1e; state finite: %s\n",
        std::string(contact::method_name(method)).c_str(),
        static_cast<unsigned long long>(stepper.steps()), with_contact,
        static_cast<unsigned long long>(stepper.non_converged_steps()), std::max(worst_gain, 0.0),
        system.states()[0].q.allFinite() && system.states()[0].u.allFinite() ? "yes" : "no");
  }
}

// ---------------------------------------------------------------------------------------------
// A settling pile: spheres dropped from rest on a jittered cubic lattice into an open box.

struct PileRun {
  std::vector<StepReport> reports;
  std::size_t spheres = 0;
  double seconds = 0.0;
  double solve_seconds = 0.0;  // the contact solver's share
};

/// The pile's solvers: SOR warm- and cold-started, and chapter 5's Newton and hybrid, warm.
enum class PileSolver { sor_warm, sor_cold, newton_warm, hybrid_warm };

/// Newton's iterations per step at most: each costs up to 300 GMRES products, so the prox
/// solvers' 1000 would be thousands of sweeps' work.
constexpr int kPileNewtonIterations = 50;
/// The hybrid's SOR sweeps per step at most before Newton takes over.
constexpr int kPileHybridSweeps = 1000;
/// Newton and the hybrid in the time stepper cost 20-35 times SOR's time per step here: they run
/// kLateSteps steps from the warm SOR run's state after kLateStart steps (t = 0.2 s, most
/// spheres in contact), side by side with SOR from the same state.
constexpr std::uint64_t kLateStart = 1000;
constexpr int kLateSteps = 100;

/// The settings of a pile run: the default solver (SOR, its default tolerance and 1000
/// iterations), or Newton and the hybrid with the same criterion and tolerances.
StepSettings pile_settings(PileSolver solver, double dt) {
  StepSettings settings;
  settings.dt = dt;
  settings.warm_start = solver != PileSolver::sor_cold;
  if (solver == PileSolver::newton_warm || solver == PileSolver::hybrid_warm) {
    settings.method = contact::Method::newton;
    settings.solver.max_iterations = kPileNewtonIterations;
  }
  if (solver == PileSolver::hybrid_warm) {
    settings.solver.newton.hybrid_sweeps = kPileHybridSweeps;
    settings.solver.max_iterations = 1 + kPileNewtonIterations;  // the SOR phase is one
  }
  settings.reorder_interval = 50;
  return settings;
}

/// The pile's bodies, box and material, and (a snapshot) its stepper's clock and warm starts.
struct PileState {
  BodySystem system;
  StaticGeometry statics;
  MaterialTable materials;
  timestep::WarmStartTable warm;
  double t = 0.0;
  std::uint64_t steps = 0;
};

PileState pile_state(int n, double r) {
  const double spacing = 2.4 * r;
  const double L = n * spacing + 0.4 * r;
  PileState state;
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> jitter(-0.1 * r, 0.1 * r);
  GlobalId id = 1;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        state.system.add(demo::sphere_body(id++, r,
                          Vector3(1.2 * r + spacing * i + jitter(rng),
                                  1.2 * r + spacing * j + jitter(rng), 1.1 * r + spacing * k)));
      }
    }
  }
  state.statics.add(half_space(0, Vector3::UnitZ(), 0.0));
  state.statics.add(half_space(1, Vector3::UnitX(), 0.0));  // the solid x ≤ 0
  state.statics.add(half_space(2, -Vector3::UnitX(), -L));  // x ≥ L
  state.statics.add(half_space(3, Vector3::UnitY(), 0.0));
  state.statics.add(half_space(4, -Vector3::UnitY(), -L));
  const timestep::MaterialId glass = state.materials.add("glass");
  state.materials.set_pair(glass, glass, {0.5, 0.0, 0.0});
  return state;
}

/// Runs `state` with `solver` until t_end; keeps a snapshot after `snapshot_step` steps when
/// `snapshot` is given. `adjust` may change the settings (the gap-aware law's runs).
PileRun settle(PileState& state, PileSolver solver, double dt, double t_end,
               PileState* snapshot = nullptr, std::uint64_t snapshot_step = 0,
               const std::function<void(StepSettings&)>& adjust = {}) {
  StepSettings settings = pile_settings(solver, dt);
  if (adjust) adjust(settings);
  MoreauStepper stepper(state.system, state.statics, state.materials, settings);
  stepper.warm_starts() = state.warm;
  stepper.set_clock(state.t, state.steps);
  PileRun run;
  run.spheres = state.system.size();
  while (stepper.time() < t_end - 0.5 * dt) {
    stepper.reorder_if_due();
    run.reports.push_back(stepper.step());
    run.seconds += run.reports.back().seconds.total;
    run.solve_seconds += run.reports.back().seconds.solve;
    if (snapshot != nullptr && stepper.steps() == snapshot_step) {
      *snapshot = state;
      snapshot->warm = stepper.warm_starts();
      snapshot->t = stepper.time();
      snapshot->steps = stepper.steps();
    }
  }
  return run;
}

void pile(const std::filesystem::path& dir) {
  // Glass beads of 1 mm radius at the chute's Δt = 0.2 ms (Nützi 2016), six layers.
  const int n = 6;
  const double r = 1e-3;
  const double dt = 2e-4;
  const double t_end = 0.3;
  PileState late;  // the warm run after kLateStart steps
  PileState warm_state = pile_state(n, r);
  PileState cold_state = pile_state(n, r);
  const PileRun warm = settle(warm_state, PileSolver::sor_warm, dt, t_end, &late, kLateStart);
  const PileRun cold = settle(cold_state, PileSolver::sor_cold, dt, t_end);
  // From the warm run's state at step kLateStart, kLateSteps steps with each warm solver.
  const double t_late = late.t + kLateSteps * dt;
  std::vector<PileRun> late_runs;
  for (const PileSolver solver :
       {PileSolver::sor_warm, PileSolver::newton_warm, PileSolver::hybrid_warm}) {
    PileState state = late;
    late_runs.push_back(settle(state, solver, dt, t_late));
  }
  demo::OutputFile out(dir / "pile.csv",
                       "step,t,Ek_warm,contacts_warm,iterations_warm,converged_warm,"
                       "penetration_warm,residual_warm,Ek_cold,contacts_cold,iterations_cold,"
                       "converged_cold,penetration_cold,residual_cold");
  char row[400];
  for (std::size_t k = 0; k < warm.reports.size(); ++k) {
    const StepReport& w = warm.reports[k];
    const StepReport& c = cold.reports[k];
    std::snprintf(row, sizeof row, "%llu,%.5f,%.6e,%zu,%d,%d,%.6e,%.6e,%.6e,%zu,%d,%d,%.6e,%.6e\n",
                  static_cast<unsigned long long>(w.step), w.t, w.kinetic_energy, w.contacts,
                  w.iterations, w.converged ? 1 : 0, w.max_penetration, w.residual,
                  c.kinetic_energy, c.contacts, c.iterations, c.converged ? 1 : 0,
                  c.max_penetration, c.residual);
    out << row;
  }
  out.finish();
  value("pile.steps", "%zu", warm.reports.size());
  long iterations_of[2] = {0, 0};
  for (const PileRun* run : std::initializer_list<const PileRun*>{
           &warm, &cold, &late_runs[0], &late_runs[1], &late_runs[2]}) {
    // Iterations over the steps with contacts, and over the last quarter (the settled pile).
    long total = 0;
    long late = 0;
    int late_steps = 0;
    int non_converged = 0;
    double penetration = 0.0;
    double log_residual = 0.0;
    const std::size_t steps = run->reports.size();
    for (std::size_t k = 0; k < steps; ++k) {
      const StepReport& report = run->reports[k];
      total += report.iterations;
      if (!report.converged) ++non_converged;
      if (4 * k >= 3 * steps) {
        late += report.iterations;
        log_residual += std::log(std::max(report.residual, 1e-300));
        ++late_steps;
      }
      penetration = std::max(penetration, report.max_penetration);
    }
    const StepReport& last = run->reports.back();
    const char* const name = run == &warm           ? "warm"
                             : run == &cold         ? "cold"
                             : run == &late_runs[0] ? "late_sor"
                             : run == &late_runs[1] ? "late_newton"
                                                    : "late_hybrid";
    const std::string key = "pile." + std::string(name) + ".";
    if (run == &warm || run == &cold) iterations_of[run == &warm ? 0 : 1] = total;
    value((key + "solve").c_str(), "%.1f", run->solve_seconds);
    value((key + "solve_ms").c_str(), "%.1f", 1e3 * run->solve_seconds / double(steps));
    value((key + "iterations").c_str(), "%.0f", double(total) / double(steps));
    value((key + "iterations_late").c_str(), "%.0f", double(late) / late_steps);
    value((key + "capped").c_str(), "%d", non_converged);
    value((key + "residual_late").c_str(), "%s",
          tex_power(std::exp(log_residual / late_steps)).c_str());
    value((key + "contacts").c_str(), "%zu", last.contacts);
    value((key + "cpu").c_str(), "%.1f", run->seconds);
    value((key + "penetration").c_str(), "%s", tex_power(penetration).c_str());
    say("pile of %zu spheres (r = %.0e m, mu = 0.5), %s, dt = %.0e s, %zu steps to t = %.2f s: "
        "%zu contacts at the end, E_kin %.1e J; iterations per step %.1f on average, %.1f over the last "
        "quarter (geometric mean of the residual ||F|| there %.1e); %d of %zu steps at "
        "max_iterations; "
        "largest penetration %.2e m (%.1e r); %.1f s of CPU, %.1f s of it in the solver\n",
        run->spheres, r, name, dt, steps, last.t, last.contacts,
        last.kinetic_energy, double(total) / double(steps), double(late) / late_steps,
        std::exp(log_residual / late_steps), non_converged, steps, penetration, penetration / r,
        run->seconds, run->solve_seconds);
  }
  value("pile.late.newton_over_sor", "%.0f", late_runs[1].solve_seconds / late_runs[0].solve_seconds);
  value("pile.late.hybrid_over_sor", "%.0f", late_runs[2].solve_seconds / late_runs[0].solve_seconds);
  value("pile.warm.saves_iterations", "%.0f",
        100.0 * (1.0 - double(iterations_of[0]) / double(iterations_of[1])));
  value("pile.warm.saves_time", "%.0f", 100.0 * (1.0 - warm.seconds / cold.seconds));
}

// The gap-aware normal law on the same pile (The gap-aware normal law): SOR warm-started with
// chapter 8's practice — tolerance 1e-4, at most 100 sweeps — with the law off and at two
// settings; the overlaps, convergence and energies of the settled pile (the last quarter).
void gap_law_pile() {
  const int n = 6;
  const double r = 1e-3;
  const double dt = 2e-4;
  const double t_end = 0.3;
  struct Law {
    const char* name;
    double beta;
    double v_max;
    double look_ahead;  // in units of r
  };
  for (const Law law : {Law{"off", 0.0, 1.0, 0.0}, Law{"b1v001", 1.0, 0.01, 0.0},
                        Law{"b02v005", 0.2, 0.05, 0.0}, Law{"ahead", 0.0, 1.0, 0.1},
                        Law{"ahead_b02v005", 0.2, 0.05, 0.1}}) {
    PileState state = pile_state(n, r);
    const PileRun run = settle(state, PileSolver::sor_warm, dt, t_end, nullptr, 0,
                               [&](StepSettings& s) {
                                 s.solver.rel_tol = 1e-4;
                                 s.solver.max_iterations = 100;
                                 s.overlap_recovery = law.beta;
                                 s.max_recovery_speed = law.v_max;
                                 s.look_ahead = law.look_ahead;
                               });
    const std::size_t steps = run.reports.size();
    OverlapHistogram late;
    double largest = 0.0;
    double sum = 0.0;
    std::size_t contacts = 0;
    int converged = 0;
    int late_steps = 0;
    for (std::size_t k = 3 * steps / 4; k < steps; ++k) {
      const StepReport& report = run.reports[k];
      late.add(report.overlaps);
      largest = std::max(largest, report.max_penetration);
      sum += report.mean_penetration * static_cast<double>(report.contacts);
      contacts += report.contacts;
      converged += report.converged ? 1 : 0;
      ++late_steps;
    }
    const StepReport& last = run.reports.back();
    const std::string key = "gap." + std::string(law.name) + ".";
    const double mean = sum / static_cast<double>(std::max<std::size_t>(contacts, 1));
    // Micrometres as TeX: two digits, powers of ten below 0.01 µm.
    const auto um = [](double metres) {
      const double x = 1e6 * metres;
      if (x <= 0.0) return std::string("0");
      if (x < 0.01) return tex_power(x);
      char text[32];
      std::snprintf(text, sizeof text, "%.2g", x);
      return std::string(text);
    };
    value((key + "largest").c_str(), "%s", um(largest).c_str());
    value((key + "p99").c_str(), "%s", um(late.quantile(0.99) * r).c_str());
    value((key + "mean").c_str(), "%s", um(mean).c_str());
    value((key + "converged").c_str(), "%.0f", 100.0 * converged / late_steps);
    value((key + "kinetic").c_str(), "%s", tex_power(last.kinetic_energy).c_str());
    value((key + "cpu").c_str(), "%.1f", run.seconds);
    say("gap-aware law on the pile, %s (beta_g %.1f, v_max %.2f m/s, look-ahead %.1f r), SOR tol 1e-4, at most 100 "
        "sweeps, last quarter: largest overlap %.2g um, 99th percentile %.2g um, mean %.2g um; "
        "%d of %d steps converged; E_kin at the end %.1e J; %.1f s\n",
        law.name, law.beta, law.v_max, law.look_ahead, 1e6 * largest, 1e6 * late.quantile(0.99) * r, 1e6 * mean,
        converged, late_steps, last.kinetic_energy, run.seconds);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>"},
          "writes bouncing_ball.csv, impacts.csv, zeno.csv, incline.csv, billiard.csv, "
          "cradle.csv, pile.csv, validation.txt and values.txt (the numbers the chapter quotes)")) {
    return *exit_code;
  }
  try {
    const std::filesystem::path dir = argv[1];
    bouncing_balls(dir);
    inclines(dir);
    billiard(dir);
    cradle(dir);
    half_steps();
    painleve();
    pile(dir);
    gap_law_pile();
    grbd::demo::OutputFile table(dir / "validation.txt");
    table << summary;
    table.finish();
    values.write(dir / "values.txt");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "Exercises 6.1-6.6");
  }
}
