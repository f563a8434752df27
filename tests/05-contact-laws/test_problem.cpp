// Chapter 5: the contact problem in body form — Newton's impact law (Exercise 5.4), the Delassus
// block of one contact (Exercise 5.5), its r-factors (Exercise 5.6), one SOR contact update
// (Exercise 5.7) and the convergence test of the iterations (Exercise 5.8); validation of a
// problem, M⁻¹ of a body, the velocities of given percussions and the assembly of a problem from
// collision contacts.
//
// Independent references: dense matrices built here with Eigen — the 6n × 3k matrix W of all
// contacts (+W_a in the rows of body a, −W_b in those of body b), the block-diagonal 6n × 6n M⁻¹
// and the products WᵀM⁻¹W, u_free + M⁻¹WΛ and Wᵀu; contact Jacobians written out column by
// column, (d, K_ρ × A_IKᵀ d), with rotation matrices of Eigen::Quaterniond (no code of chapters 1
// and 4); the closed forms of a homogeneous sphere on the ground (G = diag(1/m, 7/(2m), 7/(2m)),
// rolling without slip v' = 5/7 v, dry friction Δv = −μ λ_N/m), of a bouncing ball (end normal
// velocity ε_N v) and of two touching spheres; conservation of linear and angular momentum in a
// two-body contact; the prox updates written out; and exactly representable values (dyadic
// fractions) for the boundary of the convergence test.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_test/bodies.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::Matrix3;
using grbd::Matrix6;
using grbd::Vector2;
using grbd::Vector3;
using grbd::Vector6;
using grbd::body::RigidBody;
using grbd::body::State;
using grbd::collision::ContactJacobian;
using grbd::contact::assemble_problem;
using grbd::contact::BodyIndex;
using grbd::contact::contact_velocities;
using grbd::contact::ContactConstraint;
using grbd::contact::ContactMaterial;
using grbd::contact::ContactProblem;
using grbd::contact::delassus_block;
using grbd::contact::has_converged;
using grbd::contact::impact_velocity;
using grbd::contact::inverse_mass;
using grbd::contact::InverseMass;
using grbd::contact::kStatic;
using grbd::contact::ProxForm;
using grbd::contact::r_factors;
using grbd::contact::RFactors;
using grbd::contact::sor_contact_update;
using grbd::contact::validate;
using grbd::contact::velocities_from_percussions;
using grbd::kinematics::make_q;
using grbd::kinematics::make_u;
using grbd::test::describe;
using grbd::test::Random;
using grbd::test::reference_A_IK;
using grbd::test::WorstCase;
using MatrixX = Eigen::MatrixXd;
using VectorX = Eigen::VectorXd;

}  // namespace

// describe() of the inputs of a contact problem, for the failure messages of the worst cases.
namespace grbd::test {

template <>
struct Describer<contact::InverseMass> {
  static void put(std::ostream& os, const contact::InverseMass& m) {
    os << "(" << describe("inv_m", m.inv_m, "K_Theta_inv", m.K_Theta_inv) << ")";
  }
};

template <>
struct Describer<contact::ContactConstraint> {
  static void put(std::ostream& os, const contact::ContactConstraint& c) {
    os << "(" << describe("body_a", c.body_a, "body_b", c.body_b, "W_a", c.W_a, "W_b", c.W_b,
                          "gamma_A", c.gamma_A, "mu", c.mu, "eps_N", c.eps_N, "eps_T", c.eps_T)
       << ")";
  }
};

template <>
struct Describer<contact::ContactProblem> {
  static void put(std::ostream& os, const contact::ContactProblem& p) {
    os << "(" << describe("M_inv", p.M_inv, "u_free", p.u_free, "contacts", p.contacts) << ")";
  }
};

}  // namespace grbd::test

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;
// Products of a few 3- and 6-vectors with entries of order 1–10: round-off ≲ 1e-15 relative.
constexpr double kProductTol = 1e-13;
// Iterated single-contact problems reach their fixed point to round-off: tolerance 1e-12
// relative to the size of the percussions and velocities.
constexpr double kSolutionTol = 1e-12;

// A_IK of a unit quaternion by Eigen::Quaterniond.
Matrix3 rotation(const grbd::kinematics::Quaternion& p) {
  return reference_A_IK(make_q(Vector3::Zero(), p));
}

// A random right-handed orthonormal contact frame: the columns n, t1, t2.
Matrix3 random_frame(Random& rng) { return rotation(rng.unit_quaternion()); }

// A random symmetric positive definite 3 × 3 matrix with eigenvalues in [lo, hi).
Matrix3 random_spd(Random& rng, double lo, double hi) {
  const Matrix3 R = random_frame(rng);
  const Matrix3 S =
      R * Vector3(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi)).asDiagonal() *
      R.transpose();
  return 0.5 * (S + S.transpose());
}

// The contact Jacobian of one body written out: column k is (d_k, K_ρ × A_IKᵀ d_k) for the
// directions d = (n, t1, t2), the columns of `frame`.
ContactJacobian jacobian(const Matrix3& A_IK, const Vector3& K_rho, const Matrix3& frame) {
  ContactJacobian W;
  for (int k = 0; k < 3; ++k) {
    W.col(k).head<3>() = frame.col(k);
    W.col(k).tail<3>() = K_rho.cross(A_IK.transpose() * frame.col(k));
  }
  return W;
}

// M⁻¹ of one body as a dense 6 × 6 matrix.
Matrix6 dense(const InverseMass& M_inv) {
  Matrix6 D = Matrix6::Zero();
  D.topLeftCorner<3, 3>() = M_inv.inv_m * Matrix3::Identity();
  D.bottomRightCorner<3, 3>() = Matrix3(M_inv.K_Theta_inv.asDiagonal());
  return D;
}

// A random problem: `bodies` bodies (1/m ∈ (1/3, 2], inverse principal moments in [0.2, 3)),
// random free velocities, and one contact per pair with a random frame, random lever arms in
// [−1, 1)³ and orientations, random γ_A, μ ∈ [0, 1), ε_N ∈ [0, 1), ε_T ∈ [−1, 1).
ContactProblem random_problem(Random& rng, int bodies,
                              const std::vector<std::pair<BodyIndex, BodyIndex>>& pairs) {
  ContactProblem p;
  for (int b = 0; b < bodies; ++b) {
    p.M_inv.push_back({1.0 / rng.uniform(0.5, 3.0), rng.vector3(0.2, 3.0)});
    p.u_free.push_back(make_u(rng.vector3(-2, 2), rng.vector3(-2, 2)));
  }
  for (const auto& [a, b] : pairs) {
    ContactConstraint c;
    c.body_a = a;
    c.body_b = b;
    const Matrix3 frame = random_frame(rng);
    if (a != kStatic) c.W_a = jacobian(random_frame(rng), rng.vector3(), frame);
    if (b != kStatic) c.W_b = jacobian(random_frame(rng), rng.vector3(), frame);
    c.gamma_A = rng.vector3(-2, 2);
    c.mu = rng.uniform(0.0, 1.0);
    c.eps_N = rng.uniform(0.0, 1.0);
    c.eps_T = rng.uniform(-1.0, 1.0);
    p.contacts.push_back(c);
  }
  return p;
}

// The dense 6n × 3k matrix W of all contacts: +W_a in the rows of body a, −W_b in those of b.
MatrixX dense_W(const ContactProblem& p) {
  MatrixX W = MatrixX::Zero(6 * static_cast<Eigen::Index>(p.M_inv.size()),
                            3 * static_cast<Eigen::Index>(p.contacts.size()));
  for (std::size_t i = 0; i < p.contacts.size(); ++i) {
    const ContactConstraint& c = p.contacts[i];
    const Eigen::Index col = 3 * static_cast<Eigen::Index>(i);
    if (c.body_a != kStatic) W.block<6, 3>(6 * c.body_a, col) += c.W_a;
    if (c.body_b != kStatic) W.block<6, 3>(6 * c.body_b, col) -= c.W_b;
  }
  return W;
}

// The dense block-diagonal 6n × 6n matrix M⁻¹.
MatrixX dense_M_inv(const ContactProblem& p) {
  const Eigen::Index n = static_cast<Eigen::Index>(p.M_inv.size());
  MatrixX M = MatrixX::Zero(6 * n, 6 * n);
  for (Eigen::Index b = 0; b < n; ++b) {
    M.block<6, 6>(6 * b, 6 * b) = dense(p.M_inv[static_cast<std::size_t>(b)]);
  }
  return M;
}

// Stacks per-body or per-contact vectors into one.
template <int N>
VectorX stack(const std::vector<Eigen::Matrix<double, N, 1>>& parts) {
  VectorX x(N * static_cast<Eigen::Index>(parts.size()));
  for (std::size_t i = 0; i < parts.size(); ++i) {
    x.segment<N>(N * static_cast<Eigen::Index>(i)) = parts[i];
  }
  return x;
}

// ε ∘ γ_A of all contacts, stacked.
VectorX restituted(const ContactProblem& p) {
  VectorX x(3 * static_cast<Eigen::Index>(p.contacts.size()));
  for (std::size_t i = 0; i < p.contacts.size(); ++i) {
    const ContactConstraint& c = p.contacts[i];
    x.segment<3>(3 * static_cast<Eigen::Index>(i)) =
        Vector3(c.eps_N, c.eps_T, c.eps_T).cwiseProduct(c.gamma_A);
  }
  return x;
}

