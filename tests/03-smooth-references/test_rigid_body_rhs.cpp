// Chapter 3: the rigid body as an ODE for SUNDIALS — the right-hand side of a body under constant
// loads (Exercise 3.1), the projection onto |p| = 1 (Exercise 3.2), and the core functions of
// rigid_body_rhs.hpp (pack/unpack, the RhsFunction wrappers, the prescribed torque, the heavy top).
//
// Independent references: the kinematics and Euler's equations written out (the complex-matrix
// quaternion product of grbd_test/references.hpp, the gyroscopic torque of grbd_test/bodies.hpp);
// the conservation laws of the torque-free body (E, I_L, uniform motion of S) and of the heavy top
// (E, the vertical and the axial angular momentum); the parabola of a constant force; the closed
// form ω(t) = ω0 + a sin t of an isotropic body under the torque Θ a cos t; the geometry of the
// radial projection onto S³.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>

#include "grbd/body/rigid_body.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
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
using grbd::Vector4;
using grbd::Vector6;
using grbd::Vector7;
using grbd::body::Loads;
using grbd::body::RigidBody;
using grbd::body::State;
using grbd::kinematics::make_q;
using grbd::kinematics::make_u;
using grbd::kinematics::Quaternion;
using grbd::ode::Cvode;
using grbd::ode::CvodeMethod;
using grbd::test::describe;
using grbd::test::max_abs;
using grbd::test::reference_A_IK;
using grbd::test::WorstCase;

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// The tumbling asymmetric body of these tests: Θ = (1, 2, 3), m = 2, ω0 = (0.4, 1.2, 0.9)
/// (|ω| ≈ 1.55, the period of ω is 6.29 s), moving with v0 = (0.1, 0.2, 0.3).
const RigidBody kBody{2.0, Vector3(1.0, 2.0, 3.0)};
State tumbling_state() {
  return {make_q(Vector3(1.0, 2.0, 3.0),
                 Quaternion(std::cos(0.25),
                            Vector3(std::sin(0.25) / std::sqrt(2.0) * Vector3(1.0, 1.0, 0.0)))),
          make_u(Vector3(0.1, 0.2, 0.3), Vector3(0.4, 1.2, 0.9))};
}

/// A_IK of the unit quaternion p/|p| at `offset` in y, by Eigen (no code of chapter 1).
Matrix3 A_IK_at(const Eigen::VectorXd& y, Eigen::Index offset) {
  return Eigen::Quaterniond(y[offset], y[offset + 1], y[offset + 2], y[offset + 3])
      .normalized()
      .toRotationMatrix();
}

