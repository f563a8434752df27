#pragma once
/// \file
/// \brief Rotations of E³ by quaternions: the sandwich, R(p), the scalable body motion, and the
/// conversions between quaternions, rotation matrices and axis–angle pairs (chapter 1).

#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"

namespace grbd::kinematics {

// [rotation matrix declaration]
/// \brief <b>Exercise 1.3</b>: the rotation matrix R(p).
///
/// The matrix of the map x ↦ p x p̄ on pure quaternions (3 × 3),
/// \f[ \mathbf R(p) = (p_0^2 - \mathbf p_r^\mathsf{T}\mathbf p_r)\,\mathbf I
///       + 2\,\mathbf p_r \mathbf p_r^\mathsf{T} + 2 p_0\,\tilde{\mathbf p}_r . \f]
/// For a unit quaternion p this is the rotation R(p) ∈ SO(3) (A_IK when p is the orientation of
/// body frame K); for any p it equals |p|² R(p/|p|), the linear part of the scalable body motion.
/// R(p) = R(−p): p and −p are the same rotation.
Matrix3 rotation_matrix(const Quaternion& p);
// [rotation matrix declaration]

/// The sandwich x ↦ P x P⁻¹ of E³ for any P ≠ 0 (3 × 1 in and out, same frame). It equals
/// R(P/|P|) x; throws grbd::InvalidArgument for P = 0.
Vector3 sandwich(const Quaternion& P, const Vector3& x);

/// The scalable body motion ξ(ρ) = P ρ P̄ + r = s R(P/|P|) ρ + r with scale s = |P|² (3 × 1).
/// For unit P this is the rigid body motion ξ = R ρ + r.
Vector3 body_motion(const Quaternion& P, const Vector3& r, const Vector3& rho);

// [from rotation matrix declaration]
/// \brief <b>Exercise 1.4</b>: the quaternion of a rotation matrix (Shepperd's method).
///
/// The unit quaternion p with R(p) = R and p0 ≥ 0, for a proper rotation
/// matrix R (3 × 3). Robust at every angle, 0 and π included (Shepperd's method: divide by the
/// largest of 4p0², 4p1², 4p2², 4p3², which are read off the diagonal of R). Throws
/// InvalidArgument unless is_rotation_matrix(R, 1e-6): a zero, scaled, reflecting or non-finite
/// matrix has no quaternion (it used to come back as the identity).
Quaternion quaternion_from_rotation_matrix(const Matrix3& R);
// [from rotation matrix declaration]

/// A rotation by `angle` (radians) about the unit vector `axis`.
struct AxisAngle {
  Vector3 axis;  ///< unit vector, 3 × 1
  double angle;  ///< radians
};

/// The unit quaternion p = (cos(φ/2), sin(φ/2) n) of the rotation by φ about the axis n; the axis
/// is normalised here, a zero axis throws grbd::InvalidArgument.
Quaternion quaternion_from_axis_angle(const Vector3& axis, double angle);

/// The axis n and angle φ ∈ [0, π] of the rotation R(p), p unit; for φ = 0 the axis is e_x.
AxisAngle axis_angle(const Quaternion& p);

/// true when R is a proper rotation to tolerance `tol`: ‖RᵀR − I‖_max ≤ tol and |det R − 1| ≤ tol.
bool is_rotation_matrix(const Matrix3& R, double tol = 1e-12);

}  // namespace grbd::kinematics