// The Coulomb cone projection written out from its three cases, for the reference update.
Vector3 reference_cone(const Vector3& x, double mu) {
  const double t = x.tail<2>().norm();
  if (x(0) >= 0.0 && t <= mu * x(0)) return x;
  if (mu * t <= -x(0) || t == 0.0) return Vector3::Zero();
  const double y_N = (x(0) + mu * t) / (1.0 + mu * mu);
  Vector3 y;
  y << y_N, mu * y_N / t * x.tail<2>();
  return y;
}

// The prox update of `form` written out; De Saxcé's takes the single r = min(r_N, r_T).
Vector3 reference_update(const Vector3& lambda, const Vector3& xi, const RFactors& r, ProxForm form,
                         double mu) {
  if (form == ProxForm::de_saxce) {
    const Vector3 augmented = xi + Vector3(mu * xi.tail<2>().norm(), 0.0, 0.0);
    return reference_cone(lambda - std::min(r.r_N, r.r_T) * augmented, mu);
  }
  const double lambda_N = std::max(lambda(0) - r.r_N * xi(0), 0.0);
  const Vector2 x_T = lambda.tail<2>() - r.r_T * xi.tail<2>();
  const double radius = mu * lambda_N;
  const Vector2 lambda_T = x_T.norm() <= radius ? x_T : Vector2(radius * x_T.normalized());
  return {lambda_N, lambda_T(0), lambda_T(1)};
}

// A homogeneous sphere (mass m, radius R, Θ = 2/5 m R², orientation A_IK) touching the ground
// z = 0 with its lowest point, body 0 of a one-body problem: either side a of the contact (the
// normal e_z points from the ground b to it) or side b (the normal −e_z points from it to the
// ground a). The tangents are turned by φ about the normal. Velocities in frame I.
struct Ball {
  double m = 1.0;
  double R = 1.0;
  Matrix3 A = Matrix3::Identity();
  bool is_a = true;
  double phi = 0.0;

  double Theta() const { return 0.4 * m * R * R; }
  InverseMass M_inv() const { return {1.0 / m, Vector3::Constant(1.0 / Theta())}; }
  // The contact frame (n, t1, t2) as columns.
  Matrix3 frame() const {
    const Vector3 n = is_a ? Vector3::UnitZ() : Vector3(-Vector3::UnitZ());
    const Vector3 t1(std::cos(phi), std::sin(phi), 0.0);
    Matrix3 F;
    F << n, t1, n.cross(t1);
    return F;
  }
  ContactJacobian W() const { return jacobian(A, A.transpose() * Vector3(0.0, 0.0, -R), frame()); }
  // u = (v, K_ω) of the frame-I velocities v, ω.
  Vector6 u(const Vector3& v, const Vector3& omega) const {
    return make_u(v, A.transpose() * omega);
  }
  Vector3 v(const Vector6& u) const { return u.head<3>(); }
  Vector3 omega(const Vector6& u) const { return A * u.tail<3>(); }
  // γ = W_aᵀ u_a − W_bᵀ u_b for the ball's velocity u.
  Vector3 gamma(const Vector6& u) const {
    return is_a ? Vector3(W().transpose() * u) : Vector3(-W().transpose() * u);
  }
  ContactConstraint contact(double mu, double eps_N, double eps_T) const {
    ContactConstraint c;
    (is_a ? c.body_a : c.body_b) = 0;
    (is_a ? c.W_a : c.W_b) = W();
    c.mu = mu;
    c.eps_N = eps_N;
    c.eps_T = eps_T;
    return c;
  }
  // The percussion on the ball in frame I for the contact percussion λ.
  Vector3 percussion(const Vector3& lambda) const {
    return is_a ? Vector3(frame() * lambda) : Vector3(-frame() * lambda);
  }
  // The r-factors for the relaxation α from the closed-form G = diag(1/m, 7/(2m), 7/(2m)):
  // r_N = α m, r_T = 2α m/7 (De Saxcé's single r is the smaller, 2α m/7).
  RFactors r(double alpha) const { return {alpha * m, 2.0 * alpha * m / 7.0}; }
};

// Runs `n` SOR contact updates of one contact.
void iterate(const ContactConstraint& c, const RFactors& r, ProxForm form,
             const std::vector<InverseMass>& M_inv, std::vector<Vector6>& u, Vector3& lambda,
             int n) {
  for (int k = 0; k < n; ++k) sor_contact_update(c, r, form, M_inv, u, lambda);
}

constexpr ProxForm kForms[] = {ProxForm::alart_curnier, ProxForm::de_saxce};

const char* name(ProxForm form) {
  return form == ProxForm::alart_curnier ? "Alart-Curnier" : "De Saxce";
}

// The message of the InvalidArgument that validate() throws; a failure when it throws none.
std::string refusal(const ContactProblem& problem) {
  try {
    validate(problem);
  } catch (const grbd::InvalidArgument& e) {
    return e.what();
  }
  ADD_FAILURE() << "validate() accepted the problem";
  return {};
}

// Whether `message` contains each of `parts`.
::testing::AssertionResult mentions(const std::string& message,
                                    std::initializer_list<std::string> parts) {
  for (const std::string& part : parts) {
    if (message.find(part) == std::string::npos) {
      return ::testing::AssertionFailure()
             << "the message \"" << message << "\" lacks \"" << part << "\"";
    }
  }
  return ::testing::AssertionSuccess();
}

