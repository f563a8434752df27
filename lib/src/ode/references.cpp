/// \file
/// \brief The closed-form references of chapter 3 that are not exercises: DETEST B5, the
/// parameters of the elliptic solution of the free asymmetric body (Landau–Lifshitz §37), the
/// flip interval, the precession of the symmetric top, and the nutation band of the heavy top.

#include "grbd/ode/references.hpp"

#include <algorithm>
#include <boost/math/special_functions/ellint_1.hpp>
#include <boost/math/special_functions/jacobi_elliptic.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::ode {

namespace {

/// The parameter m = k² of DETEST B5.
constexpr double kDetestB5Parameter = 0.51;

std::string format_vector(const Vector3& v) {
  return "(" + format_number(v[0]) + ", " + format_number(v[1]) + ", " + format_number(v[2]) + ")";
}

void require_finite(const Vector3& v, const char* name, const char* where) {
  if (!v.allFinite()) {
    throw InvalidArgument(std::string(where) + ": " + name + " must be finite, but it is " +
                          format_vector(v));
  }
}

}  // namespace

RhsFunction detest_b5() {
  return [](double /*t*/, const Eigen::Ref<const Eigen::VectorXd>& y,
            Eigen::Ref<Eigen::VectorXd> y_dot) {
    if (y.size() != 3 || y_dot.size() != 3) {
      throw InvalidArgument("detest_b5: y and y_dot must have 3 entries, but they have " +
                            std::to_string(y.size()) + " and " + std::to_string(y_dot.size()));
    }
    y_dot << y[1] * y[2], -y[0] * y[2], -kDetestB5Parameter * y[0] * y[1];
  };
}

Vector3 detest_b5_exact(double t) {
  double cn = 0.0;
  double dn = 0.0;
  const double sn = boost::math::jacobi_elliptic(std::sqrt(kDetestB5Parameter), t, &cn, &dn);
  return {sn, cn, dn};
}

EulerTop euler_top(const Vector3& K_Theta, const Vector3& K_omega0) {
  require_finite(K_Theta, "K_Theta", "euler_top");
  require_finite(K_omega0, "K_omega0", "euler_top");
  if (!(K_Theta[0] > 0.0 && K_Theta[0] < K_Theta[1] && K_Theta[1] < K_Theta[2])) {
    throw InvalidArgument(
        "euler_top: the principal moments must be positive and strictly increasing, "
        "Θ1 < Θ2 < Θ3, but K_Theta = " +
        format_vector(K_Theta));
  }
  // [euler top]
  const double T1 = K_Theta[0];
  const double T2 = K_Theta[1];
  const double T3 = K_Theta[2];
  const Vector3 w2 = K_omega0.cwiseProduct(K_omega0);
  // The three combinations of L² = Σ Θi² ωi² and 2E = Σ Θi ωi² that the solution needs, written
  // as sums of the other two axes' terms: no cancellation between L² and 2EΘi.
  const double L2_minus_2ET1 = T2 * (T2 - T1) * w2[1] + T3 * (T3 - T1) * w2[2];    // > 0
  const double twoET3_minus_L2 = T1 * (T3 - T1) * w2[0] + T2 * (T3 - T2) * w2[1];  // ≥ 0
  const double L2_minus_2ET2 = T3 * (T3 - T2) * w2[2] - T1 * (T2 - T1) * w2[0];
  if (!(L2_minus_2ET2 > 0.0)) {
    throw InvalidArgument(
        "euler_top: the solution is written for the branch L² > 2EΘ2 (the body tumbles about "
        "the axis of the largest moment Θ3), but L² − 2EΘ2 = " +
        format_number(L2_minus_2ET2) + " for K_omega0 = " + format_vector(K_omega0) +
        " (on the other branch, exchange the axes 1 and 3)");
  }
  EulerTop top;
  top.lambda = std::sqrt((T3 - T2) * L2_minus_2ET1 / (T1 * T2 * T3));
  top.m = (T2 - T1) * twoET3_minus_L2 / ((T3 - T2) * L2_minus_2ET1);
  top.A = Vector3(std::sqrt(twoET3_minus_L2 / (T1 * (T3 - T1))),
                  std::sqrt(twoET3_minus_L2 / (T2 * (T3 - T2))),
                  std::sqrt(L2_minus_2ET1 / (T3 * (T3 - T1))));
  // Euler's equations keep their form under ω → (s1 ω1, s2 ω2, s3 ω3) iff s1 = s2 s3. dn > 0, so
  // s3 is the sign of ω3 (never 0 on this branch); s2 = +1 leaves the phase to sn, and s1 = s3.
  const double s3 = K_omega0[2] > 0.0 ? 1.0 : -1.0;
  top.sign = Vector3(s3, 1.0, s3);
  // The phase: (cn, sn)(τ0) = (cos φ0, sin φ0) with the amplitude φ0 = am τ0, so
  // τ0 = F(φ0 | m), the incomplete elliptic integral of the first kind (Boost takes k = √m and
  // any φ, counting whole quarter periods K). A steady rotation about e3 has A1 = A2 = 0: τ0 = 0.
  const double k = std::sqrt(top.m);
  double tau0 = 0.0;
  if (twoET3_minus_L2 > 0.0) {
    const double phi0 = std::atan2(K_omega0[1] / top.A[1], s3 * K_omega0[0] / top.A[0]);
    tau0 = boost::math::ellint_1(k, phi0);
  }
  top.t0 = -tau0 / top.lambda;  // τ = λ(t − t0) = τ0 at t = 0
  top.period = 4.0 * boost::math::ellint_1(k) / top.lambda;
  // [euler top]
  return top;
}

