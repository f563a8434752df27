// Chapter 3 demo: work–precision diagrams.
//
// The problem of the convergence study (tumbling_body.hpp: K_Theta = (2, 3, 4) kg m²,
// K_omega(0) = (1, 1, 1) rad/s, torque-free, end time T = 10 s) is solved
//
//   - by every integrator of chapter 2 with h = 0.1 · 2^−k s, k = 0 … 10;
//   - by CVODE (BDF with |p| = 1 projected, and Adams, which CVODE cannot project) and by ARKODE's
//   explicit Runge–Kutta methods
//     of orders 2, 4 and 8, with rtol = atol = 10^−3, 10^−3.5, …, 10^−10,
//
// and every run's error at T (the angle between its orientation and the reference's) is set
// against its cost, counted two ways: evaluations of the
// right-hand side (SUNDIALS' statistics, difference-quotient Jacobians included; for the
// fixed-step schemes of chapter 2, one per step) and wall time (each run repeated until 10 ms
// have passed and at least three times unless that takes more than 0.1 s, the shortest time
// taken).
//
// For every method the file `<method>.csv` is written to the data directory, one row per h or
// tolerance:
//
//   parameter          h [s] for the schemes of chapter 2, rtol for SUNDIALS
//   rhs_evaluations    right-hand-side evaluations (for chapter 2: steps)
//   steps              (accepted) steps
//   seconds            wall time of one run [s]
//   angle_error_rad    orientation error at T [rad]
//   omega_error_rad_s  |K_omega − K_omega_ref| at T [rad/s]
//
// The reference is ARKODE's explicit Runge–Kutta pair of order 8 at rtol 1e-13 (tumbling_body.hpp),
// not the CVODE reference of the convergence study, whose own error (3e-10 rad) would hide the
// most accurate runs; the summary line reports the distance between the two and between the
// reference's ω(T) and the closed form of Landau–Lifshitz §37.
//
// A summary line names, for the errors 1e-3, 1e-6 and 1e-9 rad, the cheapest method that reached
// each, by evaluations and by wall time. The numbers the chapter quotes are written to
// `values.txt` (key = value lines read by the book at build time:
// \demo{ch03_work_precision/values.txt#KEY} in chapter.md):
//
//   ref.omega_error, ref.cvode_angle  the reference's |ω − closed form| [rad/s] and its angle to
//                                     the CVODE reference [rad]
//   e<k>.evaluations, e<k>.time       for the error 10^-k rad (k = 3, 6, 9): the cheapest run by
//                                     evaluations and by wall time, as "method, parameter: cost"
//   adams.floor                       the error of CVODE Adams at rtol 1e-10 [rad]
//   sundials.min_ms                   the shortest SUNDIALS run [ms]
//   first_order.steps_e3              the fewest steps of a first-order scheme to 1e-3 rad
//   lie_poisson.steps_e3              the fewest steps of lie_poisson to 1e-3 rad
//   e3.splitting_over_adaptive        lie_poisson's shortest time to 1e-3 rad over the shortest of
//                                     the SUNDIALS runs
//   erk2.best_error, erk2_over_erk8   ARKODE order 2's smallest error, and its evaluations for it
//                                     over the fewest of order 8 to an error at least as small
//   seconds                           the wall time of the whole program [s]
//
// Usage: `ch03_work_precision <data directory>`.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "grbd/body/integrators.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/ode/references.hpp"
#include "grbd_demo/demo.hpp"
#include "tumbling_body.hpp"

