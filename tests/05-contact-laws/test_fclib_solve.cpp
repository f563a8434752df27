// Chapter 5: grbd's solvers on the FCLIB problems of chapters/05-contact-laws/data, to the residuals that
// Siconos 4.4 reaches on them (chapters/05-contact-laws/data/README.md): ‖F‖/‖q‖ ≤ 4.6e-8 on PerioBox-60
// (NSGS), ≤ 2.7e-10 on Capsules-286 (NSGS) and ≤ 1.1e-8 on Spheres-356 (NSGS).
//
// Independent references: the Siconos residuals above; the natural map recomputed here from
// ξ = W λ + q (local_velocities) and prox_cone, not from the solver's own bookkeeping; the Coulomb
// law checked contact by contact; and two different methods (SOR, APGD) that must agree on the
// contact velocities ξ, which are unique even where W is rank-deficient and λ is not.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "grbd/contact/fclib.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd_test/fclib_data.hpp"

namespace {

using grbd::Vector3;
using grbd::contact::LocalProblem;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

using grbd::test::norm;
using grbd::test::to_tolerance;

using grbd::test::fclib_file;

/// Solves, then checks the result independently: the residual recomputed from ξ = Wλ + q, the
/// percussions inside the cone, and the Siconos bound. `solver` is "SOR" or "APGD". Returns ξ.
std::vector<Vector3> solve_and_check(const LocalProblem& problem, const std::string& solver,
                                     double siconos_residual, int max_iterations) {
  std::vector<Vector3> lambda;
  // Ask for a little less than Siconos reached, so that meeting the criterion meets the bound.
  const SolverOptions options = to_tolerance(0.9 * siconos_residual, max_iterations);
  const SolverResult result = solver == "SOR" ? grbd::contact::solve_sor(problem, lambda, options)
                                              : grbd::contact::solve_apgd(problem, lambda, options);
  EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
  const std::vector<Vector3> xi = grbd::contact::local_velocities(problem, lambda);
  const double residual = grbd::contact::natural_map_residual(lambda, xi, problem.mu);
  const double norm_q = norm(problem.q);
  EXPECT_LE(residual / norm_q, siconos_residual) << solver;
  EXPECT_NEAR(residual, result.residual, 1e-12 * norm_q) << solver;
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    EXPECT_LE(lambda[i].tail<2>().norm(), problem.mu[i] * lambda[i](0) * (1 + 1e-12) + 1e-15)
        << solver << ": contact " << i << " outside the Coulomb cone";
  }
  return xi;
}

void expect_same_velocities(const std::vector<Vector3>& a, const std::vector<Vector3>& b,
                            double relative) {
  double diff = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) diff += (a[i] - b[i]).squaredNorm();
  EXPECT_LE(std::sqrt(diff), relative * norm(a));
}

/// Reads `file` (n contacts), solves it with SOR and with APGD to the Siconos residual, and
/// checks that the two agree on ξ to `agreement` relative.
void expect_siconos_residual_with_sor_and_apgd(const std::string& file, std::size_t n,
                                               double siconos_residual, int max_iterations,
                                               double agreement) {
  const LocalProblem problem = grbd::contact::read_fclib_as_local(fclib_file(file));
  ASSERT_EQ(problem.q.size(), n);
  const auto xi_sor = solve_and_check(problem, "SOR", siconos_residual, max_iterations);
  const auto xi_apgd = solve_and_check(problem, "APGD", siconos_residual, max_iterations);
  expect_same_velocities(xi_sor, xi_apgd, agreement);
}

TEST(FclibSolve, PerioBox60ReachesSiconosResidualWithSorAndApgd) {
  expect_siconos_residual_with_sor_and_apgd("LMGC_100_PR_PerioBox-i00361-60-03000.hdf5", 60, 4.6e-8,
                                            20000, 1e-5);
}

TEST(FclibSolve, Capsules286ReachesSiconosResidualWithSorAndApgd) {
  expect_siconos_residual_with_sor_and_apgd("Capsules-i125-1213.hdf5", 286, 2.7e-10, 40000, 1e-6);
}

TEST(FclibSolve, Spheres356GlobalReachesSiconosResidualWithSorAndApgd) {
  expect_siconos_residual_with_sor_and_apgd("Spheres-i099-356-679.hdf5", 356, 1.1e-8, 20000, 1e-5);
}

TEST(FclibSolve, NonConvergenceIsReportedNotHidden) {
  const LocalProblem problem =
      grbd::contact::read_fclib_as_local(fclib_file("Capsules-i125-1213.hdf5"));
  std::vector<Vector3> lambda;
  const SolverResult result = grbd::contact::solve_sor(problem, lambda, to_tolerance(1e-10, 50));
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 50);
  EXPECT_GT(result.relative_residual(), 1e-10);
  EXPECT_NE(grbd::contact::describe(result).find("did NOT converge"), std::string::npos);
}

}  // namespace
