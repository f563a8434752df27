#pragma once
// Chapter 3 demos: the common test problem and the helpers the three demos share.
//
// The test problem is a torque-free asymmetric rigid body, principal moments
// K_Theta = (2, 3, 4) kg m² (mass 1 kg), started at K_omega = s (1, 1, 1) rad/s with a generic
// orientation and at rest as a whole (I_v_S = 0). For s = 1 the motion is on the branch
// L² > 2EΘ2 of Landau–Lifshitz §37 with m = 7/11 and λ = √(11/24) s⁻¹: a tumbling body, far from
// both the steady spins and the separatrix. Scaling ω by s scales time by 1/s.
//
// The reference of the convergence study is CVODE (BDF, rtol 1e-12, atol 1e-14) with the
// quaternion projected onto |p| = 1 after every step (grbd::ode::quaternion_projection_at; CVODE
// offers projection only with its BDF methods). Its orientation error at T = 10 s is about
// 3e-10 rad, which the more accurate ARKODE reference (explicit Runge–Kutta of order 8, rtol
// 1e-13) reveals; the work–precision study, which measures errors down to 1e-10, uses the latter.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <Eigen/Core>

#include "grbd/body/rigid_body.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/ode/rigid_body_rhs.hpp"
#include "grbd/ode/sundials.hpp"
#include "grbd_demo/demo.hpp"

namespace ch03 {

using grbd::Vector3;
namespace body = grbd::body;
namespace kin = grbd::kinematics;
namespace ode = grbd::ode;

/// The body: K_Theta = (2, 3, 4) kg m², m = 1 kg.
inline body::RigidBody tumbling_body() { return body::RigidBody{1.0, Vector3(2.0, 3.0, 4.0)}; }

/// The start: K_omega = spin (1, 1, 1) rad/s, a generic orientation, I_r_S = I_v_S = 0.
inline body::State tumbling_start(double spin = 1.0) {
  const kin::Quaternion p0 = kin::quaternion_from_axis_angle(Vector3(0.3, -0.2, 0.9), 0.8);
  return body::State{kin::make_q(Vector3::Zero(), p0),
                     kin::make_u(Vector3::Zero(), spin * Vector3(1.0, 1.0, 1.0))};
}

/// The angle [rad] of the rotation that takes the orientation p_ref to p: 2 atan2(|d_r|, |d_0|)
/// for d = p_ref⁻¹ p (both normalised first), accurate also for tiny angles.
inline double orientation_angle_error(const kin::Quaternion& p, const kin::Quaternion& p_ref) {
  const kin::Quaternion d = kin::product(p_ref.normalized().conjugate(), p.normalized());
  return 2.0 * std::atan2(d.p_r().norm(), std::abs(d.p0()));
}

/// The rotation angle error and |ω − ω_ref| [rad/s] of x against x_ref.
struct StateError {
  double angle = 0.0;  ///< [rad]
  double omega = 0.0;  ///< [rad/s]
};
inline StateError state_error(const body::State& x, const body::State& x_ref) {
  return {orientation_angle_error(kin::orientation(x.q), kin::orientation(x_ref.q)),
          (kin::angular_velocity(x.u) - kin::angular_velocity(x_ref.u)).norm()};
}

/// The CVODE reference at time T (BDF, rtol 1e-12, atol 1e-14, |p| = 1 projected; CVODE offers
/// projection only with BDF, so an Adams run is not projected), and the statistics of the run.
struct Reference {
  body::State x;
  ode::Statistics statistics;
};
// [cvode reference]
inline Reference cvode_reference(const body::RigidBody& rb, const body::State& x0, double T,
                                 ode::CvodeMethod method = ode::CvodeMethod::bdf,
                                 double rtol = 1e-12) {
  ode::Tolerances tolerances;
  tolerances.rtol = rtol;
  tolerances.atol = 1e-14;
  ode::Cvode cvode(ode::free_body(rb), 0.0, ode::pack(x0), method, tolerances);
  if (method == ode::CvodeMethod::bdf) {  // CVODE projects only with BDF
    cvode.set_projection(ode::quaternion_projection_at(3));
  }
  cvode.set_max_steps(10'000'000);
  const Eigen::VectorXd y = cvode.advance(T);
  return {ode::unpack(y), cvode.statistics()};
}
// [cvode reference]

/// A second, independent reference at time T: ARKODE's explicit Runge–Kutta pair of order 8 at
/// rtol 1e-13, atol 1e-15 (not projected: ARKODE has no projection).
inline body::State arkode_reference(const body::RigidBody& rb, const body::State& x0, double T) {
  ode::Tolerances tolerances;
  tolerances.rtol = 1e-13;
  tolerances.atol = 1e-15;
  ode::Arkode arkode(ode::free_body(rb), ode::RhsFunction{}, 0.0, ode::pack(x0), 8, tolerances);
  arkode.set_max_steps(10'000'000);
  return ode::unpack(arkode.advance(T));
}

/// Opens `file` for writing with a header line, 10 significant digits; throws grbd::Error naming
/// the file if it cannot. The caller ends it with finish(), which checks that every write worked.
inline grbd::demo::OutputFile open_csv(const std::filesystem::path& file,
                                       const std::string& header) {
  grbd::demo::OutputFile out(file, header);
  out.precision(10);
  return out;
}

/// x ≥ 0 as TeX with `digits` significant digits ("2.7\cdot10^{-10}" for 2, "2.74\cdot10^{-3}" for
/// 3), "0" for an exact zero: the form in which values.txt gives the errors the chapter quotes.
inline std::string tex_or_zero(double x, int digits = 2) {
  if (!(x > 0.0)) return "0";
  if (digits == 2) return grbd::demo::tex_power(x);
  int exponent = static_cast<int>(std::floor(std::log10(x)));
  double mantissa = x / std::pow(10.0, exponent);
  const double rounded = std::round(mantissa * std::pow(10.0, digits - 1)) / std::pow(10.0, digits - 1);
  if (rounded >= 10.0) {  // 9.995 rounds up to 10.0
    mantissa /= 10.0;
    ++exponent;
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.*f\\cdot10^{%d}", digits - 1, mantissa, exponent);
  return text;
}

/// n with its digits in groups of three from 10 000 on: "465 259", "1780".
inline std::string grouped(long n) {
  const std::string digits = std::to_string(n);
  if (n < 10000) return digits;
  std::string text;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) text.push_back(' ');
    text.push_back(digits[i]);
  }
  return text;
}

/// Seconds since `start`.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace ch03
