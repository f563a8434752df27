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
// h ≤ 6.25 ms) are printed in one summary line. The numbers the chapter quotes are written to
// `values.txt` (key = value lines read by the book at build time:
// \demo{ch03_convergence/values.txt#KEY} in chapter.md):
//
//   top.lambda, top.m, top.period          the closed form's λ [1/s], m and period of ω [s]
//   ref.steps, ref.omega_error, ref.angle  the reference's steps, |ω − closed form| [rad/s] and
//                                          its angle to the ARKODE reference [rad]
//   ref.adams13, ref.bdf13, ref.bdf14      the angle to the ARKODE reference of CVODE Adams at
//                                          rtol 1e-13 and BDF at 1e-13 and 1e-14 (atol 1e-14) [rad]
//   <integrator>.order, .angle_order, .omega_order, .finest_error
//                                          expected and observed orders, the angle error at the
//                                          finest h [rad]
//   order_deviation                        the largest |observed − expected order|
//   finest_ratio                           explicit_exp_map's error over lie_poisson's, finest h
//   floor_ratio                            lie_poisson's error at the finest h over ref.angle
//   coarsest_error                         the largest first-order error at h = 0.1 s [rad]
//   seconds                                wall time of the whole program [s]
//
// Usage: `ch03_convergence <data directory>`.

#include <algorithm>
#include <chrono>
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
  double coarsest_angle_error = 0.0;
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
          ode::observed_order(finest(hs), finest(omega_errors)), angle_errors.back(),
          angle_errors.front()};
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch03_convergence", {"<data directory>"},
          "writes <integrator>.csv for every integrator of chapter 2 and values.txt")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];
  try {
    const auto start = std::chrono::steady_clock::now();
    const body::RigidBody rb = tumbling_body();
    const body::State x0 = tumbling_start();

    const Reference reference = cvode_reference(rb, x0, kEndTime);
    const body::State arkode = arkode_reference(rb, x0, kEndTime);
    const StateError ref_vs_arkode = state_error(reference.x, arkode);
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

    // The numbers the chapter quotes. How good CVODE can be as a reference: its angle to the
    // ARKODE reference with Adams and with tighter tolerances.
    const auto angle_to_arkode = [&](ode::CvodeMethod method, double rtol) {
      return state_error(cvode_reference(rb, x0, kEndTime, method, rtol).x, arkode).angle;
    };
    grbd::demo::Values values;
    values.set("top.lambda", "%.4f", top.lambda);
    values.set("top.m", "%.4f", top.m);
    values.set("top.period", "%.3f", top.period);
    values.set("ref.steps", "%ld", reference.statistics.steps);
    values.set("ref.omega_error", "%s", tex_or_zero(ref_vs_closed_form).c_str());
    values.set("ref.angle", "%s", tex_or_zero(ref_vs_arkode.angle).c_str());
    values.set("ref.adams13", "%s",
               tex_or_zero(angle_to_arkode(ode::CvodeMethod::adams, 1e-13)).c_str());
    values.set("ref.bdf13", "%s", tex_or_zero(angle_to_arkode(ode::CvodeMethod::bdf, 1e-13)).c_str());
    values.set("ref.bdf14", "%s", tex_or_zero(angle_to_arkode(ode::CvodeMethod::bdf, 1e-14)).c_str());
    double order_deviation = 0.0;
    double coarsest_error = 0.0;
    const Result* explicit_map = nullptr;
    const Result* lie_poisson = nullptr;
    for (const Result& r : results) {
      values.set(r.name + ".order", "%d", r.expected_order);
      values.set(r.name + ".angle_order", "%.3f", r.angle_order);
      values.set(r.name + ".omega_order", "%.3f", r.omega_order);
      values.set(r.name + ".finest_error", "%s",
                 tex_or_zero(r.finest_angle_error, r.expected_order == 1 ? 3 : 2).c_str());
      order_deviation = std::max({order_deviation, std::abs(r.angle_order - r.expected_order),
                                  std::abs(r.omega_order - r.expected_order)});
      if (r.expected_order == 1) coarsest_error = std::max(coarsest_error, r.coarsest_angle_error);
      if (r.name == "explicit_exp_map") explicit_map = &r;
      if (r.name == "lie_poisson") lie_poisson = &r;
    }
    if (explicit_map == nullptr || lie_poisson == nullptr) {
      throw grbd::Error("integrators() lacks explicit_exp_map or lie_poisson");
    }
    values.set("order_deviation", "%.3f", order_deviation);
    values.set("finest_ratio", "%s",
               tex_or_zero(explicit_map->finest_angle_error / lie_poisson->finest_angle_error)
                   .c_str());
    values.set("floor_ratio", "%.0f", lie_poisson->finest_angle_error / ref_vs_arkode.angle);
    values.set("coarsest_error", "%.2f", coarsest_error);
    values.set("seconds", "%.2f", seconds_since(start));
    values.write(data_dir / "values.txt");
  } catch (...) {
    return grbd::demo::report_exception("ch03_convergence", "the exercises of chapters 1 to 3");
  }
  return 0;
}
