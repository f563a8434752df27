// Chapter 3: the observed order of convergence (Exercise 3.3) and the convergence study of every
// integrator of chapter 2 against a CVODE reference.
//
// Independent references: synthetic data e = C h^p (exact power laws, and power laws with a
// perturbation orthogonal to the regressor, whose least-squares slope is still exactly p); for
// the study, CVODE (BDF, rtol 1e-12, atol 1e-14, with projection onto |p| = 1) on the free body,
// itself checked against CVODE's Adams method, and the orders of REFERENCES.md (1 for the
// exponential-map, normalised-Euler and implicit gyroscopic steps, 2 for Lie–Poisson splitting).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "grbd/body/integrators.hpp"
#include "grbd/body/rigid_body.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/ode/convergence.hpp"
#include "grbd/ode/rigid_body_rhs.hpp"
#include "grbd/ode/sundials.hpp"
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
using grbd::ode::observed_order;
using grbd::test::describe;
using grbd::test::WorstCase;

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// e_i = C h_i^p exp(δ_i).
std::vector<double> power_law(const std::vector<double>& h, double C, double p,
                              const std::vector<double>& delta = {}) {
  std::vector<double> e;
  for (std::size_t i = 0; i < h.size(); ++i) {
    e.push_back(C * std::pow(h[i], p) * (delta.empty() ? 1.0 : std::exp(delta[i])));
  }
  return e;
}

