/// \file
/// \brief The logarithm on SO(3) and rotation vectors (the non-exercise part of the exponential
/// maps of chapter 1; exp_S3, log_S3 and exp_SO3 are exercises).

#include "grbd/kinematics/exponential.hpp"

#include "grbd/core/error.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::kinematics {

// [log SO3]
Vector3 log_SO3(const Matrix3& R) {
  if (!R.allFinite()) {
    throw InvalidArgument("log_SO3: the rotation matrix R has a NaN or infinite entry");
  }
  // Through S³ rather than through acos((tr R − 1)/2), which loses half the digits near 0 and π:
  // Shepperd's method and the atan2-based logarithm are both accurate at every angle.
  return rotation_vector(quaternion_from_rotation_matrix(R));
}
// [log SO3]

Quaternion quaternion_from_rotation_vector(const Vector3& theta) {
  // p = (cos(θ/2), sin(θ/2) n): the quaternion turns by half the angle, the sandwich doubles it.
  return exp_S3(0.5 * theta);
}

// [rotation vector]
Vector3 rotation_vector(const Quaternion& p) {
  if (!(p.squared_norm() > 0.0)) {
    throw InvalidArgument(
        "rotation_vector: p = 0 (or |p|² underflows or is NaN) is not a "
        "rotation; expected a unit quaternion");
  }
  // S³ covers SO(3) twice: p and −p are the same rotation. The representative with p0 ≥ 0 has
  // |log p| ≤ π/2, hence |θ| = 2|log p| ≤ π, the principal rotation vector.
  return 2.0 * log_S3(p.p0() < 0.0 ? -p : p);
}
// [rotation vector]

}  // namespace grbd::kinematics
