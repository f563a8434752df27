// Chapter 3: the SUNDIALS wrapper (sundials.hpp) — CVODE BDF and Adams, ARKODE explicit, IMEX and
// DIRK Runge–Kutta — on DETEST problem B5 against its exact solution (sn, cn, dn)(t | 0.51);
// vector tolerances; statistics against a count of the calls of f; projection; every invalid
// input, SUNDIALS failures with their flag names and messages, and exceptions thrown by f and
// by the projection. No exercise: every suite here must pass against the stubs too.
//
// Independent references: the Jacobi elliptic functions of Boost.Math (detest_b5_exact(), itself
// checked in test_references.cpp); the exact flow of the rotation y' = ω J y (cos, sin); counts of
// the user's function calls kept by the test.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/ode/references.hpp"
#include "grbd/ode/sundials.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::InvalidArgument;
using grbd::ode::Arkode;
using grbd::ode::Cvode;
using grbd::ode::CvodeMethod;
using grbd::ode::RhsFunction;
using grbd::ode::Statistics;
using grbd::ode::SundialsError;
using grbd::ode::Tolerances;
using grbd::test::describe;
using grbd::test::WorstCase;
using Ref = Eigen::Ref<const Eigen::VectorXd>;
using Out = Eigen::Ref<Eigen::VectorXd>;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// DETEST B5's initial value y(0) = (0, 1, 1) and its final time T = 20 (Hull et al. 1972).
Eigen::VectorXd b5_y0() { return Eigen::Vector3d(0.0, 1.0, 1.0); }
constexpr double kB5End = 20.0;

/// The max-norm error at T = 20 against (sn, cn, dn)(20 | 0.51).
double b5_error(const Eigen::VectorXd& y) {
  return (y - Eigen::VectorXd(grbd::ode::detest_b5_exact(kB5End))).cwiseAbs().maxCoeff();
}

/// The explicit and implicit parts of an IMEX split of B5: the third equation implicit.
RhsFunction b5_explicit_part() {
  return [](double, const Ref& y, Out y_dot) { y_dot << y[1] * y[2], -y[0] * y[2], 0.0; };
}
RhsFunction b5_implicit_part() {
  return [](double, const Ref& y, Out y_dot) { y_dot << 0.0, 0.0, -0.51 * y[0] * y[1]; };
}

/// A solver of B5 at tolerance rtol = atol = tol.
using B5Solver = std::function<Eigen::VectorXd(double tol)>;

B5Solver cvode_b5(CvodeMethod method) {
  return [method](double tol) {
    Cvode solver(grbd::ode::detest_b5(), 0.0, b5_y0(), method, {tol, tol, {}});
    return solver.advance(kB5End);
  };
}

B5Solver arkode_b5(int order, bool imex, bool dirk = false) {
  return [=](double tol) {
    RhsFunction f_E = imex ? b5_explicit_part() : grbd::ode::detest_b5();
    RhsFunction f_I = imex ? b5_implicit_part() : nullptr;
    if (dirk) {
      f_I = grbd::ode::detest_b5();
      f_E = nullptr;
    }
    Arkode solver(f_E, f_I, 0.0, b5_y0(), order, {tol, tol, {}});
    return solver.advance(kB5End);
  };
}

/// The least-squares slope of log e over log tol, written out (no code of Exercise 3.3).
double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double xm = 0.0;
  double ym = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    xm += std::log(x[i]) / static_cast<double>(x.size());
    ym += std::log(y[i]) / static_cast<double>(y.size());
  }
  double sxy = 0.0;
  double sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (std::log(x[i]) - xm) * (std::log(y[i]) - ym);
    sxx += (std::log(x[i]) - xm) * (std::log(x[i]) - xm);
  }
  return sxy / sxx;
}

