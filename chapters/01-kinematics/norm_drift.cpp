// Chapter 1 demo: explicit Euler on q̇ = F(q) u leaves the unit sphere S³, the
// exponential-map update does not.
//
// A body spins with constant body angular velocity K_omega, |K_omega| = 2π rad/s (one turn per
// second) about a generic body axis, for T = 10 s. For each step size h in {0.1, 0.05, 0.01} s
// the orientation is integrated with grbd::kinematics::explicit_euler_step() and with
// grbd::kinematics::exp_map_step(), and the file `drift_h<h>.csv` is written to the data
// directory, one row per step n (t = n h) with the columns
//
//   t_s                          time t = n h [s]
//   n                            step number
//   euler_norm                   |p_n| of explicit Euler [-]
//   euler_norm_predicted         the exact law (1 + h²|ω|²/4)^(n/2) [-]
//   expmap_norm_minus_one        |p_n| − 1 of the exp-map update [-]
//   euler_angle_error_rad        angle of the rotation between R(p_n/|p_n|) (explicit Euler) and
//                                the exact A_IK(t) = A_IK(0) exp(t K_omega~) [rad]
//   euler_angle_error_predicted_rad
//                                the exact law |n (h|ω| − 2 atan(h|ω|/2))|, folded into [0, π]
//   expmap_angle_error_rad       the same angle for the exp-map update [rad]
//
// The exact rotation is computed with Eigen::AngleAxis, independently of grbd. The program prints
// a one-line summary and writes the numbers the chapter quotes to `values.txt` (key = value lines,
// read by the book at build time: \demo{ch01_norm_drift/values.txt#KEY} in chapter.md):
//
//   euler.h<h>.norm, euler.h<h>.scale   |p| of explicit Euler at T and the scale |p|² of the body
//   euler.h<h>.lag                      its orientation error at T [rad]
//   expmap.max_norm_deviation           the largest ||p| − 1| of the exp-map update, all h
//   expmap.drift_per_step               that of h = 0.01 s divided by its number of steps
//   expmap.max_angle_error              the largest orientation error of the exp-map update [rad]
//
// Usage: `ch01_norm_drift <data directory>`.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/kinematics/skew.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Matrix3;
using grbd::Vector3;
using grbd::Vector6;
using grbd::Vector7;
namespace kin = grbd::kinematics;

constexpr double kPi = std::numbers::pi;

// The angle in [0, π] of the rotation A_ref^T A, accurate also for small angles (an acos of the
// trace alone would lose half the digits there).
double rotation_angle_between(const Matrix3& A_ref, const Matrix3& A) {
  const Matrix3 D = A_ref.transpose() * A;
  const double sin_angle = 0.5 * kin::unskew(D - D.transpose()).norm();
  const double cos_angle = 0.5 * (D.trace() - 1.0);
  return std::atan2(sin_angle, cos_angle);
}

struct Result {
  double h;
  double euler_norm_end;
  double euler_norm_predicted_end;
  double expmap_max_norm_deviation;
  double expmap_max_angle_error;
  double euler_angle_error_end;  // [rad]
  int steps;
};

// Integrates the spinning body with step h up to `t_end` and writes `file`.
Result integrate(double h, double t_end, const Vector3& K_omega, const Vector3& axis0,
                 double angle0, const std::filesystem::path& file) {
  const int steps = static_cast<int>(std::lround(t_end / h));
  const double omega = K_omega.norm();
  const Vector3 n_omega = K_omega / omega;

  const kin::Quaternion p0 = kin::quaternion_from_axis_angle(axis0, angle0);
  const Matrix3 A_IK_0 = Eigen::AngleAxisd(angle0, axis0.normalized()).toRotationMatrix();
  const Vector6 u = kin::make_u(Vector3::Zero(), K_omega);

  Vector7 q_euler = kin::make_q(Vector3::Zero(), p0);
  Vector7 q_expmap = q_euler;

  // One explicit Euler step rotates p/|p| by 2 atan(h|ω|/2) instead of h|ω| about the fixed axis.
  const double euler_lag_per_step = h * omega - 2.0 * std::atan(0.5 * h * omega);
  const double growth_per_step = 1.0 + 0.25 * h * h * omega * omega;

  grbd::demo::OutputFile out(file,
                             "t_s,n,euler_norm,euler_norm_predicted,expmap_norm_minus_one,"
                             "euler_angle_error_rad,euler_angle_error_predicted_rad,"
                             "expmap_angle_error_rad");
  out.precision(17);

  Result result{h, 1.0, 1.0, 0.0, 0.0, 0.0, steps};
  for (int n = 0; n <= steps; ++n) {
    if (n > 0) {
      q_euler = kin::explicit_euler_step(q_euler, u, h);
      q_expmap = kin::exp_map_step(q_expmap, u, h);
    }
    const double t = n * h;
    const Matrix3 A_IK_exact = A_IK_0 * Eigen::AngleAxisd(omega * t, n_omega).toRotationMatrix();

    const kin::Quaternion p_euler = kin::orientation(q_euler);
    const kin::Quaternion p_expmap = kin::orientation(q_expmap);
    const double euler_norm = p_euler.norm();
    const double euler_norm_predicted = std::pow(growth_per_step, 0.5 * n);
    const double expmap_norm_minus_one = p_expmap.norm() - 1.0;
    const double euler_angle_error =
        rotation_angle_between(A_IK_exact, kin::rotation_matrix(p_euler.normalized()));
    const double euler_angle_error_predicted =
        std::abs(std::remainder(n * euler_lag_per_step, 2.0 * kPi));
    const double expmap_angle_error =
        rotation_angle_between(A_IK_exact, kin::rotation_matrix(p_expmap.normalized()));

    out << t << ',' << n << ',' << euler_norm << ',' << euler_norm_predicted << ','
        << expmap_norm_minus_one << ',' << euler_angle_error << ',' << euler_angle_error_predicted
        << ',' << expmap_angle_error << '\n';

    result.euler_norm_end = euler_norm;
    result.euler_norm_predicted_end = euler_norm_predicted;
    result.euler_angle_error_end = euler_angle_error;
    result.expmap_max_norm_deviation =
        std::max(result.expmap_max_norm_deviation, std::abs(expmap_norm_minus_one));
    result.expmap_max_angle_error = std::max(result.expmap_max_angle_error, expmap_angle_error);
  }
  out.finish();
  return result;
}

