/// \file
/// \brief Rotations of E³ by quaternions: the sandwich, the scalable body motion, axis–angle
/// conversions and the rotation-matrix check (the non-exercise part of chapter 1).

#include "grbd/kinematics/rotation.hpp"

#include <Eigen/LU>  // determinant()
#include <cmath>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::kinematics {

// [sandwich]
Vector3 sandwich(const Quaternion& P, const Vector3& x) {
  if (!(P.squared_norm() > 0.0)) {
    throw InvalidArgument(
        "sandwich: P x P⁻¹ needs P ≠ 0, but P = 0 (or |P|² underflows or "
        "is NaN)");
  }
  // P (0, x) P⁻¹ is again a pure quaternion: its scalar part is −x·p_r p0 + p0 x·p_r = 0 up to
  // round-off, so only the vector part is returned. P⁻¹ = P̄/|P|² cancels the scale |P|².
  return (P * Quaternion::pure(x) * P.inverse()).p_r();
}
// [sandwich]

Vector3 body_motion(const Quaternion& P, const Vector3& r, const Vector3& rho) {
  // P ρ P̄ = |P|² R(P/|P|) ρ, and rotation_matrix(P) is exactly that matrix for any P: no
  // normalisation, so that P = 0 (scale s = 0) is a valid, if degenerate, scalable motion.
  return rotation_matrix(P) * rho + r;
}

Quaternion quaternion_from_axis_angle(const Vector3& axis, double angle) {
  const double n = axis.norm();
  if (!(n > 0.0) || !std::isfinite(n)) {
    throw InvalidArgument(
        "quaternion_from_axis_angle: the axis must be a finite non-zero vector, "
        "but |axis| = " +
        format_number(n));
  }
  if (!std::isfinite(angle)) {
    throw InvalidArgument("quaternion_from_axis_angle: the angle must be finite, but it is " +
                          format_number(angle));
  }
  const double half = 0.5 * angle;
  return {std::cos(half), Vector3((std::sin(half) / n) * axis)};
}

AxisAngle axis_angle(const Quaternion& p) {
  if (!(p.squared_norm() > 0.0)) {
    throw InvalidArgument(
        "axis_angle: p = 0 (or |p|² underflows or is NaN) is not a rotation; "
        "expected a unit quaternion");
  }
  // p and −p are the same rotation; the one with p0 ≥ 0 has half-angle φ/2 ∈ [0, π/2].
  const double sign = p.p0() < 0.0 ? -1.0 : 1.0;
  const Vector3 p_r = sign * p.p_r();
  const double s = p_r.norm();  // sin(φ/2)
  if (s == 0.0) {
    return {Vector3::UnitX(), 0.0};
  }
  // atan2 of (sin, cos) is accurate at every angle, unlike acos(p0) near φ = 0 or asin(s) near
  // φ = π; it also makes the result independent of the scale |p|.
  return {p_r / s, 2.0 * std::atan2(s, sign * p.p0())};
}

bool is_rotation_matrix(const Matrix3& R, double tol) {
  // Written with `<=` so that NaN entries give false.
  const double orthogonality = (R.transpose() * R - Matrix3::Identity()).cwiseAbs().maxCoeff();
  return orthogonality <= tol && std::abs(R.determinant() - 1.0) <= tol;
}

}  // namespace grbd::kinematics
