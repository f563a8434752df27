// Chapter 3 demo: the convergence study of the integrators of chapter 2.
//
// The torque-free asymmetric body of tumbling_body.hpp (K_Theta = (2, 3, 4) kg m²,
// K_omega(0) = (1, 1, 1) rad/s) is integrated to T = 10 s by every integrator of
// grbd::body::integrators() with the steps h = 0.1 · 2^−k s, k = 0 … 8 (100 to 25 600 steps),
// and compared at T with a CVODE reference (BDF, rtol 1e-12, |p| = 1 projected). The reference is
// checked twice: its ω(T) against the closed form of Landau–Lifshitz §37 (grbd::ode::euler_top),
// and its orientation against a more accurate second reference, ARKODE's explicit Runge–Kutta
// pair of order 8 at rtol 1e-13. The difference, about 3e-10 rad, is the reference's own error;
// the steps stop where the smallest measured error (Lie–Poisson's) is still a hundred times
// larger.
//
// For every integrator the file `<name>.csv` is written to the data directory, one row per h:
//
//   h_s               step size [s]
//   steps             number of steps to T
//   angle_error_rad   angle of the rotation between the computed and the reference orientation
//   omega_error_rad_s |K_omega − K_omega_ref| at T [rad/s]
//
// The observed orders (grbd::ode::observed_order, least squares over the five finest steps,
// h ≤ 6.25 ms) are printed in one summary line.
//
// Usage: `ch03_convergence <data directory>`.

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <span>
#include <string>
#include <vector>

#include "grbd/body/integrators.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/ode/convergence.hpp"
#include "grbd/ode/references.hpp"
#include "grbd_demo/demo.hpp"
#include "tumbling_body.hpp"

namespace {

using namespace ch03;

constexpr double kEndTime = 10.0;  // T [s]
constexpr double kCoarsest = 0.1;  // h for k = 0 [s]
constexpr int kRefinements = 9;    // k = 0 … 8
constexpr int kFitPoints = 5;      // the observed order is fitted over the finest five

struct Result {
  std::string name;
  int expected_order = 0;
  double angle_order = 0.0;
  double omega_order = 0.0;
  double finest_angle_error = 0.0;
};

Result study(const body::RigidBody& rb, const body::State& x0, const body::IntegratorInfo& info,
             const body::State& x_ref, const std::filesystem::path& data_dir) {
  grbd::demo::OutputFile out = open_csv(data_dir / (std::string(info.name) + ".csv"),
                                        "h_s,steps,angle_error_rad,omega_error_rad_s");
  std::vector<double> hs;
  std::vector<double> angle_errors;
  std::vector<double> omega_errors;
  const body::Loads no_loads;
  for (int k = 0; k < kRefinements; ++k) {
    const long steps = std::lround(kEndTime / kCoarsest) << k;
    const double h = kEndTime / static_cast<double>(steps);
    body::State x = x0;
    for (long n = 0; n < steps; ++n) {
      x = body::step(rb, x, no_loads, h, info.scheme);
    }
    const StateError e = state_error(x, x_ref);
    if (!std::isfinite(e.angle) || !std::isfinite(e.omega)) {
      throw grbd::Error(std::string(info.name) +
                        " produced a non-finite state at h = " + std::to_string(h) + " s");
    }
    out << h << ',' << steps << ',' << e.angle << ',' << e.omega << '\n';
    hs.push_back(h);
    angle_errors.push_back(e.angle);
    omega_errors.push_back(e.omega);
  }
  out.finish();
  const auto finest = [](const std::vector<double>& v) {
    return std::span<const double>(v).last(kFitPoints);
  };
  return {std::string(info.name), info.order, ode::observed_order(finest(hs), finest(angle_errors)),
          ode::observed_order(finest(hs), finest(omega_errors)), angle_errors.back()};
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch03_convergence", {"<data directory>"},
          "writes <integrator>.csv for every integrator of chapter 2")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];
  try {
    const body::RigidBody rb = tumbling_body();
    const body::State x0 = tumbling_start();

    const Reference reference = cvode_reference(rb, x0, kEndTime);
    const StateError ref_vs_arkode = state_error(reference.x, arkode_reference(rb, x0, kEndTime));
    const ode::EulerTop top = ode::euler_top(rb.K_Theta, kin::angular_velocity(x0.u));
    const double ref_vs_closed_form =
        (kin::angular_velocity(reference.x.u) - ode::euler_top_omega(top, kEndTime)).norm();

    std::vector<Result> results;
    for (const body::IntegratorInfo& info : body::integrators()) {
      results.push_back(study(rb, x0, info, reference.x, data_dir));
    }

    std::printf(
        "ch03_convergence: T = %g s, h = %g ... %.3g s; reference CVODE BDF rtol 1e-12 "
        "(%ld steps): |omega - closed form| = %.1e rad/s, angle to ARKODE order-8 reference %.1e "
        "rad "
        "(lambda = %.4f 1/s, m = %.4f, period %.3f s); observed orders (angle / omega, %d finest "
        "h):",
        kEndTime, kCoarsest, kCoarsest / static_cast<double>(1 << (kRefinements - 1)),
        reference.statistics.steps, ref_vs_closed_form, ref_vs_arkode.angle, top.lambda, top.m,
        top.period, kFitPoints);
    for (const Result& r : results) {
      std::printf(" %s %.3f / %.3f (expected %d, angle error %.1e at the finest h);",
                  r.name.c_str(), r.angle_order, r.omega_order, r.expected_order,
                  r.finest_angle_error);
    }
    std::printf("\n");
  } catch (...) {
    return grbd::demo::report_exception("ch03_convergence", "the exercises of chapters 1 to 3");
  }
  return 0;
}