// A valid problem for the validation tests: two bodies, three contacts (0, 1), (1, static),
// (static, 0), and three keys.
ContactProblem valid_problem() {
  Random rng(5900);
  ContactProblem p = random_problem(rng, 2, {{0, 1}, {1, kStatic}, {kStatic, 0}});
  for (int i = 0; i < 3; ++i) p.keys.push_back({i, i + 1, 0, 0});
  return p;
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 5.4: the velocity of Newton's impact law
// ----------------------------------------------------------------------------------------------

// Reference: ξ = γ_E + diag(ε_N, ε_T, ε_T) γ_A with Eigen's diagonal product, for seeded random
// velocities and restitutions ε_N ∈ [0, 1], ε_T ∈ [−1, 1]; tolerance 4 ε (|γ_E| + |γ_A|).
TEST(Exercise5_4, IsTheEndVelocityPlusTheRestitutedStartVelocity) {
  Random rng(5401);
  WorstCase worst;
  for (int k = 0; k < 10000; ++k) {
    const Vector3 gamma_E = rng.vector3(-5, 5), gamma_A = rng.vector3(-5, 5);
    const double eps_N = rng.uniform(0.0, 1.0), eps_T = rng.uniform(-1.0, 1.0);
    const Vector3 expected = gamma_E + Vector3(eps_N, eps_T, eps_T).asDiagonal() * gamma_A;
    worst.update(
        (impact_velocity(gamma_E, gamma_A, eps_N, eps_T) - expected).norm() /
            (gamma_E.norm() + gamma_A.norm()),
        k, [&] {
          return describe("gamma_E", gamma_E, "gamma_A", gamma_A, "eps_N", eps_N, "eps_T", eps_T);
        });
  }
  EXPECT_LE(worst.value(), 4 * kEps) << worst;
}

// Reference: Newton's law. For a closing contact γ_A = (−v, s) the law ξ = 0 of a persisting
// contact means γ_E = (ε_N v, −ε_T s): the ball leaves with ε_N times its approach speed. With
// dyadic ε and v the values are exact. ε = 0 gives ξ = γ_E exactly.
TEST(Exercise5_4, ZeroImpactVelocityIsNewtonsLaw) {
  for (const double eps_N : {0.0, 0.25, 0.5, 1.0}) {
    for (const double eps_T : {-1.0, -0.5, 0.0, 0.75, 1.0}) {
      for (const double v : {0.5, 3.0}) {
        const Vector3 gamma_A(-v, 1.25, -2.5);
        const Vector3 gamma_E(eps_N * v, -eps_T * 1.25, eps_T * 2.5);
        EXPECT_EQ(impact_velocity(gamma_E, gamma_A, eps_N, eps_T), Vector3::Zero())
            << "eps_N = " << eps_N << ", eps_T = " << eps_T;
      }
    }
  }
  const Vector3 gamma_E(0.125, -3.0, 7.5);
  EXPECT_EQ(impact_velocity(gamma_E, Vector3(-1.0, 2.0, 3.0), 0.0, 0.0), gamma_E);
  // ε_N restitutes only the normal, ε_T only the tangential components
  EXPECT_EQ(impact_velocity(Vector3::Zero(), Vector3(2.0, 4.0, 8.0), 0.5, 0.0),
            Vector3(1.0, 0.0, 0.0));
  EXPECT_EQ(impact_velocity(Vector3::Zero(), Vector3(2.0, 4.0, 8.0), 0.0, -0.25),
            Vector3(0.0, -1.0, -2.0));
}

// ----------------------------------------------------------------------------------------------
// Exercise 5.5: the Delassus block of one contact
// ----------------------------------------------------------------------------------------------

// Reference: the diagonal 3 × 3 blocks of the dense WᵀM⁻¹W of random three-body problems with
// contacts between two bodies (both orders) and with a static side (both sides), random
// orientations, lever arms and positive inverse principal moments. Tolerance kProductTol ‖G‖.
TEST(Exercise5_5, MatchesTheDenseProduct) {
  Random rng(5501);
  WorstCase worst;
  for (int k = 0; k < 200; ++k) {
    const ContactProblem p = random_problem(rng, 3, {{2, 0}, {1, kStatic}, {kStatic, 2}, {0, 1}});
    const MatrixX W = dense_W(p);
    const MatrixX G = W.transpose() * dense_M_inv(p) * W;
    for (std::size_t i = 0; i < p.contacts.size(); ++i) {
      const Matrix3 expected =
          G.block<3, 3>(3 * static_cast<Eigen::Index>(i), 3 * static_cast<Eigen::Index>(i));
      const Matrix3 block = delassus_block(p.contacts[i], p.M_inv);
      worst.update((block - expected).norm() / expected.norm(), k, [&] {
        return describe("contact", i, "c", p.contacts[i], "M_inv", p.M_inv);
      });
    }
  }
  RecordProperty("worst_relative_error", grbd::format_number(worst.value()));
  EXPECT_LE(worst.value(), kProductTol) << worst;
}

// Reference: G is symmetric (to kProductTol ‖G‖) and, because the translational part of W is the
// orthonormal frame, G ⪰ (1/m_a + 1/m_b) I: every eigenvalue (Eigen's SelfAdjointEigenSolver) is
// at least the sum of the inverse masses of the dynamic sides.
TEST(Exercise5_5, IsSymmetricAndBoundedBelowByTheInverseMasses) {
  Random rng(5502);
  for (int k = 0; k < 500; ++k) {
    const ContactProblem p = random_problem(rng, 2, {{0, 1}, {kStatic, 1}, {0, kStatic}});
    for (const ContactConstraint& c : p.contacts) {
      const Matrix3 G = delassus_block(c, p.M_inv);
      ASSERT_LE((G - G.transpose()).norm(), kProductTol * G.norm());
      const double bound = (c.body_a == kStatic ? 0.0 : p.M_inv[c.body_a].inv_m) +
                           (c.body_b == kStatic ? 0.0 : p.M_inv[c.body_b].inv_m);
      const Eigen::SelfAdjointEigenSolver<Matrix3> eig(0.5 * (G + G.transpose()));
      ASSERT_GE(eig.eigenvalues().minCoeff(), bound * (1.0 - kProductTol))
          << "contact " << c.body_a << "-" << c.body_b;
    }
  }
}

// Reference: a homogeneous sphere (Θ = 2/5 m R²) on the ground at its lowest point, as side a or
// side b, any orientation and any tangents: G = diag(1/m, 1/m + R²/Θ, 1/m + R²/Θ) =
// diag(1/m, 7/(2m), 7/(2m)). Tolerance kProductTol relative.
TEST(Exercise5_5, SphereOnTheGround) {
  Random rng(5503);
  for (int k = 0; k < 200; ++k) {
    const Ball ball{rng.uniform(0.1, 5.0), rng.uniform(0.05, 2.0), random_frame(rng), k % 2 == 0,
                    rng.uniform(0.0, 2 * kPi)};
    const std::vector<InverseMass> M_inv{ball.M_inv()};
    const Matrix3 G = delassus_block(ball.contact(0.5, 0.0, 0.0), M_inv);
    const Matrix3 expected = Vector3(1.0, 3.5, 3.5).asDiagonal() * (1.0 / ball.m);
    EXPECT_LE((G - expected).norm(), kProductTol * expected.norm())
        << "m = " << ball.m << ", R = " << ball.R << ", side " << (ball.is_a ? "a" : "b")
        << "\nG =\n"
        << G;
  }
}

// Reference: two homogeneous spheres touching, a on top of b along a random normal n:
// G = diag(1/m_a + 1/m_b, 7/2 (1/m_a + 1/m_b), 7/2 (1/m_a + 1/m_b)) in any frame (n, t1, t2).
TEST(Exercise5_5, TwoTouchingSpheres) {
  Random rng(5504);
  for (int k = 0; k < 200; ++k) {
    const double m_a = rng.uniform(0.1, 5.0), m_b = rng.uniform(0.1, 5.0);
    const double R_a = rng.uniform(0.05, 2.0), R_b = rng.uniform(0.05, 2.0);
    const Matrix3 frame = random_frame(rng);
    const Vector3 n = frame.col(0);
    const Matrix3 A_a = random_frame(rng), A_b = random_frame(rng);
    ContactConstraint c;
    c.body_a = 1;
    c.body_b = 0;
    c.W_a = jacobian(A_a, A_a.transpose() * (-R_a * n), frame);
    c.W_b = jacobian(A_b, A_b.transpose() * (R_b * n), frame);
    const std::vector<InverseMass> M_inv{
        {1.0 / m_b, Vector3::Constant(1.0 / (0.4 * m_b * R_b * R_b))},
        {1.0 / m_a, Vector3::Constant(1.0 / (0.4 * m_a * R_a * R_a))}};
    const double s = 1.0 / m_a + 1.0 / m_b;
    const Matrix3 expected = Vector3(s, 3.5 * s, 3.5 * s).asDiagonal();
    const Matrix3 G = delassus_block(c, M_inv);
    EXPECT_LE((G - expected).norm(), kProductTol * expected.norm()) << "G =\n" << G;
  }
}

// Reference: only the bodies of the contact contribute, a static side not at all: with NaN in
// the inverse masses of every other body the block stays finite and equals W_aᵀM_a⁻¹W_a (dense).
TEST(Exercise5_5, OnlyTheBodiesOfTheContactContribute) {
  Random rng(5505);
  ContactProblem p = random_problem(rng, 3, {{1, kStatic}, {kStatic, 1}});
  const InverseMass nan_mass{kNaN, Vector3::Constant(kNaN)};
  p.M_inv[0] = nan_mass;
  p.M_inv[2] = nan_mass;
  for (const ContactConstraint& c : p.contacts) {
    const ContactJacobian& W = c.body_a == 1 ? c.W_a : c.W_b;
    const Matrix3 expected = W.transpose() * dense(p.M_inv[1]) * W;
    const Matrix3 G = delassus_block(c, p.M_inv);
    ASSERT_TRUE(G.allFinite()) << G;
    EXPECT_LE((G - expected).norm(), kProductTol * expected.norm());
  }
}

// ----------------------------------------------------------------------------------------------
// Exercise 5.6: the r-factors of one contact
// ----------------------------------------------------------------------------------------------

// Reference: r_N = α/G_NN and r_T = α/max(G_T1T1, G_T2T2) for random SPD G (either tangential
// entry the larger) and α ∈ (0, 2), to 2 ε relative; the off-diagonal entries play no part.
TEST(Exercise5_6, AreTheRelaxationOverTheDiagonal) {
  Random rng(5601);
  int t1_larger = 0;
  for (int k = 0; k < 10000; ++k) {
    Matrix3 G = random_spd(rng, 0.01, 10.0);
    const double alpha = rng.uniform(1e-3, 1.999);
    t1_larger += G(1, 1) > G(2, 2);
    const RFactors r = r_factors(G, alpha);
    const double r_N = alpha / G(0, 0), r_T = alpha / std::max(G(1, 1), G(2, 2));
    ASSERT_NEAR(r.r_N, r_N, 2 * kEps * r_N) << "G =\n" << G << "\nalpha = " << alpha;
    ASSERT_NEAR(r.r_T, r_T, 2 * kEps * r_T) << "G =\n" << G << "\nalpha = " << alpha;
    G(0, 1) = G(1, 0) = 100.0;
    G(1, 2) = G(2, 1) = -5.0;
    const RFactors s = r_factors(G, alpha);
    ASSERT_EQ(s.r_N, r.r_N);
    ASSERT_EQ(s.r_T, r.r_T);
  }
  EXPECT_GT(t1_larger, 1000);
  EXPECT_LT(t1_larger, 9000);
  // the diagonal case written out with exact numbers
  const RFactors r = r_factors(Matrix3(Vector3(0.5, 4.0, 2.0).asDiagonal()), 1.0);
  EXPECT_EQ(r.r_N, 2.0);
  EXPECT_EQ(r.r_T, 0.25);
}

// Reference: the open interval (0, 2): α = 0, −0, −1, 2, 2.5, ±∞ and NaN are refused with
// InvalidArgument; the smallest positive α, 1 and the largest double below 2 are accepted.
TEST(Exercise5_6, RefusesARelaxationOutsideTheOpenInterval) {
  const Matrix3 G(Vector3(1.0, 2.0, 3.0).asDiagonal());
  for (const double alpha : {0.0, -0.0, -1.0, 2.0, 2.5, kInf, -kInf, kNaN}) {
    EXPECT_THROW(r_factors(G, alpha), grbd::InvalidArgument) << "alpha = " << alpha;
  }
  for (const double alpha :
       {std::numeric_limits<double>::denorm_min(), 1.0, std::nextafter(2.0, 0.0)}) {
    const RFactors r = r_factors(G, alpha);
    EXPECT_EQ(r.r_N, alpha / 1.0) << "alpha = " << alpha;
    EXPECT_EQ(r.r_T, alpha / 3.0) << "alpha = " << alpha;
  }
}

// Reference: a diagonal entry 0, −0, −1 or NaN in any of the three places is refused with
// InvalidArgument (even where it would not enter the formula, like the smaller tangential one).
TEST(Exercise5_6, RefusesANonPositiveDiagonal) {
  for (int k = 0; k < 3; ++k) {
    for (const double bad : {0.0, -0.0, -1.0, kNaN}) {
      Matrix3 G(Vector3(1.0, 5.0, 5.0).asDiagonal());
      G(k, k) = bad;
      EXPECT_THROW(r_factors(G, 1.0), grbd::InvalidArgument)
          << "G(" << k << "," << k << ") = " << bad;
    }
  }
}

// ----------------------------------------------------------------------------------------------
// Exercise 5.7: one SOR contact update
// ----------------------------------------------------------------------------------------------

// Reference: one update of a random contact in a three-body problem (two bodies, and a static
// side on either side), both prox forms: the returned ξ is W_aᵀu_a − W_bᵀu_b + ε∘γ_A by dense
// products, λ⁺ the prox update written out (reference_update; De Saxcé with the single
// r = min(r_N, r_T)) for that ξ, u_a changes by
// M_a⁻¹W_aΔλ and u_b by −M_b⁻¹W_bΔλ (dense), every other body not at all. Tolerance
// kProductTol relative.
TEST(Exercise5_7, OneUpdateMovesTheBodiesByMInvWDeltaLambda) {
  Random rng(5701);
  WorstCase worst;
  for (int k = 0; k < 300; ++k) {
    const ContactProblem p = random_problem(rng, 3, {{2, 0}, {kStatic, 1}, {1, kStatic}});
    for (const ContactConstraint& c : p.contacts) {
      for (const ProxForm form : kForms) {
        const Vector3 lambda0 = rng.vector3(-0.5, 2.0);
        const RFactors r{rng.uniform(0.05, 2.0), rng.uniform(0.05, 2.0)};
        std::vector<Vector6> u = p.u_free;
        Vector3 lambda = lambda0;
        const Vector3 xi = sor_contact_update(c, r, form, p.M_inv, u, lambda);

        Vector3 gamma = Vector3::Zero();
        if (c.body_a != kStatic) gamma += c.W_a.transpose() * p.u_free[c.body_a];
        if (c.body_b != kStatic) gamma -= c.W_b.transpose() * p.u_free[c.body_b];
        const Vector3 expected_xi =
            gamma + Vector3(c.eps_N, c.eps_T, c.eps_T).cwiseProduct(c.gamma_A);
        const Vector3 expected = reference_update(lambda0, expected_xi, r, form, c.mu);
        const double size = 1.0 + lambda0.norm() + expected_xi.norm();
        const auto inputs = [&] {
          return describe("form", name(form), "lambda0", lambda0, "r_N", r.r_N, "r_T", r.r_T, "c",
                          c, "M_inv", p.M_inv, "u_free", p.u_free);
        };
        worst.update((xi - expected_xi).norm() / size, k, [&] { return "ξ, " + inputs(); });
        worst.update((lambda - expected).norm() / size, k, [&] { return "λ⁺, " + inputs(); });
        for (int b = 0; b < 3; ++b) {
          Vector6 expected_u = p.u_free[b];
          if (b == c.body_a) expected_u += dense(p.M_inv[b]) * c.W_a * (lambda - lambda0);
          if (b == c.body_b) expected_u -= dense(p.M_inv[b]) * c.W_b * (lambda - lambda0);
          if (b != c.body_a && b != c.body_b) {
            ASSERT_EQ(u[b], p.u_free[b]) << "body " << b << " is not part of the contact";
          }
          const double u_size = 1.0 + p.u_free[b].norm() + (expected_u - p.u_free[b]).norm();
          worst.update((u[b] - expected_u).norm() / u_size, k,
                       [&] { return "u of body " + std::to_string(b) + ", " + inputs(); });
        }
      }
    }
  }
  RecordProperty("worst_relative_error", grbd::format_number(worst.value()));
  EXPECT_LE(worst.value(), kProductTol) << worst;
}

// Reference: a homogeneous sphere resting on the ground, with the gravity impulse of one step in
// u_free, v = (0, 0, −g h): the ground carries λ = (m g h, 0, 0) and the sphere ends at rest. Side
// a and side b, both forms, α = 0.5, 1, 1.5, 300 updates from λ = 0.
TEST(Exercise5_7, SphereRestsOnTheGround) {
  Random rng(5702);
  const double gh = 9.81 * 1e-2;
  for (int k = 0; k < 20; ++k) {
    for (const bool is_a : {true, false}) {
      const Ball ball{rng.uniform(0.1, 5.0), rng.uniform(0.05, 2.0), random_frame(rng), is_a,
                      rng.uniform(0.0, 2 * kPi)};
      const ContactConstraint c = ball.contact(rng.uniform(0.0, 1.0), 0.0, 0.0);
      const std::vector<InverseMass> M_inv{ball.M_inv()};
      for (const ProxForm form : kForms) {
        for (const double alpha : {0.5, 1.0, 1.5}) {
          std::vector<Vector6> u{ball.u(Vector3(0.0, 0.0, -gh), Vector3::Zero())};
          Vector3 lambda = Vector3::Zero();
          iterate(c, ball.r(alpha), form, M_inv, u, lambda, 300);
          const double scale = ball.m * gh;
          EXPECT_LE((lambda - Vector3(ball.m * gh, 0.0, 0.0)).norm(), kSolutionTol * scale)
              << name(form) << ", alpha = " << alpha << ", lambda = " << lambda.transpose();
          EXPECT_LE(u[0].norm(), kSolutionTol * gh) << name(form) << ": u = " << u[0].transpose();
        }
      }
    }
  }
}

// Reference: dry friction on a sphere on the ground. With the free slip s of the contact point
// (v_T + ω × (−R e_z)) and the gravity impulse g h, the ground pushes λ_N = m g h and the
// tangential percussion F sticks, F = −(2m/7) s, when |s| ≤ 7/2 μ g h (rolling without slip:
// v' = v − 2/7 s, the contact point comes to rest), and slides, F = −μ m g h ŝ, otherwise.
// End velocities v' = v + F/m, ω' = ω + (−R e_z × F)/Θ. Random spheres, slips and spins
// (half sticking, half sliding), side a and b, both forms, α = 0.5, 1, 1.5, 500 updates.
TEST(Exercise5_7, SphereSticksOrSlidesOnTheGround) {
  Random rng(5703);
  const double gh = 9.81 * 1e-2;
  int sticking = 0, sliding = 0;
  WorstCase worst;
  for (int k = 0; k < 60; ++k) {
    const double mu = rng.uniform(0.1, 1.0);
    const Ball ball0{rng.uniform(0.1, 5.0), rng.uniform(0.05, 2.0), random_frame(rng), true,
                     rng.uniform(0.0, 2 * kPi)};
    const double threshold = 3.5 * mu * gh;
    const double slip = rng.uniform(0.0, 2.0) * threshold;
    if (std::abs(slip - threshold) < 1e-3 * threshold) continue;
    const double direction = rng.uniform(0.0, 2 * kPi);
    const Vector3 s(slip * std::cos(direction), slip * std::sin(direction), 0.0);
    const Vector3 omega0 = rng.vector3(-3.0, 3.0) / ball0.R;
    const Vector3 v0 = s - omega0.cross(Vector3(0.0, 0.0, -ball0.R));  // v0_z = 0
    const bool sticks = slip <= threshold;
    (sticks ? sticking : sliding) += 1;
    const Vector3 F =
        sticks ? Vector3(-2.0 * ball0.m / 7.0 * s) : Vector3(-mu * ball0.m * gh * s.normalized());
    const Vector3 v_end = v0 + F / ball0.m;
    const Vector3 omega_end = omega0 + Vector3(0.0, 0.0, -ball0.R).cross(F) / ball0.Theta();
    for (const bool is_a : {true, false}) {
      Ball ball = ball0;
      ball.is_a = is_a;
      ContactConstraint c = ball.contact(mu, 0.0, 0.0);
      c.gamma_A = ball.gamma(ball.u(v0, omega0));
      const std::vector<InverseMass> M_inv{ball.M_inv()};
      for (const ProxForm form : kForms) {
        for (const double alpha : {0.5, 1.0, 1.5}) {
          std::vector<Vector6> u{ball.u(v0 - Vector3(0.0, 0.0, gh), omega0)};
          Vector3 lambda = Vector3::Zero();
          iterate(c, ball.r(alpha), form, M_inv, u, lambda, 500);
          const double scale = ball.m * (gh + slip);
          const double speed = gh + slip + v0.norm() + omega0.norm() * ball.R;
          const std::string what = std::string(name(form)) + ", alpha = " + std::to_string(alpha) +
                                   (sticks ? ", sticking" : ", sliding") +
                                   (is_a ? ", side a" : ", side b");
          const double error_lambda =
              (ball.percussion(lambda) - Vector3(F.x(), F.y(), ball.m * gh)).norm() / scale;
          const double error_u = std::max((ball.v(u[0]) - v_end).norm(),
                                          (ball.omega(u[0]) - omega_end).norm() * ball.R) /
                                 speed;
          worst.update(error_lambda, k, [&] { return "λ, " + what; });
          worst.update(error_u, k, [&] { return "u, " + what; });
          EXPECT_LE(error_lambda, kSolutionTol) << what << ": lambda = " << lambda.transpose();
          EXPECT_LE(error_u, kSolutionTol) << what << ": u = " << u[0].transpose();
        }
      }
    }
  }
  RecordProperty("worst_relative_error", grbd::format_number(worst.value()));
  EXPECT_GT(sticking, 15);
  EXPECT_GT(sliding, 15);
}

// Reference: a contact that opens (the free normal velocity points away from the ground) carries
// no percussion: from λ = 0 the first update leaves λ = 0 and u unchanged, exactly; from a wrong
// initial guess λ₀ (with u = u_free + M⁻¹Wλ₀) the updates return to λ = 0 and u = u_free.
TEST(Exercise5_7, SeparatingSphereFeelsNoPercussion) {
  Random rng(5704);
  for (int k = 0; k < 20; ++k) {
    for (const bool is_a : {true, false}) {
      const Ball ball{rng.uniform(0.1, 5.0), rng.uniform(0.05, 2.0), random_frame(rng), is_a,
                      rng.uniform(0.0, 2 * kPi)};
      const ContactConstraint c = ball.contact(rng.uniform(0.1, 1.0), 0.0, 0.0);
      const std::vector<InverseMass> M_inv{ball.M_inv()};
      const Vector6 u_free =
          ball.u(Vector3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0.01, 1.0)),
                 rng.vector3(-1, 1));
      for (const ProxForm form : kForms) {
        std::vector<Vector6> u{u_free};
        Vector3 lambda = Vector3::Zero();
        const Vector3 xi = sor_contact_update(c, ball.r(1.0), form, M_inv, u, lambda);
        EXPECT_GT(xi(0), 0.0);
        EXPECT_EQ(lambda, Vector3::Zero()) << name(form);
        EXPECT_EQ(u[0], u_free) << name(form);

        const Vector3 lambda0(1.0, 0.2 * c.mu, -0.1 * c.mu);
        const ContactJacobian W = is_a ? c.W_a : c.W_b;
        u[0] = u_free + (is_a ? 1.0 : -1.0) * M_inv[0].apply(W * lambda0);
        lambda = lambda0;
        iterate(c, ball.r(1.0), form, M_inv, u, lambda, 300);
        EXPECT_LE(lambda.norm(), kSolutionTol) << name(form) << ": " << lambda.transpose();
        EXPECT_LE((u[0] - u_free).norm(), kSolutionTol * (1.0 + u_free.norm())) << name(form);
      }
    }
  }
}