/// B5 at each tolerance: the error is at most `factor` × tol (the local error control bounds
/// the global error only up to the growth of errors over [0, 20]: observed ≤ 170 tol), and the
/// error follows the tolerance: the log–log slope of error over tol lies in [0.8, 1.2]
/// (tolerance proportionality; observed 0.9–1.05).
void expect_tolerance_proportional(const B5Solver& solve, const std::vector<double>& tolerances,
                                   const std::string& name, double factor = 500.0) {
  std::vector<double> errors;
  for (double tol : tolerances) {
    const double error = b5_error(solve(tol));
    errors.push_back(error);
    EXPECT_LE(error, factor * tol) << name << " at tol " << tol;
  }
  const double slope = log_log_slope(tolerances, errors);
  EXPECT_GE(slope, 0.8) << name;
  EXPECT_LE(slope, 1.2) << name;
}

const std::vector<double> kTolerances{1e-4, 1e-6, 1e-8, 1e-10};

/// f wrapped so that the test counts its calls.
RhsFunction counted(RhsFunction f, long& calls) {
  return [f = std::move(f), &calls](double t, const Ref& y, Out y_dot) {
    ++calls;
    f(t, y, y_dot);
  };
}

/// The exception that the tests throw from inside SUNDIALS' callbacks.
struct Boom : std::runtime_error {
  explicit Boom(const std::string& what) : std::runtime_error(what) {}
};

/// The rotation y' = ω J y, J = ((0, −1), (1, 0)): |y| is constant, y(t) = R(ωt) y(0).
RhsFunction rotation(double omega) {
  return [omega](double, const Ref& y, Out y_dot) { y_dot << -omega * y[1], omega * y[0]; };
}

/// The projection onto the unit circle |y| = 1.
void project_onto_circle(double, const Ref& y, Out correction) { correction = y / y.norm() - y; }

}  // namespace

// ----------------------------------------------------------------------------------------------
// DETEST B5 against the Jacobi elliptic functions
// ----------------------------------------------------------------------------------------------

// Reference: (sn, cn, dn)(20 | 0.51), Boost.Math. Tolerances: see expect_tolerance_proportional()
// (observed BDF 5.6e-3, 2.0e-5, 3.6e-7, 1.7e-8 at tol 1e-4 … 1e-10).
TEST(DetestB5, CvodeBdfErrorFollowsTheTolerance) {
  expect_tolerance_proportional(cvode_b5(CvodeMethod::bdf), kTolerances, "CVODE BDF");
}

// Reference and tolerances as above (observed Adams 3.1e-3 … 6.4e-9).
TEST(DetestB5, CvodeAdamsErrorFollowsTheTolerance) {
  expect_tolerance_proportional(cvode_b5(CvodeMethod::adams), kTolerances, "CVODE Adams");
}

// Reference and tolerances as above, for every explicit order ARKODE offers. Order 2 (Heun–Euler)
// needs > 10⁵ steps below tol 1e-6, so it is run at 1e-4 and 1e-6 only.
TEST(DetestB5, ArkodeExplicitErrorFollowsTheTolerance) {
  expect_tolerance_proportional(arkode_b5(2, false), {1e-4, 1e-6}, "ERK 2");
  for (int order : {3, 4, 5, 6, 8}) {
    expect_tolerance_proportional(arkode_b5(order, false), kTolerances,
                                  "ERK " + std::to_string(order));
  }
}

// Reference and tolerances as above: the IMEX split f_E = (y2y3, −y1y3, 0), f_I = (0, 0,
// −0.51 y1y2), and the fully implicit DIRK methods (order 2 at loose tolerances only).
TEST(DetestB5, ArkodeImexAndDirkErrorFollowsTheTolerance) {
  for (int order : {3, 4, 5}) {
    expect_tolerance_proportional(arkode_b5(order, true), kTolerances,
                                  "IMEX " + std::to_string(order));
    expect_tolerance_proportional(arkode_b5(order, false, true), kTolerances,
                                  "DIRK " + std::to_string(order));
  }
  expect_tolerance_proportional(arkode_b5(2, false, true), {1e-4, 1e-6}, "DIRK 2");
}

