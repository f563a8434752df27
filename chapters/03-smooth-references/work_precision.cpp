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
// each, by evaluations and by wall time.
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

/// The cheapest run of all methods whose error is at most `target`, by `cost`.
void print_cheapest(const std::vector<Method>& methods, double target,
                    const std::function<double(const Run&)>& cost, const char* unit) {
  const Method* best_method = nullptr;
  const Run* best = nullptr;
  for (const Method& m : methods) {
    for (const Run& r : m.runs) {
      if (r.error.angle <= target && (best == nullptr || cost(r) < cost(*best))) {
        best = &r;
        best_method = &m;
      }
    }
  }
  if (best == nullptr) {
    std::printf(" none reached %.0e;", target);
  } else {
    std::printf(" %s %.3g %s (parameter %.2g, error %.1e);", best_method->name.c_str(), cost(*best),
                unit, best->parameter, best->error.angle);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code =
          grbd::demo::check_arguments(argc, argv, "ch03_work_precision", {"<data directory>"},
                                      "writes <method>.csv for the integrators of chapter 2, CVODE "
                                      "and ARKODE")) {
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
  } catch (...) {
    return grbd::demo::report_exception("ch03_work_precision", "the exercises of chapters 1 to 3");
  }
  return 0;
}
