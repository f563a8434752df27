/// \file
/// \brief Chapter 2 exercises on the rigid body: the Jacobian of a material point and the
/// right-hand side of the Newton–Euler equations.

#include "grbd/body/rigid_body.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/kinematics/skew.hpp"

#include <Eigen/Geometry>  // cross()

namespace grbd::body {

Matrix36 point_jacobian(const Vector7& q, const Vector3& K_rho) {
  // BEGIN EXERCISE 2.3: the Jacobian of a material point
  // Hint: split point_velocity() of chapter 1 into a term linear in I_v_S and one in K_omega.
  // Hint: K_omega × K_rho = −K_rho × K_omega, and skew(a) is the matrix of x ↦ a × x.
  Matrix36 J_P;
  J_P.leftCols<3>().setIdentity();
  // A_IK (K_omega × K_rho) = −A_IK K_ρ̃ K_omega: the rotational block acts on K_omega directly.
  J_P.rightCols<3>() =
      -kinematics::rotation_matrix(kinematics::orientation(q)) * kinematics::skew(K_rho);
  return J_P;
  // END EXERCISE 2.3
}

Vector6 newton_euler_h(const RigidBody& body, const Vector6& u, const Loads& loads) {
  // BEGIN EXERCISE 2.4: the right-hand side of the Newton–Euler equations
  // Hint: Θ is diagonal in the principal frame, so K_L = Θ K_omega is a component-wise product.
  // Hint: the gyroscopic term comes from d/dt (A_IK K_L) with Ȧ_IK = A_IK K_ω̃.
  const Vector3 K_omega = kinematics::angular_velocity(u);
  const Vector3 K_L = body.K_Theta.cwiseProduct(K_omega);
  // The force is already in frame I and the torque in frame K: no rotation is needed. The
  // gyroscopic term ω × Θω is what a body frame that turns with the body adds to Euler's law.
  Vector6 h;
  h << loads.I_F, loads.K_M - K_omega.cross(K_L);
  return h;
  // END EXERCISE 2.4
}

}  // namespace grbd::body