double flip_interval(const EulerTop& top) {
  require_positive_finite("flip_interval", "lambda", top.lambda);
  if (!(top.m >= 0.0 && top.m < 1.0)) {
    throw InvalidArgument("flip_interval: the parameter m must lie in [0, 1), but m = " +
                          format_number(top.m));
  }
  // sn has its zeros at τ = 2nK(m).
  return 2.0 * boost::math::ellint_1(std::sqrt(top.m)) / top.lambda;
}

double symmetric_top_precession_rate(const Vector3& K_Theta, const Vector3& K_omega) {
  require_finite(K_omega, "K_omega", "symmetric_top_precession_rate");
  require_positive_finite("symmetric_top_precession_rate", "K_Theta[0]", K_Theta[0]);
  require_positive_finite("symmetric_top_precession_rate", "K_Theta[1]", K_Theta[1]);
  require_positive_finite("symmetric_top_precession_rate", "K_Theta[2]", K_Theta[2]);
  // Θ1 = Θ2 up to the round-off of a computed inertia tensor.
  if (std::abs(K_Theta[0] - K_Theta[1]) > 1e-12 * std::max(K_Theta[0], K_Theta[1])) {
    throw InvalidArgument(
        "symmetric_top_precession_rate: a symmetric top has Θ1 = Θ2 = Θ⊥, but K_Theta = " +
        format_vector(K_Theta));
  }
  const double Theta_perp = 0.5 * (K_Theta[0] + K_Theta[1]);
  return K_Theta.cwiseProduct(K_omega).norm() / Theta_perp;
}