// Reference: Newton's impact law for a ball that hits the ground with normal speed v and slip s
// (|s| ≤ v) under high friction (μ = 10): it leaves with normal speed ε_N v and slip −ε_T s. The
// percussions: λ_N = (1 + ε_N) m v, F = −(2m/7)(1 + ε_T) s. γ_A is the contact velocity of
// the start velocity, which is also u_free (no gravity in this step).
TEST(Exercise5_7, BallBouncesWithRestitution) {
  Random rng(5705);
  for (int k = 0; k < 40; ++k) {
    const double v = rng.uniform(0.1, 3.0);
    const double eps_N = k == 0 ? 1.0 : (k == 1 ? 0.0 : rng.uniform(0.0, 1.0));
    const double eps_T = k < 2 ? 0.0 : rng.uniform(-1.0, 1.0);
    const double direction = rng.uniform(0.0, 2 * kPi);
    const Vector3 s = (k < 2 ? 0.0 : rng.uniform(0.0, v)) *
                      Vector3(std::cos(direction), std::sin(direction), 0.0);
    for (const bool is_a : {true, false}) {
      const Ball ball{rng.uniform(0.1, 5.0), rng.uniform(0.05, 2.0), random_frame(rng), is_a,
                      rng.uniform(0.0, 2 * kPi)};
      const Vector3 omega0 = rng.vector3(-3.0, 3.0) / ball.R;
      const Vector3 v0 = s - omega0.cross(Vector3(0.0, 0.0, -ball.R)) - Vector3(0.0, 0.0, v);
      const Vector6 u_A = ball.u(v0, omega0);
      ContactConstraint c = ball.contact(10.0, eps_N, eps_T);
      c.gamma_A = ball.gamma(u_A);
      ASSERT_NEAR(c.gamma_A(0), -v, 1e-14 * (1.0 + v0.norm() + omega0.norm() * ball.R));
      const std::vector<InverseMass> M_inv{ball.M_inv()};
      const Vector3 F = -2.0 * ball.m / 7.0 * (1.0 + eps_T) * s;
      const Vector3 expected_percussion(F.x(), F.y(), (1.0 + eps_N) * ball.m * v);
      for (const ProxForm form : kForms) {
        std::vector<Vector6> u{u_A};
        Vector3 lambda = Vector3::Zero();
        iterate(c, ball.r(1.0), form, M_inv, u, lambda, 500);
        const double scale = ball.m * (v + s.norm());
        EXPECT_LE((ball.percussion(lambda) - expected_percussion).norm(), kSolutionTol * scale)
            << name(form) << ": eps_N = " << eps_N << ", eps_T = " << eps_T;
        const Vector3 gamma_E = ball.gamma(u[0]);
        EXPECT_NEAR(ball.v(u[0]).z(), eps_N * v, kSolutionTol * (v + s.norm())) << name(form);
        EXPECT_NEAR(gamma_E(0), eps_N * v, kSolutionTol * (v + s.norm())) << name(form);
        const Vector3 slip_E = ball.v(u[0]) + ball.omega(u[0]).cross(Vector3(0.0, 0.0, -ball.R));
        EXPECT_LE((slip_E.head<2>() + eps_T * s.head<2>()).norm(),
                  kSolutionTol * (v + s.norm() + omega0.norm() * ball.R))
            << name(form) << ": eps_T = " << eps_T;
      }
    }
  }
}