/// A heavy top and initial states for it (see test_references.cpp for its nutation band).
const grbd::ode::HeavyTop kTop{1.0, 0.1, 0.004, 0.002, 9.81};
Eigen::VectorXd tilted_top(double theta0, const Vector3& K_omega) {
  Eigen::VectorXd y0(7);
  y0 << std::cos(0.5 * theta0), std::sin(0.5 * theta0), 0.0, 0.0, K_omega;
  return y0;
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 3.1: the right-hand side of a rigid body under constant loads
// ----------------------------------------------------------------------------------------------

// Reference: ẏ = (v, ½ p (0, ω), F/m, Θ⁻¹(M + gyroscopic torque)), each part written out: the
// quaternion product through 2 × 2 complex matrices, Euler's equations component by component.
// Random bodies, states (also with |p| ≠ 1: F(q)u is linear in p) and loads; entries O(10):
// tolerance 1e-14 (1 + |ẏ|).
TEST(Exercise3_1, IsTheKinematicsAndNewtonEulerEquationsWrittenOut) {
  grbd::test::Random rng(3101);
  WorstCase worst;
  for (int n = 0; n < 5000; ++n) {
    const RigidBody body = grbd::test::random_body(rng);
    State x = grbd::test::random_state(rng);
    if (n % 2 == 1) x.q.tail<4>() *= rng.uniform(0.5, 2.0);
    const Loads loads = grbd::test::random_loads(rng);
    Eigen::VectorXd y_dot(13);
    grbd::ode::free_body_rhs(body, loads, grbd::ode::pack(x), y_dot);

    const Vector3 v = x.u.head<3>();
    const Vector3 w = x.u.tail<3>();
    const Quaternion p(Vector4(x.q.tail<4>()));
    Eigen::VectorXd expected(13);
    expected << v, 0.5 * grbd::test::reference_product(p, Quaternion::pure(w)).coeffs(),
        loads.I_F / body.m,
        (loads.K_M + grbd::test::gyroscopic_torque(body, w)).cwiseQuotient(body.K_Theta);
    worst.update(max_abs(y_dot - expected) / (1.0 + max_abs(expected)), n,
                 [&] { return describe("body", body, "x", x, "loads", loads); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the torque-free body keeps E = ½ uᵀMu and I_L = A_IK Θω exactly, and S moves
// uniformly, r = r0 + v0 t. CVODE (BDF, rtol 1e-12, atol 1e-14, no projection) on free_body()
// over 10 periods of ω (63 s): relative drift of E and I_L ≤ 1e-8 (observed 1.1e-9 and 5e-10),
// |r − r0 − v0 t| ≤ 1e-10 (observed 1.3e-12) and |v − v0| ≤ 1e-12 (observed 0).
TEST(Exercise3_1, CvodeConservesEnergyAndAngularMomentumOverManyPeriods) {
  const State x0 = tumbling_state();
  const double E0 = grbd::body::kinetic_energy(kBody, x0.u);
  const Vector3 L0 = reference_A_IK(x0.q) * kBody.K_Theta.cwiseProduct(x0.u.tail<3>());
  Cvode cvode(grbd::ode::free_body(kBody), 0.0, grbd::ode::pack(x0), CvodeMethod::bdf,
              {1e-12, 1e-14, {}});
  WorstCase worst_E;
  WorstCase worst_L;
  WorstCase worst_r;
  WorstCase worst_v;
  for (int k = 1; k <= 400; ++k) {
    const double t = 0.1575 * k;
    const Eigen::VectorXd y = cvode.advance(t);
    const State x = grbd::ode::unpack(y);
    const Vector3 L = A_IK_at(y, 3) * kBody.K_Theta.cwiseProduct(x.u.tail<3>());
    const auto inputs = [&] { return describe("t", t, "x(t)", x); };
    worst_E.update(std::abs(grbd::body::kinetic_energy(kBody, x.u) - E0) / E0, inputs);
    worst_L.update((L - L0).norm() / L0.norm(), inputs);
    worst_r.update((x.q.head<3>() - x0.q.head<3>() - t * x0.u.head<3>()).norm(), inputs);
    worst_v.update((x.u.head<3>() - x0.u.head<3>()).norm(), inputs);
  }
  EXPECT_LE(worst_E.value(), 1e-8) << worst_E;
  EXPECT_LE(worst_L.value(), 1e-8) << worst_L;
  EXPECT_LE(worst_r.value(), 1e-10) << worst_r;
  EXPECT_LE(worst_v.value(), 1e-12) << worst_v;
}

// Reference: under a constant force and torque-free rotation, S follows the parabola
// r0 + v0 t + ½ (F/m) t² whatever the body does. CVODE (BDF, rtol 1e-10, atol 1e-12) with a
// tumbling body under gravity for 3 s: tolerance 1e-8 on r and v (observed 1.4e-10).
TEST(Exercise3_1, ConstantForceMovesTheCentreOfMassOnTheParabola) {
  const State x0 = tumbling_state();
  const Vector3 g(0.0, 0.0, -9.81);
  Cvode cvode(grbd::ode::free_body(kBody, Loads{kBody.m * g, Vector3::Zero()}), 0.0,
              grbd::ode::pack(x0), CvodeMethod::bdf, {1e-10, 1e-12, {}});
  WorstCase worst;
  for (int k = 1; k <= 30; ++k) {
    const double t = 0.1 * k;
    const State x = grbd::ode::unpack(cvode.advance(t));
    const Vector3 r = x0.q.head<3>() + t * x0.u.head<3>() + 0.5 * t * t * g;
    const Vector3 v = x0.u.head<3>() + t * g;
    worst.update((x.q.head<3>() - r).norm(),
                 [&] { return "r, " + describe("t", t, "x(t)", x, "r exact", r); });
    worst.update((x.u.head<3>() - v).norm(),
                 [&] { return "v, " + describe("t", t, "x(t)", x, "v exact", v); });
  }
  EXPECT_LE(worst.value(), 1e-8) << worst;
}

// ----------------------------------------------------------------------------------------------
// Exercise 3.2: the projection onto |p| = 1
// ----------------------------------------------------------------------------------------------

// Reference: the nearest point of S³ to p is p/|p|: the correction is (1/|p| − 1) p in the four
// entries of p (parallel to p, so its tangential part is zero), y + correction has |p| = 1 to
// round-off, and every other entry is exactly zero. Random y of sizes 4 to 20 and every offset,
// |p| between 0.1 and 10; tolerances 4 eps on |p| − 1, and 16 eps |p| between the correction and
// (1/|p| − 1) p (the two forms round differently by a few ulps of max(1, |p|)).
TEST(Exercise3_2, CorrectionIsTheRadialProjectionOntoTheUnitSphere) {
  grbd::test::Random rng(3201);
  WorstCase worst_norm;
  WorstCase worst_correction;
  bool others_zero = true;
  for (int n = 0; n < 3000; ++n) {
    const Eigen::Index size = 4 + n % 17;
    const Eigen::Index offset = n % (size - 3);
    Eigen::VectorXd y = Eigen::VectorXd::NullaryExpr(size, [&] { return rng.uniform(-5, 5); });
    const Vector4 p = rng.unit_quaternion().coeffs() * std::pow(10.0, rng.uniform(-1.0, 1.0));
    y.segment<4>(offset) = p;
    Eigen::VectorXd correction = Eigen::VectorXd::Constant(size, 123.0);  // must be overwritten
    grbd::ode::quaternion_projection(offset, y, correction);
    const double norm = p.norm();
    const auto inputs = [&] { return describe("offset", offset, "y", y); };
    worst_norm.update(std::abs((y + correction).segment<4>(offset).norm() - 1.0), n, inputs);
    worst_correction.update(
        max_abs(Vector4(correction.segment<4>(offset)) - (1.0 / norm - 1.0) * p) / norm, n, inputs);
    for (Eigen::Index i = 0; i < size; ++i) {
      if ((i < offset || i >= offset + 4) && correction[i] != 0.0) others_zero = false;
    }
  }
  EXPECT_LE(worst_norm.value(), 4.0 * kEps) << worst_norm;
  EXPECT_LE(worst_correction.value(), 16.0 * kEps) << worst_correction;
  EXPECT_TRUE(others_zero) << "entries outside the quaternion must be exactly zero";
}

// Reference: the exact heavy top keeps |p| = 1; BDF does not. CVODE (BDF, rtol 1e-6, atol 1e-8)
// on heavy_top() over 2 s: without projection ||p| − 1| grows beyond 1e-7 (observed 2.9e-5); with
// quaternion_projection_at(0) it stays ≤ 4 eps at every output, and CVODE projects at least once
// per step.
TEST(Exercise3_2, KeepsTheUnitQuaternionWhereCvodeAloneDrifts) {
  const Eigen::VectorXd y0 = tilted_top(0.5, Vector3(2.0, -3.0, 150.0));
  Cvode free(grbd::ode::heavy_top(kTop), 0.0, y0, CvodeMethod::bdf, {1e-6, 1e-8, {}});
  Cvode projected(grbd::ode::heavy_top(kTop), 0.0, y0, CvodeMethod::bdf, {1e-6, 1e-8, {}});
  projected.set_projection(grbd::ode::quaternion_projection_at(0));
  double drift_free = 0.0;
  WorstCase drift_projected;
  for (int k = 1; k <= 200; ++k) {
    const double t = 0.01 * k;
    drift_free = std::max(drift_free, std::abs(free.advance(t).head<4>().norm() - 1.0));
    const Eigen::VectorXd y = projected.advance(t);
    drift_projected.update(std::abs(y.head<4>().norm() - 1.0),
                           [&] { return describe("t", t, "y(t)", y); });
  }
  EXPECT_GE(drift_free, 1e-7);
  EXPECT_LE(drift_projected.value(), 4.0 * kEps) << drift_projected;
  const grbd::ode::Statistics s = projected.statistics();
  EXPECT_GE(s.projections, s.steps);
}

// ----------------------------------------------------------------------------------------------
// Core: packing, the RhsFunction wrappers, the prescribed torque, the heavy top
// ----------------------------------------------------------------------------------------------

// Reference: y = (q, u) entry by entry; unpack() inverts pack() exactly and checks the size.
TEST(RigidBodyRhs, PackAndUnpackAreInverse) {
  grbd::test::Random rng(3301);
  const State x = grbd::test::random_state(rng);
  const Eigen::VectorXd y = grbd::ode::pack(x);
  ASSERT_EQ(y.size(), 13);
  EXPECT_EQ(Vector7(y.head<7>()), x.q);
  EXPECT_EQ(Vector6(y.tail<6>()), x.u);
  const State back = grbd::ode::unpack(y);
  EXPECT_EQ(back.q, x.q);
  EXPECT_EQ(back.u, x.u);
  EXPECT_THROW(grbd::ode::unpack(Eigen::VectorXd::Zero(12)), InvalidArgument);
  EXPECT_THROW(grbd::ode::unpack(Eigen::VectorXd::Zero(14)), InvalidArgument);
}

// Reference: the preconditions of rigid_body_rhs.hpp: a valid body (m, Θ > 0), y and y_dot of the
// problem's size, a non-empty torque, a heavy top with m, I1, I3 > 0 and l, g ≥ 0, a quaternion
// inside y and not zero. All checked before any exercise code runs.
TEST(RigidBodyRhs, WrappersRejectInvalidInput) {
  EXPECT_THROW(grbd::ode::free_body(RigidBody{0.0, Vector3::Ones()}), InvalidArgument);
  EXPECT_THROW(grbd::ode::free_body(RigidBody{1.0, Vector3(1.0, -1.0, 1.0)}), InvalidArgument);
  EXPECT_THROW(grbd::ode::prescribed_torque_body(kBody, nullptr), InvalidArgument);
  const auto f = grbd::ode::free_body(kBody);
  Eigen::VectorXd y_dot(13);
  EXPECT_THROW(f(0.0, Eigen::VectorXd::Zero(12), y_dot), InvalidArgument);
  Eigen::VectorXd short_y_dot(7);
  EXPECT_THROW(f(0.0, Eigen::VectorXd::Zero(13), short_y_dot), InvalidArgument);
  for (const grbd::ode::HeavyTop& top : {grbd::ode::HeavyTop{0.0, 0.1, 1.0, 1.0, 9.81},
                                         grbd::ode::HeavyTop{1.0, -0.1, 1.0, 1.0, 9.81},
                                         grbd::ode::HeavyTop{1.0, 0.1, 0.0, 1.0, 9.81},
                                         grbd::ode::HeavyTop{1.0, 0.1, 1.0, -1.0, 9.81},
                                         grbd::ode::HeavyTop{1.0, 0.1, 1.0, 1.0, std::nan("")}}) {
    EXPECT_THROW(grbd::ode::heavy_top(top), InvalidArgument);
  }
  EXPECT_THROW(grbd::ode::heavy_top(kTop)(0.0, Eigen::VectorXd::Zero(13), y_dot), InvalidArgument);
  EXPECT_THROW(grbd::ode::quaternion_projection_at(-1), InvalidArgument);
  const auto project = grbd::ode::quaternion_projection_at(10);
  Eigen::VectorXd correction(13);
  EXPECT_THROW(project(0.0, Eigen::VectorXd::Ones(13), correction), InvalidArgument);
  EXPECT_THROW(grbd::ode::quaternion_projection_at(3)(0.0, Eigen::VectorXd::Zero(13), correction),
               InvalidArgument);
}

// Reference: for an isotropic body (Θ = θI, so ω × Θω = 0) under K_M(t) = θ a cos t, Euler's
// equations give ω(t) = ω0 + a sin t exactly. CVODE (BDF, rtol 1e-10, atol 1e-12) over 5 s: the
// torque is read at the time of each evaluation; tolerance 1e-8 (observed 4.5e-10).
TEST(RigidBodyRhs, PrescribedTorqueIsAppliedAtTheTimeOfEachEvaluation) {
  const RigidBody sphere{3.0, Vector3::Constant(0.4)};
  const Vector3 a(0.5, -1.0, 2.0);
  const Vector3 omega0(0.3, 0.2, -0.1);
  const State x0{make_q(Vector3::Zero(), Quaternion()), make_u(Vector3(1.0, 0.0, 0.0), omega0)};
  Cvode cvode(grbd::ode::prescribed_torque_body(
                  sphere, [&](double t) -> Vector3 { return 0.4 * a * std::cos(t); }),
              0.0, grbd::ode::pack(x0), CvodeMethod::bdf, {1e-10, 1e-12, {}});
  WorstCase worst;
  for (int k = 1; k <= 50; ++k) {
    const double t = 0.1 * k;
    const Eigen::VectorXd y = cvode.advance(t);
    worst.update((Vector3(y.tail<3>()) - (omega0 + a * std::sin(t))).norm(),
                 [&] { return describe("t", t, "y(t)", y); });
  }
  EXPECT_LE(worst.value(), 1e-8) << worst;
}

// Reference: the heavy top about its fixed point O keeps the energy
// E = ½ ωᵀΘ_Oω + m g l cos θ, the vertical angular momentum (A_IK Θ_O ω)_z and the axial one
// I3 ω3 (gravity has no moment about the vertical nor about the symmetry axis). CVODE (BDF,
// rtol 1e-12, atol 1e-14, projection) over 1 s (3 nutations) of a tilted, fast top: relative
// drift ≤ 1e-8 for each (observed 1e-10, 9e-10 and 0: Θ1 = Θ2 makes ω̇3 = 0 exactly).
TEST(HeavyTop, CvodeConservesEnergyAndTheVerticalAndAxialAngularMomenta) {
  const double I1_O = kTop.I1 + kTop.m * kTop.l * kTop.l;
  const Vector3 Theta_O(I1_O, I1_O, kTop.I3);
  const auto invariants = [&](const Eigen::VectorXd& y) {
    const Matrix3 A = A_IK_at(y, 0);
    const Vector3 w = y.tail<3>();
    return Vector3(0.5 * w.dot(Theta_O.cwiseProduct(w)) + kTop.m * kTop.g * kTop.l * A(2, 2),
                   (A * Theta_O.cwiseProduct(w)).z(), kTop.I3 * w.z());
  };
  const Eigen::VectorXd y0 = tilted_top(0.5, Vector3(2.0, -3.0, 150.0));
  const Vector3 start = invariants(y0);
  Cvode cvode(grbd::ode::heavy_top(kTop), 0.0, y0, CvodeMethod::bdf, {1e-12, 1e-14, {}});
  cvode.set_projection(grbd::ode::quaternion_projection_at(0));
  WorstCase worst[3];
  for (int k = 1; k <= 100; ++k) {
    const double t = 0.01 * k;
    const Eigen::VectorXd y = cvode.advance(t);
    const Vector3 drift = (invariants(y) - start).cwiseAbs().cwiseQuotient(start.cwiseAbs());
    for (int i = 0; i < 3; ++i) {
      worst[i].update(drift[i], [&] { return describe("t", t, "y(t)", y); });
    }
  }
  EXPECT_LE(worst[0].value(), 1e-8) << "energy; " << worst[0];
  EXPECT_LE(worst[1].value(), 1e-8) << "vertical angular momentum; " << worst[1];
  EXPECT_LE(worst[2].value(), 1e-8) << "axial angular momentum; " << worst[2];
}