namespace {

using namespace ch03;

constexpr double kEndTime = 10.0;     // T [s]
constexpr double kCoarsest = 0.1;     // h for k = 0 [s]
constexpr int kRefinements = 11;      // k = 0 … 10
constexpr double kMinSeconds = 0.01;  // repeat a run until this much wall time has passed …
constexpr int kMinRepetitions = 3;    // … and at least this often,
constexpr double kMaxSeconds = 0.1;   // unless that takes longer than this

struct Run {
  double parameter = 0.0;
  long rhs_evaluations = 0;
  long steps = 0;
  double seconds = 0.0;
  StateError error;
};

struct Method {
  std::string name;
  std::vector<Run> runs;
};

/// Runs `solve` (which returns the state at T and fills in the counts) until kMinSeconds have
/// passed and at least three times (unless that takes more than kMaxSeconds), and keeps the
/// shortest wall time of one run: the other processes of a busy machine can only make a run slower.
Run measure(double parameter, const std::function<body::State(Run&)>& solve,
            const body::State& x_ref) {
  Run run;
  run.parameter = parameter;
  run.seconds = std::numeric_limits<double>::infinity();
  int repetitions = 0;
  body::State x;
  const auto start = std::chrono::steady_clock::now();
  do {
    const auto run_start = std::chrono::steady_clock::now();
    x = solve(run);
    run.seconds = std::min(run.seconds, seconds_since(run_start));
    ++repetitions;
  } while (seconds_since(start) < kMinSeconds ||
           (repetitions < kMinRepetitions && seconds_since(start) < kMaxSeconds));
  run.error = state_error(x, x_ref);
  if (!std::isfinite(run.error.angle) || !std::isfinite(run.error.omega)) {
    throw grbd::Error("a run with parameter " + std::to_string(parameter) +
                      " produced a non-finite state");
  }
  return run;
}

Method fixed_step(const body::RigidBody& rb, const body::State& x0, body::Integrator scheme,
                  const body::State& x_ref) {
  Method method{std::string(body::integrator_name(scheme)), {}};
  const body::Loads no_loads;
  for (int k = 0; k < kRefinements; ++k) {
    const long steps = std::lround(kEndTime / kCoarsest) << k;
    const double h = kEndTime / static_cast<double>(steps);
    method.runs.push_back(measure(
        h,
        [&](Run& run) {
          body::State x = x0;
          for (long n = 0; n < steps; ++n) {
            x = body::step(rb, x, no_loads, h, scheme);
          }
          run.steps = steps;
          run.rhs_evaluations = steps;
          return x;
        },
        x_ref));
  }
  return method;
}

std::vector<double> tolerances() {
  std::vector<double> tols;
  for (int i = 0; i <= 14; ++i) {
    tols.push_back(std::pow(10.0, -3.0 - 0.5 * i));
  }
  return tols;
}

ode::Tolerances uniform(double tol) {
  ode::Tolerances t;
  t.rtol = tol;
  t.atol = tol;
  return t;
}

body::State finish(const ode::Statistics& stats, const Eigen::VectorXd& y, Run& run) {
  run.steps = stats.steps;
  run.rhs_evaluations = stats.rhs_evaluations;
  return ode::unpack(y);
}

Method cvode(const body::RigidBody& rb, const body::State& x0, ode::CvodeMethod which,
             const std::string& name, const body::State& x_ref) {
  Method method{name, {}};
  for (const double tol : tolerances()) {
    method.runs.push_back(measure(
        tol,
        [&](Run& run) {
          ode::Cvode solver(ode::free_body(rb), 0.0, ode::pack(x0), which, uniform(tol));
          if (which == ode::CvodeMethod::bdf) {  // CVODE projects only with BDF
            solver.set_projection(ode::quaternion_projection_at(3));
          }
          solver.set_max_steps(10'000'000);
          const Eigen::VectorXd y = solver.advance(kEndTime);
          return finish(solver.statistics(), y, run);
        },
        x_ref));
  }
  return method;
}

Method arkode(const body::RigidBody& rb, const body::State& x0, int order,
              const body::State& x_ref) {
  Method method{"arkode_erk" + std::to_string(order), {}};
  for (const double tol : tolerances()) {
    method.runs.push_back(measure(
        tol,
        [&](Run& run) {
          ode::Arkode solver(ode::free_body(rb), ode::RhsFunction{}, 0.0, ode::pack(x0), order,
                             uniform(tol));
          solver.set_max_steps(10'000'000);
          const Eigen::VectorXd y = solver.advance(kEndTime);
          return finish(solver.statistics(), y, run);
        },
        x_ref));
  }
  return method;
}

void write(const Method& method, const std::filesystem::path& data_dir) {
  grbd::demo::OutputFile out =
      open_csv(data_dir / (method.name + ".csv"),
               "parameter,rhs_evaluations,steps,seconds,angle_error_rad,omega_error_rad_s");
  for (const Run& r : method.runs) {
    out << r.parameter << ',' << r.rhs_evaluations << ',' << r.steps << ',' << r.seconds << ','
        << r.error.angle << ',' << r.error.omega << '\n';
  }
  out.finish();
}

/// The cheapest run of `methods` whose error is at most `target`, by `cost`, and its method (both
/// null when none reached it). `which` selects the methods taken into account.
struct Cheapest {
  const Method* method = nullptr;
  const Run* run = nullptr;
};
Cheapest cheapest(
    const std::vector<Method>& methods, double target,
    const std::function<double(const Run&)>& cost,
    const std::function<bool(const Method&)>& which = [](const Method&) { return true; }) {
  Cheapest best;
  for (const Method& m : methods) {
    if (!which(m)) continue;
    for (const Run& r : m.runs) {
      if (r.error.angle <= target && (best.run == nullptr || cost(r) < cost(*best.run))) {
        best = {&m, &r};
      }
    }
  }
  return best;
}

void print_cheapest(const std::vector<Method>& methods, double target,
                    const std::function<double(const Run&)>& cost, const char* unit) {
  const auto [best_method, best] = cheapest(methods, target, cost);
  if (best == nullptr) {
    std::printf(" none reached %.0e;", target);
  } else {
    std::printf(" %s %.3g %s (parameter %.2g, error %.1e);", best_method->name.c_str(), cost(*best),
                unit, best->parameter, best->error.angle);
  }
}

bool is_sundials(const Method& m) {
  return m.name.starts_with("cvode") || m.name.starts_with("arkode");
}

/// How the chapter names a method and its parameter: "(d) Lie–Poisson, \f$h = 50\f$ ms",
/// "ARKODE order 8, \f$\mathrm{rtol} = 10^{-6.5}\f$".
std::string run_label(const Method& m, const Run& r) {
  static const std::pair<const char*, const char*> names[] = {
      {"explicit_exp_map", "(a) `explicit_exp_map`"},
      {"symplectic_exp_map", "(b) `symplectic_exp_map`"},
      {"explicit_euler_normalized", "(c) `explicit_euler_normalized`"},
      {"lie_poisson", "(d) Lie–Poisson"},
      {"implicit_gyroscopic", "(e) `implicit_gyroscopic`"},
      {"cvode_bdf", "CVODE BDF"},
      {"cvode_adams", "CVODE Adams"},
      {"arkode_erk2", "ARKODE order 2"},
      {"arkode_erk4", "ARKODE order 4"},
      {"arkode_erk8", "ARKODE order 8"}};
  std::string label = m.name;
  for (const auto& [name, text] : names) {
    if (m.name == name) label = text;
  }
  char parameter[96];
  if (is_sundials(m)) {
    std::snprintf(parameter, sizeof parameter, "\\f$\\mathrm{rtol} = 10^{%g}\\f$",
                  std::round(2.0 * std::log10(r.parameter)) / 2.0);
  } else {
    std::snprintf(parameter, sizeof parameter, "\\f$h = %g\\f$ ms", 1e3 * r.parameter);
  }
  return label + ", " + parameter;
}

/// The cell "method, parameter: cost" of the cheapest run to `target` by `cost`, or "none".
std::string cheapest_cell(const std::vector<Method>& methods, double target,
                          const std::function<double(const Run&)>& cost, const char* format) {
  const auto [method, run] = cheapest(methods, target, cost);
  if (run == nullptr) return "none";
  char text[32];
  std::snprintf(text, sizeof text, format, cost(*run));
  return run_label(*method, *run) + ": " + text;
}

/// The method called `name`; throws grbd::Error if there is none.
const Method& method_named(const std::vector<Method>& methods, const std::string& name) {
  for (const Method& m : methods) {
    if (m.name == name) return m;
  }
  throw grbd::Error("no method " + name);
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code =
          grbd::demo::check_arguments(argc, argv, "ch03_work_precision", {"<data directory>"},
                                      "writes <method>.csv for the integrators of chapter 2, CVODE "
                                      "and ARKODE, and values.txt")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];
  try {
    const auto start = std::chrono::steady_clock::now();
    const body::RigidBody rb = tumbling_body();
    const body::State x0 = tumbling_start();
    const body::State x_ref = arkode_reference(rb, x0, kEndTime);
    const double ref_vs_cvode = state_error(cvode_reference(rb, x0, kEndTime).x, x_ref).angle;
    const double ref_vs_closed_form =
        (kin::angular_velocity(x_ref.u) -
         ode::euler_top_omega(ode::euler_top(rb.K_Theta, kin::angular_velocity(x0.u)), kEndTime))
            .norm();

    // Every method's file is written as soon as its runs are done: a file that cannot be written
    // stops the program before it measures the other methods.
    std::vector<Method> methods;
    const auto add = [&](Method method) {
      write(method, data_dir);
      methods.push_back(std::move(method));
    };
    for (const body::IntegratorInfo& info : body::integrators()) {
      add(fixed_step(rb, x0, info.scheme, x_ref));
    }
    add(cvode(rb, x0, ode::CvodeMethod::bdf, "cvode_bdf", x_ref));
    add(cvode(rb, x0, ode::CvodeMethod::adams, "cvode_adams", x_ref));
    for (const int order : {2, 4, 8}) {
      add(arkode(rb, x0, order, x_ref));
    }

    std::printf(
        "ch03_work_precision: T = %g s; reference ARKODE order 8, rtol 1e-13: "
        "|omega - closed form| = %.1e rad/s, angle to the CVODE reference %.1e rad; "
        "cheapest to reach an orientation error of",
        kEndTime, ref_vs_closed_form, ref_vs_cvode);
    for (const double target : {1e-3, 1e-6, 1e-9}) {
      std::printf(" %.0e rad, by evaluations:", target);
      print_cheapest(
          methods, target, [](const Run& r) { return double(r.rhs_evaluations); }, "evaluations");
      std::printf(" by time:");
      print_cheapest(
          methods, target, [](const Run& r) { return 1e3 * r.seconds; }, "ms");
    }
    std::printf(" (%.1f s)\n", seconds_since(start));

    // The numbers the chapter quotes.
    grbd::demo::Values values;
    values.set("ref.omega_error", "%s", tex_or_zero(ref_vs_closed_form).c_str());
    values.set("ref.cvode_angle", "%s", tex_or_zero(ref_vs_cvode).c_str());
    const auto evaluations = [](const Run& r) { return double(r.rhs_evaluations); };
    const auto milliseconds = [](const Run& r) { return 1e3 * r.seconds; };
    for (const int k : {3, 6, 9}) {
      const double target = std::pow(10.0, -k);
      const std::string key = "e" + std::to_string(k);
      values.set(key + ".evaluations", "%s",
                 cheapest_cell(methods, target, evaluations, "%.0f").c_str());
      values.set(key + ".time", "%s", cheapest_cell(methods, target, milliseconds, "%#.2g ms").c_str());
    }
    values.set("adams.floor", "%s",
               tex_or_zero(method_named(methods, "cvode_adams").runs.back().error.angle).c_str());
    double sundials_min = std::numeric_limits<double>::infinity();
    for (const Method& m : methods) {
      if (!is_sundials(m)) continue;
      for (const Run& r : m.runs) sundials_min = std::min(sundials_min, r.seconds);
    }
    values.set("sundials.min_ms", "%#.2g", 1e3 * sundials_min);
    const auto steps = [](const Run& r) { return double(r.steps); };
    const Cheapest first_order = cheapest(methods, 1e-3, steps, [](const Method& m) {
      return !is_sundials(m) && m.name != "lie_poisson";
    });
    const Cheapest splitting_steps =
        cheapest(methods, 1e-3, steps, [](const Method& m) { return m.name == "lie_poisson"; });
    const Cheapest splitting_time = cheapest(methods, 1e-3, milliseconds, [](const Method& m) {
      return m.name == "lie_poisson";
    });
    const Cheapest adaptive_time = cheapest(methods, 1e-3, milliseconds, is_sundials);
    if (first_order.run == nullptr || splitting_steps.run == nullptr ||
        adaptive_time.run == nullptr) {
      throw grbd::Error("no first-order, Lie-Poisson or SUNDIALS run reached 1e-3 rad");
    }
    values.set("first_order.steps_e3", "%s", grouped(first_order.run->steps).c_str());
    values.set("lie_poisson.steps_e3", "%ld", splitting_steps.run->steps);
    values.set("e3.splitting_over_adaptive", "%.1f",
               splitting_time.run->seconds / adaptive_time.run->seconds);
    const Method& erk2 = method_named(methods, "arkode_erk2");
    const Run* erk2_best = &erk2.runs.front();
    for (const Run& r : erk2.runs) {
      if (r.error.angle < erk2_best->error.angle) erk2_best = &r;
    }
    const Cheapest erk8 = cheapest(methods, erk2_best->error.angle, evaluations,
                                   [](const Method& m) { return m.name == "arkode_erk8"; });
    values.set("erk2.best_error", "%s", tex_or_zero(erk2_best->error.angle).c_str());
    if (erk8.run != nullptr) {
      values.set("erk2_over_erk8", "%.0f",
                 double(erk2_best->rhs_evaluations) / double(erk8.run->rhs_evaluations));
    }
    values.set("seconds", "%.1f", seconds_since(start));
    values.write(data_dir / "values.txt");
  } catch (...) {
    return grbd::demo::report_exception("ch03_work_precision", "the exercises of chapters 1 to 3");
  }
  return 0;
}
