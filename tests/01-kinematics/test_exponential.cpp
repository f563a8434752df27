// Chapter 1: the exponential and logarithm on S³ and SO(3) (Exercises 1.5, 1.6, 1.7, and the
// core functions of exponential.hpp).
//
// Independent references: the closed forms exp(a n) = (cos a, sin a n) and log of
// (cos a, sin a n) = a n for a unit n, evaluated from known (n, a) in this file; the matrix
// exponential of Eigen's unsupported MatrixFunctions module (Padé approximation with scaling and
// squaring, no Rodrigues); and quaternion products through 2 × 2 complex matrices.

#include <gtest/gtest.h>

#include <Eigen/LU>  // determinant()
#include <cmath>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include "grbd/core/error.hpp"
#include "grbd/kinematics/exponential.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/kinematics/skew.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using namespace grbd::test;  // NOLINT: the shared reference formulas

using grbd::Matrix3;
using grbd::Vector3;
using grbd::kinematics::exp_S3;
using grbd::kinematics::exp_SO3;
using grbd::kinematics::log_S3;
using grbd::kinematics::Quaternion;
using grbd::kinematics::skew;

constexpr int kSamples = 10000;
constexpr double pi = std::numbers::pi;

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 1.5: the exponential on S³
// ----------------------------------------------------------------------------------------------

