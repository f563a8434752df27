// Chapter 3: the closed-form references — DETEST B5, the elliptic solution of the free asymmetric
// body (Exercise 3.4 and euler_top()), the intermediate-axis flip, the precession of the symmetric
// top, and the nutation band of the heavy top.
//
// Independent references: the identities of the Jacobi elliptic functions (sn² + cn² = 1,
// dn² + m sn² = 1, sn(K) = 1) and central differences; Euler's equations written out and
// integrated by CVODE at rtol 1e-12 (a numerical reference that shares no code with the closed
// forms); the energy and |L| of the body; the swept angle of the symmetry axis about L; the cosine
// of the heavy top's tilt along a CVODE trajectory; the sleeping-top criterion I3²ω3² > 4 I1 m g l.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <boost/math/special_functions/ellint_1.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "grbd/body/rigid_body.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/ode/references.hpp"
#include "grbd/ode/rigid_body_rhs.hpp"
#include "grbd/ode/sundials.hpp"
#include "grbd_test/bodies.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::InvalidArgument;
using grbd::Matrix3;
using grbd::Vector3;
using grbd::body::RigidBody;
using grbd::body::State;
using grbd::kinematics::make_q;
using grbd::kinematics::make_u;
using grbd::kinematics::Quaternion;
using grbd::ode::Cvode;
using grbd::ode::CvodeMethod;
using grbd::ode::EulerTop;
using grbd::ode::HeavyTop;
using grbd::ode::RhsFunction;
using grbd::test::describe;
using grbd::test::WorstCase;
using Ref = Eigen::Ref<const Eigen::VectorXd>;
using Out = Eigen::Ref<Eigen::VectorXd>;

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// Euler's equations of the torque-free body, Θ_i ω̇_i = (Θ_j − Θ_k) ω_j ω_k, written out for
/// CVODE: the numerical reference shares no code with the closed forms or with free_body().
RhsFunction euler_equations(const RigidBody& body) {
  return [body](double, const Ref& w, Out w_dot) {
    w_dot = grbd::test::gyroscopic_torque(body, Vector3(w)).cwiseQuotient(body.K_Theta);
  };
}

/// 2E = ωᵀΘω and |L|² = |Θω|².
double two_energy(const Vector3& Theta, const Vector3& w) { return w.dot(Theta.cwiseProduct(w)); }
double momentum2(const Vector3& Theta, const Vector3& w) {
  return Theta.cwiseProduct(w).squaredNorm();
}

/// Random principal moments Θ1 < Θ2 < Θ3 in [0.1, 3.1), at least 0.1 apart.
Vector3 random_moments(grbd::test::Random& rng) {
  const double T1 = rng.uniform(0.1, 1.1);
  const double T2 = T1 + rng.uniform(0.1, 1.0);
  return {T1, T2, T2 + rng.uniform(0.1, 1.0)};
}

/// Random initial angular velocities on the branch L² > 2EΘ2 of Θ (with a margin of 1e-3 2EΘ2,
/// so m ≤ ~0.999), with every sign pattern: ω ∈ [−2, 2)³ by rejection.
std::vector<Vector3> branch_states(const Vector3& Theta, grbd::test::Random& rng, int count) {
  std::vector<Vector3> states;
  while (static_cast<int>(states.size()) < count) {
    const Vector3 w = rng.vector3(-2.0, 2.0);
    if (momentum2(Theta, w) > 1.001 * two_energy(Theta, w) * Theta[1]) states.push_back(w);
  }
  return states;
}

/// The heavy top of these tests: a small top, 1 kg, S 10 cm above the tip, Θ_S = (4, 4, 2) g m².
const HeavyTop kTop{1.0, 0.1, 0.004, 0.002, 9.81};

/// y0 = (p, K_omega) with the symmetry axis tilted by θ0 about the x axis.
Eigen::VectorXd tilted_top(double theta0, const Vector3& K_omega) {
  Eigen::VectorXd y0(7);
  y0 << std::cos(0.5 * theta0), std::sin(0.5 * theta0), 0.0, 0.0, K_omega;
  return y0;
}

