// Chapter 5: the prox operators of the contact laws — the prox onto ℝ₊, onto the friction disk
// and onto the Coulomb cone (Exercises 5.1–5.3) — and what is built from them: the Alart–Curnier
// and De Saxcé prox updates of one contact and the natural-map residual.
//
// Independent references: the variational characterisation of the Euclidean projection onto a
// closed convex set C, y = P_C(x) ⟺ y ∈ C and (x − y)ᵀ(z − y) ≤ 0 for all z ∈ C, checked on
// seeded random x against sampled z ∈ C (interior, boundary, apex); closed forms written out
// differently from the library (max(x, 0); ρ (cos θ, sin θ) with θ = atan2; the projection onto
// the generator (1, μ)/√(1 + μ²) of the cone's half-plane section); idempotence and
// non-expansiveness of projections; positive homogeneity of the cone projection and its
// symmetry about the normal axis; Moreau's decomposition x = P_K(x) + P_K°(x), P_K(x) ⟂ P_K°(x),
// with the polar cone K_μ° = −K_{1/μ}; and for the prox updates and the natural map, the
// solutions of the Coulomb law written out case by case (sticking, sliding, separating).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/contact/prox.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::Vector2;
using grbd::Vector3;
using grbd::contact::alart_curnier_update;
using grbd::contact::de_saxce_update;
using grbd::contact::natural_map;
using grbd::contact::natural_map_residual;
using grbd::contact::prox_cone;
using grbd::contact::prox_disk;
using grbd::contact::prox_nonnegative;
using grbd::test::describe;
using grbd::test::Random;
using grbd::test::WorstCase;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;

// The variational inequality (x − y)ᵀ(z − y) ≤ 0 holds to round-off: its terms are products of
// |x − y| ≤ |x| and |z − y| ≤ |z| + |x|, each with a relative error of a few ε. Tolerance 1e-12
// times max(1, |x|) max(1, |x| + |z|).
constexpr double kVariationalTol = 1e-12;
// Membership y ∈ C, idempotence, homogeneity, symmetry: a few rounding errors of size |x|.
constexpr double kRoundOff = 16 * kEps;

// max(1, |x|) max(1, |x| + |z|): the scale of the variational inequality.
double scale(double x_norm, double z_norm) {
  return std::max(1.0, x_norm) * std::max(1.0, x_norm + z_norm);
}

// A point of the unit circle.
Vector2 circle(double phi) { return {std::cos(phi), std::sin(phi)}; }

// The Coulomb cone K_μ = {‖y_T‖ ≤ μ y_N} (which forces y_N ≥ 0): by how much y lies outside,
// max(‖y_T‖ − μ y_N, −y_N, 0).
double cone_violation(const Vector3& y, double mu) {
  return std::max({std::hypot(y(1), y(2)) - mu * y(0), -y(0), 0.0});
}

// A point of K_μ: normal part s ≥ 0 and tangential part of length t μ s, t ∈ [0, 1], along φ.
Vector3 cone_point(double s, double t, double phi, double mu) {
  const Vector2 T = t * mu * s * circle(phi);
  return {s, T(0), T(1)};
}

// Reference for the cone projection: in the half-plane (x_N, ‖x_T‖) the cone is the wedge
// between the normal axis and the generator d = (1, μ)/√(1 + μ²); a point outside the wedge and
// outside its polar projects onto the generator, (pᵀd) d, and the tangential direction is x_T's.
Vector3 reference_prox_cone(const Vector3& x, double mu) {
  const Vector2 x_T(x(1), x(2));
  const double t = x_T.norm();
  if (x(0) >= 0.0 && t <= mu * x(0)) return x;  // inside the wedge
  const Vector2 d = Vector2(1.0, mu) / std::sqrt(1.0 + mu * mu);
  const double along = Vector2(x(0), t).dot(d);
  if (along <= 0.0) return Vector3::Zero();  // in the polar wedge
  const Vector2 y = along * d;
  const Vector2 y_T = t > 0.0 ? Vector2(y(1) / t * x_T) : Vector2::Zero();
  return {y(0), y_T(0), y_T(1)};
}

// The rotation of the tangential components by φ about the normal axis.
Vector3 rotate_about_normal(const Vector3& x, double phi) {
  const double c = std::cos(phi), s = std::sin(phi);
  return {x(0), c * x(1) - s * x(2), s * x(1) + c * x(2)};
}

// A random x for the cone tests: x_N ∈ [−3, 3), x_T ∈ [−3, 3)², and a random μ ∈ [0, 3) or one of
// the special values 1e-8, 1, 1e3; every fifth x is scaled by 1e-3 or 1e3.
struct ConeSample {
  Vector3 x;
  double mu;
};
ConeSample random_cone_sample(Random& rng, int k) {
  ConeSample s{rng.vector3(-3.0, 3.0), rng.uniform(0.0, 3.0)};
  if (k % 7 == 1) s.mu = 1e-8;
  if (k % 7 == 2) s.mu = 1.0;
  if (k % 11 == 3) s.mu = 1e3;
  if (k % 5 == 4) s.x *= (k % 10 == 4) ? 1e-3 : 1e3;
  return s;
}

// A solution (λ, ξ) of the Coulomb law at one contact, and a description of its case.
struct Solution {
  Vector3 lambda;
  Vector3 xi;
  double mu;
  const char* kind;
};

