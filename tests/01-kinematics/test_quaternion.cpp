// Chapter 1: the quaternion algebra ℍ (Exercises 1.1 and 1.2, and the core functions of
// quaternion.hpp).
//
// The independent reference throughout is the 2 × 2 complex representation ℍ ⊂ ℂ²ˣ²
// (complex_matrix, from_complex_matrix): its product is Eigen's complex matrix product, which
// shares no code with product(), phi_L() or phi_R(). The QuaternionAlgebra suite checks that
// reference itself on the basis i, j, k, without using product().
//
// Tolerances: the algebra identities are checked on inputs with coordinates in [−2, 2), where
// every coordinate of a product is a sum of four products of O(1) numbers. The error of such a
// sum is a few ulps of |P||Q|, so 1e-14 relative to |P||Q| (about 45 ulps) is tight and safe.

#include <gtest/gtest.h>

#include <Eigen/LU>  // determinant()
#include <cmath>
#include <complex>

#include "grbd/core/error.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using namespace grbd::test;  // NOLINT: the shared reference formulas

using grbd::Matrix4;
using grbd::Vector4;
using grbd::kinematics::complex_matrix;
using grbd::kinematics::from_complex_matrix;
using grbd::kinematics::Quaternion;

constexpr int kSamples = 10000;
constexpr double kRel = 1e-14;  // relative tolerance of algebra identities on O(1) inputs

const Quaternion one{1, 0, 0, 0};
const Quaternion qi{0, 1, 0, 0};
const Quaternion qj{0, 0, 1, 0};
const Quaternion qk{0, 0, 0, 1};

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 1.1: the quaternion product
// ----------------------------------------------------------------------------------------------

// Reference: Hamilton's defining relations. The products of basis elements involve only 0 and
// ±1, so they are exact in floating point: compared with ==.
TEST(Exercise1_1, BasisRelations) {
  const Quaternion minus_one{-1, 0, 0, 0};
  EXPECT_EQ((qi * qi).coeffs(), minus_one.coeffs()) << "i² = −1";
  EXPECT_EQ((qj * qj).coeffs(), minus_one.coeffs()) << "j² = −1";
  EXPECT_EQ((qk * qk).coeffs(), minus_one.coeffs()) << "k² = −1";
  EXPECT_EQ((qi * qj * qk).coeffs(), minus_one.coeffs()) << "ijk = −1";
  EXPECT_EQ((qi * qj).coeffs(), qk.coeffs()) << "ij = k";
  EXPECT_EQ((qj * qi).coeffs(), (-qk).coeffs()) << "ji = −k";
  EXPECT_EQ((qj * qk).coeffs(), qi.coeffs()) << "jk = i";
  EXPECT_EQ((qk * qj).coeffs(), (-qi).coeffs()) << "kj = −i";
  EXPECT_EQ((qk * qi).coeffs(), qj.coeffs()) << "ki = j";
  EXPECT_EQ((qi * qk).coeffs(), (-qj).coeffs()) << "ik = −j";
  for (const Quaternion& e : {one, qi, qj, qk}) {
    EXPECT_EQ((one * e).coeffs(), e.coeffs()) << "1 is the identity";
    EXPECT_EQ((e * one).coeffs(), e.coeffs()) << "1 is the identity";
  }
}