// Reference: the point of high order. At tol 1e-10 each higher explicit order needs fewer calls
// of f (observed 44559, 22275, 3161, 2095, 1398 for orders 3, 4, 5, 6, 8) while every error stays
// below 100 tol. (With SUNDIALS 6.4's ERKStep, order 6 would need more calls than order 5 and
// still miss the tolerance: the wrapper uses ARKStep, see sundials.hpp.)
TEST(DetestB5, HigherExplicitOrdersNeedFewerEvaluations) {
  long previous = std::numeric_limits<long>::max();
  for (int order : {3, 4, 5, 6, 8}) {
    Arkode solver(grbd::ode::detest_b5(), nullptr, 0.0, b5_y0(), order, {1e-10, 1e-10, {}});
    EXPECT_LE(b5_error(solver.advance(kB5End)), 100.0 * 1e-10) << "order " << order;
    const long evaluations = solver.statistics().rhs_evaluations;
    EXPECT_LT(evaluations, previous) << "order " << order;
    previous = evaluations;
  }
}

// Reference: (sn, cn, dn) at t = −3 (sn odd, cn and dn even): the first output time fixes the
// direction, and CVODE and ARKODE integrate backward as well as forward (tolerance 1e-7 at
// tol 1e-10).
TEST(DetestB5, IntegratesBackward) {
  Cvode cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf, {1e-10, 1e-10, {}});
  Arkode arkode(grbd::ode::detest_b5(), nullptr, 0.0, b5_y0(), 5, {1e-10, 1e-10, {}});
  const Eigen::VectorXd exact = grbd::ode::detest_b5_exact(-3.0);
  EXPECT_LE((cvode.advance(-3.0) - exact).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LE((arkode.advance(-3.0) - exact).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_EQ(cvode.time(), -3.0);
  EXPECT_EQ(arkode.time(), -3.0);
}

// ----------------------------------------------------------------------------------------------
// Tolerances
// ----------------------------------------------------------------------------------------------

// Reference: the weights are 1/(rtol |y_i| + atol_i) either way, so a vector of equal entries
// must reproduce the scalar tolerance bit for bit, with the same statistics.
TEST(SundialsTolerances, VectorOfEqualEntriesReproducesTheScalarTolerance) {
  const Tolerances scalar{1e-8, 1e-9, {}};
  const Tolerances vector{1e-8, 0.0, Eigen::Vector3d::Constant(1e-9)};
  for (CvodeMethod method : {CvodeMethod::bdf, CvodeMethod::adams}) {
    Cvode a(grbd::ode::detest_b5(), 0.0, b5_y0(), method, scalar);
    Cvode b(grbd::ode::detest_b5(), 0.0, b5_y0(), method, vector);
    EXPECT_EQ(a.advance(kB5End), b.advance(kB5End));
    EXPECT_EQ(a.statistics().steps, b.statistics().steps);
  }
  Arkode a(grbd::ode::detest_b5(), nullptr, 0.0, b5_y0(), 4, scalar);
  Arkode b(grbd::ode::detest_b5(), nullptr, 0.0, b5_y0(), 4, vector);
  EXPECT_EQ(a.advance(kB5End), b.advance(kB5End));
  EXPECT_EQ(a.statistics().rhs_evaluations, b.statistics().rhs_evaluations);
}

// Reference: with rtol = 0 the test is |e_i| ≤ atol_i alone. Tightening atol on y3 alone from
// 1e-4 to 1e-10 must make CVODE take more steps and shrink the error of y3 (observed 161 → 934
// steps, 5.9e-4 → 1.5e-8 at T = 20), while pure absolute tolerances of 1e-10 bound every error
// by 1e-7 (observed 2.6e-9).
TEST(SundialsTolerances, AbsoluteToleranceOfEachComponentIsHonoured) {
  const auto run = [](const Eigen::Vector3d& atol) {
    Cvode solver(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf, {0.0, 0.0, atol});
    const Eigen::VectorXd y = solver.advance(kB5End);
    return std::pair<double, long>{std::abs(y[2] - grbd::ode::detest_b5_exact(kB5End)[2]),
                                   solver.statistics().steps};
  };
  const auto loose = run(Eigen::Vector3d(1e-4, 1e-4, 1e-4));
  const auto tight_y3 = run(Eigen::Vector3d(1e-4, 1e-4, 1e-10));
  EXPECT_GT(tight_y3.second, loose.second);
  EXPECT_LT(tight_y3.first, loose.first);
  Cvode solver(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf,
               {0.0, 0.0, Eigen::Vector3d::Constant(1e-10)});
  EXPECT_LE(b5_error(solver.advance(kB5End)), 1e-7);
}

// ----------------------------------------------------------------------------------------------
// Statistics
// ----------------------------------------------------------------------------------------------

// Reference: the test's own count of the calls of f (f_E and f_I), which rhs_evaluations must
// equal exactly; the structure of each method: BDF uses Newton (Jacobians, iterations ≥ steps),
// Adams fixed-point iteration (no Jacobian, iterations ≥ steps), explicit RK neither, IMEX and
// DIRK Newton on f_I; the last step is positive and at most T; counters only grow.
TEST(SundialsStatistics, AreNonZeroAndCountEveryCallOfTheRightHandSide) {
  for (CvodeMethod method : {CvodeMethod::bdf, CvodeMethod::adams}) {
    long calls = 0;
    Cvode solver(counted(grbd::ode::detest_b5(), calls), 0.0, b5_y0(), method, {1e-8, 1e-8, {}});
    solver.advance(5.0);
    const Statistics first = solver.statistics();
    solver.advance(kB5End);
    const Statistics s = solver.statistics();
    const bool bdf = method == CvodeMethod::bdf;
    EXPECT_EQ(s.rhs_evaluations, calls);
    EXPECT_GT(s.steps, first.steps);
    EXPECT_GT(s.rhs_evaluations, first.rhs_evaluations);
    EXPECT_GE(s.rhs_evaluations, s.steps);
    EXPECT_GE(s.nonlinear_iterations, s.steps);
    EXPECT_EQ(s.jacobian_evaluations > 0, bdf);
    EXPECT_EQ(s.projections, 0);
    EXPECT_GT(s.last_step, 0.0);
    EXPECT_LE(s.last_step, kB5End);
    EXPECT_LE(s.error_test_failures, s.steps);
  }
  for (int kind = 0; kind < 3; ++kind) {
    long calls = 0;
    const bool explicit_rk = kind == 0;
    RhsFunction f_E =
        kind == 1 ? counted(b5_explicit_part(), calls) : counted(grbd::ode::detest_b5(), calls);
    RhsFunction f_I = kind == 1 ? counted(b5_implicit_part(), calls) : nullptr;
    if (kind == 2) std::swap(f_E, f_I);
    Arkode solver(f_E, f_I, 0.0, b5_y0(), 4, {1e-8, 1e-8, {}});
    solver.advance(kB5End);
    const Statistics s = solver.statistics();
    EXPECT_EQ(s.rhs_evaluations, calls) << "kind " << kind;
    EXPECT_GT(s.steps, 0);
    // A Runge–Kutta step calls f at least once per stage beyond the first (Zonneveld: 5 stages).
    EXPECT_GE(s.rhs_evaluations, 4 * s.steps);
    EXPECT_EQ(s.jacobian_evaluations > 0, !explicit_rk) << "kind " << kind;
    EXPECT_EQ(s.nonlinear_iterations > 0, !explicit_rk) << "kind " << kind;
    EXPECT_GT(s.last_step, 0.0);
    EXPECT_EQ(s.projections, 0);
  }
}

// ----------------------------------------------------------------------------------------------
// Projection
// ----------------------------------------------------------------------------------------------

// Reference: the exact flow of y' = ωJy keeps |y| = 1; BDF does not (it damps). At rtol 1e-6
// over 10 turns, without projection |y| − 1 drifts beyond 1e-7 (observed 9.5e-5); with the
// projection onto the circle every output has ||y| − 1| ≤ 4 eps, CVODE projects at least once per
// step, and y stays within 1e-4 of (cos ωt, sin ωt) (observed 1.2e-5: the projection does not
// spoil the accuracy).
TEST(SundialsProjection, KeepsTheConstraintToRoundOffWhereBdfAloneDrifts) {
  const double omega = 2.0 * std::numbers::pi;
  const Eigen::VectorXd y0 = Eigen::Vector2d(1.0, 0.0);
  Cvode free(rotation(omega), 0.0, y0, CvodeMethod::bdf, {1e-6, 1e-8, {}});
  Cvode projected(rotation(omega), 0.0, y0, CvodeMethod::bdf, {1e-6, 1e-8, {}});
  projected.set_projection(project_onto_circle);
  double drift_free = 0.0;
  WorstCase drift_projected;
  WorstCase phase_error;
  for (int k = 1; k <= 1000; ++k) {
    const double t = 0.01 * k;
    drift_free = std::max(drift_free, std::abs(free.advance(t).norm() - 1.0));
    const Eigen::VectorXd y = projected.advance(t);
    const auto inputs = [&] { return describe("t", t, "y(t)", y); };
    drift_projected.update(std::abs(y.norm() - 1.0), inputs);
    phase_error.update((y - Eigen::Vector2d(std::cos(omega * t), std::sin(omega * t))).norm(),
                       inputs);
  }
  EXPECT_GE(drift_free, 1e-7);
  EXPECT_LE(drift_projected.value(), 4.0 * kEps) << drift_projected;
  EXPECT_LE(phase_error.value(), 1e-4) << phase_error;
  const Statistics s = projected.statistics();
  EXPECT_GE(s.projections, s.steps);
  EXPECT_EQ(free.statistics().projections, 0);
}

// ----------------------------------------------------------------------------------------------
// Invalid input: grbd::InvalidArgument
// ----------------------------------------------------------------------------------------------

// Reference: the preconditions of sundials.hpp: tolerances finite and ≥ 0, atol_vector of size
// n, not rtol = 0 with a zero atol; for Cvode and Arkode alike.
TEST(SundialsErrors, RejectsInvalidTolerances) {
  const std::vector<Tolerances> bad{
      {-1e-6, 1e-8, {}},
      {kNaN, 1e-8, {}},
      {kInf, 1e-8, {}},
      {1e-6, -1e-8, {}},
      {1e-6, kInf, {}},
      {1e-6, kNaN, {}},
      {1e-6, 1e-8, Eigen::Vector2d(1e-8, 1e-8)},
      {1e-6, 1e-8, Eigen::Vector4d::Constant(1e-8)},
      {1e-6, 1e-8, Eigen::Vector3d(1e-8, -1e-8, 1e-8)},
      {1e-6, 1e-8, Eigen::Vector3d(1e-8, kNaN, 1e-8)},
      {0.0, 0.0, {}},
      {0.0, 1e-8, Eigen::Vector3d(1e-8, 0.0, 1e-8)},
  };
  for (const Tolerances& tolerances : bad) {
    EXPECT_THROW(Cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf, tolerances),
                 InvalidArgument)
        << "rtol " << tolerances.rtol << ", atol " << tolerances.atol;
    EXPECT_THROW(Cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::adams, tolerances),
                 InvalidArgument);
    EXPECT_THROW(Arkode(grbd::ode::detest_b5(), nullptr, 0.0, b5_y0(), 4, tolerances),
                 InvalidArgument);
    EXPECT_THROW(Arkode(b5_explicit_part(), b5_implicit_part(), 0.0, b5_y0(), 4, tolerances),
                 InvalidArgument);
  }
  // Zero tolerances where allowed: rtol = 0 with positive atol, atol = 0 with positive rtol.
  EXPECT_NO_THROW(Cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf, {0.0, 1e-8, {}}));
  EXPECT_NO_THROW(Cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf, {1e-6, 0.0, {}}));
}

