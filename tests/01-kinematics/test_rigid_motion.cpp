// Chapter 1: rigid-body coordinates q = (I_r_S, p), velocities u = (I_v_S, K_omega), the
// kinematic map q̇ = F(q) u, point kinematics (Exercises 1.8 and 1.9), and the two time steps
// (explicit Euler, exponential map).
//
// Independent references: the exact motion with constant u,
//   q(t) = (r0 + t v, p0 ⊗ exp(t ω / 2)),
// with the product through 2 × 2 complex matrices and exp in closed form (cos, sin n), both
// written out in grbd_test/references.hpp (exact_motion()); central differences of it; the
// inertial-frame formula v_P = v_S + I_ω × I_r_SP with the classical axis–angle matrix; the
// closed-form growth factor of explicit Euler; and Eigen's matrix exponential (MatrixFunctions).

#include <gtest/gtest.h>

#include <Eigen/Geometry>  // cross()
#include <cmath>
#include <limits>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/kinematics/skew.hpp"
#include "grbd_test/bodies.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using namespace grbd::test;  // NOLINT: the shared reference formulas

using grbd::Matrix3;
using grbd::Matrix76;
using grbd::Vector3;
using grbd::Vector4;
using grbd::Vector6;
using grbd::Vector7;
using grbd::kinematics::make_q;
using grbd::kinematics::make_u;
using grbd::kinematics::orientation;
using grbd::kinematics::Quaternion;
using grbd::kinematics::skew;

constexpr double pi = std::numbers::pi;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// Central differences with step h = 1e-5 along the exact motion. Truncation error h²/6 |q⃛|;
// with |ω| ≤ 2√3 and |ρ| ≤ √3, |q⃛| ≤ |ω|³/8 for p and ≤ |ω|³|ρ| ≈ 72 for a point, so at most
// ~1.2e-9. Round-off: ~2 ulps of |q| ≤ 3 divided by 2h, ~1e-10. Tolerance 1e-8 leaves a
// margin of about 10 over the worst case while still catching any wrong sign or factor.
constexpr double kH = 1e-5;
constexpr double kDifferenceTol = 1e-8;

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 1.8: the kinematic map F(q)
// ----------------------------------------------------------------------------------------------

// Reference: central differences of the exact motion q(t) = (r0 + t v, p0 exp(t ω/2)).
TEST(Exercise1_8, MatchesCentralDifferencesOfTheExactMotion) {
  grbd::test::Random rng(3801);
  WorstCase worst;
  for (int n = 0; n < 2000; ++n) {
    const auto [q, u] = random_state(rng);
    const Vector7 difference = (exact_motion(q, u, kH) - exact_motion(q, u, -kH)) / (2.0 * kH);
    worst.update((grbd::kinematics::kinematic_map(q) * u - difference).cwiseAbs().maxCoeff(), n,
                 [&] { return describe("q", q, "u", u); });
  }
  EXPECT_LE(worst.value(), kDifferenceTol) << worst;
}