/// cos θ = (A_IK e3)_z, by Eigen.
double cos_tilt(const Eigen::VectorXd& y) {
  return Eigen::Quaterniond(y[0], y[1], y[2], y[3]).normalized().toRotationMatrix()(2, 2);
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// DETEST B5
// ----------------------------------------------------------------------------------------------

// Reference: y(0) = (0, 1, 1); the identities sn² + cn² = 1 and dn² + 0.51 sn² = 1 (tolerance
// 4 eps); sn(K) = 1 at the quarter period K = K(0.51) (tolerance 1e-15); and the ODE itself:
// fourth-order central differences of the exact solution (δ = 1e-3, truncation ~δ⁴ ≈ 1e-12)
// equal detest_b5() at the exact solution to 1e-10, for t ∈ [−20, 20].
TEST(DetestB5Reference, ExactSolutionSatisfiesTheProblem) {
  EXPECT_EQ(grbd::ode::detest_b5_exact(0.0), Vector3(0.0, 1.0, 1.0));
  const double K = boost::math::ellint_1(std::sqrt(0.51));
  EXPECT_NEAR(grbd::ode::detest_b5_exact(K)[0], 1.0, 1e-15);
  const RhsFunction f = grbd::ode::detest_b5();
  const double delta = 1e-3;
  WorstCase worst_identity;
  WorstCase worst_ode;
  for (double t = -20.0; t <= 20.0; t += 0.173) {
    const Vector3 y = grbd::ode::detest_b5_exact(t);
    worst_identity.update(std::abs(y[0] * y[0] + y[1] * y[1] - 1.0),
                          [&] { return "sn² + cn² = 1, " + describe("t", t, "y(t)", y); });
    worst_identity.update(std::abs(y[2] * y[2] + 0.51 * y[0] * y[0] - 1.0),
                          [&] { return "dn² + 0.51 sn² = 1, " + describe("t", t, "y(t)", y); });
    const Vector3 derivative =
        (8.0 * (grbd::ode::detest_b5_exact(t + delta) - grbd::ode::detest_b5_exact(t - delta)) -
         (grbd::ode::detest_b5_exact(t + 2 * delta) - grbd::ode::detest_b5_exact(t - 2 * delta))) /
        (12.0 * delta);
    Eigen::VectorXd y_dot(3);
    f(t, Eigen::VectorXd(y), y_dot);
    worst_ode.update((y_dot - Eigen::VectorXd(derivative)).cwiseAbs().maxCoeff(), [&] {
      return describe("t", t, "y(t)", y, "f(t, y)", y_dot, "differences", derivative);
    });
  }
  EXPECT_LE(worst_identity.value(), 4.0 * kEps) << worst_identity;
  EXPECT_LE(worst_ode.value(), 1e-10) << worst_ode;
}

// Reference: Hull et al. (1972), problem B5, written out; three entries or InvalidArgument.
TEST(DetestB5Reference, RightHandSideIsProblemB5) {
  const RhsFunction f = grbd::ode::detest_b5();
  Eigen::VectorXd y_dot(3);
  f(0.0, Eigen::Vector3d(2.0, 3.0, 5.0), y_dot);
  EXPECT_EQ(y_dot, Eigen::Vector3d(15.0, -10.0, -0.51 * 6.0));
  Eigen::VectorXd wrong(4);
  EXPECT_THROW(f(0.0, Eigen::Vector4d::Zero(), wrong), InvalidArgument);
}

// ----------------------------------------------------------------------------------------------
// euler_top(): the parameters of the elliptic solution
// ----------------------------------------------------------------------------------------------

// Reference: inserting ω = (s1A1 cn, s2A2 sn, s3A3 dn)(λ(t − t0)) into Euler's equations
// (d sn = cn dn, d cn = −sn dn, d dn = −m sn cn) requires
//   Θ1 A1 λ = (Θ3 − Θ2) A2 A3,  Θ2 A2 λ = (Θ3 − Θ1) A1 A3,  Θ3 A3 m λ = (Θ2 − Θ1) A1 A2,
// s1 = s2 s3; at sn = 0 the invariants read 2E = Θ1A1² + Θ3A3², L² = Θ1²A1² + Θ3²A3²; and
// m ∈ [0, 1), period = 4K(m)/λ. Random bodies and branch states; tolerance 1e-13 relative.
TEST(EulerTop, ParametersSolveEulersEquationsAndKeepTheInvariants) {
  grbd::test::Random rng(3401);
  WorstCase worst;
  for (int n = 0; n < 200; ++n) {
    const Vector3 Theta = random_moments(rng);
    for (const Vector3& w : branch_states(Theta, rng, 5)) {
      const EulerTop top = grbd::ode::euler_top(Theta, w);
      const Vector3& A = top.A;
      const double scale = Theta.maxCoeff() * A.squaredNorm();
      const auto inputs = [&] {
        return describe("Theta", Theta, "w", w, "A", A, "lambda", top.lambda, "m", top.m,
                        "period", top.period);
      };
      worst.update(
          std::abs(Theta[0] * A[0] * top.lambda - (Theta[2] - Theta[1]) * A[1] * A[2]) / scale, n,
          [&] { return "Θ1 A1 λ, " + inputs(); });
      worst.update(
          std::abs(Theta[1] * A[1] * top.lambda - (Theta[2] - Theta[0]) * A[0] * A[2]) / scale, n,
          [&] { return "Θ2 A2 λ, " + inputs(); });
      worst.update(
          std::abs(Theta[2] * A[2] * top.m * top.lambda - (Theta[1] - Theta[0]) * A[0] * A[1]) /
              scale,
          n, [&] { return "Θ3 A3 m λ, " + inputs(); });
      worst.update(
          std::abs(Theta[0] * A[0] * A[0] + Theta[2] * A[2] * A[2] - two_energy(Theta, w)) /
              two_energy(Theta, w),
          n, [&] { return "2E, " + inputs(); });
      worst.update(std::abs(Theta[0] * Theta[0] * A[0] * A[0] + Theta[2] * Theta[2] * A[2] * A[2] -
                            momentum2(Theta, w)) /
                       momentum2(Theta, w),
                   n, [&] { return "L², " + inputs(); });
      worst.update(
          std::abs(top.period - 4.0 * boost::math::ellint_1(std::sqrt(top.m)) / top.lambda) /
              top.period,
          n, [&] { return "period, " + inputs(); });
      EXPECT_EQ(top.sign[0], top.sign[1] * top.sign[2]);
      EXPECT_GE(top.m, 0.0);
      EXPECT_LT(top.m, 1.0);
    }
  }
  EXPECT_LE(worst.value(), 1e-13) << worst;
}

// Reference: the preconditions of references.hpp: Θ1 < Θ2 < Θ3, positive and finite, and the
// branch L² > 2EΘ2 (a body spinning about its smallest axis is on the other branch).
TEST(EulerTop, RejectsTheOtherBranchAndMomentsThatDoNotIncrease) {
  const Vector3 Theta(1.0, 2.0, 3.0);
  EXPECT_THROW(grbd::ode::euler_top(Theta, Vector3(2.0, 0.1, 0.1)), InvalidArgument);
  EXPECT_THROW(grbd::ode::euler_top(Theta, Vector3(0.0, 1.0, 0.0)), InvalidArgument);
  for (const Vector3& bad :
       {Vector3(1.0, 1.0, 3.0), Vector3(1.0, 3.0, 2.0), Vector3(0.0, 2.0, 3.0),
        Vector3(-1.0, 2.0, 3.0), Vector3(1.0, 2.0, std::numeric_limits<double>::infinity())}) {
    EXPECT_THROW(grbd::ode::euler_top(bad, Vector3(0.1, 0.1, 1.0)), InvalidArgument) << bad;
  }
  EXPECT_THROW(grbd::ode::euler_top(Theta, Vector3(0.1, std::nan(""), 1.0)), InvalidArgument);
}

// ----------------------------------------------------------------------------------------------
// Exercise 3.4: the elliptic solution of Euler's equations
// ----------------------------------------------------------------------------------------------

// Reference: the initial value itself, for random bodies and branch states with every sign
// pattern of ω0: |ω(0) − ω0| ≤ 1e-13 |ω0| (the phase goes through atan2 and F(φ | m)).
TEST(Exercise3_4, StartsAtTheInitialAngularVelocity) {
  grbd::test::Random rng(3402);
  WorstCase worst;
  for (int n = 0; n < 200; ++n) {
    const Vector3 Theta = random_moments(rng);
    for (const Vector3& w : branch_states(Theta, rng, 5)) {
      const EulerTop top = grbd::ode::euler_top(Theta, w);
      worst.update((grbd::ode::euler_top_omega(top, 0.0) - w).norm() / w.norm(), n,
                   [&] { return describe("Theta", Theta, "w0", w); });
    }
  }
  EXPECT_LE(worst.value(), 1e-13) << worst;
}

// Reference: the torque-free body keeps 2E = ωᵀΘω and L² = |Θω|², and ω has the period 4K/λ;
// ω2 changes sign every flip_interval(). Tolerances 1e-13 relative (invariants, at 100 times in
// two periods) and 1e-12 |ω| (periodicity).
TEST(Exercise3_4, KeepsEnergyAndMomentumAndIsPeriodic) {
  grbd::test::Random rng(3403);
  WorstCase worst_invariants;
  WorstCase worst_period;
  const Vector3 Theta(0.7, 1.1, 2.5);
  for (const Vector3& w : branch_states(Theta, rng, 20)) {
    const EulerTop top = grbd::ode::euler_top(Theta, w);
    for (int k = 0; k < 100; ++k) {
      const double t = 0.02 * k * top.period;
      const Vector3 omega = grbd::ode::euler_top_omega(top, t);
      const auto inputs = [&] { return describe("Theta", Theta, "w0", w, "t", t); };
      worst_invariants.update(std::abs(two_energy(Theta, omega) / two_energy(Theta, w) - 1.0),
                              [&] { return "2E, " + inputs(); });
      worst_invariants.update(std::abs(momentum2(Theta, omega) / momentum2(Theta, w) - 1.0),
                              [&] { return "L², " + inputs(); });
      worst_period.update(
          (grbd::ode::euler_top_omega(top, t + top.period) - omega).norm() / w.norm(), inputs);
    }
    EXPECT_NEAR(grbd::ode::flip_interval(top), 0.5 * top.period, 1e-14 * top.period);
  }
  EXPECT_LE(worst_invariants.value(), 1e-13) << worst_invariants;
  EXPECT_LE(worst_period.value(), 1e-12) << worst_period;
}

// Reference: Euler's equations written out and integrated by CVODE (BDF, rtol 1e-12, atol 1e-14)
// over two periods, sampled 200 times, for three bodies and sign patterns. Agreement within
// 2e-9 |ω0| (observed ≤ 4e-10 |ω0|: CVODE's global error at rtol 1e-12 grows by ~2e-10 per
// period).
TEST(Exercise3_4, MatchesCvodeOnEulersEquations) {
  const std::vector<std::pair<Vector3, Vector3>> cases{
      {Vector3(1.0, 2.0, 3.0), Vector3(0.4, 1.2, 0.9)},
      {Vector3(1.0, 2.0, 3.0), Vector3(-0.4, 1.2, -0.9)},
      {Vector3(0.2, 0.5, 0.6), Vector3(1.5, -0.3, 2.0)},
  };
  for (const auto& [Theta, w0] : cases) {
    const RigidBody body{1.0, Theta};
    const EulerTop top = grbd::ode::euler_top(Theta, w0);
    Cvode cvode(euler_equations(body), 0.0, w0, CvodeMethod::bdf, {1e-12, 1e-14, {}});
    WorstCase worst;
    for (int k = 1; k <= 200; ++k) {
      const double t = 0.01 * k * top.period;
      const Vector3 by_cvode = cvode.advance(t);
      worst.update((by_cvode - grbd::ode::euler_top_omega(top, t)).norm() / w0.norm(),
                   [&] { return describe("t", t, "CVODE ω(t)", by_cvode); });
    }
    EXPECT_LE(worst.value(), 2e-9) << "Θ = " << Theta.transpose() << ", ω0 = " << w0.transpose()
                                   << "; " << worst;
  }
}

// ----------------------------------------------------------------------------------------------
// The intermediate-axis (Dzhanibekov) flip
// ----------------------------------------------------------------------------------------------

// Reference: CVODE (BDF, rtol 1e-12, atol 1e-14) on Euler's equations written out, from a spin
// Ω = 2 rad/s about the intermediate axis with a small disturbance (m = 1 − 2.7e-6): the times
// at which ω2 changes sign (located by linear interpolation between outputs 1 ms apart, where
// ω2'' = 0) are 2K(m)/λ = 13.49 s apart. Tolerance 1e-7 relative (observed ~2e-10).
TEST(Dzhanibekov, FlipIntervalMatchesTheSignChangesOfOmega2) {
  const RigidBody body{1.0, Vector3(1.0, 2.0, 3.0)};
  const Vector3 w0(1e-3, 2.0, 2e-3);
  const EulerTop top = grbd::ode::euler_top(body.K_Theta, w0);
  const double predicted = grbd::ode::flip_interval(top);
  ASSERT_GT(predicted, 13.0);
  Cvode cvode(euler_equations(body), 0.0, w0, CvodeMethod::bdf, {1e-12, 1e-14, {}});
  std::vector<double> sign_changes;
  double t_previous = 0.0;
  double w2_previous = w0[1];
  const double dt = 1e-3;
  for (int k = 1; k <= static_cast<int>(3.5 * predicted / dt); ++k) {
    const double t = k * dt;
    const double w2 = cvode.advance(t)[1];
    if ((w2 > 0.0) != (w2_previous > 0.0)) {
      sign_changes.push_back(t_previous + dt * w2_previous / (w2_previous - w2));
    }
    t_previous = t;
    w2_previous = w2;
  }
  ASSERT_GE(sign_changes.size(), 3u);
  for (std::size_t i = 1; i < sign_changes.size(); ++i) {
    EXPECT_NEAR(sign_changes[i] - sign_changes[i - 1], predicted, 1e-7 * predicted);
  }
}

// ----------------------------------------------------------------------------------------------
// The torque-free symmetric top
// ----------------------------------------------------------------------------------------------

// Reference: REFERENCES.md: the symmetry axis a = A_IK e3 precesses about the fixed L at
// |L|/I⊥. CVODE (BDF, rtol 1e-12, atol 1e-14, projection) on free_body() over 10 s; the angle
// that the part of a normal to L sweeps about L̂ (accumulated between outputs 5 ms apart),
// divided by the time: tolerance 1e-8 relative (observed 4e-11). And the formula itself on the
// closed-form top of grbd_test/bodies.hpp; Θ1 ≠ Θ2 is rejected.
TEST(SymmetricTop, PrecessionRateMatchesTheSweptAngleOfTheSymmetryAxis) {
  const RigidBody body{1.0, Vector3(1.0, 1.0, 0.4)};
  const grbd::test::SymmetricTop top(
      body, Vector3(0.6, -0.3, 2.0),
      grbd::test::axis_angle_matrix(0.7 * Vector3(1, 2, 3).normalized()));
  const double rate = grbd::ode::symmetric_top_precession_rate(body.K_Theta, top.omega0);
  EXPECT_NEAR(rate, top.I_L.norm() / top.I_perp, 1e-15 * rate);

  const State x0{make_q(Vector3::Zero(), grbd::test::reference_quaternion(top.A0)),
                 make_u(Vector3::Zero(), top.omega0)};
  Cvode cvode(grbd::ode::free_body(body), 0.0, grbd::ode::pack(x0), CvodeMethod::bdf,
              {1e-12, 1e-14, {}});
  cvode.set_projection(grbd::ode::quaternion_projection_at(3));
  const Vector3 L_hat = top.I_L.normalized();
  const auto normal_part = [&](const Eigen::VectorXd& y) {
    const Vector3 a = grbd::test::reference_A_IK(y.head<7>()).col(2);
    return Vector3(a - a.dot(L_hat) * L_hat);
  };
  Vector3 previous = normal_part(grbd::ode::pack(x0));
  double swept = 0.0;
  const double T = 10.0;
  for (int k = 1; k <= 2000; ++k) {
    const Vector3 a = normal_part(cvode.advance(T * k / 2000));
    swept += std::atan2(L_hat.dot(previous.cross(a)), previous.dot(a));
    previous = a;
  }
  EXPECT_NEAR(swept / T, rate, 1e-8 * rate);
  EXPECT_THROW(grbd::ode::symmetric_top_precession_rate(Vector3(1.0, 1.1, 0.4), top.omega0),
               InvalidArgument);
}

// ----------------------------------------------------------------------------------------------
// The heavy symmetric top
// ----------------------------------------------------------------------------------------------

// Reference: cos θ along CVODE's trajectory (BDF, rtol 1e-12, atol 1e-14, projection) of the
// heavy top, 1 s (three nutations) sampled every 0.25 ms, for a cusp (released with θ̇ = φ̇ = 0:
// u_max = u0) and a general start. Every sample lies in [u_min, u_max] (tolerance 1e-9), and
// the band is touched at both ends: the extremes of the samples, refined by the vertex of the
// parabola through three samples, lie within 1e-8 of u_min and u_max (observed ≤ 3e-10).
TEST(HeavyTop, NutationBoundsContainTheMotionAndAreTouched) {
  for (const Vector3& w0 : {Vector3(0.0, 0.0, 150.0), Vector3(2.0, -3.0, 150.0)}) {
    const Eigen::VectorXd y0 = tilted_top(0.5, w0);
    const grbd::ode::NutationBounds bounds = grbd::ode::heavy_top_nutation_bounds(kTop, y0);
    ASSERT_LT(bounds.u_min, bounds.u_max - 0.1);
    Cvode cvode(grbd::ode::heavy_top(kTop), 0.0, y0, CvodeMethod::bdf, {1e-12, 1e-14, {}});
    cvode.set_projection(grbd::ode::quaternion_projection_at(0));
    std::vector<double> u{cos_tilt(y0)};
    for (int k = 1; k <= 4000; ++k) u.push_back(cos_tilt(cvode.advance(2.5e-4 * k)));
    double lowest = 1.0;
    double highest = -1.0;
    WorstCase outside;
    for (std::size_t k = 1; k + 1 < u.size(); ++k) {
      const auto inputs = [&] { return describe("t", 2.5e-4 * static_cast<double>(k), "u", u[k]); };
      outside.update(bounds.u_min - u[k], inputs);
      outside.update(u[k] - bounds.u_max, inputs);
      const double second = u[k + 1] - 2.0 * u[k] + u[k - 1];
      const double vertex = u[k] - std::pow(u[k + 1] - u[k - 1], 2) / (8.0 * second);
      if (u[k] <= u[k - 1] && u[k] <= u[k + 1]) lowest = std::min(lowest, vertex);
      if (u[k] >= u[k - 1] && u[k] >= u[k + 1]) highest = std::max(highest, vertex);
    }
    EXPECT_LE(outside.value(), 1e-9) << "ω0 = " << w0.transpose() << "; " << outside;
    EXPECT_NEAR(lowest, bounds.u_min, 1e-8) << "ω0 = " << w0.transpose();
    EXPECT_NEAR(highest, bounds.u_max, 1e-8) << "ω0 = " << w0.transpose();
  }
}

// Reference: REFERENCES.md: a sleeping top (vertical, ω = ω3 e3) is stable iff
// I3²ω3² > 4 I1' m g l (I1' = I1 + m l² about the tip). Then f(u) = (1 − u)²(β(1 + u) − a²) has
// the double root 1 and the band is [1, 1]; below the critical spin the top falls to
// u_min = a²/β − 1 = I3²ω3²/(2 I1' m g l) − 1. Tolerance 1e-10.
TEST(HeavyTop, SleepingTopIsStableAboveTheCriticalSpin) {
  const double I1_O = kTop.I1 + kTop.m * kTop.l * kTop.l;
  const double critical = std::sqrt(4.0 * I1_O * kTop.m * kTop.g * kTop.l) / kTop.I3;
  for (double factor : {0.5, 0.9, 0.99, 1.01, 1.5, 3.0}) {
    const double w3 = factor * critical;
    const grbd::ode::NutationBounds bounds =
        grbd::ode::heavy_top_nutation_bounds(kTop, tilted_top(0.0, Vector3(0.0, 0.0, w3)));
    const double expected =
        std::min(1.0, kTop.I3 * kTop.I3 * w3 * w3 / (2.0 * I1_O * kTop.m * kTop.g * kTop.l) - 1.0);
    EXPECT_NEAR(bounds.u_max, 1.0, 1e-10) << factor;
    EXPECT_NEAR(bounds.u_min, expected, 1e-10) << factor;
  }
}

// Reference: the preconditions of references.hpp: m, l, I1, I3, g positive and finite; y0 with
// seven finite entries and p ≠ 0.
TEST(HeavyTop, NutationBoundsRejectInvalidInput) {
  const Eigen::VectorXd y0 = tilted_top(0.5, Vector3(0.0, 0.0, 150.0));
  for (const HeavyTop& top :
       {HeavyTop{0.0, 0.1, 1.0, 1.0, 9.81}, HeavyTop{1.0, 0.0, 1.0, 1.0, 9.81},
        HeavyTop{1.0, 0.1, -1.0, 1.0, 9.81}, HeavyTop{1.0, 0.1, 1.0, 0.0, 9.81},
        HeavyTop{1.0, 0.1, 1.0, 1.0, 0.0}}) {
    EXPECT_THROW(grbd::ode::heavy_top_nutation_bounds(top, y0), InvalidArgument);
  }
  EXPECT_THROW(grbd::ode::heavy_top_nutation_bounds(kTop, Eigen::VectorXd::Zero(6)),
               InvalidArgument);
  Eigen::VectorXd zero_p = y0;
  zero_p.head<4>().setZero();
  EXPECT_THROW(grbd::ode::heavy_top_nutation_bounds(kTop, zero_p), InvalidArgument);
}
