#pragma once
/// \file
/// \brief Independent reference computations shared by the tests: each is written out from its
/// textbook formula, sharing no code with the library function it checks.

#include <Eigen/Geometry>  // Quaterniond
#include <algorithm>
#include <cmath>

#include <unsupported/Eigen/MatrixFunctions>

#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/skew.hpp"

namespace grbd::test {

using kinematics::Quaternion;

/// The quaternion product through the 2 × 2 complex matrices (ℍ ⊂ ℂ²ˣ²): independent of the
/// coordinate formula of Exercise 1.1.
inline Quaternion reference_product(const Quaternion& P, const Quaternion& Q) {
  return kinematics::from_complex_matrix(kinematics::complex_matrix(P) *
                                         kinematics::complex_matrix(Q));
}

/// exp(0, v) = (cos|v|, sin|v| v/|v|) written out; the identity for v = 0.
inline Quaternion closed_form_exp(const Vector3& v) {
  const double a = v.norm();
  if (a == 0.0) return Quaternion::identity();
  return {std::cos(a), Vector3(std::sin(a) / a * v)};
}

/// exp(a n) = (cos a, sin a n) for a unit vector n and any real a.
inline Quaternion closed_form_exp(const Vector3& n, double a) {
  return {std::cos(a), Vector3(std::sin(a) * n)};
}

/// The rotation by `angle` about the unit vector n in the classical axis–angle form (Euler,
/// Rodrigues), sharing no code with the quaternion functions.
inline Matrix3 axis_angle_matrix(const Vector3& n, double angle) {
  return std::cos(angle) * Matrix3::Identity() + std::sin(angle) * kinematics::skew(n) +
         (1.0 - std::cos(angle)) * n * n.transpose();
}

/// The rotation by the rotation vector θ in axis–angle form; the identity for θ = 0.
inline Matrix3 axis_angle_matrix(const Vector3& theta) {
  const double a = theta.norm();
  return a == 0.0 ? Matrix3::Identity() : axis_angle_matrix(theta / a, a);
}

/// The matrix exponential of θ̃ by Eigen's unsupported MatrixFunctions module (Padé approximation
/// with scaling and squaring): a reference independent of Rodrigues' formula.
inline Matrix3 expm(const Vector3& theta) {
  const Matrix3 theta_tilde = kinematics::skew(theta);
  return theta_tilde.exp();
}

/// The exact motion for constant u = (v, ω) from q0 at t = 0: q(t) = (r0 + t v, p0 exp(t ω/2)),
/// with the closed-form exp and the complex-matrix product.
inline Vector7 exact_motion(const Vector7& q0, const Vector6& u, double t) {
  const Quaternion p0(Vector4(q0.tail<4>()));
  const Quaternion p = reference_product(p0, closed_form_exp(0.5 * t * u.tail<3>()));
  return kinematics::make_q(q0.head<3>() + t * u.head<3>(), p);
}

/// The rotation matrix A_IK of the unit quaternion stored in q, by Eigen::Quaterniond (scalar
/// first in q, Eigen's constructor takes w, x, y, z): shares no code with rotation_matrix().
inline Matrix3 reference_A_IK(const Vector7& q) {
  return Eigen::Quaterniond(q[3], q[4], q[5], q[6]).toRotationMatrix();
}

/// The unit quaternion (scalar first) of a rotation matrix, by Eigen::Quaterniond.
inline Quaternion reference_quaternion(const Matrix3& A) {
  const Eigen::Quaterniond e(A);
  return {e.w(), e.x(), e.y(), e.z()};
}

/// Max-norm of the coordinate difference of two quaternions.
inline double distance(const Quaternion& P, const Quaternion& Q) {
  return (P.coeffs() - Q.coeffs()).cwiseAbs().maxCoeff();
}

/// Distance of p from the nearer of ±expected (p and −p are the same rotation).
inline double distance_up_to_sign(const Quaternion& p, const Quaternion& expected) {
  return std::min(distance(p, expected), distance(p, -expected));
}

/// Largest absolute entry of a matrix.
template <typename Derived>
double max_abs(const Eigen::MatrixBase<Derived>& A) {
  return A.cwiseAbs().maxCoeff();
}

}  // namespace grbd::test