// Reference: conservation of momentum. Two random bodies (random principal inertias) touching at one
// point P, approaching: every update changes Σ m v and Σ (r_S × m v + A_IK Θ ω) (about the
// origin) by nothing but round-off, and keeps λ in the Coulomb cone. Both forms, 100 updates,
// r from the dense G.
TEST(Exercise5_7, TwoBodyContactConservesMomentum) {
  Random rng(5706);
  WorstCase worst_linear, worst_angular;
  for (int k = 0; k < 100; ++k) {
    const Vector3 P = rng.vector3();
    const Vector3 r_a = P + rng.uniform(0.2, 1.0) * rng.unit_vector3();
    const Vector3 r_b = P + rng.uniform(0.2, 1.0) * rng.unit_vector3();
    const Matrix3 A_a = random_frame(rng), A_b = random_frame(rng);
    const Matrix3 frame = random_frame(rng);
    const std::vector<InverseMass> M_inv{{1.0 / rng.uniform(0.5, 3.0), rng.vector3(0.2, 3.0)},
                                         {1.0 / rng.uniform(0.5, 3.0), rng.vector3(0.2, 3.0)}};
    ContactConstraint c;
    c.body_a = 1;
    c.body_b = 0;
    c.W_a = jacobian(A_a, A_a.transpose() * (P - r_a), frame);
    c.W_b = jacobian(A_b, A_b.transpose() * (P - r_b), frame);
    c.mu = rng.uniform(0.0, 1.0);
    const Matrix3 G =
        c.W_a.transpose() * dense(M_inv[1]) * c.W_a + c.W_b.transpose() * dense(M_inv[0]) * c.W_b;
    const RFactors r{1.0 / G(0, 0), 1.0 / std::max(G(1, 1), G(2, 2))};
    const auto momentum = [&](const std::vector<Vector6>& u) {
      Vector6 h = Vector6::Zero();
      const Vector3 r_S[2] = {r_b, r_a};
      const Matrix3 A[2] = {A_b, A_a};
      for (int b = 0; b < 2; ++b) {
        const double m = 1.0 / M_inv[b].inv_m;
        h.head<3>() += m * u[b].head<3>();
        h.tail<3>() += r_S[b].cross(m * u[b].head<3>()) +
                       A[b] * M_inv[b].K_Theta_inv.cwiseInverse().cwiseProduct(u[b].tail<3>());
      }
      return h;
    };
    for (const ProxForm form : kForms) {
      std::vector<Vector6> u{make_u(rng.vector3(-2, 2), rng.vector3(-2, 2)),
                             make_u(rng.vector3(-2, 2), rng.vector3(-2, 2))};
      // make the contact close: shift body a's velocity along −n until γ_N = −1
      const double gamma_N = (c.W_a.transpose() * u[1] - c.W_b.transpose() * u[0])(0);
      u[1].head<3>() -= (gamma_N + 1.0) * frame.col(0);
      const std::vector<Vector6> u0 = u;
      const Vector6 h0 = momentum(u);
      Vector3 lambda = Vector3::Zero();
      for (int i = 0; i < 100; ++i) {
        sor_contact_update(c, r, form, M_inv, u, lambda);
        const Vector6 h = momentum(u);
        const double size = 1.0 + h0.norm();
        const auto inputs = [&] {
          return describe("form", name(form), "update", i, "r_a", r_a, "r_b", r_b, "A_a", A_a,
                          "A_b", A_b, "M_inv", M_inv, "c", c, "u0", u0);
        };
        worst_linear.update((h - h0).head<3>().norm() / size, k, inputs);
        worst_angular.update((h - h0).tail<3>().norm() / size, k, inputs);
        ASSERT_LE(lambda.tail<2>().norm(), c.mu * lambda(0) + 1e-14) << name(form);
      }
      EXPECT_GT(lambda(0), 0.0) << name(form);
    }
  }
  RecordProperty("worst_linear_momentum", grbd::format_number(worst_linear.value()));
  RecordProperty("worst_angular_momentum", grbd::format_number(worst_angular.value()));
  EXPECT_LE(worst_linear.value(), kSolutionTol) << worst_linear;
  EXPECT_LE(worst_angular.value(), kSolutionTol) << worst_angular;
}

// ----------------------------------------------------------------------------------------------
// Exercise 5.8: the convergence test of an iteration
// ----------------------------------------------------------------------------------------------

// Reference: dyadic numbers, exact in floating point. abs_tol = 1/4, rel_tol = 1/2, x = 4: the
// bound is 1/4 + 2 = 9/4, reached exactly by x_old = 7/4 and 25/4 (converged, equality counts)
// and exceeded by 2⁻⁵⁰ (not converged).
TEST(Exercise5_8, EqualityAtTheBoundCounts) {
  const std::vector<double> x{4.0};
  for (const double x_old : {1.75, 6.25, 4.0, 3.0, 5.5}) {
    EXPECT_TRUE(has_converged(std::vector<double>{x_old}, x, 0.25, 0.5)) << "x_old = " << x_old;
  }
  // 7/4 − 2⁻⁵⁰ and 25/4 + 2⁻⁵⁰: |x − x_old| = 9/4 + 2⁻⁵⁰, exact in floating point
  for (const double x_old : {1.75 - std::ldexp(1.0, -50), 6.25 + std::ldexp(1.0, -50), 0.0, 10.0}) {
    EXPECT_FALSE(has_converged(std::vector<double>{x_old}, x, 0.25, 0.5)) << "x_old = " << x_old;
  }
  // zero tolerances: only equality converges
  EXPECT_TRUE(
      has_converged(std::vector<double>{0.0, 3.0}, std::vector<double>{0.0, 3.0}, 0.0, 0.0));
  EXPECT_FALSE(has_converged(std::vector<double>{0.0, std::nextafter(3.0, 4.0)},
                             std::vector<double>{0.0, 3.0}, 0.0, 0.0));
}

