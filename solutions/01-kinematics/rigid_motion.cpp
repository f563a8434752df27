/// \file
/// \brief Chapter 1 exercises on rigid motion: the kinematic map F(q) and the velocity of a
/// material point.

#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rotation.hpp"

#include <Eigen/Geometry>  // cross()

namespace grbd::kinematics {

Matrix76 kinematic_map(const Vector7& q) {
  // BEGIN EXERCISE 1.8: the kinematic map F(q)
  // Hint: ṗ = ½ p (0, K_omega) = ½ φ_L(p) K((0, K_omega)); which columns of φ_L(p) survive?
  // Hint: the translational block is the identity: I_v_S is already the rate of I_r_S.
  Matrix76 F = Matrix76::Zero();
  F.topLeftCorner<3, 3>().setIdentity();
  // φ_L(p) E drops the first column of φ_L(p): the scalar part of (0, K_omega) is zero.
  F.bottomRightCorner<4, 3>() = 0.5 * phi_L(orientation(q)).rightCols<3>();
  return F;
  // END EXERCISE 1.8
}

Vector3 point_velocity(const Vector7& q, const Vector6& u, const Vector3& K_rho) {
  // BEGIN EXERCISE 1.9: the velocity of a material point
  // Hint: differentiate I_r_P = I_r_S + A_IK K_rho in time; K_rho is constant in frame K.
  // Hint: A_IK = rotation_matrix(p) with p = orientation(q); K_omega and K_rho are in frame K.
  // Ȧ_IK = A_IK K_ω̃: the angular velocity in the body frame acts on the body-fixed offset first,
  // and A_IK then takes the result to frame I. A_IK = R(p) as in point_position().
  return linear_velocity(u) + rotation_matrix(orientation(q)) * angular_velocity(u).cross(K_rho);
  // END EXERCISE 1.9
}

}  // namespace grbd::kinematics