// Reference: the 2 × 2 complex matrix product (complex_matrix is an algebra homomorphism).
TEST(Exercise1_1, EqualsComplexMatrixProduct) {
  grbd::test::Random rng(101);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion Q = rng.quaternion();
    worst.update(distance(P * Q, reference_product(P, Q)) / (P.norm() * Q.norm()), n,
                 [&] { return describe("P", P, "Q", Q); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: associativity of ℍ, (PQ)R = P(QR).
TEST(Exercise1_1, IsAssociative) {
  grbd::test::Random rng(102);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion Q = rng.quaternion();
    const Quaternion R = rng.quaternion();
    const double scale = P.norm() * Q.norm() * R.norm();
    worst.update(distance((P * Q) * R, P * (Q * R)) / scale, n,
                 [&] { return describe("P", P, "Q", Q, "R", R); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: ℍ is a normed division algebra, |PQ| = |P||Q|.
TEST(Exercise1_1, NormIsMultiplicative) {
  grbd::test::Random rng(103);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion Q = rng.quaternion();
    const double expected = P.norm() * Q.norm();
    worst.update(std::abs((P * Q).norm() - expected) / expected, n,
                 [&] { return describe("P", P, "Q", Q); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: conjugation reverses products, conj(PQ) = Q̄ P̄, and P P̄ = |P|² (a real number).
TEST(Exercise1_1, ConjugateReversesProductsAndGivesTheNorm) {
  grbd::test::Random rng(104);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion Q = rng.quaternion();
    const double scale = P.norm() * Q.norm();
    worst.update(distance((P * Q).conjugate(), Q.conjugate() * P.conjugate()) / scale, n,
                 [&] { return "conj(PQ) = Q̄ P̄, " + describe("P", P, "Q", Q); });
    const Quaternion norm2{P.squared_norm(), 0, 0, 0};
    worst.update(distance(P * P.conjugate(), norm2) / P.squared_norm(), n,
                 [&] { return "P P̄ = |P|², " + describe("P", P); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: distributivity, P(Q + R) = PQ + PR, and ℝ-linearity.
TEST(Exercise1_1, IsBilinear) {
  grbd::test::Random rng(105);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion Q = rng.quaternion();
    const Quaternion R = rng.quaternion();
    const double s = rng.uniform();
    const double scale = P.norm() * (Q.norm() + R.norm());
    worst.update(distance(P * (Q + R), P * Q + P * R) / scale, n,
                 [&] { return "P(Q + R) = PQ + PR, " + describe("P", P, "Q", Q, "R", R); });
    worst.update(distance((s * P) * Q, s * (P * Q)) / scale, n, [&] {
      return "(sP)Q = s(PQ), " + describe("P", P, "Q", Q, "R", R, "s", s);
    });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// ----------------------------------------------------------------------------------------------
// Exercise 1.2: the multiplication matrices φ_L and φ_R
// ----------------------------------------------------------------------------------------------

// Reference: the complex matrix product. φ_L(P) K(Q) = K(PQ) = φ_R(Q) K(P).
TEST(Exercise1_2, MultiplicationMatricesReproduceTheProduct) {
  grbd::test::Random rng(201);
  WorstCase worst_L;
  WorstCase worst_R;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion Q = rng.quaternion();
    const Vector4 K_PQ = reference_product(P, Q).coeffs();
    const double scale = P.norm() * Q.norm();
    const Vector4 by_L = grbd::kinematics::phi_L(P) * Q.coeffs();
    const Vector4 by_R = grbd::kinematics::phi_R(Q) * P.coeffs();
    worst_L.update((by_L - K_PQ).cwiseAbs().maxCoeff() / scale, n,
                   [&] { return describe("P", P, "Q", Q); });
    worst_R.update((by_R - K_PQ).cwiseAbs().maxCoeff() / scale, n,
                   [&] { return describe("P", P, "Q", Q); });
  }
  EXPECT_LE(worst_L.value(), kRel) << "φ_L(P) K(Q) = K(PQ); " << worst_L;
  EXPECT_LE(worst_R.value(), kRel) << "φ_R(Q) K(P) = K(PQ); " << worst_R;
}

// Reference: associativity of ℍ, (PX)Q = P(XQ) for every X, is the commutation of the left and
// right multiplications.
TEST(Exercise1_2, LeftAndRightMultiplicationsCommute) {
  grbd::test::Random rng(202);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion Q = rng.quaternion();
    const Matrix4 L = grbd::kinematics::phi_L(P);
    const Matrix4 R = grbd::kinematics::phi_R(Q);
    worst.update((L * R - R * L).cwiseAbs().maxCoeff() / (P.norm() * Q.norm()), n,
                 [&] { return describe("P", P, "Q", Q); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: |PQ| = |P||Q| for every Q means φ_L(P)/|P| and φ_R(P)/|P| are orthogonal:
// φ_L(P)ᵀ φ_L(P) = φ_R(P)ᵀ φ_R(P) = |P|² I.
TEST(Exercise1_2, MultiplicationMatricesAreScaledOrthogonal) {
  grbd::test::Random rng(203);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Matrix4 L = grbd::kinematics::phi_L(P);
    const Matrix4 R = grbd::kinematics::phi_R(P);
    const Matrix4 expected = P.squared_norm() * Matrix4::Identity();
    worst.update((L.transpose() * L - expected).cwiseAbs().maxCoeff() / P.squared_norm(), n,
                 [&] { return "φ_L(P)ᵀ φ_L(P) = |P|² I, " + describe("P", P); });
    worst.update((R.transpose() * R - expected).cwiseAbs().maxCoeff() / P.squared_norm(), n,
                 [&] { return "φ_R(P)ᵀ φ_R(P) = |P|² I, " + describe("P", P); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: K(1·Q) = K(Q) and K(P·1) = K(P): φ_L(1) = φ_R(1) = I exactly; the first column of
// φ_L(P) and of φ_R(P) is K(P) exactly (it is the product with 1).
TEST(Exercise1_2, IdentityAndFirstColumn) {
  EXPECT_EQ(grbd::kinematics::phi_L(one), Matrix4::Identity());
  EXPECT_EQ(grbd::kinematics::phi_R(one), Matrix4::Identity());
  grbd::test::Random rng(204);
  for (int n = 0; n < 100; ++n) {
    const Quaternion P = rng.quaternion();
    EXPECT_EQ(Vector4(grbd::kinematics::phi_L(P).col(0)), P.coeffs());
    EXPECT_EQ(Vector4(grbd::kinematics::phi_R(P).col(0)), P.coeffs());
  }
}

// ----------------------------------------------------------------------------------------------
// Core: the complex representation, inverse, normalisation, rotations of E⁴
// ----------------------------------------------------------------------------------------------

// Reference: Hamilton's relations, checked on the complex matrices themselves (this validates
// the reference used by every other test of this file). Exact: entries are 0 and ±1, ±i.
TEST(QuaternionAlgebra, ComplexMatricesObeyHamiltonsRelations) {
  const Eigen::Matrix2cd I = complex_matrix(one);
  const Eigen::Matrix2cd Mi = complex_matrix(qi);
  const Eigen::Matrix2cd Mj = complex_matrix(qj);
  const Eigen::Matrix2cd Mk = complex_matrix(qk);
  EXPECT_EQ(I, Eigen::Matrix2cd::Identity());
  EXPECT_EQ(Mi * Mi, -I);
  EXPECT_EQ(Mj * Mj, -I);
  EXPECT_EQ(Mk * Mk, -I);
  EXPECT_EQ(Mi * Mj * Mk, -I);
  EXPECT_EQ(Mi * Mj, Mk);
  EXPECT_EQ(Mj * Mi, -Mk);
}

// Reference: det of the complex matrix is |P|² (it is p0² + p1² + p2² + p3²), and
// from_complex_matrix inverts complex_matrix exactly.
TEST(QuaternionAlgebra, ComplexMatrixRoundTripAndDeterminant) {
  grbd::test::Random rng(301);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Eigen::Matrix2cd M = complex_matrix(P);
    EXPECT_EQ(from_complex_matrix(M).coeffs(), P.coeffs());
    const std::complex<double> det = M.determinant();
    worst.update(std::abs(det - P.squared_norm()) / P.squared_norm(), n,
                 [&] { return describe("P", P); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: P P⁻¹ = P⁻¹ P = 1, computed with complex matrices (independent of product()).
TEST(QuaternionAlgebra, InverseIsTwoSided) {
  grbd::test::Random rng(302);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    worst.update(distance(reference_product(P, P.inverse()), one), n,
                 [&] { return "P P⁻¹ = 1, " + describe("P", P); });
    worst.update(distance(reference_product(P.inverse(), P), one), n,
                 [&] { return "P⁻¹ P = 1, " + describe("P", P); });
  }
  // |P| ∈ (0, 4): |P||P⁻¹| = 1, so the products are O(1); for |P| ≪ 1 the division by |P|² is
  // exact to an ulp and the cancellation is of O(1) terms. 1e-14 absolute.
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: |P/|P|| = 1, and the direction is unchanged.
TEST(QuaternionAlgebra, NormalizedIsUnitAndParallel) {
  grbd::test::Random rng(303);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.quaternion();
    const Quaternion p = P.normalized();
    worst.update(std::abs(p.norm() - 1.0), n,
                 [&] { return "|P/|P|| = 1, " + describe("P", P, "P/|P|", p); });
    worst.update(distance(P.norm() * p, P) / P.norm(), n,
                 [&] { return "|P| (P/|P|) = P, " + describe("P", P, "P/|P|", p); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}

// Reference: the documented precondition P ≠ 0 (a NaN coordinate is rejected as well).
TEST(QuaternionAlgebra, ZeroHasNoInverseAndNoDirection) {
  const Quaternion zero{0, 0, 0, 0};
  EXPECT_THROW((void)zero.inverse(), grbd::InvalidArgument);
  EXPECT_THROW((void)zero.normalized(), grbd::InvalidArgument);
  const Quaternion nan{std::nan(""), 0, 0, 0};
  EXPECT_THROW((void)nan.inverse(), grbd::InvalidArgument);
  EXPECT_THROW((void)nan.normalized(), grbd::InvalidArgument);
}

// Reference: P X Q through complex matrices; for unit P, Q the map is an isometry of E⁴ = ℍ.
TEST(RotateE4, EqualsTwoSidedProductAndIsAnIsometry) {
  grbd::test::Random rng(304);
  WorstCase worst;
  for (int n = 0; n < kSamples; ++n) {
    const Quaternion P = rng.unit_quaternion();
    const Quaternion Q = rng.unit_quaternion();
    const Quaternion X = rng.quaternion();
    const Vector4 y = grbd::kinematics::rotate_E4(P, X.coeffs(), Q);
    const Quaternion expected = reference_product(reference_product(P, X), Q);
    worst.update((y - expected.coeffs()).cwiseAbs().maxCoeff() / X.norm(), n,
                 [&] { return "P X Q, " + describe("P", P, "Q", Q, "X", X); });
    worst.update(std::abs(y.norm() - X.norm()) / X.norm(), n,
                 [&] { return "|P X Q| = |X|, " + describe("P", P, "Q", Q, "X", X); });
  }
  EXPECT_LE(worst.value(), kRel) << worst;
}