// Reference: exp(a n) = (cos a, sin a n) for a unit n, |exp| = 1. Inputs |a| ≤ 2π, so the
// round-off of |v| (one ulp of a ≤ 2π) moves cos and sin by at most ~1e-15: tolerance 1e-14.
TEST(Exercise1_5, ClosedFormAlongAnAxisAndUnitNorm) {
  grbd::test::Random rng(2501);
  WorstCase worst;
  WorstCase worst_norm;
  for (int n = 0; n < kSamples; ++n) {
    const Vector3 axis = rng.unit_vector3();
    const double a = rng.uniform(-2.0 * pi, 2.0 * pi);
    const Quaternion p = exp_S3(a * axis);
    worst.update(distance(p, closed_form_exp(axis, a)), n,
                 [&] { return describe("axis", axis, "a", a, "exp_S3(a axis)", p); });
    worst_norm.update(std::abs(p.norm() - 1.0), n,
                      [&] { return describe("axis", axis, "a", a, "exp_S3(a axis)", p); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
  EXPECT_LE(worst_norm.value(), 1e-15) << "cos² + sin² = 1 to a few ulps; " << worst_norm;
}

// Reference: t ↦ exp(t n) is a one-parameter subgroup, exp(a n) exp(b n) = exp((a + b) n); the
// product through complex matrices.
TEST(Exercise1_5, OneParameterSubgroup) {
  grbd::test::Random rng(2502);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Vector3 axis = rng.unit_vector3();
    const double a = rng.uniform(-pi, pi);
    const double b = rng.uniform(-pi, pi);
    worst.update(distance(reference_product(exp_S3(a * axis), exp_S3(b * axis)),
                          exp_S3((a + b) * axis)),
                 n, [&] { return describe("axis", axis, "a", a, "b", b); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the Taylor series exp(0, v) = (1 − |v|²/2, (1 − |v|²/6) v) + O(|v|⁴), which for
// |v| ~ 1e-10 is (1, v) to far below round-off. The vector part must be accurate relative to |v|
// (2 ulps), and v = 0 must give exactly 1, not 0/0.
TEST(Exercise1_5, AccurateForTinyArguments) {
  grbd::test::Random rng(2503);
  WorstCase worst_relative;
  for (int n = 0; n < kSamples; ++n) {
    const Vector3 v = rng.uniform(1e-11, 1e-9) * rng.unit_vector3();
    const Quaternion p = exp_S3(v);
    EXPECT_EQ(p.p0(), 1.0);  // 1 − |v|²/2 = 1 − O(1e-18) rounds to 1
    worst_relative.update((p.p_r() - v).norm() / v.norm(), n,
                          [&] { return describe("v", v, "exp_S3(v)", p); });
  }
  EXPECT_LE(worst_relative.value(), 4.5e-16) << worst_relative;
  EXPECT_EQ(exp_S3(Vector3::Zero()).coeffs(), Quaternion::identity().coeffs());
  const Vector3 tiny(1e-200, -2e-200, 3e-200);  // |v|² underflows to 0
  EXPECT_EQ(exp_S3(tiny).p0(), 1.0);
  EXPECT_LE((exp_S3(tiny).p_r() - tiny).norm(), 1e-15 * tiny.norm());
}

// ----------------------------------------------------------------------------------------------
// Exercise 1.6: the logarithm on S³
// ----------------------------------------------------------------------------------------------

// Reference: log (cos a, sin a n) = a n for a ∈ [0, π], evaluated from the known (n, a); then
// exp(log p) = p through the closed form. Random a in [0, π] plus a = 1e-9 and a = π − 1e-9,
// where acos(p0) would lose about half of the digits; atan2 keeps them all.
TEST(Exercise1_6, InvertsTheExponentialNearZeroNearPiAndAtRandom) {
  grbd::test::Random rng(2601);
  WorstCase worst;
  WorstCase worst_relative;
  for (int n = 0; n < kSamples; ++n) {
    const Vector3 axis = rng.unit_vector3();
    double a = rng.uniform(0.0, pi);
    if (n % 4 == 1) a = 1e-9 * rng.uniform(0.5, 1.5);
    if (n % 4 == 2) a = pi - 1e-9 * rng.uniform(0.5, 1.5);
    const Quaternion p = closed_form_exp(axis, a);
    const Vector3 v = log_S3(p);
    // The logarithm itself, relative to |v| = a (which is ≥ 5e-10): a few ulps.
    worst_relative.update((v - a * axis).norm() / a, n, [&] {
      return describe("axis", axis, "a", a, "p", p, "log_S3(p)", v);
    });
    // exp∘log = id, exp in closed form from the computed v.
    const double b = v.norm();
    worst.update(distance(closed_form_exp(v / b, b), p), n, [&] {
      return describe("axis", axis, "a", a, "p", p, "log_S3(p)", v);
    });
  }
  EXPECT_LE(worst_relative.value(), 1e-15) << worst_relative;
  EXPECT_LE(worst.value(), 1e-15) << worst;
}

// Reference: log∘exp = id on the ball |v| < π (the principal branch), exp by the exercise.
// Conditioning: log's direction is p_r/|p_r|, and exp_S3 stores p_r = (sin|v|/|v|) v with a
// relative error of a few ulps at any |v| < π, so the round trip is good to ~1e-15 · |v|.
TEST(Exercise1_6, LogOfExpIsIdentityOnTheBallOfRadiusPi) {
  grbd::test::Random rng(2602);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    double a = rng.uniform(0.0, pi);
    if (n % 4 == 1) a = rng.uniform(1e-12, 1e-6);
    if (n % 4 == 2) a = pi - rng.uniform(1e-12, 1e-6);
    const Vector3 v = a * rng.unit_vector3();
    worst.update((log_S3(exp_S3(v)) - v).norm() / std::max(a, 1e-300), n,
                 [&] { return describe("v", v); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: log 1 = 0, and at p = −1 the documented choice π e_x; |v| ∈ [0, π] always.
TEST(Exercise1_6, IdentityMinusOneAndPrincipalRange) {
  EXPECT_EQ(log_S3(Quaternion::identity()), Vector3::Zero());
  EXPECT_EQ(log_S3(Quaternion(-1, 0, 0, 0)), Vector3(pi, 0, 0));
  grbd::test::Random rng(2603);
  for (int n = 0; n < kSamples; ++n) {
    const double a = log_S3(rng.unit_quaternion()).norm();
    ASSERT_GE(a, 0.0);
    ASSERT_LE(a, pi);
  }
}

// ----------------------------------------------------------------------------------------------
// Exercise 1.7: Rodrigues' formula, the exponential on SO(3)
// ----------------------------------------------------------------------------------------------

// Reference: the matrix exponential of θ̃ by Eigen's MatrixFunctions. For |θ| ≤ 2π Eigen scales
// θ̃ by 2⁻ˢ to norm < ~1, uses a Padé approximant and squares s ≤ 3 times; each squaring about
// doubles the relative error, so ~10 ulps of ‖R‖ ≈ 1 are expected: tolerance 1e-14.
TEST(Exercise1_7, EqualsTheMatrixExponential) {
  grbd::test::Random rng(2701);
  WorstCase worst;
  for (int n = 0; n < 2000; ++n) {
    const Vector3 theta = rng.uniform(0.0, 2.0 * pi) * rng.unit_vector3();
    worst.update(max_abs(exp_SO3(theta) - expm(theta)), n,
                 [&] { return describe("theta", theta); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the matrix exponential again, for tiny and small rotation vectors, where the
// closed-form coefficients sin θ/θ and (1 − cos θ)/θ² must not be evaluated naively. θ = 0
// must give I exactly.
TEST(Exercise1_7, AccurateForSmallAngles) {
  grbd::test::Random rng(2702);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const double a = std::pow(10.0, rng.uniform(-12.0, -2.0));
    const Vector3 theta = a * rng.unit_vector3();
    // I + θ̃ + θ̃²/2 has O(1), O(a) and O(a²) entries; the error is relative to the largest.
    worst.update(max_abs(exp_SO3(theta) - expm(theta)), n,
                 [&] { return "exp_SO3 = expm, " + describe("theta", theta); });
    // The skew part, R − Rᵀ = 2 sin a ñ, must be accurate relative to a (not just to 1).
    const Matrix3 R = exp_SO3(theta);
    const Matrix3 skew_part = 0.5 * (R - R.transpose());
    worst.update(max_abs(skew_part - std::sin(a) / a * skew(theta)) / a, n,
                 [&] { return "skew part relative to |θ|, " + describe("theta", theta); });
  }
  EXPECT_LE(worst.value(), 1e-15) << worst;
  EXPECT_EQ(exp_SO3(Vector3::Zero()), Matrix3::Identity());
}

// Reference: R(exp_S3(θ/2)), the rotation matrix of the quaternion of θ (Exercises 1.3 and 1.5
// are the other way round S³ → SO(3)), also for tiny θ; and RᵀR = I, det R = 1.
TEST(Exercise1_7, EqualsTheRotationMatrixOfTheQuaternion) {
  grbd::test::Random rng(2703);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const double a =
        n % 2 == 0 ? rng.uniform(0.0, 2.0 * pi) : std::pow(10.0, rng.uniform(-12.0, -2.0));
    const Vector3 theta = a * rng.unit_vector3();
    const Matrix3 R = exp_SO3(theta);
    const Matrix3 expected =
        grbd::kinematics::rotation_matrix(grbd::kinematics::quaternion_from_rotation_vector(theta));
    worst.update(max_abs(R - expected), n,
                 [&] { return "R(exp_S3(θ/2)), " + describe("theta", theta); });
    worst.update(max_abs(R.transpose() * R - Matrix3::Identity()), n,
                 [&] { return "RᵀR = I, " + describe("theta", theta); });
    worst.update(std::abs(R.determinant() - 1.0), n,
                 [&] { return "det R = 1, " + describe("theta", theta); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// ----------------------------------------------------------------------------------------------
// Core: log on SO(3), rotation vectors
// ----------------------------------------------------------------------------------------------

// Reference: log_SO3∘exp_SO3 = id on |θ| < π, with the exponential in the form of Eigen's
// matrix exponential (independent of the code under test). Near |θ| = π the rotation vector is
// read from the diagonal of R (Shepperd), still a few ulps: tolerance 1e-14 absolute.
TEST(LogSO3, InvertsTheExponential) {
  grbd::test::Random rng(2801);
  WorstCase worst;
  for (int n = 0; n < 5000; ++n) {
    double a = rng.uniform(0.0, pi);
    if (n % 4 == 1) a = std::pow(10.0, rng.uniform(-12.0, -2.0));
    if (n % 4 == 2) a = pi - std::pow(10.0, rng.uniform(-9.0, -2.0));
    const Vector3 theta = a * rng.unit_vector3();
    worst.update((grbd::kinematics::log_SO3(expm(theta)) - theta).norm(), n,
                 [&] { return "log_SO3(expm(θ)), " + describe("theta", theta); });
    worst.update((grbd::kinematics::log_SO3(exp_SO3(theta)) - theta).norm(), n,
                 [&] { return "log_SO3(exp_SO3(θ)), " + describe("theta", theta); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: at |θ| = π, θ and −θ are the same rotation; either is a correct logarithm.
TEST(LogSO3, HalfTurnsGiveEitherSign) {
  grbd::test::Random rng(2802);
  for (int n = 0; n < 1000; ++n) {
    const Vector3 axis = rng.unit_vector3();
    const Matrix3 R = 2.0 * axis * axis.transpose() - Matrix3::Identity();  // rotation by π
    const Vector3 theta = grbd::kinematics::log_SO3(R);
    ASSERT_NEAR(theta.norm(), pi, 1e-14);
    ASSERT_LE(std::min((theta - pi * axis).norm(), (theta + pi * axis).norm()), 1e-14);
  }
}

// Reference: a matrix with a NaN entry is no rotation; it must not produce a silent NaN.
TEST(LogSO3, NaNThrows) {
  EXPECT_THROW((void)grbd::kinematics::log_SO3(Matrix3::Constant(std::nan(""))),
               grbd::InvalidArgument);
}

// Reference: the written-out quaternion (cos(a/2), sin(a/2) n) of the rotation vector a n, and
// the principal range: p and −p give the same rotation vector, |θ| ≤ π.
TEST(RotationVector, RoundTripAndSignOfQuaternion) {
  using grbd::kinematics::quaternion_from_rotation_vector;
  using grbd::kinematics::rotation_vector;
  grbd::test::Random rng(2901);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Vector3 axis = rng.unit_vector3();
    const double a = rng.uniform(0.0, pi);
    const Quaternion p = quaternion_from_rotation_vector(a * axis);
    worst.update(distance(p, closed_form_exp(axis, 0.5 * a)), n, [&] {
      return "quaternion_from_rotation_vector, " + describe("axis", axis, "a", a);
    });
    worst.update((rotation_vector(p) - a * axis).norm(), n,
                 [&] { return "rotation_vector(p), " + describe("axis", axis, "a", a, "p", p); });
    worst.update((rotation_vector(-p) - a * axis).norm(), n,
                 [&] { return "rotation_vector(−p), " + describe("axis", axis, "a", a, "p", p); });
    ASSERT_LE(rotation_vector(rng.unit_quaternion()).norm(), pi);
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
  EXPECT_THROW((void)rotation_vector(Quaternion(0, 0, 0, 0)), grbd::InvalidArgument);
}
