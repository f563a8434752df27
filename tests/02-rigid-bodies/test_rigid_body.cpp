// Chapter 2: the rigid body in its principal frame — the Jacobian of a material point and the
// Newton–Euler right-hand side (Exercises 2.3 and 2.4), and the core functions of rigid_body.hpp
// (the body of a mesh, mass matrix, kinetic energy, angular momentum, generalized force, u̇).
//
// Independent references: central differences of point_position() along the exact motion with
// constant u, q(t) = (r0 + t v, p0 exp(t ω/2)), written out with the closed-form exp and the
// complex-matrix product (grbd_test/references.hpp); rotation matrices of Eigen::Quaterniond (no
// code of chapter 1); the spatial formula v_P = v_S + I_ω × I_ρ; Euler's equations written
// component by component (grbd_test/bodies.hpp); the power balance of the gyroscopic term; the
// moment of a couple; the closed-form solution of the torque-free symmetric top; and the
// closed-form inertia of a box.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>

#include "grbd/body/mass_properties.hpp"
#include "grbd/body/rigid_body.hpp"
#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_test/bodies.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::Matrix3;
using grbd::Matrix36;
using grbd::Matrix6;
using grbd::Vector3;
using grbd::Vector6;
using grbd::Vector7;
using grbd::body::Loads;
using grbd::body::RigidBody;
using grbd::body::State;
using grbd::kinematics::make_q;
using grbd::kinematics::make_u;
using grbd::test::describe;
using grbd::test::exact_motion;
using grbd::test::gyroscopic_torque;
using grbd::test::max_abs;
using grbd::test::random_body;
using grbd::test::random_loads;
using grbd::test::random_state;
using grbd::test::reference_A_IK;
using grbd::test::WorstCase;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Central differences with step δ = 1e-5, as in chapter 1: truncation δ²/6 |r⃛_P| ≤ ~1e-9 for
// |ω| ≤ 2√3 and |ρ| ≤ √3, round-off ~1e-10; tolerance 1e-8.
constexpr double kDelta = 1e-5;
constexpr double kDifferenceTol = 1e-8;

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 2.3: the Jacobian of a material point
// ----------------------------------------------------------------------------------------------

// Reference: central differences of point_position() (chapter 1) along the exact motion with
// constant u: J_P(q) u = d/dt I_r_P. Tolerance 1e-8 (see kDifferenceTol).
TEST(Exercise2_3, MatchesCentralDifferencesOfPointPositionAlongAMotion) {
  using grbd::kinematics::point_position;
  grbd::test::Random rng(2301);
  WorstCase worst;
  for (int n = 0; n < 2000; ++n) {
    const State x = random_state(rng);
    const Vector3 rho = rng.vector3();
    const Vector3 difference = (point_position(exact_motion(x.q, x.u, kDelta), rho) -
                                point_position(exact_motion(x.q, x.u, -kDelta), rho)) /
                               (2.0 * kDelta);
    const Matrix36 J_P = grbd::body::point_jacobian(x.q, rho);
    worst.update(max_abs(J_P * x.u - difference), n,
                 [&] { return describe("x", x, "rho", rho); });
  }
  EXPECT_LE(worst.value(), kDifferenceTol) << worst;
}