// Seeded random solutions of the Coulomb law, written out case by case: sticking (λ in the
// cone, ξ = 0), sliding (λ on the cone's surface opposing the slip ξ_T ≠ 0, ξ_N = 0), separating
// (λ = 0, ξ_N > 0, any ξ_T), grazing (λ = 0, ξ_N = 0, any ξ_T).
std::vector<Solution> random_solutions(Random& rng, int count) {
  std::vector<Solution> solutions;
  for (int k = 0; k < count; ++k) {
    const double mu = rng.uniform(0.05, 2.0);
    const double lambda_N = rng.uniform(0.01, 3.0);
    switch (k % 4) {
      case 0:
        solutions.push_back(
            {cone_point(lambda_N, rng.uniform(0.0, 1.0), rng.uniform(0.0, 2 * kPi), mu),
             Vector3::Zero(), mu, "sticking"});
        break;
      case 1: {
        const Vector2 slip = rng.uniform(0.01, 3.0) * circle(rng.uniform(0.0, 2 * kPi));
        const Vector2 lambda_T = -mu * lambda_N * slip.normalized();
        solutions.push_back({Vector3(lambda_N, lambda_T(0), lambda_T(1)),
                             Vector3(0.0, slip(0), slip(1)), mu, "sliding"});
        break;
      }
      case 2:
        solutions.push_back(
            {Vector3::Zero(),
             Vector3(rng.uniform(0.01, 3.0), rng.uniform(-3, 3), rng.uniform(-3, 3)), mu,
             "separating"});
        break;
      default:
        solutions.push_back(
            {Vector3::Zero(), Vector3(0.0, rng.uniform(-3, 3), rng.uniform(-3, 3)), mu, "grazing"});
        break;
    }
  }
  return solutions;
}

// describe() of a solution: its case, λ, ξ and μ.
std::string describe_solution(const Solution& s) {
  return describe("kind", s.kind, "lambda", s.lambda, "xi", s.xi, "mu", s.mu);
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 5.1: the prox onto ℝ₊
// ----------------------------------------------------------------------------------------------

// Reference: max(x, 0), exactly, for seeded random x ∈ [−10, 10), the signed zeros, subnormals,
// ±1e300 and ±∞.
TEST(Exercise5_1, IsMaxWithZero) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const double x : {-kInf, -1e300, -1.0, -tiny, -0.0, 0.0, tiny, 1e-300, 1.0, 1e300, kInf}) {
    EXPECT_EQ(prox_nonnegative(x), std::max(x, 0.0)) << "x = " << x;
  }
  Random rng(5101);
  for (int k = 0; k < 10000; ++k) {
    const double x = rng.uniform(-10.0, 10.0);
    ASSERT_EQ(prox_nonnegative(x), std::max(x, 0.0)) << "x = " << x;
  }
}

// Reference: the variational inequality on C = ℝ₊: y ≥ 0 and (x − y)(z − y) ≤ 0 for z = 0, 2y
// and random z ≥ 0; idempotence.
TEST(Exercise5_1, SatisfiesTheVariationalInequality) {
  Random rng(5102);
  WorstCase worst;
  for (int k = 0; k < 10000; ++k) {
    const double x = rng.uniform(-5.0, 5.0);
    const double y = prox_nonnegative(x);
    ASSERT_GE(y, 0.0) << "x = " << x;
    for (const double z : {0.0, 2.0 * y, rng.uniform(0.0, 5.0), rng.uniform(0.0, 1e-3)}) {
      worst.update((x - y) * (z - y), k, [&] { return describe("x", x, "y", y, "z", z); });
    }
    ASSERT_EQ(prox_nonnegative(y), y) << "x = " << x;
  }
  RecordProperty("worst_variational_inequality", grbd::format_number(worst.value()));
  EXPECT_LE(worst.value(), kVariationalTol) << worst;
}

// Reference: the unilateral contact law written as complementarity, 0 ≤ λ ⟂ ξ ≥ 0, holds exactly
// when λ = prox_ℝ₊(λ − r ξ) for r = 1e-3, 1, 1e3: complementary pairs are fixed points,
// pairs with λ > 0 and ξ ≠ 0, or with λ = 0 and ξ < 0, are not.
TEST(Exercise5_1, FixedPointsAreTheComplementaryPairs) {
  Random rng(5103);
  for (int k = 0; k < 1000; ++k) {
    const double a = rng.uniform(0.01, 3.0);
    const double b = rng.uniform(0.01, 3.0);
    for (const double r : {1e-3, 1.0, 1e3}) {
      // complementary: (λ, ξ) = (a, 0), (0, b), (0, 0)
      EXPECT_EQ(prox_nonnegative(a - r * 0.0), a);
      EXPECT_EQ(prox_nonnegative(0.0 - r * b), 0.0);
      EXPECT_EQ(prox_nonnegative(0.0), 0.0);
      // not complementary: (a, b), (a, −b), (0, −b)
      EXPECT_NE(prox_nonnegative(a - r * b), a);
      EXPECT_NE(prox_nonnegative(a + r * b), a);
      EXPECT_NE(prox_nonnegative(r * b), 0.0);
    }
  }
}

// ----------------------------------------------------------------------------------------------
// Exercise 5.2: the prox onto the disk of radius ρ
// ----------------------------------------------------------------------------------------------

