#pragma once
/// \file
/// \brief Closed-form references for the smooth problems: DETEST B5, the free asymmetric body
/// (Jacobi elliptic functions), the symmetric top, the heavy top's nutation bounds and the
/// intermediate-axis flip (chapter 3; see Landau and Lifshitz, Mechanics §37).

#include <Eigen/Core>

#include "grbd/core/types.hpp"
#include "grbd/ode/rigid_body_rhs.hpp"
#include "grbd/ode/sundials.hpp"

namespace grbd::ode {

/// DETEST problem B5 (Hull et al. 1972): y1' = y2 y3, y2' = −y1 y3, y3' = −0.51 y1 y2,
/// y(0) = (0, 1, 1).
RhsFunction detest_b5();
/// Its exact solution (sn, cn, dn)(t | m = 0.51) (Boost.Math).
Vector3 detest_b5_exact(double t);

/// The torque-free asymmetric body Θ1 < Θ2 < Θ3 on the branch L² > 2E Θ2 (rotation about the
/// axis of the largest moment), from Landau–Lifshitz §37:
/// λ = √((Θ3−Θ2)(L²−2EΘ1)/(Θ1Θ2Θ3)), m = (Θ2−Θ1)(2EΘ3−L²)/((Θ3−Θ2)(L²−2EΘ1)),
/// A1 = √((2EΘ3−L²)/(Θ1(Θ3−Θ1))), A2 = √((2EΘ3−L²)/(Θ2(Θ3−Θ2))), A3 = √((L²−2EΘ1)/(Θ3(Θ3−Θ1))).
struct EulerTop {
  double lambda = 0.0;             ///< frequency λ [1/s]
  double m = 0.0;                  ///< elliptic parameter m ∈ [0, 1)
  Vector3 A = Vector3::Zero();     ///< amplitudes (A1, A2, A3) [rad/s]
  Vector3 sign = Vector3::Ones();  ///< signs (s1, s2, s3) of the three components
  double t0 = 0.0;      ///< time shift: ω(t) = (s1 A1 cn, s2 A2 sn, s3 A3 dn)(λ(t − t0) | m)
  double period = 0.0;  ///< period of ω, 4K(m)/λ [s]
};

/// The parameters of the elliptic solution through ω(0) = K_omega0 for principal moments
/// K_Theta (strictly increasing); throws grbd::InvalidArgument off the branch L² > 2EΘ2 or for
/// moments that are not strictly increasing.
EulerTop euler_top(const Vector3& K_Theta, const Vector3& K_omega0);

// [euler top omega declaration]
/// \brief <b>Exercise 3.4</b>: the elliptic solution of Euler's equations.
///
/// The body angular velocity ω(t) = (s1 A1 cn τ, s2 A2 sn τ, s3 A3 dn τ), τ = λ(t − t0), with
/// the Jacobi elliptic functions of parameter m (Boost.Math: boost::math::jacobi_elliptic, which
/// takes the modulus k = √m).
Vector3 euler_top_omega(const EulerTop& top, double t);
// [euler top omega declaration]

/// The half-period of the intermediate-axis (Dzhanibekov) flip: ω2 changes sign every 2K(m)/λ.
/// Throws grbd::InvalidArgument unless λ > 0 and m ∈ [0, 1).
double flip_interval(const EulerTop& top);

/// The precession rate |L|/Θ⊥ of the symmetry axis of a torque-free symmetric top (Θ1 = Θ2 = Θ⊥)
/// about the fixed angular momentum L = Θ ω [rad/s]. Throws grbd::InvalidArgument unless the
/// moments are positive and Θ1 = Θ2 to 1e-12 relative.
double symmetric_top_precession_rate(const Vector3& K_Theta, const Vector3& K_omega);

/// The nutation band of the heavy symmetric top: the roots u_min ≤ u_max in [−1, 1] of
/// (α − βu)(1 − u²) − (b − a u)², u = cos θ, for the initial state y0 = (p, K_omega) of
/// heavy_top() (θ the angle between the symmetry axis and the vertical).
struct NutationBounds {
  double u_min = 0.0;  ///< cos θ at the lowest point of the axis
  double u_max = 0.0;  ///< cos θ at the highest point of the axis
};
/// See NutationBounds. With I1' = I1 + m l², L_z = (A_IK Θ_O ω)_z and L_3 = I3 ω3:
/// a = L_3/I1', b = L_z/I1', β = 2 m g l/I1', α = ω1² + ω2² + β u0. The roots are found by
/// bisection for the root u3 ≥ 1 and deflation to a quadratic, polished by Newton steps on the
/// cubic; a double root (a sleeping top above the critical spin) gives u_min = u_max. Throws
/// grbd::InvalidArgument unless m, l, I1, I3, g > 0 and y0 has 7 finite entries with p ≠ 0.
NutationBounds heavy_top_nutation_bounds(const HeavyTop& top, const Eigen::VectorXd& y0);

}  // namespace grbd::ode