// Reference: the relative part scales with the new iterate |x_k|, not x_old, and with its
// absolute value: (x_old, x) = (1.75, 4) and (−1.75, −4) converge with the bound 9/4, but
// (4, 1.75) does not: its bound is 1/4 + 7/8 = 9/8 < 9/4.
TEST(Exercise5_8, RelativePartUsesTheNewIterate) {
  EXPECT_TRUE(has_converged(std::vector<double>{1.75}, std::vector<double>{4.0}, 0.25, 0.5));
  EXPECT_TRUE(has_converged(std::vector<double>{-1.75}, std::vector<double>{-4.0}, 0.25, 0.5));
  EXPECT_FALSE(has_converged(std::vector<double>{4.0}, std::vector<double>{1.75}, 0.25, 0.5));
  EXPECT_FALSE(has_converged(std::vector<double>{-4.0}, std::vector<double>{-1.75}, 0.25, 0.5));
  // absolute only and relative only
  EXPECT_TRUE(has_converged(std::vector<double>{1e6}, std::vector<double>{1e6 + 0.5}, 0.5, 0.0));
  EXPECT_FALSE(has_converged(std::vector<double>{1e6}, std::vector<double>{1e6 + 0.75}, 0.5, 0.0));
  EXPECT_TRUE(has_converged(std::vector<double>{0.0}, std::vector<double>{1e-300}, 0.0, 1.0));
  EXPECT_FALSE(has_converged(std::vector<double>{1e-300}, std::vector<double>{0.0}, 0.0, 1.0));
}

// Reference: every component counts: 1000 components within the bound converge; one component
// beyond it at the start, middle or end does not. No components: converged.
TEST(Exercise5_8, EveryComponentCounts) {
  Random rng(5801);
  std::vector<double> x(1000), x_old(1000);
  for (std::size_t k = 0; k < x.size(); ++k) {
    x[k] = rng.uniform(-10.0, 10.0);
    x_old[k] = x[k] + 0.9 * rng.uniform(-1.0, 1.0) * (1e-8 + 1e-6 * std::abs(x[k]));
  }
  EXPECT_TRUE(has_converged(x_old, x, 1e-8, 1e-6));
  for (const std::size_t bad : {std::size_t{0}, std::size_t{500}, std::size_t{999}}) {
    std::vector<double> y = x_old;
    y[bad] = x[bad] + 1.1 * (1e-8 + 1e-6 * std::abs(x[bad]));
    EXPECT_FALSE(has_converged(y, x, 1e-8, 1e-6)) << "component " << bad;
  }
  EXPECT_TRUE(has_converged(std::vector<double>{}, std::vector<double>{}, 0.0, 0.0));
}

// Reference: NaN never converges, whatever the tolerances: NaN in x, in x_old, in both at the same
// place, and ∞ in both (∞ − ∞ is NaN).
TEST(Exercise5_8, NaNNeverConverges) {
  const std::vector<double> ok{1.0, 2.0, 3.0};
  for (const std::size_t place : {std::size_t{0}, std::size_t{2}}) {
    std::vector<double> bad = ok;
    bad[place] = kNaN;
    for (const double tol : {1e-12, 1.0, 1e300}) {
      EXPECT_FALSE(has_converged(ok, bad, tol, tol)) << "NaN in x at " << place;
      EXPECT_FALSE(has_converged(bad, ok, tol, tol)) << "NaN in x_old at " << place;
      EXPECT_FALSE(has_converged(bad, bad, tol, tol)) << "NaN in both at " << place;
    }
    bad[place] = kInf;
    EXPECT_FALSE(has_converged(bad, bad, 1.0, 1.0)) << "inf in both at " << place;
  }
}

// Reference: random vectors whose components differ by a factor f ∈ [0.5, 0.99] or [1.01, 2] of
// abs_tol + rel_tol |x_k|: converged exactly when no f exceeds 1. The tolerance is kept above
// 1e5 ulp(x_k) (rel_tol ≥ 1e-10, or |x_k| ≤ 1e6 abs_tol when rel_tol = 0), so that rounding
// x_old cannot move f across 1.
TEST(Exercise5_8, MatchesTheMixedTestOnRandomVectors) {
  Random rng(5802);
  int converged = 0;
  for (int k = 0; k < 10000; ++k) {
    const double abs_tol = std::pow(10.0, rng.uniform(-14.0, -2.0));
    const double rel_tol = k % 5 == 0 ? 0.0 : std::pow(10.0, rng.uniform(-10.0, -2.0));
    const double magnitude = rel_tol == 0.0 ? 1e6 * abs_tol : 1e6;
    std::vector<double> x(8), x_old(8);
    bool expected = true;
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] = rng.uniform(-1.0, 1.0) * magnitude * std::pow(10.0, rng.uniform(-12.0, 0.0));
      const bool beyond = rng.uniform(0.0, 1.0) < 0.1;
      expected = expected && !beyond;
      const double f = beyond ? rng.uniform(1.01, 2.0) : rng.uniform(0.5, 0.99);
      const double sign = rng.uniform(0.0, 1.0) < 0.5 ? 1.0 : -1.0;
      x_old[i] = x[i] + sign * f * (abs_tol + rel_tol * std::abs(x[i]));
    }
    converged += expected;
    ASSERT_EQ(has_converged(x_old, x, abs_tol, rel_tol), expected) << "sample " << k;
  }
  EXPECT_GT(converged, 2000);
  EXPECT_LT(converged, 8000);
}

// ----------------------------------------------------------------------------------------------
// M⁻¹ of a body
// ----------------------------------------------------------------------------------------------

// Reference: M⁻¹ = diag(1/m I₃, diag(1/Θ)) written out with exact numbers, and apply() against
// the dense inverse of the mass matrix; a body with m ≤ 0 or a non-positive moment is refused.
TEST(InverseMassOfABody, IsTheInverseOfTheMassMatrix) {
  const InverseMass M_inv = inverse_mass(RigidBody{2.0, Vector3(0.5, 4.0, 4.0)});
  EXPECT_EQ(M_inv.inv_m, 0.5);
  EXPECT_EQ(M_inv.K_Theta_inv, Vector3(2.0, 0.25, 0.25));
  Random rng(5901);
  for (int k = 0; k < 100; ++k) {
    const double m = rng.uniform(0.1, 10.0);
    const RigidBody body{m, grbd::test::random_moments(rng, 0.1, 5.0)};
    Matrix6 M = Matrix6::Zero();
    M.diagonal() << body.m, body.m, body.m, body.K_Theta;
    const Vector6 x = make_u(rng.vector3(), rng.vector3());
    const Vector6 y = inverse_mass(body).apply(x);
    EXPECT_LE((M * y - x).norm(), 4 * kEps * x.norm());
  }
  EXPECT_THROW(inverse_mass(RigidBody{0.0, Vector3::Ones()}), grbd::InvalidArgument);
  EXPECT_THROW(inverse_mass(RigidBody{-1.0, Vector3::Ones()}), grbd::InvalidArgument);
  EXPECT_THROW(inverse_mass(RigidBody{1.0, Vector3(1.0, 0.0, 1.0)}), grbd::InvalidArgument);
  EXPECT_THROW(inverse_mass(RigidBody{1.0, Vector3(1.0, 1.0, kNaN)}), grbd::InvalidArgument);
}

// ----------------------------------------------------------------------------------------------
// Validation of a problem
// ----------------------------------------------------------------------------------------------

// Reference: a well-formed problem passes, with or without keys, with the boundary values
// μ = 0, ε_N ∈ {0, 1}, ε_T = ±1; a problem without contacts passes.
TEST(ContactProblemValidation, AcceptsAWellFormedProblem) {
  ContactProblem p = valid_problem();
  EXPECT_NO_THROW(validate(p));
  p.keys.clear();
  EXPECT_NO_THROW(validate(p));
  p.contacts[0].mu = 0.0;
  p.contacts[0].eps_N = 0.0;
  p.contacts[1].eps_N = 1.0;
  p.contacts[1].eps_T = -1.0;
  p.contacts[2].eps_T = 1.0;
  EXPECT_NO_THROW(validate(p));
  p.contacts.clear();
  EXPECT_NO_THROW(validate(p));
}

// Reference: M_inv and u_free of different lengths; the message names both counts.
TEST(ContactProblemValidation, RefusesBodyCountsThatDisagree) {
  ContactProblem p = valid_problem();
  p.u_free.push_back(Vector6::Zero());
  EXPECT_TRUE(mentions(refusal(p), {"u_free", "2", "3"}));
}

// Reference: 1/m = 0, −0.5, ∞ or NaN for body 1; the message names the body and the value.
TEST(ContactProblemValidation, RefusesANonPositiveInverseMass) {
  for (const double inv_m : {0.0, -0.5, kInf, kNaN}) {
    ContactProblem p = valid_problem();
    p.M_inv[1].inv_m = inv_m;
    EXPECT_TRUE(mentions(refusal(p), {"body 1", grbd::format_number(inv_m)}));
  }
}

