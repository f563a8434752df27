/// \file
/// \brief Chapter 2 exercises on time integration: one step of the lecture's exponential-map
/// scheme, and the exact free rotation about one principal axis (the building block of the
/// Lie–Poisson splitting).

#include "grbd/body/integrators.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"

#include <cmath>
#include <string>

namespace grbd::body {

State explicit_exp_map_step(const RigidBody& body, const State& x, const Loads& loads, double h) {
  // BEGIN EXERCISE 2.5: one step of the lecture's exponential-map scheme
  // Hint: chapter 1 already moves q with a constant u exactly; which u is held over the step?
  // Hint: M is diagonal, so M⁻¹ h(u) needs no linear solve; a function of this chapter gives it.
  // Both updates read the state at the start of the step: q with u (not u⁺), u with h(u).
  return {kinematics::exp_map_step(x.q, x.u, h), x.u + h * newton_euler_u_dot(body, x.u, loads)};
  // END EXERCISE 2.5
}

State free_rotation_about_axis(const RigidBody& body, const State& x, int axis, double t) {
  // BEGIN EXERCISE 2.6: the exact free rotation about one principal axis
  // Hint: along this flow L_i stays constant, so the rate φ̇ = L_i/Θ_i = ω_i is constant too.
  // Hint: exp_S3(½ φ e_i) = (cos ½φ, sin ½φ e_i); exp_SO3(−φ e_i) turns only the other two axes.
  if (axis < 0 || axis > 2) {
    throw InvalidArgument("free_rotation_about_axis: the axis must be 0, 1 or 2, but it is " +
                          std::to_string(axis));
  }
  const Vector3 K_omega = kinematics::angular_velocity(x.u);
  const double angle = t * K_omega[axis];  // φ = t φ̇, φ̇ = L_i/Θ_i = ω_i
  const double c = std::cos(0.5 * angle);
  const double s = std::sin(0.5 * angle);
  Vector3 half_turn = Vector3::Zero();
  half_turn[axis] = s;
  // The body turns about its own axis e_i: a right factor, p⁺ = p exp_S3(½ φ e_i).
  const kinematics::Quaternion p =
      kinematics::orientation(x.q) * kinematics::Quaternion(c, half_turn);
  // Meanwhile L turns by −φ about e_i in the body frame (in space it stands still). cos φ and
  // sin φ come from the half angle, so that L and p turn by exactly the same rotation.
  const double cos_angle = c * c - s * s;
  const double sin_angle = 2.0 * s * c;
  const int j = (axis + 1) % 3;  // (i, j, k) cyclic: e_i × e_j = e_k
  const int k = (axis + 2) % 3;
  const Vector3& Theta = body.K_Theta;
  const double L_j = Theta[j] * K_omega[j];
  const double L_k = Theta[k] * K_omega[k];
  Vector3 K_omega_plus = K_omega;  // ω_i = L_i/Θ_i is kept exactly
  K_omega_plus[j] = (cos_angle * L_j + sin_angle * L_k) / Theta[j];
  K_omega_plus[k] = (-sin_angle * L_j + cos_angle * L_k) / Theta[k];
  return {kinematics::make_q(kinematics::position(x.q), p),
          kinematics::make_u(kinematics::linear_velocity(x.u), K_omega_plus)};
  // END EXERCISE 2.6
}

}  // namespace grbd::body
