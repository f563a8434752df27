/// \file
/// \brief The exercises of chapter 6: the pieces of the midpoint step, each against a closed form
/// or an independent computation.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/exponential.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/timestep/midpoint.hpp"
#include "grbd_test/bodies.hpp"

namespace grbd::timestep {
namespace {

Vector7 random_q(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  Vector4 p(n(rng), n(rng), n(rng), n(rng));
  p.normalize();
  Vector7 q;
  q << n(rng), n(rng), n(rng), p;
  return q;
}

Vector6 random_u(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  Vector6 u;
  for (int i = 0; i < 6; ++i) u(i) = 3.0 * n(rng);
  return u;
}

// Closed form: for constant u, r moves by Δt/2 v and p turns about the body axis ω/|ω| by the
// angle |ω| Δt/2, i.e. p ← p (cos(|ω|Δt/4), sin(|ω|Δt/4) ω/|ω|).
TEST(Exercise6_1, MovesHalfAStepAlongTheExactFlowOfConstantVelocity) {
  std::mt19937_64 rng(61);
  for (int trial = 0; trial < 100; ++trial) {
    const Vector7 q = random_q(rng);
    const Vector6 u = random_u(rng);
    const double dt = 0.01 * (1 + trial % 7);
    const Vector7 qM = half_step(q, u, dt);
    EXPECT_LE((qM.head<3>() - (q.head<3>() + 0.5 * dt * u.head<3>())).norm(), 1e-14);
    const Vector3 w = u.tail<3>();
    const double angle = w.norm() * dt / 4.0;
    Vector4 e;
    e << std::cos(angle), std::sin(angle) * w.normalized();
    const kinematics::Quaternion expected =
        kinematics::orientation(q) * kinematics::Quaternion(e);
    EXPECT_LE((qM.tail<4>() - expected.coeffs()).norm(), 1e-14) << "trial " << trial;
    EXPECT_NEAR(qM.tail<4>().norm(), 1.0, 1e-15);
  }
}

TEST(Exercise6_1, TwoHalfStepsAreOneStepOfTheExponentialMap) {
  std::mt19937_64 rng(62);
  for (int trial = 0; trial < 50; ++trial) {
    const Vector7 q = random_q(rng);
    const Vector6 u = random_u(rng);
    const Vector7 twice = half_step(half_step(q, u, 0.02), u, 0.02);
    EXPECT_LE((twice - kinematics::exp_map_step(q, u, 0.02)).norm(), 1e-14);
  }
}

TEST(Exercise6_1, AgreesWithAddAndNormalizeToSecondOrderInTheAngle) {
  // The two variants differ by O((|ω|Δt)³) in the orientation (compared in the chapter): halving
  // Δt divides the difference by about 8.
  std::mt19937_64 rng(63);
  const Vector7 q = random_q(rng);
  const Vector6 u = random_u(rng);
  const double d1 = (half_step(q, u, 0.02) - half_step_add_normalize(q, u, 0.02)).norm();
  const double d2 = (half_step(q, u, 0.01) - half_step_add_normalize(q, u, 0.01)).norm();
  EXPECT_GT(d1, 0.0);
  EXPECT_NEAR(d1 / d2, 8.0, 0.5);
}

TEST(Exercise6_2, IsOneEulerStepOfNewtonEulerFromTheStartVelocity) {
  std::mt19937_64 rng(64);
  test::Random random(64);
  for (int trial = 0; trial < 50; ++trial) {
    const body::RigidBody body = test::random_body(random);
    const Vector6 u = random_u(rng);
    body::Loads loads;
    std::normal_distribution<double> n;
    loads.I_F = Vector3(n(rng), n(rng), n(rng));
    loads.K_M = Vector3(n(rng), n(rng), n(rng));
    const double dt = 1e-3;
    // Written out: v + Δt F/m and ω + Δt Θ⁻¹ (M − ω × Θ ω).
    const Vector3 w = u.tail<3>();
    const Vector3 Theta_w = body.K_Theta.cwiseProduct(w);
    Vector6 expected;
    expected << u.head<3>() + dt * loads.I_F / body.m,
        w + dt * (loads.K_M - w.cross(Theta_w)).cwiseQuotient(body.K_Theta);
    const Vector6 got = free_velocity(body, u, loads, dt);
    EXPECT_LE((got - expected).norm(), 1e-12 * (1.0 + expected.norm())) << "trial " << trial;
  }
}

TEST(Exercise6_2, FreeFallGainsExactlyGravityTimesTheStep) {
  const body::RigidBody body{2.0, Vector3(0.1, 0.2, 0.25)};
  body::Loads gravity;
  gravity.I_F = body.m * Vector3(0.0, 0.0, -9.81);
  const Vector6 u = free_velocity(body, Vector6::Zero(), gravity, 1e-3);
  EXPECT_DOUBLE_EQ(u(2), -9.81e-3);
  EXPECT_EQ(u.tail<3>(), Vector3::Zero());
}

TEST(Exercise6_3, ClosedContactsAreActiveOpenOnesAndNaNAreNot) {
  collision::ContactGeometry g;
  for (const double tolerance : {0.0, 1e-9}) {
    g.g_N = 0.0;
    EXPECT_TRUE(is_active(g, tolerance));
    g.g_N = -1e-300;
    EXPECT_TRUE(is_active(g, tolerance));
    g.g_N = -1.0;
    EXPECT_TRUE(is_active(g, tolerance));
    g.g_N = tolerance;
    EXPECT_TRUE(is_active(g, tolerance)) << "equality counts";
    g.g_N = std::nextafter(tolerance, 1.0);
    EXPECT_FALSE(is_active(g, tolerance)) << tolerance;
    g.g_N = 2e-9;
    EXPECT_FALSE(is_active(g, tolerance));
    g.g_N = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(is_active(g, tolerance));
  }
}

TEST(Exercise6_4, IsTheRelativeVelocityOfTheContactPointsInTheContactFrame) {
  std::mt19937_64 rng(65);
  for (int trial = 0; trial < 50; ++trial) {
    const Vector7 qa = random_q(rng);
    const Vector7 qb = random_q(rng);
    const Vector6 ua = random_u(rng);
    const Vector6 ub = random_u(rng);
    std::normal_distribution<double> n;
    const Vector3 K_rho_a(n(rng), n(rng), n(rng));
    const Vector3 K_rho_b(n(rng), n(rng), n(rng));
    const Vector3 I_n = Vector3(n(rng), n(rng), n(rng)).normalized();
    const Eigen::Matrix<double, 3, 2> T = collision::tangent_basis(I_n);
    const collision::ContactJacobian Wa =
        collision::contact_jacobian(kinematics::orientation(qa), K_rho_a, I_n, T.col(0), T.col(1));
    const collision::ContactJacobian Wb =
        collision::contact_jacobian(kinematics::orientation(qb), K_rho_b, I_n, T.col(0), T.col(1));
    // Independent: the velocities of the two material points (chapter 1) projected on the frame.
    const Vector3 dv = kinematics::point_velocity(qa, ua, K_rho_a) -
                       kinematics::point_velocity(qb, ub, K_rho_b);
    const Vector3 expected(I_n.dot(dv), T.col(0).dot(dv), T.col(1).dot(dv));
    EXPECT_LE((start_contact_velocity(&Wa, &ua, &Wb, &ub) - expected).norm(),
              1e-12 * (1.0 + expected.norm()));
    // A static side contributes nothing.
    const Vector3 va = kinematics::point_velocity(qa, ua, K_rho_a);
    EXPECT_LE((start_contact_velocity(&Wa, &ua, nullptr, nullptr) -
               Vector3(I_n.dot(va), T.col(0).dot(va), T.col(1).dot(va)))
                  .norm(),
              1e-12 * (1.0 + va.norm()));
    const Vector3 vb = kinematics::point_velocity(qb, ub, K_rho_b);
    EXPECT_LE((start_contact_velocity(nullptr, nullptr, &Wb, &ub) +
               Vector3(I_n.dot(vb), T.col(0).dot(vb), T.col(1).dot(vb)))
                  .norm(),
              1e-12 * (1.0 + vb.norm()));
  }
}

TEST(Exercise6_5, IsKineticPlusPotentialEnergyOfGravity) {
  const std::vector<body::RigidBody> bodies = {{2.0, Vector3(1.0, 2.0, 2.5)},
                                               {0.5, Vector3(0.1, 0.1, 0.1)}};
  std::vector<body::State> states(2);
  states[0].q << 1.0, 2.0, 3.0, 1.0, 0.0, 0.0, 0.0;
  states[0].u << 1.0, 0.0, -2.0, 0.5, 0.0, 1.0;
  states[1].q << 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0;
  states[1].u << 0.0, 3.0, 0.0, 0.0, 2.0, 0.0;
  const Vector3 g(0.0, 0.0, -9.81);
  // ½ m v² + ½ Σ Θ_k ω_k² − m gᵀ r, term by term.
  const double T0 = 0.5 * 2.0 * 5.0 + 0.5 * (1.0 * 0.25 + 2.5 * 1.0);
  const double V0 = 2.0 * 9.81 * 3.0;
  const double T1 = 0.5 * 0.5 * 9.0 + 0.5 * 0.1 * 4.0;
  const double V1 = 0.5 * 9.81 * -1.0;
  EXPECT_NEAR(mechanical_energy(bodies, states, g), T0 + V0 + T1 + V1, 1e-12);
  // Gravity in another direction: the potential follows it.
  EXPECT_NEAR(mechanical_energy(bodies, states, Vector3(9.81, 0.0, 0.0)),
              T0 + T1 - 2.0 * 9.81 * 1.0 - 0.0, 1e-12);
  EXPECT_THROW(mechanical_energy(bodies, std::span(states).first(1), g), InvalidArgument);
}

TEST(Exercise6_6, ImpactTimesFollowTheGeometricSeriesAndAccumulateAtTheZenoTime) {
  const double h0 = 1.0;
  const double g = 9.81;
  const double t1 = std::sqrt(2.0 * h0 / g);
  for (const double eps : {0.0, 0.5, 0.8}) {
    EXPECT_NEAR(bouncing_ball_impact_time(1, h0, g, eps), t1, 1e-15);
    for (int k = 1; k <= 30; ++k) {
      // Closed sum: t₁ (1 + 2ε (1 − ε^(k−1))/(1 − ε)).
      const double expected = t1 * (1.0 + 2.0 * eps * (1.0 - std::pow(eps, k - 1)) / (1.0 - eps));
      EXPECT_NEAR(bouncing_ball_impact_time(k, h0, g, eps), expected, 1e-14) << eps << " " << k;
    }
    EXPECT_NEAR(bouncing_ball_impact_time(2000, h0, g, eps), bouncing_ball_zeno_time(h0, g, eps),
                1e-13);
  }
  EXPECT_NEAR(bouncing_ball_impact_time(2, 2.0, 9.81, 0.5), 2.0 * std::sqrt(4.0 / 9.81), 1e-15);
  EXPECT_THROW(bouncing_ball_impact_time(0, h0, g, 0.5), InvalidArgument);
  EXPECT_THROW(bouncing_ball_impact_time(1, h0, g, 1.0), InvalidArgument);
  EXPECT_THROW(bouncing_ball_impact_time(1, -1.0, g, 0.5), InvalidArgument);
}

}  // namespace
}  // namespace grbd::timestep