// Reference: x itself (exactly) inside the disk; ρ (cos θ, sin θ) with θ = atan2(x₂, x₁) outside,
// tolerance 8 ε ρ. Seeded random x ∈ [−3, 3)², ρ ∈ [0, 3).
TEST(Exercise5_2, MatchesTheClosedForm) {
  Random rng(5201);
  int inside = 0, outside = 0;
  WorstCase worst;
  for (int k = 0; k < 10000; ++k) {
    const Vector2 x(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
    const double rho = rng.uniform(0.0, 3.0);
    const Vector2 y = prox_disk(x, rho);
    if (std::hypot(x(0), x(1)) < rho * (1.0 - 1e-12)) {
      ++inside;
      ASSERT_EQ(y, x) << "x = " << x.transpose() << ", rho = " << rho;
    } else if (std::hypot(x(0), x(1)) > rho * (1.0 + 1e-12)) {
      ++outside;
      const Vector2 expected = rho * circle(std::atan2(x(1), x(0)));
      worst.update((y - expected).cwiseAbs().maxCoeff() / std::max(rho, 1e-300), k,
                   [&] { return describe("x", x, "rho", rho, "found", y); });
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_GT(outside, 1000);
  RecordProperty("worst_relative_error", grbd::format_number(worst.value()));
  EXPECT_LE(worst.value(), 8 * kEps) << worst;
}

// Reference: points on the circle come back (to round-off), the centre stays, and the disk of
// radius 0 is the origin: exactly 0 for every x, 0 included.
TEST(Exercise5_2, BoundaryCentreAndRadiusZero) {
  Random rng(5202);
  for (int k = 0; k < 1000; ++k) {
    const double rho = rng.uniform(0.1, 3.0);
    const Vector2 on = rho * circle(rng.uniform(0.0, 2 * kPi));
    EXPECT_LE((prox_disk(on, rho) - on).norm(), kRoundOff * rho);
    EXPECT_EQ(prox_disk(Vector2::Zero(), rho), Vector2::Zero());
    const Vector2 x(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
    EXPECT_EQ(prox_disk(x, 0.0), Vector2::Zero()) << "x = " << x.transpose();
  }
  EXPECT_EQ(prox_disk(Vector2::Zero(), 0.0), Vector2::Zero());
  EXPECT_EQ(prox_disk(Vector2(1e300, -1e300), 0.0), Vector2::Zero());
}

// Reference: the variational inequality on the disk for 10⁴ seeded x (some scaled by 1e-3 and
// 1e3) against the centre, the point itself scaled towards the centre, four random points of
// the circle, two of the interior and the boundary points along ±x. Tolerance kVariationalTol.
TEST(Exercise5_2, SatisfiesTheVariationalInequality) {
  Random rng(5203);
  WorstCase worst, worst_outside;
  for (int k = 0; k < 10000; ++k) {
    Vector2 x(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
    if (k % 5 == 4) x *= (k % 10 == 4) ? 1e-3 : 1e3;
    const double rho = k % 13 == 0 ? 0.0 : rng.uniform(0.0, 3.0);
    const Vector2 y = prox_disk(x, rho);
    worst_outside.update(y.norm() - rho, k, [&] { return describe("x", x, "rho", rho, "y", y); });
    std::vector<Vector2> z{Vector2::Zero(), 0.5 * y};
    for (int i = 0; i < 4; ++i) z.push_back(rho * circle(rng.uniform(0.0, 2 * kPi)));
    for (int i = 0; i < 2; ++i) {
      z.push_back(rng.uniform(0.0, rho) * circle(rng.uniform(0.0, 2 * kPi)));
    }
    if (x.norm() > 0.0) {
      z.push_back(rho * x.normalized());
      z.push_back(-rho * x.normalized());
    }
    for (const Vector2& zi : z) {
      worst.update((x - y).dot(zi - y) / scale(x.norm(), zi.norm()), k,
                   [&] { return describe("x", x, "rho", rho, "y", y, "z", zi); });
    }
  }
  RecordProperty("worst_variational_inequality", grbd::format_number(worst.value()));
  EXPECT_LE(worst.value(), kVariationalTol) << worst;
  EXPECT_LE(worst_outside.value(), kRoundOff * 3e3) << worst_outside;
}

// Reference: a projection is idempotent and non-expansive, ‖P(x) − P(x')‖ ≤ ‖x − x'‖, for random
// pairs far apart and 1e-6 apart; tolerance a few ε (|x| + |x'|).
TEST(Exercise5_2, IsIdempotentAndNonExpansive) {
  Random rng(5204);
  WorstCase worst_idempotence, worst_expansion;
  for (int k = 0; k < 10000; ++k) {
    const double rho = rng.uniform(0.0, 3.0);
    const Vector2 x(rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0));
    const Vector2 x2 = k % 2 == 0 ? Vector2(rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0))
                                  : Vector2(x + 1e-6 * Vector2(rng.uniform(), rng.uniform()));
    const Vector2 y = prox_disk(x, rho);
    worst_idempotence.update((prox_disk(y, rho) - y).norm() / x.norm(), k,
                             [&] { return describe("x", x, "rho", rho); });
    const double expansion = (y - prox_disk(x2, rho)).norm() - (x - x2).norm();
    worst_expansion.update(expansion / (x.norm() + x2.norm()), k,
                           [&] { return describe("x", x, "x'", x2, "rho", rho); });
  }
  RecordProperty("worst_idempotence", grbd::format_number(worst_idempotence.value()));
  RecordProperty("worst_expansion", grbd::format_number(worst_expansion.value()));
  EXPECT_LE(worst_idempotence.value(), kRoundOff) << worst_idempotence;
  EXPECT_LE(worst_expansion.value(), kRoundOff) << worst_expansion;
}

// ----------------------------------------------------------------------------------------------
// Exercise 5.3: the prox onto the Coulomb cone
// ----------------------------------------------------------------------------------------------

// Reference: reference_prox_cone (the projection onto the generator of the cone's half-plane
// section), for 10⁴ seeded x and μ, each of the three cases (inside, polar, surface) at least
// 1000 times; x inside the cone comes back exactly, x in the polar cone gives exactly 0.
// Tolerance 16 ε max(|x|, ...) relative to |x|.
TEST(Exercise5_3, MatchesTheClosedForm) {
  Random rng(5301);
  int inside = 0, polar = 0, surface = 0;
  WorstCase worst;
  for (int k = 0; k < 10000; ++k) {
    const auto [x, mu] = random_cone_sample(rng, k);
    const Vector3 y = prox_cone(x, mu);
    const double t = std::hypot(x(1), x(2));
    if (t < mu * x(0) * (1.0 - 1e-12)) {
      ++inside;
      ASSERT_EQ(y, x) << "x = " << x.transpose() << ", mu = " << mu;
    } else if (mu * t < -x(0) * (1.0 - 1e-12)) {
      ++polar;
      ASSERT_EQ(y, Vector3::Zero()) << "x = " << x.transpose() << ", mu = " << mu;
    } else {
      ++surface;
      worst.update((y - reference_prox_cone(x, mu)).norm() / x.norm(), k,
                   [&] { return describe("x", x, "mu", mu, "found", y); });
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_GT(polar, 1000);
  EXPECT_GT(surface, 1000);
  RecordProperty("worst_relative_error", grbd::format_number(worst.value()));
  EXPECT_LE(worst.value(), kRoundOff) << worst;
}

// Reference: the variational inequality on K_μ for 10⁴ seeded x: y ∈ K_μ to round-off and
// (x − y)ᵀ(z − y) ≤ 0 against the apex, 2y and y/2 (which make it an equation, (x − y)ᵀy = 0),
// four random points of the surface, two of the interior, and the surface points along ±x_T.
TEST(Exercise5_3, SatisfiesTheVariationalInequality) {
  Random rng(5302);
  WorstCase worst, worst_membership;
  for (int k = 0; k < 10000; ++k) {
    const auto [x, mu] = random_cone_sample(rng, k);
    const Vector3 y = prox_cone(x, mu);
    worst_membership.update(cone_violation(y, mu) / x.norm(), k,
                            [&] { return describe("x", x, "mu", mu, "y", y); });
    std::vector<Vector3> z{Vector3::Zero(), 2.0 * y, 0.5 * y};
    for (int i = 0; i < 4; ++i) {
      z.push_back(cone_point(rng.uniform(0.0, 3.0), 1.0, rng.uniform(0.0, 2 * kPi), mu));
    }
    for (int i = 0; i < 2; ++i) {
      z.push_back(
          cone_point(rng.uniform(0.0, 3.0), rng.uniform(0.0, 1.0), rng.uniform(0.0, 2 * kPi), mu));
    }
    const double phi = std::atan2(x(2), x(1));
    z.push_back(cone_point(rng.uniform(0.0, 3.0), 1.0, phi, mu));
    z.push_back(cone_point(rng.uniform(0.0, 3.0), 1.0, phi + kPi, mu));
    for (const Vector3& zi : z) {
      worst.update((x - y).dot(zi - y) / scale(x.norm(), zi.norm()), k,
                   [&] { return describe("x", x, "mu", mu, "y", y, "z", zi); });
    }
  }
  RecordProperty("worst_variational_inequality", grbd::format_number(worst.value()));
  RecordProperty("worst_membership", grbd::format_number(worst_membership.value()));
  EXPECT_LE(worst.value(), kVariationalTol) << worst;
  EXPECT_LE(worst_membership.value(), kRoundOff) << worst_membership;
}

// Reference: Moreau's decomposition. The polar cone of K_μ is K_μ° = −K_{1/μ}, so
// P_K°(x) = −P_{K_{1/μ}}(−x), and x = P_K(x) + P_K°(x) with P_K(x) ⟂ P_K°(x), for μ ∈ [0.05, 20).
TEST(Exercise5_3, MoreauDecompositionWithThePolarCone) {
  Random rng(5303);
  WorstCase worst_sum, worst_orthogonality;
  for (int k = 0; k < 10000; ++k) {
    const Vector3 x = rng.vector3(-3.0, 3.0);
    const double mu = std::exp(rng.uniform(std::log(0.05), std::log(20.0)));
    const Vector3 p = prox_cone(x, mu);
    const Vector3 q = -prox_cone(-x, 1.0 / mu);
    const auto inputs = [&] { return describe("x", x, "mu", mu, "P_K(x)", p, "P_K°(x)", q); };
    worst_sum.update((p + q - x).norm() / x.norm(), k, inputs);
    worst_orthogonality.update(std::abs(p.dot(q)) / x.squaredNorm(), k, inputs);
  }
  RecordProperty("worst_sum", grbd::format_number(worst_sum.value()));
  RecordProperty("worst_orthogonality", grbd::format_number(worst_orthogonality.value()));
  EXPECT_LE(worst_sum.value(), kRoundOff) << worst_sum;
  EXPECT_LE(worst_orthogonality.value(), kRoundOff) << worst_orthogonality;
}

// Reference: for μ = 0 the cone is the half-line {y_N ≥ 0, y_T = 0} (frictionless contact):
// P(x) = (max(x_N, 0), 0, 0), for random x and for x on the normal axis, both signs.
TEST(Exercise5_3, MuZeroIsTheHalfLine) {
  Random rng(5304);
  for (int k = 0; k < 1000; ++k) {
    const Vector3 x = rng.vector3(-3.0, 3.0);
    EXPECT_LE((prox_cone(x, 0.0) - Vector3(std::max(x(0), 0.0), 0.0, 0.0)).norm(), kRoundOff)
        << "x = " << x.transpose();
  }
  for (const double a : {2.5, 1e-300, 0.0, -0.0, -1e-300, -2.5}) {
    EXPECT_EQ(prox_cone(Vector3(a, 0.0, 0.0), 0.0), Vector3(std::max(a, 0.0), 0.0, 0.0))
        << "x = (" << a << ", 0, 0)";
  }
}

// Reference: x exactly on the normal axis (x_T = 0) is inside the cone when x_N ≥ 0 and in the
// polar cone when x_N ≤ 0, for μ > 0: x itself or exactly 0, no division by ‖x_T‖ = 0.
TEST(Exercise5_3, PointsOnTheNormalAxis) {
  for (const double mu : {1e-8, 0.3, 1.0, 1e6}) {
    for (const double a : {2.5, 1e-300, 0.0}) {
      EXPECT_EQ(prox_cone(Vector3(a, 0.0, 0.0), mu), Vector3(a, 0.0, 0.0)) << "mu = " << mu;
    }
    for (const double a : {-2.5, -1e-300}) {
      EXPECT_EQ(prox_cone(Vector3(a, 0.0, 0.0), mu), Vector3::Zero()) << "mu = " << mu;
    }
  }
}

// Reference: x in the polar cone {μ ‖x_T‖ ≤ −x_N}, generated as −(s, t/μ (cos φ, sin φ)) with
// t ∈ [0, 1], s > 0, gives exactly 0.
TEST(Exercise5_3, PolarConeGoesToTheApex) {
  Random rng(5305);
  for (int k = 0; k < 1000; ++k) {
    const double mu = rng.uniform(0.05, 5.0);
    const double s = rng.uniform(0.01, 3.0);
    const Vector2 T = rng.uniform(0.0, 0.999) * s / mu * circle(rng.uniform(0.0, 2 * kPi));
    const Vector3 x(-s, T(0), T(1));
    EXPECT_EQ(prox_cone(x, mu), Vector3::Zero()) << "x = " << x.transpose() << ", mu = " << mu;
  }
}

// Reference: for μ = 1e6 the cone is nearly the half-space y_N ≥ 0: a point with x_N < 0 and
// ‖x_T‖ ≫ |x_N|/μ projects to ≈ (0⁺, x_T). Closed form: y_N = (x_N + μ‖x_T‖)/(1 + μ²), so
// |y_N| ≤ ‖x_T‖/μ + |x_N|/μ² and y_T = μ y_N x̂_T differs from x_T by ≤ |x_N|/μ + ‖x_T‖/μ².
TEST(Exercise5_3, LargeMuApproachesTheHalfSpace) {
  Random rng(5306);
  const double mu = 1e6;
  for (int k = 0; k < 1000; ++k) {
    const Vector3 x(rng.uniform(-3.0, -0.01), rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
    const Vector3 y = prox_cone(x, mu);
    const double t = std::hypot(x(1), x(2));
    EXPECT_GE(y(0), 0.0);
    EXPECT_LE(y(0), t / mu + std::abs(x(0)) / (mu * mu) + kRoundOff);
    EXPECT_LE((y.tail<2>() - x.tail<2>()).norm(),
              std::abs(x(0)) / mu + t / (mu * mu) + kRoundOff * t);
    // x with x_N > 0 is inside
    const Vector3 x_in(-x(0), x(1), x(2));
    EXPECT_EQ(prox_cone(x_in, mu), x_in);
  }
}

// Reference: a projection is idempotent and non-expansive, ‖P(x) − P(x')‖ ≤ ‖x − x'‖, for random
// pairs far apart and 1e-6 apart; tolerance a few ε (|x| + |x'|).
TEST(Exercise5_3, IsIdempotentAndNonExpansive) {
  Random rng(5307);
  WorstCase worst_idempotence, worst_expansion;
  for (int k = 0; k < 10000; ++k) {
    const auto [x, mu] = random_cone_sample(rng, k);
    const Vector3 x2 = k % 2 == 0 ? Vector3(x.norm() * rng.vector3())
                                  : Vector3(x + 1e-6 * x.norm() * rng.vector3());
    const Vector3 y = prox_cone(x, mu);
    worst_idempotence.update((prox_cone(y, mu) - y).norm() / x.norm(), k,
                             [&] { return describe("x", x, "mu", mu); });
    const double expansion = (y - prox_cone(x2, mu)).norm() - (x - x2).norm();
    worst_expansion.update(expansion / (x.norm() + x2.norm()), k,
                           [&] { return describe("x", x, "x'", x2, "mu", mu); });
  }
  RecordProperty("worst_idempotence", grbd::format_number(worst_idempotence.value()));
  RecordProperty("worst_expansion", grbd::format_number(worst_expansion.value()));
  EXPECT_LE(worst_idempotence.value(), kRoundOff) << worst_idempotence;
  EXPECT_LE(worst_expansion.value(), kRoundOff) << worst_expansion;
}

// Reference: the cone is invariant under positive scaling and under rotations about the normal
// axis, so P(t x) = t P(x) for t ∈ (0, 100) and P(R x) = R P(x). Tolerance 16 ε |x|.
TEST(Exercise5_3, IsPositivelyHomogeneousAndSymmetricAboutTheNormal) {
  Random rng(5308);
  WorstCase worst_scaling, worst_rotation;
  for (int k = 0; k < 10000; ++k) {
    const auto [x, mu] = random_cone_sample(rng, k);
    const double t = rng.uniform(1e-3, 100.0);
    const double phi = rng.uniform(0.0, 2 * kPi);
    const Vector3 y = prox_cone(x, mu);
    worst_scaling.update((prox_cone(t * x, mu) - t * y).norm() / (t * x.norm()), k,
                         [&] { return describe("x", x, "mu", mu, "t", t); });
    worst_rotation.update(
        (prox_cone(rotate_about_normal(x, phi), mu) - rotate_about_normal(y, phi)).norm() /
            x.norm(),
        k, [&] { return describe("x", x, "mu", mu, "phi", phi); });
  }
  RecordProperty("worst_scaling", grbd::format_number(worst_scaling.value()));
  RecordProperty("worst_rotation", grbd::format_number(worst_rotation.value()));
  EXPECT_LE(worst_scaling.value(), kRoundOff) << worst_scaling;
  EXPECT_LE(worst_rotation.value(), kRoundOff) << worst_rotation;
}

// ----------------------------------------------------------------------------------------------
// The prox updates of Alart–Curnier and De Saxcé
// ----------------------------------------------------------------------------------------------

// Reference: the solutions of the Coulomb law written out case by case (random_solutions) are
// fixed points of both updates for every r: r_N, r_T, r ∈ {1e-3, 0.7, 1, 50}. Tolerance 16 ε
// times the size of the numbers (r |ξ| + |λ|).
TEST(ProxUpdates, SolutionsAreFixedPointsForEveryR) {
  Random rng(5401);
  WorstCase worst_ac, worst_ds;
  for (const Solution& s : random_solutions(rng, 4000)) {
    for (const double r_N : {1e-3, 0.7, 1.0, 50.0}) {
      for (const double r_T : {1e-3, 1.0, 50.0}) {
        const double size = 1.0 + s.lambda.norm() + std::max(r_N, r_T) * s.xi.norm();
        worst_ac.update(
            (alart_curnier_update(s.lambda, s.xi, r_N, r_T, s.mu) - s.lambda).norm() / size,
            [&] { return describe_solution(s) + ", " + describe("r_N", r_N, "r_T", r_T); });
      }
      const double size = 1.0 + s.lambda.norm() + r_N * (1.0 + s.mu) * s.xi.norm();
      worst_ds.update((de_saxce_update(s.lambda, s.xi, r_N, s.mu) - s.lambda).norm() / size,
                      [&] { return describe_solution(s) + ", " + describe("r", r_N); });
    }
  }
  RecordProperty("worst_alart_curnier", grbd::format_number(worst_ac.value()));
  RecordProperty("worst_de_saxce", grbd::format_number(worst_ds.value()));
  EXPECT_LE(worst_ac.value(), kRoundOff) << worst_ac;
  EXPECT_LE(worst_ds.value(), kRoundOff) << worst_ds;
}

// Reference: pairs that violate the law move under both updates: force with a separating
// velocity, sticking force with slip, sliding force along (not against) the slip, force outside
// the cone, penetration without force. Each moves λ by at least 1e-3 for r = 1.
TEST(ProxUpdates, NonSolutionsAreNotFixedPoints) {
  Random rng(5402);
  for (int k = 0; k < 1000; ++k) {
    const double mu = rng.uniform(0.1, 2.0);
    const double lambda_N = rng.uniform(0.1, 3.0);
    const Vector2 dir = circle(rng.uniform(0.0, 2 * kPi));
    const Vector2 slip = rng.uniform(0.1, 3.0) * dir;
    const Vector2 inside = 0.5 * mu * lambda_N * dir;
    const Vector2 surface = mu * lambda_N * dir;
    const std::vector<std::pair<Vector3, Vector3>> cases{
        {Vector3(lambda_N, inside(0), inside(1)), Vector3(rng.uniform(0.1, 1.0), 0.0, 0.0)},
        {Vector3(lambda_N, inside(0), inside(1)), Vector3(0.0, slip(0), slip(1))},
        {Vector3(lambda_N, surface(0), surface(1)), Vector3(0.0, slip(0), slip(1))},
        {Vector3(lambda_N, 2.0 * surface(0), 2.0 * surface(1)), Vector3::Zero()},
        {Vector3::Zero(), Vector3(-rng.uniform(0.1, 1.0), slip(0), slip(1))},
    };
    for (const auto& [lambda, xi] : cases) {
      EXPECT_GE((alart_curnier_update(lambda, xi, 1.0, 1.0, mu) - lambda).norm(), 1e-3)
          << "lambda = " << lambda.transpose() << ", xi = " << xi.transpose() << ", mu = " << mu;
      EXPECT_GE((de_saxce_update(lambda, xi, 1.0, mu) - lambda).norm(), 1e-3)
          << "lambda = " << lambda.transpose() << ", xi = " << xi.transpose() << ", mu = " << mu;
    }
  }
}

// Reference: the Alart–Curnier update written out: λ_N⁺ = max(λ_N − r_N ξ_N, 0), then the disk
// of radius μ λ_N⁺ for λ_T − r_T ξ_T (radius 0: λ_T⁺ = 0); tolerance 16 ε (|λ| + r|ξ|).
TEST(ProxUpdates, AlartCurnierIsNormalThenTangential) {
  Random rng(5403);
  WorstCase worst;
  for (int k = 0; k < 10000; ++k) {
    const Vector3 lambda = rng.vector3(-1.0, 3.0);
    const Vector3 xi = rng.vector3(-2.0, 2.0);
    const double r_N = rng.uniform(0.01, 3.0), r_T = rng.uniform(0.01, 3.0);
    const double mu = rng.uniform(0.0, 2.0);
    const double lambda_N = std::max(lambda(0) - r_N * xi(0), 0.0);
    const Vector2 x_T = lambda.tail<2>() - r_T * xi.tail<2>();
    const double radius = mu * lambda_N;
    const Vector2 lambda_T = x_T.norm() <= radius ? x_T : Vector2(radius * x_T.normalized());
    const Vector3 expected(lambda_N, lambda_T(0), lambda_T(1));
    const double size = lambda.norm() + 3.0 * xi.norm();
    worst.update((alart_curnier_update(lambda, xi, r_N, r_T, mu) - expected).norm() / size, k, [&] {
      return describe("lambda", lambda, "xi", xi, "r_N", r_N, "r_T", r_T, "mu", mu);
    });
  }
  EXPECT_LE(worst.value(), kRoundOff) << worst;
}

// Reference: the De Saxcé update lands in the cone, and the result does not depend on ξ_N and
// ‖ξ_T‖ separately when they enter only through the augmented normal velocity: the updates of
// (ξ_N, ξ_T) and of (ξ_N + μ‖ξ_T‖ − μ‖ξ'_T‖, ξ'_T) with ‖ξ'_T‖ = ‖ξ_T‖ rotated about the normal
// agree up to that rotation (symmetry of the cone).
TEST(ProxUpdates, DeSaxceStaysInTheConeAndIsSymmetric) {
  Random rng(5404);
  WorstCase worst_membership, worst_rotation;
  for (int k = 0; k < 10000; ++k) {
    const Vector3 lambda = rng.vector3(-1.0, 3.0);
    const Vector3 xi = rng.vector3(-2.0, 2.0);
    const double r = rng.uniform(0.01, 3.0), mu = rng.uniform(0.0, 2.0);
    const double phi = rng.uniform(0.0, 2 * kPi);
    const Vector3 y = de_saxce_update(lambda, xi, r, mu);
    const auto inputs = [&] {
      return describe("lambda", lambda, "xi", xi, "r", r, "mu", mu, "phi", phi);
    };
    worst_membership.update(cone_violation(y, mu), k, inputs);
    const Vector3 y_rotated =
        de_saxce_update(rotate_about_normal(lambda, phi), rotate_about_normal(xi, phi), r, mu);
    worst_rotation.update((y_rotated - rotate_about_normal(y, phi)).norm(), k, inputs);
  }
  EXPECT_LE(worst_membership.value(), 10 * kRoundOff) << worst_membership;
  EXPECT_LE(worst_rotation.value(), 10 * kRoundOff) << worst_rotation;
}

// ----------------------------------------------------------------------------------------------
// The natural map
// ----------------------------------------------------------------------------------------------

// Reference: F = 0 on the solutions of random_solutions (tolerance 16 ε times their size), and
// the values written out for two violations: penetration without force, λ = 0, ξ = (−1, 0, 0):
// F = −P_K(1, 0, 0) = (−1, 0, 0); a separating contact that pushes, λ = ξ = (1, 0, 0):
// F = λ − P_K(0) = (1, 0, 0).
TEST(NaturalMap, VanishesExactlyOnSolutions) {
  Random rng(5501);
  WorstCase worst;
  for (const Solution& s : random_solutions(rng, 4000)) {
    const double size = 1.0 + s.lambda.norm() + (1.0 + s.mu) * s.xi.norm();
    worst.update(natural_map(s.lambda, s.xi, s.mu).norm() / size,
                 [&] { return describe_solution(s); });
  }
  RecordProperty("worst_natural_map", grbd::format_number(worst.value()));
  EXPECT_LE(worst.value(), kRoundOff) << worst;
  for (const double mu : {0.0, 0.5, 2.0}) {
    EXPECT_EQ(natural_map(Vector3::Zero(), Vector3(-1.0, 0.0, 0.0), mu), Vector3(-1.0, 0.0, 0.0));
    EXPECT_EQ(natural_map(Vector3(1.0, 0.0, 0.0), Vector3(1.0, 0.0, 0.0), mu),
              Vector3(1.0, 0.0, 0.0));
  }
}

// Reference: perturbing a solution by δ ∈ [0.1, 1) (a separating normal velocity under a
// sticking or sliding force; a force on a separating contact; penetration of a grazing contact
// without force) makes ‖F‖ ≥ 1e-3 δ.
TEST(NaturalMap, IsNonzeroOffSolutions) {
  Random rng(5502);
  for (const Solution& s : random_solutions(rng, 4000)) {
    const double delta = rng.uniform(0.1, 1.0);
    Vector3 lambda = s.lambda, xi = s.xi;
    const std::string kind = s.kind;
    if (kind == "sticking" || kind == "sliding") {
      xi(0) += delta;
    } else if (kind == "separating") {
      lambda(0) += delta;
    } else {
      xi(0) -= delta;
    }
    EXPECT_GE(natural_map(lambda, xi, s.mu).norm(), 1e-3 * delta)
        << s.kind << ": lambda = " << lambda.transpose() << ", xi = " << xi.transpose();
  }
}

// Reference: ‖F‖₂ = (Σ_i ‖natural_map(λ_i, ξ_i, μ_i)‖²)^½ summed here for 50 random contacts
// (tolerance 4 ε relative); 0 for no contacts; InvalidArgument for spans of different lengths.
TEST(NaturalMap, ResidualOfAProblem) {
  Random rng(5503);
  std::vector<Vector3> lambda, xi;
  std::vector<double> mu;
  double sum = 0.0;
  for (int i = 0; i < 50; ++i) {
    lambda.push_back(rng.vector3(-1.0, 2.0));
    xi.push_back(rng.vector3());
    mu.push_back(rng.uniform(0.0, 1.0));
    sum += natural_map(lambda.back(), xi.back(), mu.back()).squaredNorm();
  }
  EXPECT_NEAR(natural_map_residual(lambda, xi, mu), std::sqrt(sum), 4 * kEps * std::sqrt(sum));
  EXPECT_GT(natural_map_residual(lambda, xi, mu), 0.0);
  EXPECT_EQ(natural_map_residual({}, {}, {}), 0.0);
  const std::vector<Vector3> short_xi(xi.begin(), xi.end() - 1);
  const std::vector<double> short_mu(mu.begin(), mu.end() - 1);
  EXPECT_THROW(natural_map_residual(lambda, short_xi, mu), grbd::InvalidArgument);
  EXPECT_THROW(natural_map_residual(lambda, xi, short_mu), grbd::InvalidArgument);
  EXPECT_THROW(natural_map_residual(short_xi, xi, mu), grbd::InvalidArgument);
}

// Regression (issue 11): ‖x‖² overflows for |x| ≳ 1.3e154 and underflows for |x| ≲ 1e-162
// although ‖x‖ does not; prox_disk then returned 0 for x = (3e200, 4e200) (ρ/√∞ = 0).
// Reference: positive homogeneity, prox_D(ρ)(s x) = s prox_D(ρ/s)(x), and the closed form
// ρ x/‖x‖ with ‖(3, 4)‖ = 5 exactly.
TEST(Exercise5_2, HugeAndTinyVectorsNeitherOverflowNorUnderflow) {
  for (const double s : {1e200, 1e-200, 1e300, 1e-300}) {
    SCOPED_TRACE("scale " + std::to_string(s));
    const Vector2 x(3.0 * s, -4.0 * s);
    const Vector2 outside = prox_disk(x, 2.5 * s);
    EXPECT_NEAR(outside(0), 1.5 * s, 4 * kEps * s);
    EXPECT_NEAR(outside(1), -2.0 * s, 4 * kEps * s);
    EXPECT_EQ(prox_disk(x, 6.0 * s), x);  // inside: unchanged
    EXPECT_EQ(prox_disk(x, 5.0 * s), x);  // on the boundary: unchanged
  }
  const Vector2 unit = prox_disk(Vector2(3e200, 4e200), 1.0);
  EXPECT_NEAR(unit(0), 0.6, 4 * kEps);
  EXPECT_NEAR(unit(1), 0.8, 4 * kEps);
}

// Regression (issue 11): the cone's ‖x_T‖ overflowed in the same way (NaN from ∞/∞). Reference:
// positive homogeneity, prox_K(s x) = s prox_K(x), against the unscaled projection.
TEST(Exercise5_3, HugeAndTinyVectorsNeitherOverflowNorUnderflow) {
  Random rng(5531);
  WorstCase worst;
  for (int n = 0; n < 200; ++n) {
    const Vector3 x = rng.vector3(-2.0, 2.0);
    const double mu = rng.uniform(0.0, 2.0);
    const Vector3 y = prox_cone(x, mu);
    for (const double s : {1e200, 1e-200, 1e300, 1e-300}) {
      const Vector3 scaled = prox_cone(s * x, mu) / s;
      worst.update((scaled - y).cwiseAbs().maxCoeff() / std::max(1.0, y.norm()), n,
                   [&] { return describe("x", x, "mu", mu, "scale", s); });
    }
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Regression (issue 11): the residual of a huge but finite problem summed squares to ∞. Reference:
// the residual is positively homogeneous, ‖F(sλ, sξ)‖ = s ‖F(λ, ξ)‖.
TEST(NaturalMap, ResidualOfHugeAndTinyProblemsIsFinite) {
  Random rng(5504);
  std::vector<Vector3> lambda, xi;
  std::vector<double> mu;
  for (int i = 0; i < 20; ++i) {
    lambda.push_back(rng.vector3(-1.0, 2.0));
    xi.push_back(rng.vector3());
    mu.push_back(rng.uniform(0.0, 1.0));
  }
  const double reference = natural_map_residual(lambda, xi, mu);
  for (const double s : {1e200, 1e-200, 1e300, 1e-300}) {
    std::vector<Vector3> sl, sx;
    for (std::size_t i = 0; i < lambda.size(); ++i) {
      sl.push_back(s * lambda[i]);
      sx.push_back(s * xi[i]);
    }
    EXPECT_NEAR(natural_map_residual(sl, sx, mu) / s, reference, 1e-13 * reference)
        << "scale " << s;
  }
  const double inf = std::numeric_limits<double>::infinity();
  lambda[3](1) = inf;
  EXPECT_FALSE(std::isfinite(natural_map_residual(lambda, xi, mu)));
}