NutationBounds heavy_top_nutation_bounds(const HeavyTop& top, const Eigen::VectorXd& y0) {
  const char* where = "heavy_top_nutation_bounds";
  require_positive_finite(where, "m", top.m);
  require_positive_finite(where, "l", top.l);
  require_positive_finite(where, "I1", top.I1);
  require_positive_finite(where, "I3", top.I3);
  require_positive_finite(where, "g", top.g);
  if (y0.size() != 7 || !y0.allFinite()) {
    throw InvalidArgument(std::string(where) +
                          ": y0 = (p, K_omega) must have 7 finite entries, but it has " +
                          std::to_string(y0.size()));
  }
  const double p_norm = y0.head<4>().norm();
  if (!(p_norm > 0.0)) throw InvalidArgument(std::string(where) + ": the quaternion p is zero");

  // The conserved quantities of the initial state. u = cos θ = (A_IK e3)_z.
  const Matrix3 A_IK =
      kinematics::rotation_matrix(kinematics::Quaternion(Vector4(y0.head<4>() / p_norm)));
  const Vector3 K_omega = y0.tail<3>();
  const double I1_O = top.I1 + top.m * top.l * top.l;
  const Vector3 I_L_O = A_IK * Vector3(I1_O * K_omega[0], I1_O * K_omega[1], top.I3 * K_omega[2]);
  const double u0 = A_IK(2, 2);
  // Goldstein's constants: b and a from the vertical and axial angular momenta, β from the
  // weight, α from the energy less the (constant) axial part.
  const double a = top.I3 * K_omega[2] / I1_O;
  const double b = I_L_O[2] / I1_O;
  const double beta = 2.0 * top.m * top.g * top.l / I1_O;
  const double alpha = K_omega[0] * K_omega[0] + K_omega[1] * K_omega[1] + beta * u0;
  // f(u) = (α − βu)(1 − u²) − (b − au)² = u̇²: f(±1) = −(b ∓ a)² ≤ 0, f(u0) ≥ 0, f(∞) = ∞. Its
  // roots are u1 ≤ u0 ≤ u2 in [−1, 1] and u3 ≥ 1.
  const auto f = [&](double u) {
    return (alpha - beta * u) * (1.0 - u * u) - std::pow(b - a * u, 2);
  };
  const auto f_prime = [&](double u) {
    return -beta * (1.0 - u * u) - 2.0 * u * (alpha - beta * u) + 2.0 * a * (b - a * u);
  };
  // u3 by bisection on [1, hi] with f(1) ≤ 0 < f(hi): robust, and u3 is a simple root.
  double lo = 1.0;
  double hi = 2.0;
  for (int i = 0; i < 2000 && f(hi) <= 0.0; ++i) {
    lo = hi;
    hi *= 2.0;
  }
  for (int i = 0; i < 200 && hi - lo > 4.0 * std::numeric_limits<double>::epsilon() * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > 0.0 ? hi : lo) = mid;
  }
  const double u3 = 0.5 * (lo + hi);
  // Deflate f(u) = β u³ + c2 u² + c1 u + c0 = (u − u3)(β u² + d1 u + d0), then solve the
  // quadratic without cancellation (q has the sign of −d1).
  const double c2 = -(alpha + a * a);
  const double c1 = 2.0 * a * b - beta;
  const double d1 = c2 + beta * u3;
  const double d0 = c1 + d1 * u3;
  const double discriminant = std::max(0.0, d1 * d1 - 4.0 * beta * d0);
  const double q = -0.5 * (d1 + std::copysign(std::sqrt(discriminant), d1));
  double r1 = q / beta;
  double r2 = q != 0.0 ? d0 / q : r1;
  // A few Newton steps on f itself remove the error of the deflation where the root is simple.
  const auto polish = [&](double r) {
    for (int i = 0; i < 4; ++i) {
      const double slope = f_prime(r);
      if (slope == 0.0) break;
      const double next = r - f(r) / slope;
      if (!(std::abs(f(next)) < std::abs(f(r)))) break;
      r = next;
    }
    return r;
  };
  r1 = polish(r1);
  r2 = polish(r2);
  if (r1 > r2) std::swap(r1, r2);
  // u0 lies in the band: a cusp (θ̇ = φ̇ = 0 at t = 0) makes it a root, found up to round-off.
  NutationBounds bounds;
  bounds.u_min = std::clamp(std::min(r1, u0), -1.0, 1.0);
  bounds.u_max = std::clamp(std::max(r2, u0), -1.0, 1.0);
  return bounds;
}

}  // namespace grbd::ode