// Reference: the preconditions of sundials.hpp: a non-empty f (one of f_E, f_I), finite t0, and
// a non-empty, finite y0.
TEST(SundialsErrors, RejectsInvalidProblems) {
  const Tolerances tol{};
  EXPECT_THROW(Cvode(nullptr, 0.0, b5_y0(), CvodeMethod::bdf, tol), InvalidArgument);
  EXPECT_THROW(Arkode(nullptr, nullptr, 0.0, b5_y0(), 4, tol), InvalidArgument);
  for (double t0 : {kNaN, kInf, -kInf}) {
    EXPECT_THROW(Cvode(grbd::ode::detest_b5(), t0, b5_y0(), CvodeMethod::bdf, tol),
                 InvalidArgument);
    EXPECT_THROW(Arkode(grbd::ode::detest_b5(), nullptr, t0, b5_y0(), 4, tol), InvalidArgument);
  }
  for (const Eigen::VectorXd& y0 :
       {Eigen::VectorXd(), Eigen::VectorXd(Eigen::Vector3d(0.0, kNaN, 1.0)),
        Eigen::VectorXd(Eigen::Vector3d(kInf, 1.0, 1.0))}) {
    EXPECT_THROW(Cvode(grbd::ode::detest_b5(), 0.0, y0, CvodeMethod::adams, tol), InvalidArgument);
    EXPECT_THROW(Arkode(grbd::ode::detest_b5(), nullptr, 0.0, y0, 4, tol), InvalidArgument);
  }
  EXPECT_THROW(Cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), static_cast<CvodeMethod>(7), tol),
               InvalidArgument);
}

