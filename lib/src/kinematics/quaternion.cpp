/// \file
/// \brief Quaternions ℍ: inverse, normalisation, the 2 × 2 complex representation and the
/// rotations of E⁴ (the non-exercise part of chapter 1; the product and φ_L, φ_R are exercises).

#include "grbd/kinematics/quaternion.hpp"

#include <complex>

#include "grbd/core/error.hpp"

namespace grbd::kinematics {

Quaternion Quaternion::inverse() const {
  const double n2 = squared_norm();
  // `!(n2 > 0)` also rejects NaN coordinates; an underflowing |P|² (|P| < ~1e-154) is
  // reported as zero rather than producing infinities.
  if (!(n2 > 0.0)) {
    throw InvalidArgument(
        "Quaternion::inverse: P = 0 (or |P|² underflows or is NaN) has no "
        "inverse; expected P ≠ 0");
  }
  return conjugate() * (1.0 / n2);
}

Quaternion Quaternion::normalized() const {
  const double n = norm();
  if (!(n > 0.0)) {
    throw InvalidArgument(
        "Quaternion::normalized: cannot normalise P = 0 (or |P| is NaN); "
        "expected P ≠ 0");
  }
  return Quaternion(Vector4(K_ / n));
}

// [complex matrix]
Eigen::Matrix2cd complex_matrix(const Quaternion& P) {
  using C = std::complex<double>;
  // 1, i, j, k ↦ I, diag(i, −i), [[0, 1], [−1, 0]], [[0, i], [i, 0]]: these four matrices obey
  // i² = j² = k² = ijk = −1, so linear extension gives an algebra homomorphism ℍ → ℂ²ˣ².
  Eigen::Matrix2cd M;
  M << C(P[0], P[1]), C(P[2], P[3]),  //
      C(-P[2], P[3]), C(P[0], -P[1]);
  return M;
}
// [complex matrix]

Quaternion from_complex_matrix(const Eigen::Matrix2cd& M) {
  // The first row alone determines P: M(0,0) = p0 + i p1, M(0,1) = p2 + i p3.
  return {M(0, 0).real(), M(0, 0).imag(), M(0, 1).real(), M(0, 1).imag()};
}

Vector4 rotate_E4(const Quaternion& P, const Vector4& x, const Quaternion& Q) {
  // Left and right multiplications commute (associativity of ℍ), so the order of φ_L(P) and
  // φ_R(Q) does not matter; |PXQ| = |P||X||Q| = |X| for unit P, Q.
  return phi_L(P) * (phi_R(Q) * x);
}

}  // namespace grbd::kinematics