// Reference: point_velocity() of chapter 1, I_v_P = I_v_S + A_IK (K_ω × K_ρ). Entries up to
// |v| + |ω||ρ| ≈ 10, a handful of roundings each: tolerance 1e-14.
TEST(Exercise2_3, TimesUIsThePointVelocity) {
  grbd::test::Random rng(2302);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const State x = random_state(rng);
    const Vector3 rho = rng.vector3();
    const Vector3 expected = grbd::kinematics::point_velocity(x.q, x.u, rho);
    worst.update(max_abs(grbd::body::point_jacobian(x.q, rho) * x.u - expected), n,
                 [&] { return describe("x", x, "rho", rho); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the columns written out from the spatial formula: ∂v_P/∂v_S = I₃ exactly, and
// ∂v_P/∂ω_j = A (e_j × ρ) with A from Eigen::Quaterniond. Entries ≤ |ρ| ≤ √3; the two rotation
// matrices differ by ~2 ulps, the products add ~3 roundings: tolerance 4e-15 (≈ 8 eps √3).
TEST(Exercise2_3, ColumnsAreTheVelocitiesOfUnitMotions) {
  grbd::test::Random rng(2303);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const State x = random_state(rng);
    const Vector3 rho = rng.vector3();
    const Matrix36 J_P = grbd::body::point_jacobian(x.q, rho);
    ASSERT_EQ(Matrix3(J_P.leftCols<3>()), Matrix3::Identity());
    const Matrix3 A = reference_A_IK(x.q);
    for (int j = 0; j < 3; ++j) {
      worst.update(max_abs(J_P.col(3 + j) - A * Vector3::Unit(j).cross(rho)), n,
                   [&] { return describe("column", 3 + j, "q", x.q, "rho", rho); });
    }
  }
  EXPECT_LE(worst.value(), 4e-15) << worst;
}

// Reference: generalized_force(), which writes J_Pᵀ F as (F, K_ρ × A_IKᵀ F) without the Jacobian.
// Entries ≤ |ρ||F| ≈ 3: tolerance 1e-14.
TEST(Exercise2_3, TransposeMapsAForceToTheGeneralizedForce) {
  grbd::test::Random rng(2304);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const State x = random_state(rng);
    const Vector3 rho = rng.vector3();
    const Vector3 F = rng.vector3();
    const Vector6 expected = grbd::body::generalized_force(x.q, rho, F);
    worst.update(max_abs(grbd::body::point_jacobian(x.q, rho).transpose() * F - expected), n,
                 [&] { return describe("q", x.q, "rho", rho, "F", F); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// ----------------------------------------------------------------------------------------------
// Exercise 2.4: the right-hand side of the Newton–Euler equations
// ----------------------------------------------------------------------------------------------

// Reference: Euler's equations computed by hand for Θ = (1, 2, 3), ω = (1, −2, ½),
// M = (0.1, 0.2, 0.3): Θ₁ω̇₁ = M₁ + (Θ₂ − Θ₃)ω₂ω₃ = 0.1 + 1 = 1.1, Θ₂ω̇₂ = M₂ + (Θ₃ − Θ₁)ω₃ω₁
// = 0.2 + 1 = 1.2, Θ₃ω̇₃ = M₃ + (Θ₁ − Θ₂)ω₁ω₂ = 0.3 + 2 = 2.3; Newton's law: h = I_F. The
// products are exact in binary, one rounding in each sum: tolerance 2 ulps of the result.
TEST(Exercise2_4, MatchesHandComputedEulerEquations) {
  const RigidBody body{5.0, Vector3(1.0, 2.0, 3.0)};
  const Vector6 u = make_u(Vector3(7.0, -8.0, 9.0), Vector3(1.0, -2.0, 0.5));
  const Loads loads{Vector3(0.0, 0.0, -5.0 * 9.81), Vector3(0.1, 0.2, 0.3)};
  const Vector6 h = grbd::body::newton_euler_h(body, u, loads);
  EXPECT_EQ(h[0], 0.0);
  EXPECT_EQ(h[1], 0.0);
  EXPECT_EQ(h[2], -5.0 * 9.81);
  EXPECT_NEAR(h[3], 1.1, 2.0 * kEps * 1.1);
  EXPECT_NEAR(h[4], 1.2, 2.0 * kEps * 1.2);
  EXPECT_NEAR(h[5], 2.3, 2.0 * kEps * 2.3);
}

// Reference: Euler's equations in components, Θ_i ω̇_i = M_i + (Θ_j − Θ_k) ω_j ω_k for (i, j, k)
// cyclic, written out in grbd_test/bodies.hpp. Terms ≤ 3·2·2 = 12, a few roundings: tolerance
// 1e-13.
TEST(Exercise2_4, EqualsEulersEquationsInComponents) {
  grbd::test::Random rng(2401);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const RigidBody body = random_body(rng);
    const State x = random_state(rng);
    const Loads loads = random_loads(rng);
    const Vector6 h = grbd::body::newton_euler_h(body, x.u, loads);
    ASSERT_EQ(Vector3(h.head<3>()), loads.I_F);
    const Vector3 expected = loads.K_M + gyroscopic_torque(body, x.u.tail<3>());
    worst.update(max_abs(h.tail<3>() - expected), n,
                 [&] { return describe("body", body, "u", x.u, "loads", loads); });
  }
  EXPECT_LE(worst.value(), 1e-13) << worst;
}

// Reference: the power balance. The gyroscopic term does no work, ω · (ω × Θω) = 0, so
// uᵀ h = v · F + ω · M: the kinetic energy changes only by the power of the loads. Terms ≤ ~30,
// a few roundings each: tolerance 1e-13.
TEST(Exercise2_4, GyroscopicTermDoesNoWork) {
  grbd::test::Random rng(2402);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const RigidBody body = random_body(rng);
    const State x = random_state(rng);
    const Loads loads = random_loads(rng);
    const Vector6 h = grbd::body::newton_euler_h(body, x.u, loads);
    const double power = x.u.head<3>().dot(loads.I_F) + x.u.tail<3>().dot(loads.K_M);
    worst.update(std::abs(x.u.dot(h) - power), n,
                 [&] { return describe("body", body, "u", x.u, "loads", loads); });
  }
  EXPECT_LE(worst.value(), 1e-13) << worst;
}

// Reference: a body spinning about a principal axis with no load is in steady rotation
// (ω × Θω = 0 for ω ∥ e_i): h = 0 exactly.
TEST(Exercise2_4, SteadySpinAboutAPrincipalAxisNeedsNoTorque) {
  const RigidBody body{2.0, Vector3(0.5, 1.5, 2.5)};
  for (int i = 0; i < 3; ++i) {
    const Vector6 u = make_u(Vector3(1.0, 2.0, 3.0), 7.0 * Vector3::Unit(i));
    EXPECT_EQ(grbd::body::newton_euler_h(body, u, Loads{}), Vector6::Zero()) << "axis " << i;
  }
}

// ----------------------------------------------------------------------------------------------
// Core: mass matrix, kinetic energy, angular momentum, generalized force, u̇, the body of a mesh
// ----------------------------------------------------------------------------------------------

// Reference: the definition M = diag(m, m, m, Θ₁, Θ₂, Θ₃); exact.
TEST(MassMatrix, IsDiagonalInThePrincipalFrame) {
  const RigidBody body{2.5, Vector3(0.25, 0.5, 0.75)};
  Matrix6 expected = Matrix6::Zero();
  expected.diagonal() << 2.5, 2.5, 2.5, 0.25, 0.5, 0.75;
  EXPECT_EQ(grbd::body::mass_matrix(body), expected);
}

// Reference: T = ½ uᵀ M u with the mass matrix, and ½ m|v|² + ½ Σ Θ_i ω_i² written out. Values
// ≤ ~40: tolerance 1e-13.
TEST(KineticEnergy, IsHalfTheMassMatrixNorm) {
  grbd::test::Random rng(2501);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const RigidBody body = random_body(rng);
    const State x = random_state(rng);
    const double T = grbd::body::kinetic_energy(body, x.u);
    const double by_matrix = 0.5 * x.u.dot(grbd::body::mass_matrix(body) * x.u);
    double by_hand = 0.5 * body.m * x.u.head<3>().squaredNorm();
    for (int i = 0; i < 3; ++i) by_hand += 0.5 * body.K_Theta[i] * x.u[3 + i] * x.u[3 + i];
    worst.update(std::abs(T - by_matrix), n,
                 [&] { return "½ uᵀMu, " + describe("body", body, "u", x.u); });
    worst.update(std::abs(T - by_hand), n,
                 [&] { return "by hand, " + describe("body", body, "u", x.u); });
  }
  EXPECT_LE(worst.value(), 1e-13) << worst;
}

// Reference: I_L = A_IK Θ K_ω with A_IK from Eigen::Quaterniond. Entries ≤ ~10: tolerance 1e-14.
TEST(AngularMomentum, IsTheBodyMomentumInTheInertialFrame) {
  grbd::test::Random rng(2502);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const RigidBody body = random_body(rng);
    const State x = random_state(rng);
    const Vector3 expected = reference_A_IK(x.q) * body.K_Theta.cwiseProduct(x.u.tail<3>());
    worst.update(max_abs(grbd::body::I_angular_momentum(body, x) - expected), n,
                 [&] { return describe("body", body, "x", x); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the closed-form torque-free symmetric top (REFERENCES.md), I₁ = I₂ = I⊥:
// A(t) = exp(t I_L/I⊥) A₀ exp(t ν e₃), ω(t) = exp(−t ν e₃) A₀ᵀ I_L/I⊥ + ν e₃, ν = ω₃(1 − I₃/I⊥),
// (SymmetricTop of grbd_test/bodies.hpp). I_angular_momentum() of that motion stays I_L(0):
// relative tolerance 1e-14 over t ∈ [0, 20].
TEST(AngularMomentum, IsConstantAlongTheTorqueFreeSymmetricTop) {
  const grbd::test::SymmetricTop top(RigidBody{1.0, Vector3(0.8, 0.8, 0.3)},
                                     Vector3(0.7, -0.4, 3.0),
                                     grbd::test::axis_angle_matrix(Vector3(0.3, -1.1, 0.4)));
  WorstCase worst;
  for (double t = 0.0; t <= 20.0; t += 0.25) {
    const State x{make_q(Vector3::Zero(), grbd::test::reference_quaternion(top.A(t))),
                  make_u(Vector3::Zero(), top.omega(t))};
    worst.update((grbd::body::I_angular_momentum(top.body, x) - top.I_L).norm() / top.I_L.norm(),
                 [&] { return describe("t", t, "x(t)", x); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the virtual work of a force at a material point, uᵀ (J_Pᵀ F) = F · v_P, with v_P
// from the spatial formula v_S + I_ω × I_ρ (Eigen rotation matrix). Powers ≤ ~10: tolerance 1e-13.
TEST(GeneralizedForce, DoesTheVirtualWorkOfTheForce) {
  grbd::test::Random rng(2503);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const State x = random_state(rng);
    const Vector3 rho = rng.vector3();
    const Vector3 F = rng.vector3();
    const Matrix3 A = reference_A_IK(x.q);
    const Vector3 v_P = x.u.head<3>() + (A * x.u.tail<3>()).cross(A * rho);
    const Vector6 f = grbd::body::generalized_force(x.q, rho, F);
    worst.update(std::abs(x.u.dot(f) - F.dot(v_P)), n,
                 [&] { return describe("x", x, "rho", rho, "F", F); });
  }
  EXPECT_LE(worst.value(), 1e-13) << worst;
}

// Reference: statics. A force through S adds no moment, (F, 0) exactly; a couple (F at +ρ, −F at
// −ρ) adds no force and the moment 2 I_ρ × F about S, which in frame K is A_IKᵀ (2 I_ρ × F).
// Entries ≤ ~10: tolerance 1e-14.
TEST(GeneralizedForce, ForceThroughTheCentreAndCouple) {
  grbd::test::Random rng(2504);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const State x = random_state(rng);
    const Vector3 rho = rng.vector3();
    const Vector3 F = rng.vector3();
    Vector6 central;
    central << F, Vector3::Zero();
    ASSERT_EQ(grbd::body::generalized_force(x.q, Vector3::Zero(), F), central);
    const Vector6 couple =
        grbd::body::generalized_force(x.q, rho, F) + grbd::body::generalized_force(x.q, -rho, -F);
    const Matrix3 A = reference_A_IK(x.q);
    worst.update(max_abs(couple.head<3>()), n,
                 [&] { return "force of the couple, " + describe("q", x.q, "rho", rho, "F", F); });
    worst.update(max_abs(couple.tail<3>() - A.transpose() * (2.0 * (A * rho).cross(F))), n,
                 [&] { return "moment of the couple, " + describe("q", x.q, "rho", rho, "F", F); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: Euler's equations solved for ω̇ by hand, ω̇_i = (M_i + (Θ_j − Θ_k) ω_j ω_k)/Θ_i,
// v̇ = F/m; and M u̇ = h with the mass matrix. Values ≤ ~130 (Θ ≥ 0.1), a few roundings each:
// tolerance 2e-13 (≈ 8 eps · 130).
TEST(NewtonEulerUDot, SolvesTheNewtonEulerEquations) {
  grbd::test::Random rng(2505);
  WorstCase worst;
  for (int n = 0; n < 10000; ++n) {
    const RigidBody body = random_body(rng);
    const State x = random_state(rng);
    const Loads loads = random_loads(rng);
    const Vector6 u_dot = grbd::body::newton_euler_u_dot(body, x.u, loads);
    Vector6 expected;
    expected << loads.I_F / body.m,
        (loads.K_M + gyroscopic_torque(body, x.u.tail<3>())).cwiseQuotient(body.K_Theta);
    const auto inputs = [&] { return describe("body", body, "u", x.u, "loads", loads); };
    worst.update(max_abs(u_dot - expected), n, [&] { return "u̇ by hand, " + inputs(); });
    worst.update(max_abs(grbd::body::mass_matrix(body) * u_dot -
                         grbd::body::newton_euler_h(body, x.u, loads)),
                 n, [&] { return "M u̇ = h, " + inputs(); });
  }
  EXPECT_LE(worst.value(), 2e-13) << worst;
}

// Reference: the preconditions of rigid_body.hpp — m > 0 and K_Theta > 0, finite — are checked
// before anything is computed.
TEST(RigidBodyValidation, NonPositiveOrNonFiniteMassOrMomentsThrow) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Vector6 u = make_u(Vector3(1, 2, 3), Vector3(4, 5, 6));
  for (double bad : {0.0, -1.0, nan, inf}) {
    const RigidBody bad_mass{bad, Vector3::Ones()};
    EXPECT_THROW((void)grbd::body::mass_matrix(bad_mass), grbd::InvalidArgument) << bad;
    EXPECT_THROW((void)grbd::body::newton_euler_u_dot(bad_mass, u, Loads{}), grbd::InvalidArgument)
        << bad;
    for (int i = 0; i < 3; ++i) {
      RigidBody bad_moment{1.0, Vector3::Ones()};
      bad_moment.K_Theta[i] = bad;
      EXPECT_THROW((void)grbd::body::mass_matrix(bad_moment), grbd::InvalidArgument) << bad;
      EXPECT_THROW((void)grbd::body::newton_euler_u_dot(bad_moment, u, Loads{}),
                   grbd::InvalidArgument)
          << bad;
    }
  }
}

// Reference: the closed form of a box [−a, a] × [−b, b] × [−c, c] of density ρ: m = 8abcρ,
// Θ = m/3 (b² + c², a² + c², a² + b²) about its axes. The box is turned by a known rotation Q and
// moved by r; the body must come back with S = r, ascending moments (for a < b < c: the box's z,
// y, x axes), principal axes Q e_z, Q e_y, Q e_x up to sign, right-handed. Mass, moments and
// centre are exact for the polyhedron up to round-off: relative tolerance 1e-13.
TEST(RigidBodyFromMesh, TurnedAndMovedBoxGivesItsPrincipalFrame) {
  const double a = 0.5;
  const double b = 1.0;
  const double c = 1.5;
  const double density = 700.0;
  const Matrix3 Q = grbd::test::axis_angle_matrix(Vector3(0.4, -0.2, 0.9));
  const Vector3 r(1.0, -2.0, 3.0);
  const grbd::body::TriangleMesh mesh =
      grbd::body::transformed(grbd::body::box_mesh(Vector3(a, b, c)), Q, r);
  const grbd::body::BodyFromMesh result = grbd::body::rigid_body_from_mesh(mesh, density, "box");
  const double m = 8.0 * a * b * c * density;
  const Vector3 Theta = grbd::test::box_inertia(Vector3(a, b, c), m).diagonal().reverse();
  EXPECT_NEAR(result.body.m, m, 1e-13 * m);
  EXPECT_LE(max_abs(result.body.K_Theta - Theta) / Theta.maxCoeff(), 1e-13);
  EXPECT_LE(max_abs(result.M_r_S - r), 1e-13 * r.norm());
  EXPECT_NEAR(result.A_MK.determinant(), 1.0, 1e-13);
  const Matrix3 box_axes_ascending = (Matrix3() << Q.col(2), Q.col(1), Q.col(0)).finished();
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(std::abs(result.A_MK.col(i).dot(box_axes_ascending.col(i))), 1.0, 1e-12)
        << "principal axis " << i;
  }
}

// Reference: the contract of BodyFromMesh, K_x = A_MKᵀ (M_x − M_r_S): mapped to frame K, the
// vertices of any closed mesh have their centroid-of-volume at 0 and a diagonal inertia tensor,
// so mass_properties() of the mapped mesh is (m, 0, diag(K_Theta)). A tetrahedron with no
// symmetry; relative tolerance 1e-12.
TEST(RigidBodyFromMesh, BodyFrameIsPrincipalWithOriginAtTheCentreOfMass) {
  const grbd::body::TriangleMesh mesh =
      grbd::body::tetrahedron_mesh(Vector3(0.1, 0.2, 0.0), Vector3(1.3, 0.1, 0.2),
                                   Vector3(0.2, 0.9, 0.1), Vector3(0.4, 0.3, 1.7));
  const double density = 2.0;
  const grbd::body::BodyFromMesh result = grbd::body::rigid_body_from_mesh(mesh, density);
  const grbd::body::TriangleMesh in_K = grbd::body::transformed(
      mesh, result.A_MK.transpose(), -result.A_MK.transpose() * result.M_r_S);
  const grbd::body::MassProperties K = grbd::body::mass_properties(in_K, density);
  const double scale = result.body.K_Theta.maxCoeff();
  EXPECT_NEAR(K.mass, result.body.m, 1e-12 * result.body.m);
  EXPECT_LE(K.M_r_S.norm(), 1e-12);
  EXPECT_LE(max_abs(K.M_Theta_S - Matrix3(result.body.K_Theta.asDiagonal())) / scale, 1e-12);
  EXPECT_LE(result.body.K_Theta[0], result.body.K_Theta[1]);
  EXPECT_LE(result.body.K_Theta[1], result.body.K_Theta[2]);
}