/// The state at time T of `N` steps of a chapter-2 scheme.
State integrate(const RigidBody& body, State x, double T, int N, grbd::body::Integrator scheme) {
  const double h = T / N;
  for (int n = 0; n < N; ++n) x = grbd::body::step(body, x, grbd::body::Loads{}, h, scheme);
  return x;
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 3.3: the observed order of convergence
// ----------------------------------------------------------------------------------------------

// Reference: exact power laws e = C h^p: the slope of log e over log h is p for any C, for
// geometric and irregular h, from two pairs up to eight, h from 1e-6 to 1 (log h far from 0).
// Tolerance 1e-12 (a few roundings of logarithms of size ≤ 30).
TEST(Exercise3_3, IsExactOnPowerLaws) {
  const std::vector<std::vector<double>> step_sizes{
      {0.1, 0.05},
      {0.1, 0.05, 0.025, 0.0125},
      {1.0, 0.3, 0.21, 0.05, 0.011, 2e-3, 7e-4, 1e-6},
      {4e-6, 2e-6, 1e-6},
  };
  WorstCase worst;
  for (const auto& h : step_sizes) {
    for (double p : {0.5, 1.0, 2.0, 3.7, -1.0}) {
      for (double C : {1e-3, 1.0, 250.0}) {
        worst.update(std::abs(observed_order(h, power_law(h, C, p)) - p),
                     [&] { return describe("h", h, "C", C, "p", p); });
      }
    }
  }
  EXPECT_LE(worst.value(), 1e-12) << worst;
}

// Reference: for two pairs the least-squares line passes through both points: the slope is
// log(e1/e2)/log(h1/h2), written out. Tolerance 4 eps relative.
TEST(Exercise3_3, TwoPairsGiveTheLogarithmicRatio) {
  const std::vector<double> h{0.02, 0.005};
  const std::vector<double> e{3.1e-4, 1.7e-5};
  const double expected = std::log(e[0] / e[1]) / std::log(h[0] / h[1]);
  EXPECT_NEAR(observed_order(h, e), expected, 4.0 * kEps * expected);
}

// Reference: the least-squares slope is unchanged by perturbations δ of log e that are
// orthogonal to 1 and to the centred regressor x − x̄ (x = log h): on equally spaced x,
// δ = 0.1 (1, −2, 0, 2, −1) has Σδ = 0 and Σδ(x − x̄) = 0, so the slope is exactly p although no
// three points lie on one line; the slope of the end points alone is not p. Tolerance 1e-12.
TEST(Exercise3_3, IsTheLeastSquaresSlopeOfNoisyData) {
  const std::vector<double> h{0.1, 0.05, 0.025, 0.0125, 0.00625};  // x equally spaced
  const std::vector<double> delta{0.1, -0.2, 0.0, 0.2, -0.1};
  double sum = 0.0;
  double moment = 0.0;
  for (std::size_t i = 0; i < delta.size(); ++i) {
    sum += delta[i];
    moment += delta[i] * (static_cast<double>(i) - 2.0);
  }
  ASSERT_NEAR(sum, 0.0, 1e-15);
  ASSERT_NEAR(moment, 0.0, 1e-15);
  const std::vector<double> e = power_law(h, 3.0, 1.5, delta);
  EXPECT_NEAR(observed_order(h, e), 1.5, 1e-12);
  const double end_points = std::log(e.front() / e.back()) / std::log(h.front() / h.back());
  EXPECT_GT(std::abs(end_points - 1.5), 1e-3) << "the test data must not be a trivial line";
}

// Reference: the preconditions of convergence.hpp: at least two pairs, spans of equal length,
// positive and finite entries, not all h equal.
TEST(Exercise3_3, RejectsInvalidInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> one{0.1};
  const std::vector<double> two{0.1, 0.05};
  const std::vector<double> three{0.1, 0.05, 0.025};
  EXPECT_THROW(observed_order(one, one), InvalidArgument);
  EXPECT_THROW(observed_order(std::span<const double>(), std::span<const double>()),
               InvalidArgument);
  EXPECT_THROW(observed_order(two, three), InvalidArgument);
  for (double bad : {0.0, -1e-3, nan, inf}) {
    EXPECT_THROW(observed_order(std::vector<double>{0.1, bad}, two), InvalidArgument) << bad;
    EXPECT_THROW(observed_order(two, std::vector<double>{bad, 0.1}), InvalidArgument) << bad;
  }
  EXPECT_THROW(observed_order(std::vector<double>{0.1, 0.1, 0.1}, three), InvalidArgument);
}

// ----------------------------------------------------------------------------------------------
// The convergence study of chapter 2's integrators
// ----------------------------------------------------------------------------------------------

// Reference: a CVODE solution (BDF, rtol 1e-12, atol 1e-14, projection) of the torque-free
// asymmetric body Θ = (0.5, 1, 1.5), ω0 = (0.3, 1, 0.8), at T = 2 s; checked against CVODE's
// Adams method (no projection) at the same tolerance: they agree within 1e-9, and every
// integrator error is at least 50 times their difference (the smallest, Lie–Poisson's ω at
// h = 1.25e-3, is ~7e-8). Each scheme runs N = 100, 200, 400, 800, 1600 steps; the errors
// ‖A − A_ref‖_F and |ω − ω_ref| give the observed order (least squares), which must lie within
// ±0.15 of the order in body::integrators() (observed: within 0.004 of 1 for (a), (b), (c), (e)
// and of 2 for (d)).
TEST(ConvergenceStudy, ChapterTwoIntegratorsConvergeAtTheirOrder) {
  const RigidBody body{1.5, Vector3(0.5, 1.0, 1.5)};
  const State x0{make_q(Vector3(0.1, 0.2, 0.3),
                        Quaternion(std::cos(0.4), std::sin(0.4) * Vector3(1, -1, 2).normalized())),
                 make_u(Vector3(0.05, 0.0, -0.1), Vector3(0.3, 1.0, 0.8))};
  const double T = 2.0;
  grbd::ode::Cvode bdf(grbd::ode::free_body(body), 0.0, grbd::ode::pack(x0),
                       grbd::ode::CvodeMethod::bdf, {1e-12, 1e-14, {}});
  bdf.set_projection(grbd::ode::quaternion_projection_at(3));
  const State reference = grbd::ode::unpack(bdf.advance(T));
  grbd::ode::Cvode adams(grbd::ode::free_body(body), 0.0, grbd::ode::pack(x0),
                         grbd::ode::CvodeMethod::adams, {1e-12, 1e-14, {}});
  const State check = grbd::ode::unpack(adams.advance(T));
  const Matrix3 A_ref = grbd::test::reference_A_IK(reference.q);
  const Vector3 omega_ref = reference.u.tail<3>();
  const double reference_gap = std::max((grbd::test::reference_A_IK(check.q) - A_ref).norm(),
                                        (Vector3(check.u.tail<3>()) - omega_ref).norm());
  EXPECT_LE(reference_gap, 1e-9);

  for (const grbd::body::IntegratorInfo& info : grbd::body::integrators()) {
    std::vector<double> h;
    std::vector<double> orientation_errors;
    std::vector<double> omega_errors;
    for (int N : {100, 200, 400, 800, 1600}) {
      const State x = integrate(body, x0, T, N, info.scheme);
      h.push_back(T / N);
      orientation_errors.push_back((grbd::test::reference_A_IK(x.q) - A_ref).norm());
      omega_errors.push_back((Vector3(x.u.tail<3>()) - omega_ref).norm());
    }
    const std::string name(info.name);
    EXPECT_NEAR(observed_order(h, orientation_errors), info.order, 0.15) << name << ", A_IK";
    EXPECT_NEAR(observed_order(h, omega_errors), info.order, 0.15) << name << ", ω";
    EXPECT_GE(std::min(orientation_errors.back(), omega_errors.back()), 50.0 * reference_gap)
        << name << ": the reference is not accurate enough";
  }
}