// "0.1" for 0.1, "0.05" for 0.05: the step size as the figure script spells it in file names.
std::string step_label(double h) {
  std::ostringstream s;
  s << h;
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch01_norm_drift", {"<data directory>"},
          "writes drift_h<h>.csv for h = 0.1, 0.05, 0.01 s and values.txt into the existing "
          "directory")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];

  // One turn per second about a generic body axis, starting from a generic orientation.
  const Vector3 K_omega = 2.0 * kPi * Vector3(1.0, 2.0, 3.0).normalized();
  const Vector3 axis0(-0.3, 0.5, 0.8);
  const double angle0 = 1.2;                              // rad
  const double t_end = 10.0;                              // s
  const std::vector<double> step_sizes{0.1, 0.05, 0.01};  // s; norm_drift.gp lists the same

  try {
    std::vector<Result> results;
    for (const double h : step_sizes) {
      results.push_back(integrate(h, t_end, K_omega, axis0, angle0,
                                  data_dir / ("drift_h" + step_label(h) + ".csv")));
    }
    std::printf("ch01_norm_drift: |K_omega| = %.4f rad/s, T = %.0f s;", K_omega.norm(), t_end);
    double expmap_norm = 0.0;
    double expmap_angle = 0.0;
    for (const Result& r : results) {
      std::printf(" h = %s s: Euler |p(T)| = %.6g (law %.6g);", step_label(r.h).c_str(),
                  r.euler_norm_end, r.euler_norm_predicted_end);
      expmap_norm = std::max(expmap_norm, r.expmap_max_norm_deviation);
      expmap_angle = std::max(expmap_angle, r.expmap_max_angle_error);
    }
    std::printf(" exp map: max ||p| - 1| = %.1e, max angle error = %.1e rad\n", expmap_norm,
                expmap_angle);

    // The numbers the chapter quotes.
    grbd::demo::Values values;
    for (const Result& r : results) {
      const std::string h = "euler.h" + step_label(r.h);
      const double scale = r.euler_norm_end * r.euler_norm_end;
      values.set(h + ".norm", r.euler_norm_end >= 10.0 ? "%.0f" : "%.2f", r.euler_norm_end);
      if (scale >= 10.0) {
        values.set(h + ".scale", "%s", grbd::demo::tex_power(scale).c_str());
      } else {
        values.set(h + ".scale", "%.1f", scale);
      }
      values.set(h + ".lag", "%.2f", r.euler_angle_error_end);
    }
    const Result& finest = results.back();  // h = 0.01 s, the most steps
    values.set("expmap.max_norm_deviation", "%s", grbd::demo::tex_power(expmap_norm).c_str());
    values.set("expmap.drift_per_step", "%s",
               grbd::demo::tex_power(finest.expmap_max_norm_deviation / finest.steps).c_str());
    values.set("expmap.max_angle_error", "%s", grbd::demo::tex_power(expmap_angle).c_str());
    values.write(data_dir / "values.txt");
  } catch (...) {
    return grbd::demo::report_exception(
        "ch01_norm_drift",
        "the exercises of chapter 1 (product, phi_L, rotation_matrix, exp_S3, kinematic_map)");
  }
  return 0;
}