// Reference: φ_L(p) is |p| times an orthogonal matrix, so F(q)ᵀ F(q) = diag(I₃, ¼|p|² I₃), also
// for non-unit p. Entries O(1 + |p|²): tolerance 1e-14 relative to that.
TEST(Exercise1_8, GramMatrixIsDiagonal) {
  grbd::test::Random rng(3802);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const Quaternion p = rng.quaternion();
    const Matrix76 F = grbd::kinematics::kinematic_map(make_q(rng.vector3(), p));
    Eigen::Matrix<double, 6, 6> expected = Eigen::Matrix<double, 6, 6>::Identity();
    expected.bottomRightCorner<3, 3>() *= 0.25 * p.squared_norm();
    worst.update((F.transpose() * F - expected).cwiseAbs().maxCoeff() / (1.0 + p.squared_norm()),
                 n, [&] { return describe("p", p); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: d/dt |p|² = 2 pᵀṗ = 0 along q̇ = F(q) u (|p| is a first integral), and İ_r_S = I_v_S
// exactly, for any p.
TEST(Exercise1_8, QuaternionRateIsTangentAndTranslationIsExact) {
  grbd::test::Random rng(3803);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const Quaternion p = rng.quaternion();
    const Vector7 q = make_q(rng.vector3(), p);
    const Vector6 u = make_u(rng.vector3(), rng.vector3(-2, 2));
    const Vector7 qdot = grbd::kinematics::kinematic_map(q) * u;
    ASSERT_EQ(Vector3(qdot.head<3>()), Vector3(u.head<3>()));
    worst.update(std::abs(p.coeffs().dot(qdot.tail<4>())) / (p.squared_norm() * u.tail<3>().norm()),
                 n, [&] { return describe("q", q, "u", u); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// ----------------------------------------------------------------------------------------------
// Exercise 1.9: the velocity of a material point
// ----------------------------------------------------------------------------------------------

// Reference: central differences of point_position along the exact motion.
TEST(Exercise1_9, MatchesCentralDifferencesOfPointPosition) {
  using grbd::kinematics::point_position;
  grbd::test::Random rng(3901);
  WorstCase worst;
  for (int n = 0; n < 2000; ++n) {
    const auto [q, u] = random_state(rng);
    const Vector3 rho = rng.vector3();
    const Vector3 difference = (point_position(exact_motion(q, u, kH), rho) -
                                point_position(exact_motion(q, u, -kH), rho)) /
                               (2.0 * kH);
    worst.update((grbd::kinematics::point_velocity(q, u, rho) - difference).cwiseAbs().maxCoeff(),
                 n, [&] { return describe("q", q, "u", u, "rho", rho); });
  }
  EXPECT_LE(worst.value(), kDifferenceTol) << worst;
}

// Reference: the inertial-frame (spatial) formula v_P = v_S + I_ω × (A ρ), I_ω = A K_ω, with A
// the axis–angle matrix of the orientation. Entries O(|ω||ρ|) ≤ ~6: tolerance 1e-14.
TEST(Exercise1_9, EqualsTheSpatialVelocityFormula) {
  grbd::test::Random rng(3902);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const Vector3 theta = rng.uniform(0.0, pi) * rng.unit_vector3();
    const Quaternion p = closed_form_exp(theta.normalized(), 0.5 * theta.norm());
    const Vector3 v = rng.vector3();
    const Vector3 omega = rng.vector3(-2, 2);
    const Vector3 rho = rng.vector3();
    const Matrix3 A = axis_angle_matrix(theta);
    const Vector3 expected = v + (A * omega).cross(A * rho);
    const Vector3 found =
        grbd::kinematics::point_velocity(make_q(rng.vector3(), p), make_u(v, omega), rho);
    worst.update((found - expected).cwiseAbs().maxCoeff(), n, [&] {
      return describe("p", p, "v", v, "omega", omega, "rho", rho);
    });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: rigidity. Two points of one body keep their distance, so their relative velocity is
// orthogonal to their separation: (v_A − v_B)ᵀ (r_A − r_B) = 0; with ω = 0 every point moves
// with v_S, exactly.
TEST(Exercise1_9, VelocityFieldIsRigid) {
  using grbd::kinematics::point_position;
  using grbd::kinematics::point_velocity;
  grbd::test::Random rng(3903);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const auto [q, u] = random_state(rng);
    const Vector3 a = rng.vector3();
    const Vector3 b = rng.vector3();
    const double relative = (point_velocity(q, u, a) - point_velocity(q, u, b))
                                .dot(point_position(q, a) - point_position(q, b));
    worst.update(std::abs(relative) / (u.tail<3>().norm() * (a - b).squaredNorm()), n,
                 [&] { return describe("q", q, "u", u, "a", a, "b", b); });
    const Vector6 translation = make_u(u.head<3>(), Vector3::Zero());
    ASSERT_EQ(point_velocity(q, translation, a), Vector3(u.head<3>()));
  }
  EXPECT_LE(worst.value(), 1e-13) << worst;  // ratio of two O(1) products; ~450 ulps of margin
}

// ----------------------------------------------------------------------------------------------
// Core: coordinates, q̇, point positions, time steps
// ----------------------------------------------------------------------------------------------

// Reference: the documented layout q = (I_r_S, p), u = (I_v_S, K_omega); exact.
TEST(Coordinates, PackAndUnpack) {
  grbd::test::Random rng(4001);
  const Vector3 r = rng.vector3();
  const Quaternion p = rng.unit_quaternion();
  const Vector3 v = rng.vector3();
  const Vector3 omega = rng.vector3();
  const Vector7 q = make_q(r, p);
  const Vector6 u = make_u(v, omega);
  EXPECT_EQ(grbd::kinematics::position(q), r);
  EXPECT_EQ(orientation(q).coeffs(), p.coeffs());
  EXPECT_EQ(grbd::kinematics::linear_velocity(u), v);
  EXPECT_EQ(grbd::kinematics::angular_velocity(u), omega);
  EXPECT_EQ(Vector3(q.head<3>()), r);
  EXPECT_EQ(Vector4(q.tail<4>()), p.coeffs());
}

// Reference: q̇ = F(q) u, and ṗ = ½ p (0, ω) with the product through complex matrices.
TEST(QDot, IsTheKinematicMapTimesU) {
  grbd::test::Random rng(4002);
  WorstCase worst;
  for (int n = 0; n < 1000; ++n) {
    const auto [q, u] = random_state(rng);
    const Vector7 qdot = grbd::kinematics::q_dot(q, u);
    const Quaternion pdot = 0.5 * reference_product(orientation(q), Quaternion::pure(u.tail<3>()));
    worst.update((qdot.tail<4>() - pdot.coeffs()).cwiseAbs().maxCoeff(), n,
                 [&] { return "ṗ = ½ p (0, ω), " + describe("q", q, "u", u); });
    worst.update((qdot.head<3>() - u.head<3>()).cwiseAbs().maxCoeff(), n,
                 [&] { return "ṙ = v, " + describe("q", q, "u", u); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: I_r_P = I_r_S + A ρ with the classical axis–angle matrix A of a known rotation.
TEST(PointPosition, IsCentreOfMassPlusRotatedOffset) {
  grbd::test::Random rng(4003);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const Vector3 theta = rng.uniform(0.0, pi) * rng.unit_vector3();
    const Quaternion p = closed_form_exp(theta.normalized(), 0.5 * theta.norm());
    const Vector3 r = rng.vector3();
    const Vector3 rho = rng.vector3();
    const Vector3 expected = r + axis_angle_matrix(theta) * rho;
    worst.update(
        (grbd::kinematics::point_position(make_q(r, p), rho) - expected).cwiseAbs().maxCoeff(), n,
        [&] { return describe("theta", theta, "p", p, "r", r, "rho", rho); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the exact growth law of explicit Euler. p_{n+1} = p_n + (h/2) p_n (0, ω) adds to p_n
// a vector orthogonal to it of length (h/2)|ω||p_n|, so |p_{n+1}|² = |p_n|² (1 + h²|ω|²/4)
// exactly in exact arithmetic. In floating point each ratio |p_{n+1}|²/|p_n|² carries a few ulps:
// tolerance 1e-13 relative per step. Over N = 1000 steps the product of the factors is compared
// with N · 1e-15 relative (the errors of single steps add up, they do not compound). The centre
// of mass moves exactly as r0 + n h v up to N additions, each rounded to half an ulp of |r|, and
// the same rounding of h v repeated N times: N · eps · (1 + |r_N|).
TEST(ExplicitEulerDrift, NormSquaredGrowsByTheExactFactorEveryStep) {
  grbd::test::Random rng(4101);
  constexpr int N = 1000;
  for (double h : {1e-3, 1e-2, 1e-1}) {
    for (int c = 0; c < 5; ++c) {
      auto [q, u] = random_state(rng);
      const Vector7 q_start = q;
      const Vector3 r0 = q.head<3>();
      const double factor = 1.0 + 0.25 * h * h * u.tail<3>().squaredNorm();
      const double n0 = q.tail<4>().squaredNorm();
      WorstCase worst_step;
      for (int n = 0; n < N; ++n) {
        const double before = q.tail<4>().squaredNorm();
        q = grbd::kinematics::explicit_euler_step(q, u, h);
        worst_step.update(std::abs(q.tail<4>().squaredNorm() / before / factor - 1.0), [&] {
          return describe("step", n, "h", h, "case", c, "q_0", q_start, "u", u, "q_{n+1}", q);
        });
      }
      EXPECT_LE(worst_step.value(), 1e-13) << "h = " << h << "; " << worst_step;
      const double total = q.tail<4>().squaredNorm() / (n0 * std::pow(factor, N));
      EXPECT_NEAR(total, 1.0, N * 1e-15) << "h = " << h << ", factor^N = " << std::pow(factor, N);
      const Vector3 r_exact = r0 + N * h * u.head<3>();
      EXPECT_LE((q.head<3>() - r_exact).cwiseAbs().maxCoeff(), N * kEps * (1.0 + r_exact.norm()));
    }
  }
}

// Reference: for constant ω the exact orientation is R(p0) expm(t ω̃) (Eigen's MatrixFunctions),
// and the exact position r0 + t v. Each exp-map step multiplies by the same unit quaternion, so
// the error grows by at most a few ulps per step: over N = 1000 steps the tolerance is
// N · 1e-15 = 1e-12 for R and for |p_N| − 1 (observed far smaller, a random walk). The position
// is checked as for explicit Euler.
TEST(ExpMapStep, IsExactForConstantAngularVelocity) {
  using grbd::kinematics::rotation_matrix;
  grbd::test::Random rng(4201);
  constexpr int N = 1000;
  for (double h : {1e-3, 1e-2, 1e-1}) {
    for (int c = 0; c < 5; ++c) {
      auto [q, u] = random_state(rng);
      const Vector7 q0 = q;
      for (int n = 0; n < N; ++n) q = grbd::kinematics::exp_map_step(q, u, h);
      const Matrix3 rotation = N * h * skew(u.tail<3>());
      const Matrix3 expected = rotation_matrix(orientation(q0)) * rotation.exp();
      EXPECT_LE((rotation_matrix(orientation(q)) - expected).cwiseAbs().maxCoeff(), N * 1e-15)
          << "h = " << h;
      EXPECT_LE(std::abs(q.tail<4>().norm() - 1.0), N * 1e-15) << "h = " << h;
      const Vector3 r_exact = q0.head<3>() + N * h * u.head<3>();
      EXPECT_LE((q.head<3>() - r_exact).cwiseAbs().maxCoeff(), N * kEps * (1.0 + r_exact.norm()));
    }
  }
}

// Reference: one exp-map step equals the exact motion at t = h (closed-form exp, complex product).
TEST(ExpMapStep, OneStepIsTheExactMotion) {
  grbd::test::Random rng(4202);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const auto [q, u] = random_state(rng);
    const double h = rng.uniform(0.0, 1.0);
    worst.update(
        (grbd::kinematics::exp_map_step(q, u, h) - exact_motion(q, u, h)).cwiseAbs().maxCoeff(), n,
        [&] { return describe("q", q, "u", u, "h", h); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}
