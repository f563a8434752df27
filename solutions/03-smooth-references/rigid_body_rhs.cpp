/// \file
/// \brief Chapter 3 exercises on the rigid body as an ordinary differential equation: the
/// right-hand side ẏ = (F(q) u, M⁻¹ h) over y = (q, u) ∈ ℝ¹³, and the projection onto |p| = 1.

#include "grbd/ode/rigid_body_rhs.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"

namespace grbd::ode {

void free_body_rhs(const body::RigidBody& body, const body::Loads& loads,
                   const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> y_dot) {
  // BEGIN EXERCISE 3.1: the right-hand side of a rigid body under constant loads
  // Hint: y = (q, u) with q ∈ ℝ⁷ and u ∈ ℝ⁶; chapter 1 gives q̇ and chapter 2 gives u̇.
  // Hint: those functions take fixed-size vectors: copy the two segments of y into them first.
  const Vector7 q = y.head<7>();
  const Vector6 u = y.tail<6>();
  // q̇ = F(q) u is linear in p, so it is defined off the unit sphere too: CVODE's iterates need
  // not have |p| = 1.
  y_dot.head<7>() = kinematics::q_dot(q, u);
  y_dot.tail<6>() = body::newton_euler_u_dot(body, u, loads);
  // END EXERCISE 3.1
}

void quaternion_projection(Eigen::Index offset, const Eigen::Ref<const Eigen::VectorXd>& y,
                           Eigen::Ref<Eigen::VectorXd> correction) {
  // BEGIN EXERCISE 3.2: the projection onto |p| = 1
  // Hint: the point of the unit sphere S³ nearest to p ≠ 0 is p/|p|.
  // Hint: CVODE adds the correction to all of y: what must the other entries be?
  const Vector4 p = y.segment<4>(offset);
  correction.setZero();
  // The orthogonal projection onto S³ moves p along itself: the smallest change (in the
  // Euclidean norm of ℝ⁴) that restores |p| = 1.
  correction.segment<4>(offset) = p / p.norm() - p;
  // END EXERCISE 3.2
}

}  // namespace grbd::ode