// Reference: the default tables of ARKODE 5.4 (SUNDIALS 6.4): ERK 2, 3, 4, 5, 6, 8; IMEX 3, 4, 5;
// DIRK 2–5. ARKODE itself would warn and substitute another order; the wrapper refuses.
TEST(SundialsErrors, RejectsOrdersWithoutAMethod) {
  const Tolerances tol{};
  for (int order : {-1, 0, 1, 7, 9}) {
    EXPECT_THROW(Arkode(grbd::ode::detest_b5(), nullptr, 0.0, b5_y0(), order, tol), InvalidArgument)
        << "ERK order " << order;
  }
  for (int order : {1, 2, 6}) {
    EXPECT_THROW(Arkode(b5_explicit_part(), b5_implicit_part(), 0.0, b5_y0(), order, tol),
                 InvalidArgument)
        << "IMEX order " << order;
  }
  for (int order : {1, 6}) {
    EXPECT_THROW(Arkode(nullptr, grbd::ode::detest_b5(), 0.0, b5_y0(), order, tol), InvalidArgument)
        << "DIRK order " << order;
  }
  for (int order : {2, 3, 4, 5, 6, 8}) {
    EXPECT_NO_THROW(Arkode(grbd::ode::detest_b5(), nullptr, 0.0, b5_y0(), order, tol));
  }
}

