#pragma once
/// \file
/// \brief The tilde operator: the skew-symmetric matrix of the cross product.

#include "grbd/core/types.hpp"

namespace grbd::kinematics {

/// The skew-symmetric ("tilde") matrix ã of a ∈ ℝ³ (3 × 3), with ã b = a × b for every b.
inline Matrix3 skew(const Vector3& a) {
  Matrix3 a_tilde;
  a_tilde << 0.0, -a.z(), a.y(),  //
      a.z(), 0.0, -a.x(),         //
      -a.y(), a.x(), 0.0;
  return a_tilde;
}

/// The vector a of a skew-symmetric matrix ã (the inverse of skew()); only the strictly lower
/// triangle is read.
inline Vector3 unskew(const Matrix3& a_tilde) {
  return {a_tilde(2, 1), a_tilde(0, 2), a_tilde(1, 0)};
}

}  // namespace grbd::kinematics
