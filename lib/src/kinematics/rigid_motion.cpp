/// \file
/// \brief Generalized coordinates and velocities of a rigid body, the motion of its points, and
/// two time steps of q̇ = F(q) u (the non-exercise part of chapter 1).

#include "grbd/kinematics/rigid_motion.hpp"

#include "grbd/kinematics/exponential.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::kinematics {

Vector7 make_q(const Vector3& I_r_S, const Quaternion& p) {
  Vector7 q;
  q << I_r_S, p.coeffs();
  return q;
}

Vector6 make_u(const Vector3& I_v_S, const Vector3& K_omega) {
  Vector6 u;
  u << I_v_S, K_omega;
  return u;
}

Vector7 q_dot(const Vector7& q, const Vector6& u) { return kinematic_map(q) * u; }

Vector3 point_position(const Vector7& q, const Vector3& K_rho) {
  // I_r_P = I_r_S + A_IK K_rho is the body motion ξ = p ρ p̄ + r. No normalisation: if p has
  // drifted off S³ (explicit Euler), the body is visibly scaled by |p|², which is the point.
  return body_motion(orientation(q), position(q), K_rho);
}

// [explicit euler step]
Vector7 explicit_euler_step(const Vector7& q, const Vector6& u, double h) {
  // A straight step in ℝ⁷ along the tangent F(q) u. Since pᵀṗ = 0 the step is orthogonal to p,
  // so by Pythagoras |p|² grows to |p|² + h²|ṗ|² = |p|² (1 + h²|K_omega|²/4): the drift.
  return q + h * q_dot(q, u);
}
// [explicit euler step]

// [exp map step]
Vector7 exp_map_step(const Vector7& q, const Vector6& u, double h) {
  // For constant K_omega, ṗ = ½ p (0, K_omega) is solved by p(t) = p(0) exp_S3(t K_omega / 2):
  // the step multiplies by a unit quaternion, so it stays on S³ and is exact.
  const Quaternion p = orientation(q) * exp_S3(0.5 * h * angular_velocity(u));
  return make_q(position(q) + h * linear_velocity(u), p);
}
// [exp map step]

}  // namespace grbd::kinematics