// Reference: advance() integrates in one direction, fixed by its first call: t_out must be finite
// and lie beyond time(); the maximum number of steps is positive; a projection is a non-empty
// function and needs BDF.
TEST(SundialsErrors, RejectsOutputTimesMaxStepsAndProjectionsItCannotUse) {
  Cvode cvode(grbd::ode::detest_b5(), 1.0, b5_y0(), CvodeMethod::bdf, {});
  Arkode arkode(grbd::ode::detest_b5(), nullptr, 1.0, b5_y0(), 4, {});
  for (double t_out : {1.0, kNaN, kInf}) {
    EXPECT_THROW(cvode.advance(t_out), InvalidArgument) << t_out;
    EXPECT_THROW(arkode.advance(t_out), InvalidArgument) << t_out;
  }
  cvode.advance(2.0);
  arkode.advance(2.0);
  for (double t_out : {2.0, 1.5, 0.0}) {
    EXPECT_THROW(cvode.advance(t_out), InvalidArgument) << t_out;
    EXPECT_THROW(arkode.advance(t_out), InvalidArgument) << t_out;
  }
  EXPECT_EQ(cvode.time(), 2.0);
  EXPECT_NO_THROW(cvode.advance(2.5));
  for (long max_steps : {0L, -10L}) {
    EXPECT_THROW(cvode.set_max_steps(max_steps), InvalidArgument);
    EXPECT_THROW(arkode.set_max_steps(max_steps), InvalidArgument);
  }
  EXPECT_THROW(cvode.set_projection(nullptr), InvalidArgument);
  Cvode adams(rotation(1.0), 0.0, Eigen::Vector2d(1.0, 0.0), CvodeMethod::adams, {});
  try {
    adams.set_projection(project_onto_circle);
    ADD_FAILURE() << "projection accepted for Adams";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("bdf"), std::string::npos) << e.what();
  }
}

