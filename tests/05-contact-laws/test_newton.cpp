// Chapter 5: the semismooth Newton method on the Alart–Curnier function (newton.hpp).
//
// Independent references: central finite differences for the generalized Jacobians (Exercises
// 5.9 and 5.10, and the Alart–Curnier Jacobian built from them) away from their kinks; a dense
// LU (Eigen's PartialPivLU) for GMRES; the natural map recomputed from ξ = W λ + q for the FCLIB
// problems, to the bound 1e-10 that Siconos' Newton solvers reach on such problems (Acary,
// Brémond, Huber 2018); quadratic convergence, ‖Φ_{k+1}‖ ≤ C ‖Φ_k‖², on a problem whose
// solution is strictly complementary (every contact clearly open, sticking or sliding). The
// contact-law tests of every solver (test_solvers.cpp) run Newton too.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "grbd/contact/delassus.hpp"
#include "grbd/contact/fclib.hpp"
#include "grbd/contact/local_problem.hpp"
#include "grbd/contact/newton.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd_test/fclib_data.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/contact_problems.hpp"
#include "grbd_test/random.hpp"

namespace {

using grbd::Matrix3;
using grbd::Vector2;
using grbd::Vector3;
using grbd::contact::LinearSolver;
using grbd::contact::LocalProblem;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

using grbd::test::norm;
using grbd::test::to_tolerance;

using grbd::test::fclib_file;

TEST(Exercise5_9, ProxNonnegativeJacobianIsTheSlopeOfMax) {
  EXPECT_EQ(grbd::contact::prox_nonnegative_jacobian(2.5), 1.0);
  EXPECT_EQ(grbd::contact::prox_nonnegative_jacobian(1e-300), 1.0);
  EXPECT_EQ(grbd::contact::prox_nonnegative_jacobian(-3.0), 0.0);
  EXPECT_EQ(grbd::contact::prox_nonnegative_jacobian(0.0), 0.0);  // the kink: open
  EXPECT_EQ(grbd::contact::prox_nonnegative_jacobian(-0.0), 0.0);
}

TEST(Exercise5_10, ProxDiskJacobianMatchesFiniteDifferences) {
  // Inside and on the boundary: the identity, no dependence on the radius.
  for (const auto& [x, rho] : {std::pair{Vector2(0.3, -0.2), 1.0}, std::pair{Vector2(0.6, 0.8), 1.0},
                               std::pair{Vector2(0.0, 0.0), 0.0}}) {
    const grbd::contact::DiskJacobian J = grbd::contact::prox_disk_jacobian(x, rho);
    EXPECT_TRUE(J.d_x.isApprox(Eigen::Matrix2d::Identity())) << x.transpose();
    EXPECT_TRUE(J.d_radius.isZero(0.0)) << x.transpose();
  }
  // Outside: central differences of prox_disk, step 1e-6, agree to 1e-8.
  grbd::test::Random rng(59);
  for (int trial = 0; trial < 200; ++trial) {
    const double rho = rng.uniform(0.0, 2.0);
    Vector2 x(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
    if (x.norm() < rho + 1e-3) x *= (rho + 0.5) / std::max(x.norm(), 1e-3);
    const grbd::contact::DiskJacobian J = grbd::contact::prox_disk_jacobian(x, rho);
    const double h = 1e-6;
    for (int k = 0; k < 2; ++k) {
      Vector2 e = Vector2::Zero();
      e(k) = h;
      const Vector2 fd = (grbd::contact::prox_disk(x + e, rho) - grbd::contact::prox_disk(x - e, rho)) /
                         (2 * h);
      EXPECT_LE((J.d_x.col(k) - fd).norm(), 1e-8) << "x = " << x.transpose() << ", rho = " << rho;
    }
    const Vector2 fd_rho =
        (grbd::contact::prox_disk(x, rho + h) - grbd::contact::prox_disk(x, std::max(rho - h, 0.0))) /
        (rho + h - std::max(rho - h, 0.0));
    EXPECT_LE((J.d_radius - fd_rho).norm(), 1e-8);
  }
  // Far outside the normal range: no overflow in ‖x‖.
  const grbd::contact::DiskJacobian big =
      grbd::contact::prox_disk_jacobian(Vector2(3e200, 4e200), 1.0);
  EXPECT_TRUE(big.d_x.allFinite());
  EXPECT_NEAR(big.d_radius(0), 0.6, 1e-15);
}

TEST(NewtonJacobian, AlartCurnierJacobianMatchesFiniteDifferences) {
  grbd::test::Random rng(60);
  int open = 0, stick = 0, slip = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Vector3 lambda(rng.uniform(-1.0, 2.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    const Vector3 xi(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    const double rho_N = rng.uniform(0.5, 2.0), rho_T = rng.uniform(0.5, 2.0);
    const double mu = rng.uniform(0.0, 1.0);
    // Away from the kinks, where Φ is smooth and its Jacobian the ordinary one.
    const double sigma_N = lambda(0) - rho_N * xi(0);
    const Vector2 sigma_T = lambda.tail<2>() - rho_T * xi.tail<2>();
    const double radius = mu * std::max(sigma_N, 0.0);
    if (std::abs(sigma_N) < 1e-3 || std::abs(sigma_T.norm() - radius) < 1e-3) continue;
    (sigma_N < 0 ? open : sigma_T.norm() <= radius ? stick : slip)++;
    const grbd::contact::AlartCurnierJacobian J =
        grbd::contact::alart_curnier_jacobian(lambda, xi, rho_N, rho_T, mu);
    EXPECT_LE((J.phi - grbd::contact::alart_curnier_function(lambda, xi, rho_N, rho_T, mu)).norm(),
              1e-15);
    EXPECT_LE((J.phi - (lambda - grbd::contact::alart_curnier_update(lambda, xi, rho_N, rho_T, mu)))
                  .norm(),
              1e-15);
    const double h = 1e-7;
    for (int k = 0; k < 3; ++k) {
      Vector3 e = Vector3::Zero();
      e(k) = h;
      const Vector3 d_lambda = (grbd::contact::alart_curnier_function(lambda + e, xi, rho_N, rho_T, mu) -
                                grbd::contact::alart_curnier_function(lambda - e, xi, rho_N, rho_T, mu)) /
                               (2 * h);
      const Vector3 d_xi = (grbd::contact::alart_curnier_function(lambda, xi + e, rho_N, rho_T, mu) -
                            grbd::contact::alart_curnier_function(lambda, xi - e, rho_N, rho_T, mu)) /
                           (2 * h);
      EXPECT_LE((J.A.col(k) - d_lambda).norm(), 1e-6) << "column " << k;
      EXPECT_LE((J.B.col(k) - d_xi).norm(), 1e-6) << "column " << k;
    }
  }
  // Every branch was exercised.
  EXPECT_GT(open, 20);
  EXPECT_GT(stick, 20);
  EXPECT_GT(slip, 20);
}

// A dense operator for GMRES: J x and a preconditioner, either the identity or the inverse of
// J's diagonal.
struct DenseOperator final : grbd::contact::LinearOperator {
  Eigen::MatrixXd J;
  bool jacobi = false;
  void apply(std::span<const double> x, std::span<double> y) const override {
    const Eigen::VectorXd v = J * Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
    for (std::size_t i = 0; i < y.size(); ++i) y[i] = v(static_cast<Eigen::Index>(i));
  }
  void precondition(std::span<const double> x, std::span<double> y) const override {
    for (std::size_t i = 0; i < y.size(); ++i) {
      y[i] = jacobi ? x[i] / J(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) : x[i];
    }
  }
};

TEST(NewtonGmres, SolvesNonsymmetricSystemsLikeADenseLu) {
  grbd::test::Random rng(61);
  grbd::contact::GmresWorkspace ws;
  for (const int n : {1, 5, 40, 120}) {
    for (const bool jacobi : {false, true}) {
      for (const int restart : {5, 200}) {
        DenseOperator op;
        op.jacobi = jacobi;
        op.J = Eigen::MatrixXd(n, n);
        for (int i = 0; i < n; ++i) {
          for (int j = 0; j < n; ++j) op.J(i, j) = rng.uniform(-1.0, 1.0) / n;
        }
        op.J.diagonal().array() += 2.0;  // diagonally dominant, nonsymmetric
        std::vector<double> b(static_cast<std::size_t>(n)), x(static_cast<std::size_t>(n));
        for (double& v : b) v = rng.uniform(-1.0, 1.0);
        const Eigen::VectorXd exact =
            op.J.partialPivLu().solve(Eigen::Map<const Eigen::VectorXd>(b.data(), n));
        const grbd::contact::GmresResult r = grbd::contact::gmres(op, b, x, 1e-12, restart, 1000, ws);
        EXPECT_TRUE(r.converged) << "n = " << n << ", restart " << restart;
        EXPECT_LE((Eigen::Map<const Eigen::VectorXd>(x.data(), n) - exact).norm(),
                  1e-10 * exact.norm())
            << "n = " << n << ", jacobi " << jacobi << ", restart " << restart;
        // The residual it reports is the true one, to rounding.
        const Eigen::VectorXd res =
            Eigen::Map<const Eigen::VectorXd>(b.data(), n) - op.J * Eigen::Map<const Eigen::VectorXd>(x.data(), n);
        EXPECT_NEAR(res.norm(), r.residual, 1e-11);
      }
    }
  }
  // The iteration cap is respected and reported as non-convergence.
  DenseOperator op;
  op.J = Eigen::MatrixXd::Identity(50, 50);
  for (int i = 0; i < 50; ++i) op.J(i, (i + 1) % 50) = 3.0;  // badly conditioned for GMRES
  std::vector<double> b(50), x(50);
  for (double& v : b) v = rng.uniform(-1.0, 1.0);  // not an eigenvector, as all-ones would be
  const grbd::contact::GmresResult capped = grbd::contact::gmres(op, b, x, 1e-14, 10, 7, ws);
  EXPECT_EQ(capped.iterations, 7);
  EXPECT_FALSE(capped.converged);
  // Bad arguments are refused, naming what was wrong.
  std::vector<double> short_x(3);
  EXPECT_THROW(grbd::contact::gmres(op, b, short_x, 1e-10, 10, 10, ws), grbd::InvalidArgument);
  EXPECT_THROW(grbd::contact::gmres(op, b, x, 1e-10, 0, 10, ws), grbd::InvalidArgument);
}

// A local problem whose solution is strictly complementary and unique: W symmetric positive
// definite and strongly diagonal (a small random coupling on the identity), friction μ ≤ 0.3
// (small enough for a unique solution with such a W), and q chosen from a prescribed solution — a third of the contacts
// open (λ = 0, ξ_N > 0), a third sticking (λ inside the cone, ξ = 0), a third sliding (λ on the
// cone's surface opposite to ξ_T ≠ 0, ξ_N = 0).
LocalProblem complementary_problem(int n, grbd::test::Random& rng, std::vector<Vector3>& solution) {
  const Eigen::Index m = 3 * n;
  Eigen::MatrixXd R(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) R(i, j) = rng.uniform(-1.0, 1.0);
  }
  Eigen::MatrixXd W = 0.2 * R * R.transpose() / static_cast<double>(m);
  W.diagonal().array() += 1.0;
  std::vector<Vector3> xi(static_cast<std::size_t>(n), Vector3::Zero());
  solution.assign(static_cast<std::size_t>(n), Vector3::Zero());
  std::vector<double> mu(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    mu[k] = rng.uniform(0.1, 0.3);
    const double angle = rng.uniform(0.0, 6.283185307179586);
    const Vector2 t(std::cos(angle), std::sin(angle));
    if (i % 3 == 0) {  // open
      xi[k] = Vector3(rng.uniform(0.5, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    } else if (i % 3 == 1) {  // sticking, strictly inside the cone
      const double lambda_N = rng.uniform(0.5, 1.5);
      solution[k] = Vector3(lambda_N, 0.5 * mu[k] * lambda_N * t(0), 0.5 * mu[k] * lambda_N * t(1));
    } else {  // sliding: λ_T = −μ λ_N ξ_T/‖ξ_T‖
      const double lambda_N = rng.uniform(0.5, 1.5), speed = rng.uniform(0.5, 1.0);
      solution[k] = Vector3(lambda_N, -mu[k] * lambda_N * t(0), -mu[k] * lambda_N * t(1));
      xi[k] = Vector3(0.0, speed * t(0), speed * t(1));
    }
  }
  const Eigen::VectorXd q = grbd::test::stack(xi) - W * grbd::test::stack(solution);
  LocalProblem p;
  p.W = grbd::contact::to_block_sparse(W.sparseView());
  p.q = grbd::test::unstack(q);
  p.mu = mu;
  return p;
}

TEST(NewtonConvergence, QuadraticNearAStrictlyComplementarySolution) {
  grbd::test::Random rng(62);
  for (const LinearSolver linear : {LinearSolver::direct, LinearSolver::gmres}) {
    std::vector<Vector3> expected;
    const LocalProblem problem = complementary_problem(30, rng, expected);
    // The construction: the prescribed percussions satisfy the law exactly.
    const std::vector<Vector3> xi_expected = grbd::contact::local_velocities(problem, expected);
    ASSERT_LE(grbd::contact::natural_map_residual(expected, xi_expected, problem.mu), 1e-12);
    SolverOptions options = to_tolerance(1e-14, 50);
    options.record_history = true;
    options.newton.linear_solver = linear;
    std::vector<Vector3> lambda;
    const SolverResult result = grbd::contact::solve_newton(problem, lambda, options);
    ASSERT_TRUE(result.converged) << grbd::contact::describe(result);
    EXPECT_LE(result.iterations, 20);
    EXPECT_EQ(result.fallbacks, 0);
    // The prescribed solution, to the accuracy of the residual.
    double error = 0.0;
    for (std::size_t i = 0; i < lambda.size(); ++i) error += (lambda[i] - expected[i]).squaredNorm();
    EXPECT_LE(std::sqrt(error), 1e-10 * norm(expected));
    // Quadratic: in the iterations above rounding, r_{k+1} ≤ C r_k² with C = 100 for a problem of
    // unit scale (‖q‖ of a few; measured: 5.5e-3 → 5.5e-7 → 5.4e-12, C ≈ 18) — a linear rate
    // would give r_{k+1}/r_k² → ∞.
    const std::vector<double>& r = result.history;
    int checked = 0;
    for (std::size_t k = 0; k + 1 < r.size(); ++k) {
      if (r[k] > 1e-2 || r[k + 1] < 1e-13) continue;
      EXPECT_LE(r[k + 1], 100.0 * r[k] * r[k]) << "iteration " << k + 1 << ": " << r[k] << " -> "
                                              << r[k + 1];
      ++checked;
    }
    EXPECT_GE(checked, 1);
  }
}

TEST(NewtonFclib, EveryProblemSolvedTo1e10) {
  for (const char* file : {"LMGC_100_PR_PerioBox-i00361-60-03000.hdf5", "Capsules-i125-1213.hdf5",
                           "Spheres-i099-356-679.hdf5"}) {
    SCOPED_TRACE(file);
    const LocalProblem problem = grbd::contact::read_fclib_as_local(fclib_file(file));
    std::vector<Vector3> lambda;
    const SolverResult result = grbd::contact::solve_newton(problem, lambda, to_tolerance(1e-10, 200));
    EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
    // The residual recomputed independently from ξ = W λ + q.
    const std::vector<Vector3> xi = grbd::contact::local_velocities(problem, lambda);
    const double residual = grbd::contact::natural_map_residual(lambda, xi, problem.mu);
    EXPECT_LE(residual, 1e-10 * norm(problem.q));
    std::printf("%s: %d Newton iterations, %d factorizations, %d fall-backs, %.1f ms\n", file,
                result.iterations, result.linear_iterations, result.fallbacks, 1e3 * result.seconds);
  }
}

TEST(NewtonInput, RefusesBadOptions) {
  grbd::contact::ContactProblem empty;
  grbd::contact::ContactSolution solution;
  SolverOptions options;
  options.newton.krylov_restart = 0;
  EXPECT_THROW(grbd::contact::solve_newton(empty, solution, options), grbd::InvalidArgument);
  options = {};
  options.newton.fallback_sweeps = 0;
  EXPECT_THROW(grbd::contact::solve_newton(empty, solution, options), grbd::InvalidArgument);
  options = {};
  options.newton.linear_solver = static_cast<LinearSolver>(7);
  EXPECT_THROW(grbd::contact::solve_newton(empty, solution, options), grbd::InvalidArgument);
  for (const double stagnation : {0.0, -0.5, 1.5, std::nan("")}) {
    options = {};
    options.newton.hybrid_sweeps = 10;
    options.newton.hybrid_stagnation = stagnation;
    try {
      grbd::contact::solve_newton(empty, solution, options);
      ADD_FAILURE() << "hybrid_stagnation = " << stagnation << " was accepted";
    } catch (const grbd::InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("hybrid_stagnation"), std::string::npos) << e.what();
    }
  }
  options = {};
  options.newton.hybrid_sweeps = -1;
  EXPECT_THROW(grbd::contact::solve_newton(empty, solution, options), grbd::InvalidArgument);
}

// The assembled Delassus matrix of the body form against its definition: W Λ is the change of
// the contact velocities that the percussions Λ cause, ξ(Λ) − ξ(0) = Wᵀ M⁻¹ W Λ, computed through
// the bodies (velocities_from_percussions, contact_velocities) without W; W is symmetric and its
// diagonal blocks are the Delassus blocks G_ii; to_local's q is ξ(0).
TEST(DelassusMatrix, AssembledWIsTheBodyFormsVelocityResponse) {
  grbd::test::Random rng(2801);
  for (int trial = 0; trial < 5; ++trial) {
    grbd::test::RandomProblemSpec spec;
    spec.contacts = 40;
    spec.bodies = 30;  // more contacts than bodies are cut: 30 contacts sharing bodies
    spec.restitution = true;
    const grbd::contact::ContactProblem problem = grbd::test::random_problem(rng, spec);
    const LocalProblem local = grbd::contact::to_local(problem);
    grbd::contact::validate(local);
    const std::size_t n = problem.contacts.size();
    ASSERT_EQ(local.q.size(), n);
    const std::vector<grbd::Vector6> u0 =
        grbd::contact::velocities_from_percussions(problem, std::vector<Vector3>(n, Vector3::Zero()));
    const std::vector<Vector3> xi0 = grbd::contact::contact_velocities(problem, u0);
    for (std::size_t i = 0; i < n; ++i) EXPECT_LE((local.q[i] - xi0[i]).norm(), 1e-14);
    for (int k = 0; k < 3; ++k) {
      std::vector<Vector3> lambda(n);
      for (Vector3& l : lambda) l = rng.vector3();
      const std::vector<Vector3> xi = grbd::contact::contact_velocities(
          problem, grbd::contact::velocities_from_percussions(problem, lambda));
      std::vector<Vector3> W_lambda(n);
      grbd::contact::multiply(local.W, lambda, W_lambda);
      for (std::size_t i = 0; i < n; ++i) {
        EXPECT_LE((W_lambda[i] - (xi[i] - xi0[i])).norm(), 1e-12 * (1.0 + xi[i].norm()))
            << "contact " << i;
      }
    }
    const grbd::contact::BlockSparseMatrix& W = local.W;
    for (std::size_t i = 0; i < n; ++i) {
      const Matrix3 G = grbd::contact::delassus_block(problem.contacts[i], problem.M_inv);
      EXPECT_LE((W.blocks[static_cast<std::size_t>(W.diagonal[i])] - G).norm(), 1e-13 * G.norm());
      for (std::int64_t k = W.row_start[i]; k < W.row_start[i + 1]; ++k) {
        const auto j = static_cast<std::size_t>(W.column[k]);
        const auto* const first = W.column.data() + W.row_start[j];
        const auto* const last = W.column.data() + W.row_start[j + 1];
        const auto* const found = std::find(first, last, static_cast<std::int32_t>(i));
        ASSERT_NE(found, last) << "block (" << i << ", " << j << ") without (" << j << ", " << i << ")";
        const Matrix3& transposed = W.blocks[static_cast<std::size_t>(found - W.column.data())];
        EXPECT_LE((W.blocks[static_cast<std::size_t>(k)] - transposed.transpose()).norm(),
                  1e-14 * (1.0 + G.norm()));
      }
    }
  }
}

// Newton with the sparse LU of the assembled W in the body form reaches the same solution as with
// GMRES and as SOR: the frictionless problem has exactly one (G positive definite).
TEST(DelassusMatrix, NewtonDirectInTheBodyFormSolvesAsGmresDoes) {
  grbd::test::Random rng(2802);
  grbd::test::RandomProblemSpec spec;
  spec.contacts = 60;
  spec.bodies = 76;
  spec.mu_max = 0.0;
  const grbd::contact::ContactProblem problem = grbd::test::random_problem(rng, spec);
  std::vector<std::vector<Vector3>> solutions;
  for (const LinearSolver linear : {LinearSolver::direct, LinearSolver::gmres}) {
    SolverOptions options = to_tolerance(1e-12, 100);
    options.newton.linear_solver = linear;
    grbd::contact::ContactSolution solution;
    const SolverResult result = grbd::contact::solve_newton(problem, solution, options);
    ASSERT_TRUE(result.converged) << grbd::contact::describe(result);
    solutions.push_back(solution.lambda);
  }
  grbd::contact::ContactSolution sor;
  ASSERT_TRUE(grbd::contact::solve_sor(problem, sor, to_tolerance(1e-12, 100000)).converged);
  for (std::size_t i = 0; i < sor.lambda.size(); ++i) {
    EXPECT_LE((solutions[0][i] - sor.lambda[i]).norm(), 1e-9 * (1.0 + sor.lambda[i].norm()));
    EXPECT_LE((solutions[1][i] - sor.lambda[i]).norm(), 1e-9 * (1.0 + sor.lambda[i].norm()));
  }
}

// The hybrid: SOR sweeps, then Newton where they stagnate. On PerioBox-60 SOR needs ~2500 sweeps
// to 1e-8 and stagnates long before 1e-10: the hybrid hands over and Newton finishes (Acary,
// Brémond and Huber 2018 report NSGS stalling on this problem); on Spheres-356 SOR meets 1e-8 in
// ~240 sweeps, so the SOR phase ends there, at the end of a window, and Newton is never needed.
TEST(NewtonHybrid, HandsOverWhereSorStagnatesAndStopsWhereSorConverges) {
  {
    const LocalProblem problem = grbd::contact::read_fclib_as_local(
        fclib_file("LMGC_100_PR_PerioBox-i00361-60-03000.hdf5"));
    std::vector<Vector3> lambda;
    SolverOptions options = to_tolerance(1e-10, 201);
    options.newton.hybrid_sweeps = 2000;
    const SolverResult result = grbd::contact::solve_newton(problem, lambda, options);
    ASSERT_TRUE(result.converged) << grbd::contact::describe(result);
    EXPECT_GT(result.iterations, 1);  // Newton took over
    EXPECT_GT(result.hybrid_sweeps, 0);
    EXPECT_LE(result.hybrid_sweeps, 2000);
    EXPECT_EQ(result.hybrid_sweeps % grbd::contact::newton::kHybridWindow, 0);
    const std::vector<Vector3> xi = grbd::contact::local_velocities(problem, lambda);
    EXPECT_LE(grbd::contact::natural_map_residual(lambda, xi, problem.mu), 1e-10 * norm(problem.q));
  }
  {
    const LocalProblem problem =
        grbd::contact::read_fclib_as_local(fclib_file("Spheres-i099-356-679.hdf5"));
    std::vector<Vector3> lambda;
    SolverOptions options = to_tolerance(1e-8, 201);
    options.newton.hybrid_sweeps = 2000;
    const SolverResult result = grbd::contact::solve_newton(problem, lambda, options);
    ASSERT_TRUE(result.converged) << grbd::contact::describe(result);
    EXPECT_EQ(result.iterations, 1);  // the SOR phase alone
    EXPECT_EQ(result.linear_iterations, 0);
    EXPECT_GT(result.hybrid_sweeps, 100);
    EXPECT_EQ(result.hybrid_sweeps % grbd::contact::newton::kHybridWindow, 0);
    // Plain SOR needs about as many sweeps: the phase stops within one window of it.
    std::vector<Vector3> sor;
    const SolverResult plain = grbd::contact::solve_sor(problem, sor, to_tolerance(1e-8, 100000));
    EXPECT_LE(std::abs(result.hybrid_sweeps - plain.iterations),
              grbd::contact::newton::kHybridWindow);
  }
}

}  // namespace