// Reference: an inverse principal moment of body 1 negative, zero, NaN or infinite; the message
// names the body and K_Theta_inv.
TEST(ContactProblemValidation, RefusesInversePrincipalMomentsThatAreNotPositiveAndFinite) {
  for (const Vector3& K : {Vector3(1.0, -1.0, 1.0), Vector3(1.0, 0.0, 1.0),
                           Vector3(1.0, kNaN, 1.0), Vector3(kInf, 1.0, 1.0)}) {
    ContactProblem p = valid_problem();
    p.M_inv[1].K_Theta_inv = K;
    EXPECT_TRUE(mentions(refusal(p), {"body 1", "K_Theta_inv"})) << K.transpose();
  }
}

// Reference: a NaN or ∞ in u_free of body 1; the message names the body and u_free.
TEST(ContactProblemValidation, RefusesANonFiniteFreeVelocity) {
  for (const double bad : {kNaN, -kInf}) {
    ContactProblem p = valid_problem();
    p.u_free[1](4) = bad;
    EXPECT_TRUE(mentions(refusal(p), {"body 1", "u_free"}));
  }
}

// Reference: body indices 2 (two bodies) and −2 (neither a body nor kStatic) in contact 1; the
// message names the contact, the side and the index.
TEST(ContactProblemValidation, RefusesABodyIndexOutOfRange) {
  ContactProblem p = valid_problem();
  p.contacts[1].body_a = 2;
  EXPECT_TRUE(mentions(refusal(p), {"contact 1", "body_a = 2"}));
  p = valid_problem();
  p.contacts[1].body_b = -2;
  EXPECT_TRUE(mentions(refusal(p), {"contact 1", "body_b = -2"}));
}

// Reference: contact 1 between two static sides; contact 0 between body 1 and itself.
TEST(ContactProblemValidation, RefusesTwoStaticSidesAndSelfContact) {
  ContactProblem p = valid_problem();
  p.contacts[1].body_a = kStatic;
  p.contacts[1].body_b = kStatic;
  EXPECT_TRUE(mentions(refusal(p), {"contact 1", "static"}));
  p = valid_problem();
  p.contacts[0].body_a = 1;
  p.contacts[0].body_b = 1;
  EXPECT_TRUE(mentions(refusal(p), {"contact 0", "body 1"}));
}

// Reference: NaN in W_a of contact 1, ∞ in W_b of contact 2, NaN in γ_A of contact 1; the message
// names the contact.
TEST(ContactProblemValidation, RefusesNonFiniteContactData) {
  ContactProblem p = valid_problem();
  p.contacts[1].W_a(3, 1) = kNaN;
  EXPECT_TRUE(mentions(refusal(p), {"contact 1"}));
  p = valid_problem();
  p.contacts[2].W_b(0, 0) = kInf;
  EXPECT_TRUE(mentions(refusal(p), {"contact 2"}));
  p = valid_problem();
  p.contacts[1].gamma_A(2) = kNaN;
  EXPECT_TRUE(mentions(refusal(p), {"contact 1", "gamma_A"}));
}

// Reference: μ = −0.25, NaN, ∞; ε_N = 1.5, −0.25, NaN; ε_T = 1.25, −1.5, NaN in contact 1; the
// message names the contact and the value.
TEST(ContactProblemValidation, RefusesBadMaterialParameters) {
  for (const double mu : {-0.25, kNaN, kInf}) {
    ContactProblem p = valid_problem();
    p.contacts[1].mu = mu;
    EXPECT_TRUE(mentions(refusal(p), {"contact 1", "mu", grbd::format_number(mu)}));
  }
  for (const double eps_N : {1.5, -0.25, kNaN}) {
    ContactProblem p = valid_problem();
    p.contacts[1].eps_N = eps_N;
    EXPECT_TRUE(mentions(refusal(p), {"contact 1", "eps_N", grbd::format_number(eps_N)}));
  }
  for (const double eps_T : {1.25, -1.5, kNaN}) {
    ContactProblem p = valid_problem();
    p.contacts[1].eps_T = eps_T;
    EXPECT_TRUE(mentions(refusal(p), {"contact 1", "eps_T", grbd::format_number(eps_T)}));
  }
}

// Reference: W_a = 0 in contact 1 (body–static) gives G = 0; a zero tangential column gives
// G(1,1) = 0; both zero W of the two-body contact 0 give G = 0. The message names the contact
// and the diagonal entry.
TEST(ContactProblemValidation, RefusesADelassusBlockWithoutPositiveDiagonal) {
  ContactProblem p = valid_problem();
  p.contacts[1].W_a.setZero();
  EXPECT_TRUE(mentions(refusal(p), {"contact 1", "G(0,0) = 0"}));
  p = valid_problem();
  p.contacts[1].W_a.col(1).setZero();
  EXPECT_TRUE(mentions(refusal(p), {"contact 1", "G(1,1) = 0"}));
  p = valid_problem();
  p.contacts[0].W_a.setZero();
  p.contacts[0].W_b.setZero();
  EXPECT_TRUE(mentions(refusal(p), {"contact 0", "G(0,0) = 0"}));
}

// Reference: 5 keys or 1 key for 3 contacts; the message names both counts.
TEST(ContactProblemValidation, RefusesKeysOfTheWrongLength) {
  ContactProblem p = valid_problem();
  p.keys.push_back({7, 8, 0, 0});
  p.keys.push_back({8, 9, 0, 0});
  EXPECT_TRUE(mentions(refusal(p), {"keys", "5", "3"}));
  p.keys.resize(1);
  EXPECT_TRUE(mentions(refusal(p), {"keys", "1", "3"}));
}

// ----------------------------------------------------------------------------------------------
// Velocities of percussions
// ----------------------------------------------------------------------------------------------

// Reference: u = u_free + M⁻¹WΛ with the dense matrices, for random problems with two-body and
// static contacts and random Λ; a Λ of the wrong length is refused.
TEST(ContactVelocities, VelocitiesFromPercussionsAreTheDenseProduct) {
  Random rng(5902);
  WorstCase worst;
  for (int k = 0; k < 100; ++k) {
    const ContactProblem p = random_problem(rng, 3, {{2, 0}, {1, kStatic}, {kStatic, 2}, {0, 1}});
    std::vector<Vector3> lambda;
    for (std::size_t i = 0; i < p.contacts.size(); ++i) lambda.push_back(rng.vector3(-1, 2));
    const VectorX expected = stack(p.u_free) + dense_M_inv(p) * dense_W(p) * stack(lambda);
    const VectorX u = stack(velocities_from_percussions(p, lambda));
    worst.update((u - expected).norm() / expected.norm(), k,
                 [&] { return describe("problem", p, "lambda", lambda); });
  }
  EXPECT_LE(worst.value(), kProductTol) << worst;
  const ContactProblem p = random_problem(rng, 2, {{0, 1}, {1, kStatic}});
  EXPECT_THROW(velocities_from_percussions(p, std::vector<Vector3>(3, Vector3::Zero())),
               grbd::InvalidArgument);
}

// Reference: ξ = Wᵀu + ε∘γ_A with the dense W; and for u = u_free + M⁻¹WΛ,
// ξ(u) − ξ(u_free) = (WᵀM⁻¹W)Λ; velocities of the wrong length are refused.
TEST(ContactVelocities, ContactVelocitiesAreTheImpactLawOfWTransposeU) {
  Random rng(5903);
  WorstCase worst, worst_delassus;
  for (int k = 0; k < 100; ++k) {
    const ContactProblem p = random_problem(rng, 3, {{2, 0}, {1, kStatic}, {kStatic, 2}, {0, 1}});
    const MatrixX W = dense_W(p);
    const VectorX expected = W.transpose() * stack(p.u_free) + restituted(p);
    const VectorX xi = stack(contact_velocities(p, p.u_free));
    worst.update((xi - expected).norm() / expected.norm(), k,
                 [&] { return describe("problem", p); });
    std::vector<Vector3> lambda;
    for (std::size_t i = 0; i < p.contacts.size(); ++i) lambda.push_back(rng.vector3(-1, 2));
    const VectorX xi_end = stack(contact_velocities(p, velocities_from_percussions(p, lambda)));
    const VectorX G_lambda = W.transpose() * dense_M_inv(p) * W * stack(lambda);
    worst_delassus.update((xi_end - xi - G_lambda).norm() / G_lambda.norm(), k,
                          [&] { return describe("problem", p, "lambda", lambda); });
  }
  EXPECT_LE(worst.value(), kProductTol) << worst;
  EXPECT_LE(worst_delassus.value(), kProductTol) << worst_delassus;
  const ContactProblem p = random_problem(rng, 2, {{0, 1}});
  EXPECT_THROW(contact_velocities(p, std::vector<Vector6>(1, Vector6::Zero())),
               grbd::InvalidArgument);
}

// ----------------------------------------------------------------------------------------------
// Assembly from collision contacts
// ----------------------------------------------------------------------------------------------