// ----------------------------------------------------------------------------------------------
// SUNDIALS failures: grbd::ode::SundialsError with the flag's name and SUNDIALS' message
// ----------------------------------------------------------------------------------------------

// Reference: CVODE's and ARKODE's documented flags: more than mxstep steps before t_out is
// CV_TOO_MUCH_WORK = ARK_TOO_MUCH_WORK = −1, and the message SUNDIALS' error handler reported
// ("mxstep steps taken before reaching tout") ends up in what(), with nothing printed to stderr.
// The solver stays usable: with the default limit back, it reaches T = 20 with the same accuracy
// as a fresh run (tolerance 500 tol, as above).
TEST(SundialsErrors, TooMuchWorkNamesTheFlagAndKeepsTheSolverUsable) {
  testing::internal::CaptureStderr();
  Cvode cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf, {1e-8, 1e-8, {}});
  cvode.set_max_steps(10);
  try {
    cvode.advance(kB5End);
    ADD_FAILURE() << "CVODE took more than 10 steps without failing";
  } catch (const SundialsError& e) {
    EXPECT_EQ(e.flag(), -1);
    EXPECT_EQ(e.flag_name(), "CV_TOO_MUCH_WORK");
    const std::string what = e.what();
    EXPECT_NE(what.find("CVode failed with CV_TOO_MUCH_WORK (-1)"), std::string::npos) << what;
    EXPECT_NE(what.find("mxstep steps taken before reaching tout"), std::string::npos) << what;
  }
  EXPECT_LT(cvode.time(), kB5End);
  cvode.set_max_steps(100000);
  EXPECT_LE(b5_error(cvode.advance(kB5End)), 500.0 * 1e-8);
  for (int kind = 0; kind < 2; ++kind) {
    Arkode arkode(kind == 0 ? grbd::ode::detest_b5() : b5_explicit_part(),
                  kind == 0 ? nullptr : b5_implicit_part(), 0.0, b5_y0(), 4, {1e-8, 1e-8, {}});
    arkode.set_max_steps(10);
    try {
      arkode.advance(kB5End);
      ADD_FAILURE() << "ARKODE took more than 10 steps without failing";
    } catch (const SundialsError& e) {
      EXPECT_EQ(e.flag_name(), "ARK_TOO_MUCH_WORK");
      EXPECT_NE(std::string(e.what()).find("ARKStepEvolve failed with ARK_TOO_MUCH_WORK (-1)"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// Reference: CVODE's error weight 1/(rtol |y_i| + atol) is infinite where y_i = 0 and atol = 0:
// CVode fails with CV_ILL_INPUT (−22) and says why; a SundialsError is a grbd::Error.
TEST(SundialsErrors, ZeroErrorWeightIsReportedWithSundialsMessage) {
  testing::internal::CaptureStderr();
  Cvode cvode(grbd::ode::detest_b5(), 0.0, b5_y0(), CvodeMethod::bdf, {1e-6, 0.0, {}});
  try {
    cvode.advance(1.0);
    ADD_FAILURE() << "a zero error weight was accepted";
  } catch (const grbd::Error& e) {
    const auto* sundials = dynamic_cast<const SundialsError*>(&e);
    ASSERT_NE(sundials, nullptr) << e.what();
    EXPECT_EQ(sundials->flag(), -22);
    EXPECT_EQ(sundials->flag_name(), "CV_ILL_INPUT");
    EXPECT_NE(std::string(e.what()).find("ewt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// ----------------------------------------------------------------------------------------------
// Exceptions thrown inside SUNDIALS' callbacks
// ----------------------------------------------------------------------------------------------

// Reference: a C++ exception cannot cross SUNDIALS' C frames; the wrapper catches it in the
// callback and rethrows the same exception (type and message) from advance(). Thrown on the 20th
// call of f, in every solver, in f_E and in f_I; nothing is printed.
TEST(SundialsExceptions, ExceptionFromTheRightHandSideIsRethrown) {
  const auto failing = [](RhsFunction f, long& calls) -> RhsFunction {
    return [f = std::move(f), &calls](double t, const Ref& y, Out y_dot) {
      if (++calls == 20) throw Boom("f failed at t = " + std::to_string(t));
      f(t, y, y_dot);
    };
  };
  testing::internal::CaptureStderr();
  for (CvodeMethod method : {CvodeMethod::bdf, CvodeMethod::adams}) {
    long calls = 0;
    Cvode cvode(failing(grbd::ode::detest_b5(), calls), 0.0, b5_y0(), method, {});
    EXPECT_THROW(cvode.advance(kB5End), Boom);
    EXPECT_EQ(calls, 20);
  }
  for (int kind = 0; kind < 4; ++kind) {
    long calls = 0;
    RhsFunction f_E = kind == 0   ? failing(grbd::ode::detest_b5(), calls)
                      : kind == 1 ? failing(b5_explicit_part(), calls)
                      : kind == 2 ? b5_explicit_part()
                                  : nullptr;
    RhsFunction f_I = kind == 0 ? nullptr
                      : kind == 1
                          ? b5_implicit_part()
                          : failing(kind == 2 ? b5_implicit_part() : grbd::ode::detest_b5(), calls);
    Arkode arkode(f_E, f_I, 0.0, b5_y0(), 4, {});
    try {
      arkode.advance(kB5End);
      ADD_FAILURE() << "no exception, kind " << kind;
    } catch (const Boom& e) {
      EXPECT_NE(std::string(e.what()).find("f failed at t = "), std::string::npos);
    }
    EXPECT_EQ(calls, 20) << "kind " << kind;
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// Reference: as above, for the projection: thrown at its 5th call inside CVODE, and from the
// projection of the output; grbd::NotImplemented (not a grbd::Error) passes unchanged too.
TEST(SundialsExceptions, ExceptionFromTheProjectionIsRethrown) {
  long calls = 0;
  Cvode cvode(rotation(1.0), 0.0, Eigen::Vector2d(1.0, 0.0), CvodeMethod::bdf, {});
  cvode.set_projection([&calls](double t, const Ref& y, Out correction) {
    if (++calls == 5) throw Boom("projection failed");
    project_onto_circle(t, y, correction);
  });
  EXPECT_THROW(cvode.advance(10.0), Boom);
  EXPECT_EQ(calls, 5);

  Cvode stub(rotation(1.0), 0.0, Eigen::Vector2d(1.0, 0.0), CvodeMethod::bdf, {});
  stub.set_projection([](double, const Ref&, Out) -> void {
    throw grbd::NotImplemented("Exercise 0.0", "a test", "Chapter 0", "nowhere.cpp");
  });
  EXPECT_THROW(stub.advance(1.0), grbd::NotImplemented);
}
