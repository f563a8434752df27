/// \file
/// \brief Chapter 1 exercises on the quaternion algebra ℍ: the product and the multiplication
/// matrices φ_L and φ_R.

#include "grbd/kinematics/quaternion.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/skew.hpp"

#include <Eigen/Geometry>  // cross()

namespace grbd::kinematics {

Quaternion product(const Quaternion& P, const Quaternion& Q) {
  // BEGIN EXERCISE 1.1: the quaternion product
  // Hint: write P = (p0, p_r), Q = (q0, q_r) and expand with i² = j² = k² = ijk = −1.
  // Hint: Vector3 has dot() and cross(); the Quaternion(double, Vector3) constructor assembles P Q.
  const double p0 = P.p0();
  const double q0 = Q.p0();
  const Vector3 p_r = P.p_r();
  const Vector3 q_r = Q.p_r();
  // The scalar part collects i² = j² = k² = −1; the vector part collects ij = k, jk = i, ki = j
  // and their antisymmetric partners, which together are the cross product p_r × q_r.
  return {p0 * q0 - p_r.dot(q_r), Vector3(p0 * q_r + q0 * p_r + p_r.cross(q_r))};
  // END EXERCISE 1.1
}

Matrix4 phi_L(const Quaternion& P) {
  // BEGIN EXERCISE 1.2: the multiplication matrices φ_L and φ_R
  // Hint: K(PQ) is linear in K(Q); read the matrix off the product formula of Exercise 1.1.
  const Vector3 p_r = P.p_r();
  Matrix4 phi;
  phi(0, 0) = P.p0();
  phi.block<1, 3>(0, 1) = -p_r.transpose();
  phi.block<3, 1>(1, 0) = p_r;
  // p_r × q_r = p̃_r q_r: the cross product with P on the left is multiplication by +p̃_r.
  phi.block<3, 3>(1, 1) = P.p0() * Matrix3::Identity() + skew(p_r);
  return phi;
  // END EXERCISE 1.2
}

Matrix4 phi_R(const Quaternion& Q) {
  // BEGIN EXERCISE 1.2: the multiplication matrices φ_L and φ_R
  // Hint: K(PQ) is linear in K(P); only the sign of the cross-product term differs from φ_L.
  const Vector3 q_r = Q.p_r();
  Matrix4 phi;
  phi(0, 0) = Q.p0();
  phi.block<1, 3>(0, 1) = -q_r.transpose();
  phi.block<3, 1>(1, 0) = q_r;
  // p_r × q_r = −q̃_r p_r: with Q on the right the cross product changes sign.
  phi.block<3, 3>(1, 1) = Q.p0() * Matrix3::Identity() - skew(q_r);
  return phi;
  // END EXERCISE 1.2
}

}  // namespace grbd::kinematics