// Reference: hand-made collision::Contact structs between two bodies, body–static and
// static–body: W_a, W_b are the Jacobians written out at the orientations of `states`, γ_A is
// W_aᵀu_a − W_bᵀu_b at the velocities of `states` (not u_free), M⁻¹ comes from the bodies,
// u_free is copied, the material is applied to every contact and the keys are Contact::key().
TEST(AssembleProblem, BuildsTheContactsFromCollisionContacts) {
  Random rng(5904);
  const std::vector<RigidBody> bodies{{2.0, Vector3(0.5, 4.0, 4.0)},
                                      {0.5, Vector3(1.0, 2.0, 2.0)}};
  std::vector<State> states;
  std::vector<Vector6> u_free;
  for (int b = 0; b < 2; ++b) {
    states.push_back({make_q(rng.vector3(), rng.unit_quaternion()),
                      make_u(rng.vector3(-2, 2), rng.vector3(-2, 2))});
    u_free.push_back(make_u(rng.vector3(-2, 2), rng.vector3(-2, 2)));
  }
  const std::vector<std::pair<BodyIndex, BodyIndex>> pairs{{0, 1}, {1, kStatic}, {kStatic, 0}};
  std::vector<grbd::collision::Contact> contacts;
  std::vector<Matrix3> frames;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    grbd::collision::Contact k;
    k.body_a = pairs[i].first;
    k.body_b = pairs[i].second;
    k.collider_a = static_cast<std::int32_t>(10 + i);
    k.collider_b = static_cast<std::int32_t>(20 + i);
    k.geometry.feature_a = grbd::collision::face_feature(i);
    k.geometry.feature_b = grbd::collision::vertex_feature(3 * i + 1);
    frames.push_back(random_frame(rng));
    k.geometry.I_n = frames.back().col(0);
    k.I_t1 = frames.back().col(1);
    k.I_t2 = frames.back().col(2);
    k.K_rho_a = rng.vector3();
    k.K_rho_b = rng.vector3();
    contacts.push_back(k);
  }
  const ContactMaterial material{0.3, 0.25, -0.5};
  const ContactProblem p = assemble_problem(contacts, bodies, states, u_free, material);

  ASSERT_EQ(p.M_inv.size(), 2U);
  EXPECT_EQ(p.M_inv[0].inv_m, 0.5);
  EXPECT_EQ(p.M_inv[1].K_Theta_inv, Vector3(1.0, 0.5, 0.5));
  ASSERT_EQ(p.u_free.size(), 2U);
  EXPECT_EQ(p.u_free[0], u_free[0]);
  EXPECT_EQ(p.u_free[1], u_free[1]);
  ASSERT_EQ(p.contacts.size(), 3U);
  ASSERT_EQ(p.keys.size(), 3U);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const ContactConstraint& c = p.contacts[i];
    const grbd::collision::Contact& k = contacts[i];
    EXPECT_EQ(c.body_a, k.body_a);
    EXPECT_EQ(c.body_b, k.body_b);
    Vector3 gamma = Vector3::Zero();
    if (k.body_a != kStatic) {
      const ContactJacobian W = jacobian(reference_A_IK(states[k.body_a].q), k.K_rho_a, frames[i]);
      EXPECT_LE((c.W_a - W).cwiseAbs().maxCoeff(), kProductTol) << "contact " << i;
      gamma += W.transpose() * states[k.body_a].u;
    }
    if (k.body_b != kStatic) {
      const ContactJacobian W = jacobian(reference_A_IK(states[k.body_b].q), k.K_rho_b, frames[i]);
      EXPECT_LE((c.W_b - W).cwiseAbs().maxCoeff(), kProductTol) << "contact " << i;
      gamma -= W.transpose() * states[k.body_b].u;
    }
    EXPECT_LE((c.gamma_A - gamma).norm(), kProductTol * (1.0 + gamma.norm())) << "contact " << i;
    EXPECT_EQ(c.mu, 0.3);
    EXPECT_EQ(c.eps_N, 0.25);
    EXPECT_EQ(c.eps_T, -0.5);
    EXPECT_EQ(p.keys[i], k.key());
    EXPECT_EQ(p.keys[i], (grbd::collision::ContactKey{k.collider_a, k.collider_b,
                                                      k.geometry.feature_a, k.geometry.feature_b}));
  }
  EXPECT_NO_THROW(validate(p));
}

// Reference: bodies, states and u_free of different lengths, and a contact naming body 2 of two
// bodies, are refused with InvalidArgument.
TEST(AssembleProblem, RefusesInconsistentInput) {
  Random rng(5905);
  const std::vector<RigidBody> bodies{{1.0, Vector3::Ones()}, {1.0, Vector3::Ones()}};
  const std::vector<State> states(2, State{make_q(Vector3::Zero(), {}), Vector6::Zero()});
  const std::vector<Vector6> u_free(2, Vector6::Zero());
  grbd::collision::Contact k;
  k.body_a = 0;
  k.body_b = 1;
  const std::vector<grbd::collision::Contact> contacts{k};
  EXPECT_THROW(assemble_problem(contacts, bodies, std::vector<State>(1, states[0]), u_free, {}),
               grbd::InvalidArgument);
  EXPECT_THROW(
      assemble_problem(contacts, bodies, states, std::vector<Vector6>(3, Vector6::Zero()), {}),
      grbd::InvalidArgument);
  k.body_b = 2;
  EXPECT_THROW(
      assemble_problem(std::vector<grbd::collision::Contact>{k}, bodies, states, u_free, {}),
      grbd::InvalidArgument);
}

namespace {

// One contact between body 0 and body 1 of two bodies, with unit force directions.
ContactProblem two_body_problem() {
  ContactProblem p;
  p.M_inv.assign(2, InverseMass{});
  p.u_free.assign(2, Vector6::Zero());
  ContactConstraint c;
  c.body_a = 0;
  c.body_b = 1;
  c.W_a.topRows<3>() = Matrix3::Identity();
  c.W_b.topRows<3>() = Matrix3::Identity();
  p.contacts.push_back(c);
  return p;
}

std::string refusal_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const grbd::InvalidArgument& error) {
    return error.what();
  }
  return "";
}

}  // namespace

// Regression (issue 11): these public functions indexed their arrays with the body indices and
// lengths they were given (heap-buffer-overflow under ASan): a body index out of range, r or λ
// shorter than the contacts, spans of different lengths. Reference: their declarations (one λ
// and one r per contact, one u and one M⁻¹ per body); each refuses with InvalidArgument naming
// what is wrong.
TEST(ProblemInput, PublicFunctionsRefuseIndicesAndLengthsOutOfRange) {
  ContactProblem p = two_body_problem();
  p.contacts[0].body_b = 7;
  const std::vector<Vector3> lambda(1, Vector3::Zero());
  std::string m = refusal_of([&] { velocities_from_percussions(p, lambda); });
  EXPECT_NE(m.find("body_b = 7"), std::string::npos) << m;
  m = refusal_of([&] { contact_velocities(p, p.u_free); });
  EXPECT_NE(m.find("body_b = 7"), std::string::npos) << m;
  m = refusal_of([&] { delassus_block(p.contacts[0], p.M_inv); });
  EXPECT_NE(m.find("body_b = 7"), std::string::npos) << m;
  p.contacts[0].body_b = -5;
  m = refusal_of([&] { delassus_block(p.contacts[0], p.M_inv); });
  EXPECT_NE(m.find("body_b = -5"), std::string::npos) << m;

  const ContactProblem good = two_body_problem();
  std::vector<Vector6> u = good.u_free;
  std::vector<Vector3> l(1, Vector3::Zero());
  const std::vector<RFactors> r(1, RFactors{1.0, 1.0});
  const std::vector<RFactors> no_r;
  std::vector<Vector3> no_lambda;
  m = refusal_of([&] { grbd::contact::sor_sweep(good, no_r, ProxForm::alart_curnier, u, l); });
  EXPECT_NE(m.find("sor_sweep"), std::string::npos) << m;
  m = refusal_of(
      [&] { grbd::contact::sor_sweep(good, r, ProxForm::alart_curnier, u, no_lambda); });
  EXPECT_NE(m.find("percussions"), std::string::npos) << m;
  std::vector<Vector6> short_u(1, Vector6::Zero());
  m = refusal_of([&] { grbd::contact::sor_sweep(good, r, ProxForm::alart_curnier, short_u, l); });
  EXPECT_NE(m.find("velocities"), std::string::npos) << m;
  EXPECT_NO_THROW(grbd::contact::sor_sweep(good, r, ProxForm::alart_curnier, u, l));

  const std::vector<double> three(3, 0.0), two(2, 0.0);
  m = refusal_of([&] { has_converged(three, two, 0.0, 0.0); });
  EXPECT_NE(m.find("same length"), std::string::npos) << m;
}

// Regression (issue 11): assemble_problem used the orientations of `states` as given: p = 2 e₀
// scales every lever arm in W by |p|² = 4. Reference: body::State requires |p| = 1; the refusal
// names the body.
TEST(AssembleProblem, RefusesStatesWithoutAUnitQuaternion) {
  const std::vector<RigidBody> bodies{{1.0, Vector3::Ones()}, {1.0, Vector3::Ones()}};
  std::vector<State> states(2, State{make_q(Vector3::Zero(), {}), Vector6::Zero()});
  states[1].q.tail<4>() << 2.0, 0.0, 0.0, 0.0;
  const std::vector<Vector6> u_free(2, Vector6::Zero());
  grbd::collision::Contact k;
  k.body_a = 0;
  k.body_b = 1;
  const std::vector<grbd::collision::Contact> contacts{k};
  const std::string m = refusal_of([&] { assemble_problem(contacts, bodies, states, u_free, {}); });
  EXPECT_NE(m.find("body 1"), std::string::npos) << m;
  EXPECT_NE(m.find("|p| = 2"), std::string::npos) << m;
}

// Regression (issue 11): validate() let an infinite Delassus diagonal through (W ≈ 1e200 gives
// G = WᵀM⁻¹W = ∞); the solvers then iterated on NaN. Reference: validate()'s declaration.
TEST(ProblemInput, ValidateRefusesAnInfiniteDelassusDiagonal) {
  ContactProblem p = two_body_problem();
  p.contacts[0].W_a(0, 0) = 1e200;
  const std::string m = refusal_of([&] { validate(p); });
  EXPECT_NE(m.find("Delassus"), std::string::npos) << m;
  EXPECT_NE(m.find("inf"), std::string::npos) << m;
}
