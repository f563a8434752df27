#pragma once
/// \file
/// \brief Independent reference computations shared by the tests: each is written out from its
/// textbook formula, sharing no code with the library function it checks.

#include <algorithm>
#include <cmath>

#include <unsupported/Eigen/MatrixFunctions>

#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"
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
