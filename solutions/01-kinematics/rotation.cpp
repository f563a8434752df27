/// \file
/// \brief Chapter 1 exercises on rotations: the rotation matrix R(p) of a quaternion and its
/// inverse, the quaternion of a rotation matrix (Shepperd's method).

#include "grbd/kinematics/rotation.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/skew.hpp"

#include <Eigen/LU>  // determinant()
#include <cmath>

namespace grbd::kinematics {

Matrix3 rotation_matrix(const Quaternion& p) {
  // BEGIN EXERCISE 1.3: the rotation matrix R(p)
  // Hint: expand the vector part of p (0, x) p̄ with the product formula; collect terms in x.
  // Hint: a × (b × c) = b (aᵀc) − c (aᵀb), and skew(a) is the matrix of x ↦ a × x.
  const double p0 = p.p0();
  const Vector3 p_r = p.p_r();
  // No normalisation on purpose: every term is quadratic in p, so for any p this is
  // |p|² R(p/|p|), the linear part of the scalable body motion.
  return (p0 * p0 - p_r.squaredNorm()) * Matrix3::Identity() + 2.0 * p_r * p_r.transpose() +
         2.0 * p0 * skew(p_r);
  // END EXERCISE 1.3
}

Quaternion quaternion_from_rotation_matrix(const Matrix3& R) {
  // Not part of the exercise: Shepperd's method turns any matrix into some unit quaternion (the
  // zero matrix into the identity), so a matrix that is not a rotation is refused first. 1e-6
  // admits rotations orthogonal only to round-off or to six printed digits.
  if (!is_rotation_matrix(R, 1e-6)) {
    throw InvalidArgument(
        "quaternion_from_rotation_matrix: expected a rotation matrix (max |RᵀR − I| ≤ 1e-6 and "
        "|det R − 1| ≤ 1e-6), found max |RᵀR − I| = " +
        format_number((R.transpose() * R - Matrix3::Identity()).cwiseAbs().maxCoeff()) +
        " and det R = " + format_number(R.determinant()));
  }
  // BEGIN EXERCISE 1.4: the quaternion of a rotation matrix (Shepperd's method)
  // Hint: for |p| = 1 the diagonal of R(p) gives the squares pi², R_ij ± R_ji the products.
  // Hint: a square root of a small number is ill-conditioned: take only the largest one.
  const double tr = R.trace();
  // d_i = 4 p_i²; they sum to 4 |p|² = 4, so the largest is at least 1 and p_k ≥ ½: dividing by
  // 4 p_k below never amplifies round-off, at any angle, 0 and π included.
  const Vector4 d(1.0 + tr, 1.0 + 2.0 * R(0, 0) - tr, 1.0 + 2.0 * R(1, 1) - tr,
                  1.0 + 2.0 * R(2, 2) - tr);
  Eigen::Index k = 0;
  d.maxCoeff(&k);
  // The off-diagonal parts: the skew part of R is 2 p0 p̃_r, the symmetric part 2 p_r p_rᵀ + …
  const double s01 = R(0, 1) + R(1, 0);  // 4 p1 p2
  const double s02 = R(0, 2) + R(2, 0);  // 4 p1 p3
  const double s12 = R(1, 2) + R(2, 1);  // 4 p2 p3
  const double a1 = R(2, 1) - R(1, 2);   // 4 p0 p1
  const double a2 = R(0, 2) - R(2, 0);   // 4 p0 p2
  const double a3 = R(1, 0) - R(0, 1);   // 4 p0 p3
  const double pk = 0.5 * std::sqrt(d[k]);
  const double f = 0.25 / pk;
  Vector4 K;
  switch (k) {
    case 0:
      K << pk, f * a1, f * a2, f * a3;
      break;
    case 1:
      K << f * a1, pk, f * s01, f * s02;
      break;
    case 2:
      K << f * a2, f * s01, pk, f * s12;
      break;
    default:
      K << f * a3, f * s02, f * s12, pk;
      break;
  }
  // p and −p give the same R: return the representative with p0 ≥ 0. The final normalisation
  // absorbs the round-off of an R that is orthogonal only to a few ulps.
  if (K[0] < 0.0) K = -K;
  return Quaternion(Vector4(K.normalized()));
  // END EXERCISE 1.4
}

}  // namespace grbd::kinematics
