/// \file
/// \brief Chapter 1 exercises on the exponential maps: exp and log on S³, and Rodrigues'
/// formula for the exponential on SO(3).

#include "grbd/kinematics/exponential.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/skew.hpp"

#include <cmath>
#include <numbers>

namespace grbd::kinematics {

Quaternion exp_S3(const Vector3& v) {
  // BEGIN EXERCISE 1.5: the exponential on S³
  // Hint: (0, n)² = −1 for a unit vector n, so the power series of exp splits into cos and sin.
  // Hint: never divide by |v| when it is tiny; use the Taylor series of sin(a)/a there.
  const double a = v.norm();
  // sin(a)/a = 1 − a²/6 + a⁴/120 − …: for a < 1e-4 the first neglected term a⁴/120 < 1e-18 is
  // below round-off, and the series avoids 0/0 at a = 0 (and an underflowed a for tiny v).
  const double sinc = a < 1e-4 ? 1.0 - a * a / 6.0 : std::sin(a) / a;
  return {std::cos(a), Vector3(sinc * v)};
  // END EXERCISE 1.5
}

Vector3 log_S3(const Quaternion& p) {
  // BEGIN EXERCISE 1.6: the logarithm on S³
  // Hint: p = (cos a, sin a n); acos(p0) and asin(|p_r|) lose digits near a = 0 or a = π.
  // Hint: atan2(|p_r|, p0) returns a ∈ [0, π] accurately; treat p_r = 0 separately.
  const Vector3 p_r = p.p_r();
  const double s = p_r.norm();  // sin a
  if (s == 0.0) {
    // p = ±1: log 1 = 0; at p = −1 every unit axis n gives exp(π n) = −1, pick e_x.
    return p.p0() < 0.0 ? Vector3(std::numbers::pi, 0.0, 0.0) : Vector3::Zero();
  }
  // a / s is well conditioned near a = 0 (a ≈ s) and near a = π (p_r / s is a unit vector).
  return (std::atan2(s, p.p0()) / s) * p_r;
  // END EXERCISE 1.6
}

Matrix3 exp_SO3(const Vector3& theta) {
  // BEGIN EXERCISE 1.7: Rodrigues' formula, the exponential on SO(3)
  // Hint: the powers of the skew matrix of a unit n satisfy ñ³ = −ñ; sum the series of exp.
  // Hint: 1 − cos a loses digits for small a; 2 sin²(a/2) does not.
  const double a = theta.norm();
  const Matrix3 theta_tilde = skew(theta);
  // A = sin a / a and B = (1 − cos a)/a² = ½ (sin(a/2)/(a/2))², both written through sinc to
  // avoid 0/0 at a = 0 and the cancellation in 1 − cos a; series below 1e-4 as in exp_S3.
  const auto sinc = [](double x) { return x < 1e-4 ? 1.0 - x * x / 6.0 : std::sin(x) / x; };
  const double A = sinc(a);
  const double half = sinc(0.5 * a);
  const double B = 0.5 * half * half;
  return Matrix3::Identity() + A * theta_tilde + B * theta_tilde * theta_tilde;
  // END EXERCISE 1.7
}

}  // namespace grbd::kinematics
