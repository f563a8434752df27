// Chapter 5: the one driver behind SOR, JOR and APGD, its hooks (SolverHooks) and the reusable
// ContactSolver, and the safe default r-factors of JOR.
//
// Independent references:
// - hand-made iterations: SOR is r_factors() + velocities_from_percussions() + sor_sweep()
//   repeated, written out here, and the solver must give the same bits;
// - the call log of the hooks (which k, how often) against the iteration count of the result;
// - u = u_free + M⁻¹ W Λ recomputed with velocities_from_percussions() at every hook call;
// - the dense Delassus matrix G and its largest eigenvalue (Eigen's SelfAdjointEigenSolver) for
//   the spectral r-factors: JOR is a contraction on frictionless problems for r λ_max(G) < 2;
// - the contact law through the natural-map residual for "converges": ‖F‖/‖c‖ small.
//
// Every JOR-default test also checks that the old default (α = 1, r per contact) diverges on
// the same problem, so it would fail if the problem were too easy to show the difference.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "grbd/contact/fclib.hpp"
#include "grbd/contact/local_problem.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/contact_problems.hpp"
#include "grbd_test/fclib_data.hpp"
#include "grbd_test/random.hpp"
#include "sphere_pile.hpp"

namespace {

using grbd::Matrix3;
using grbd::Vector3;
using grbd::Vector6;
using grbd::contact::ContactProblem;
using grbd::contact::ContactSolution;
using grbd::contact::ContactSolver;
using grbd::contact::Criterion;
using grbd::contact::InverseMass;
using grbd::contact::IterationStatus;
using grbd::contact::LocalProblem;
using grbd::contact::Method;
using grbd::contact::ProxForm;
using grbd::contact::RFactorStrategy;
using grbd::contact::SolverHooks;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

constexpr Method kAllMethods[] = {Method::sor, Method::jor, Method::apgd, Method::newton};
constexpr Criterion kAllCriteria[] = {Criterion::percussion_change, Criterion::velocity_change,
                                      Criterion::natural_residual};

std::string name(Method m) { return std::string(grbd::contact::method_name(m)); }

// A small frictional body-form problem: 12 random contacts (seeded).
ContactProblem small_problem(std::uint64_t seed = 6100, double mu_max = 0.8) {
  grbd::test::Random rng(seed);
  grbd::test::RandomProblemSpec spec;
  spec.contacts = 12;
  spec.bodies = 12 + 12 / 4 + 1;
  spec.mu_max = mu_max;
  return grbd::test::random_problem(rng, spec);
}

// A frictional pyramid of 14 spheres on the ground (μ = 0.5): many contacts per sphere.
ContactProblem pyramid_problem() {
  return grbd::test::sphere_pyramid(3, 0.1, 0.3, 9.81 * 0.01, {0.5, 0.0, 0.0}).problem;
}

// Options that stop early under every method (so that the hook log is short but not trivial).
SolverOptions quick(Method m, Criterion criterion = Criterion::percussion_change) {
  SolverOptions o;
  o.criterion = criterion;
  o.rel_tol = 1e-8;
  o.abs_tol = 0.0;
  o.max_iterations = 5000;
  if (m == Method::jor) o.alpha = 0.5;  // spectral r (automatic): any α in (0, 2) is safe
  // Newton's iterates go on moving at the rounding level of the velocities that are zero at the
  // solution (sticking contacts): a change criterion needs an absolute tolerance with it.
  if (m == Method::newton) o.abs_tol = 1e-14;
  return o;
}

SolverResult solve(Method m, const ContactProblem& p, ContactSolution& s, const SolverOptions& o) {
  switch (m) {
    case Method::sor:
      return grbd::contact::solve_sor(p, s, o);
    case Method::jor:
      return grbd::contact::solve_jor(p, s, o);
    case Method::apgd:
      return grbd::contact::solve_apgd(p, s, o);
    case Method::newton:
      return grbd::contact::solve_newton(p, s, o);
  }
  return {};
}

double max_abs_difference(const std::vector<Vector6>& a, const std::vector<Vector6>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).cwiseAbs().maxCoeff());
  return d;
}

double max_abs(const std::vector<Vector6>& a) {
  double d = 0.0;
  for (const Vector6& x : a) d = std::max(d, x.cwiseAbs().maxCoeff());
  return d;
}

// Bitwise equality of two arrays of fixed-size vectors (EXPECT_EQ on each double).
template <class V>
::testing::AssertionResult same_bits(const std::vector<V>& a, const std::vector<V>& b) {
  if (a.size() != b.size()) {
    return ::testing::AssertionFailure() << "sizes " << a.size() << " and " << b.size();
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (Eigen::Index k = 0; k < a[i].size(); ++k) {
      if (!(a[i](k) == b[i](k))) {
        return ::testing::AssertionFailure()
               << "entry " << i << "(" << k << "): " << a[i](k) << " != " << b[i](k);
      }
    }
  }
  return ::testing::AssertionSuccess();
}

using grbd::test::fclib_file;

// ---------------------------------------------------------------------------------------------
// SOR through the driver is the hand-made loop of sor_sweep()
// ---------------------------------------------------------------------------------------------

// Reference: the SOR iteration written out: r-factors per contact, u = u_free + M⁻¹ W Λ₀, then
// exactly N sweeps. solve_sor() with min_iterations = max_iterations = N, and ContactSolver, must
// give the same bits in Λ and u (from a zero and from a nonzero initial guess, both prox forms).
TEST(SolverDriver, SorIsBitIdenticalToHandMadeSweeps) {
  const ContactProblem problem = small_problem();
  constexpr int kSweeps = 17;
  for (const ProxForm form : {ProxForm::alart_curnier, ProxForm::de_saxce}) {
    for (const bool warm : {false, true}) {
      SCOPED_TRACE(std::string("form ") + std::to_string(static_cast<int>(form)) +
                   (warm ? ", warm" : ", cold"));
      std::vector<Vector3> guess(problem.contacts.size(), Vector3::Zero());
      if (warm) {
        for (std::size_t i = 0; i < guess.size(); ++i) guess[i] = Vector3(0.1 * (i % 3), 0.01, 0.0);
      }
      // By hand.
      std::vector<Vector3> lambda = guess;
      std::vector<Vector6> u = grbd::contact::velocities_from_percussions(problem, lambda);
      const auto r = grbd::contact::r_factors(problem, RFactorStrategy::per_contact, 0.7);
      for (int k = 0; k < kSweeps; ++k) grbd::contact::sor_sweep(problem, r, form, u, lambda);
      // Through the driver.
      SolverOptions o;
      o.form = form;
      o.alpha = 0.7;
      o.min_iterations = kSweeps;
      o.max_iterations = kSweeps;
      ContactSolution once{guess, {}};
      const SolverResult result = grbd::contact::solve_sor(problem, once, o);
      EXPECT_EQ(result.iterations, kSweeps);
      EXPECT_TRUE(same_bits(once.lambda, lambda));
      EXPECT_TRUE(same_bits(once.u, u));
      ContactSolver solver(Method::sor, o);
      for (int repeat = 0; repeat < 2; ++repeat) {  // the second solve reuses the workspace
        ContactSolution reused{guess, {}};
        solver.solve(problem, reused);
        EXPECT_TRUE(same_bits(reused.lambda, lambda)) << "solve " << repeat + 1;
        EXPECT_TRUE(same_bits(reused.u, u)) << "solve " << repeat + 1;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Hooks
// ---------------------------------------------------------------------------------------------

// Reference: the declaration of SolverHooks::after_iteration: once after every iteration, with
// k = 1, 2, …, result.iterations, Λ of one entry per contact and, in the body form, u up to date
// with Λ (u_free + M⁻¹ W Λ recomputed independently); in the local form u is empty. Every
// method, every criterion.
TEST(SolverDriver, AfterIterationIsCalledOncePerIterationWithCurrentVelocities) {
  const ContactProblem problem = small_problem();
  const LocalProblem local = grbd::test::to_local_form(problem);
  for (const Method method : kAllMethods) {
    for (const Criterion criterion : kAllCriteria) {
      SCOPED_TRACE(name(method) + ", criterion " + std::to_string(static_cast<int>(criterion)));
      std::vector<int> calls;
      double worst_u = 0.0;
      SolverHooks hooks;
      hooks.after_iteration = [&](int k, std::span<Vector3> lambda, std::span<Vector6> u) {
        calls.push_back(k);
        ASSERT_EQ(lambda.size(), problem.contacts.size());
        ASSERT_EQ(u.size(), problem.M_inv.size());
        const std::vector<Vector6> expected = grbd::contact::velocities_from_percussions(
            problem, std::vector<Vector3>(lambda.begin(), lambda.end()));
        worst_u = std::max(worst_u, max_abs_difference(std::vector<Vector6>(u.begin(), u.end()),
                                                       expected) /
                                        std::max(1.0, max_abs(expected)));
      };
      ContactSolver solver(method, quick(method, criterion), hooks);
      ContactSolution solution;
      const SolverResult result = solver.solve(problem, solution);
      EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
      EXPECT_GT(result.iterations, 1);
      ASSERT_EQ(calls.size(), static_cast<std::size_t>(result.iterations));
      for (std::size_t k = 0; k < calls.size(); ++k) EXPECT_EQ(calls[k], static_cast<int>(k) + 1);
      EXPECT_LE(worst_u, 1e-12);

      // The local form: the same log, u empty.
      std::vector<int> local_calls;
      SolverHooks local_hooks;
      local_hooks.after_iteration = [&](int k, std::span<Vector3> lambda, std::span<Vector6> u) {
        local_calls.push_back(k);
        EXPECT_EQ(lambda.size(), local.q.size());
        EXPECT_TRUE(u.empty());
      };
      ContactSolver local_solver(method, quick(method, criterion), local_hooks);
      std::vector<Vector3> lambda;
      const SolverResult local_result = local_solver.solve(local, lambda);
      EXPECT_TRUE(local_result.converged) << grbd::contact::describe(local_result);
      ASSERT_EQ(local_calls.size(), static_cast<std::size_t>(local_result.iterations));
      for (std::size_t k = 0; k < local_calls.size(); ++k) {
        EXPECT_EQ(local_calls[k], static_cast<int>(k) + 1);
      }
    }
  }
}

// Reference: the declaration of SolverHooks::global_status: it is asked once per iteration
// and its answer is the verdict. Answering false keeps every method going to max_iterations and
// reports non-convergence, although the local verdict was true (the hook saw it); answering true
// stops at once. Every method, every criterion, both forms.
TEST(SolverDriver, GlobalVerdictOverridesTheLocalOne) {
  const ContactProblem problem = small_problem();
  const LocalProblem local = grbd::test::to_local_form(problem);
  for (const Method method : kAllMethods) {
    for (const Criterion criterion : kAllCriteria) {
      SCOPED_TRACE(name(method) + ", criterion " + std::to_string(static_cast<int>(criterion)));
      SolverOptions o = quick(method, criterion);
      // Enough iterations that every method converges locally well before them.
      ContactSolution probe;
      const SolverResult free_run = ContactSolver(method, o).solve(problem, probe);
      ASSERT_TRUE(free_run.converged) << grbd::contact::describe(free_run);
      o.max_iterations = free_run.iterations + 40;

      int asked = 0;
      int locally_true = 0;
      SolverHooks never;
      never.global_status = [&](IterationStatus local) {
        ++asked;
        locally_true += local == IterationStatus::converged ? 1 : 0;
        return IterationStatus::running;
      };
      ContactSolution solution;
      const SolverResult result = ContactSolver(method, o, never).solve(problem, solution);
      EXPECT_FALSE(result.converged) << grbd::contact::describe(result);
      EXPECT_FALSE(result.diverged);
      EXPECT_EQ(result.iterations, o.max_iterations);
      EXPECT_EQ(asked, o.max_iterations);
      EXPECT_GT(locally_true, 0);
      EXPECT_NE(grbd::contact::describe(result).find("did NOT converge"), std::string::npos);

      std::vector<Vector3> lambda;
      asked = 0;
      const SolverResult local_result = ContactSolver(method, o, never).solve(local, lambda);
      EXPECT_FALSE(local_result.converged);
      EXPECT_EQ(local_result.iterations, o.max_iterations);
      EXPECT_EQ(asked, o.max_iterations);

      SolverHooks always;
      always.global_status = [](IterationStatus) { return IterationStatus::converged; };
      ContactSolution stopped;
      const SolverResult first = ContactSolver(method, o, always).solve(problem, stopped);
      EXPECT_TRUE(first.converged);
      EXPECT_EQ(first.iterations, 1);
    }
  }
}

// Reference: the declaration of SolverHooks::global_status, the contract chapter 8's MPI reduction
// relies on. A divergence elsewhere (the hook answers diverged) stops every method at once as
// diverged; a local divergence is still reported to the hook, once, in the iteration where it
// happens, so that the other processes are not left waiting in their reduction; an answer
// outside the enumerators is refused.
TEST(SolverDriver, DivergenceIsPartOfTheGlobalVerdict) {
  const ContactProblem problem = small_problem();
  for (const Method method : kAllMethods) {
    SCOPED_TRACE(name(method));
    SolverOptions o = quick(method, Criterion::percussion_change);
    o.max_iterations = 500;
    std::vector<IterationStatus> seen;
    SolverHooks remote;
    remote.global_status = [&](IterationStatus local) {
      seen.push_back(local);
      return seen.size() == 3 ? IterationStatus::diverged : IterationStatus::running;
    };
    ContactSolution solution;
    const SolverResult result = ContactSolver(method, o, remote).solve(problem, solution);
    EXPECT_TRUE(result.diverged);
    EXPECT_FALSE(result.converged);
    EXPECT_EQ(result.iterations, 3);
    ASSERT_EQ(seen.size(), 3u);
    EXPECT_NE(seen[2], IterationStatus::diverged);  // this process was fine

    // A local divergence: masses of 10³⁰⁰ kg and velocities of 10³⁰⁰ m/s overflow λ at once.
    ContactProblem huge = problem;
    for (InverseMass& M : huge.M_inv) {
      M.inv_m *= 1e-300;
      M.K_Theta_inv *= 1e-300;
    }
    for (Vector6& u : huge.u_free) u *= 1e300;
    seen.clear();
    SolverHooks reporting;
    reporting.global_status = [&](IterationStatus local) {
      seen.push_back(local);
      return local;
    };
    ContactSolution blown;
    const SolverResult local = ContactSolver(method, o, reporting).solve(huge, blown);
    EXPECT_TRUE(local.diverged) << grbd::contact::describe(local);
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.back(), IterationStatus::diverged);
    EXPECT_EQ(static_cast<int>(seen.size()), local.iterations);

    SolverHooks broken;
    broken.global_status = [](IterationStatus) { return static_cast<IterationStatus>(7); };
    ContactSolution unused;
    EXPECT_THROW(ContactSolver(method, o, broken).solve(problem, unused), grbd::InvalidArgument);
  }
}

// Reference: a hand-made SOR loop with the same change of u between sweeps. A hook that
// replaces the velocities of two bodies by their average (what split-body averaging does in
// chapter 8) must be seen by the next sweep: the solver gives the bits of the hand-made loop,
// and not those of plain SOR.
TEST(SolverDriver, ChangesOfVelocitiesInTheHookAreSeenByTheNextSorSweep) {
  const ContactProblem problem = small_problem(6110);
  constexpr int kSweeps = 12;
  // Two bodies that touch something: side a of contacts 0 and 1.
  const auto b0 = static_cast<std::size_t>(problem.contacts[0].body_a);
  const auto b1 = static_cast<std::size_t>(problem.contacts[1].body_a);
  ASSERT_NE(b0, b1);
  const auto average = [b0, b1](std::span<Vector6> u) {
    const Vector6 mean = 0.5 * (u[b0] + u[b1]);
    u[b0] = mean;
    u[b1] = mean;
  };
  std::vector<Vector3> lambda(problem.contacts.size(), Vector3::Zero());
  std::vector<Vector6> u = grbd::contact::velocities_from_percussions(problem, lambda);
  const auto r = grbd::contact::r_factors(problem, RFactorStrategy::per_contact, 1.0);
  for (int k = 0; k < kSweeps; ++k) {
    grbd::contact::sor_sweep(problem, r, ProxForm::alart_curnier, u, lambda);
    average(u);
  }
  SolverOptions o;
  o.min_iterations = kSweeps;
  o.max_iterations = kSweeps;
  SolverHooks hooks;
  hooks.after_iteration = [&](int, std::span<Vector3>, std::span<Vector6> v) { average(v); };
  ContactSolution averaged;
  ContactSolver(Method::sor, o, hooks).solve(problem, averaged);
  EXPECT_TRUE(same_bits(averaged.lambda, lambda));
  EXPECT_TRUE(same_bits(averaged.u, u));
  ContactSolution plain;
  ContactSolver(Method::sor, o).solve(problem, plain);
  EXPECT_FALSE(same_bits(plain.lambda, lambda)) << "the averaging changed nothing: a weak test";
}

// ---------------------------------------------------------------------------------------------
// ContactSolver
// ---------------------------------------------------------------------------------------------

// Reference: ContactSolver::solve(). solve_prepared() with G_ii = delassus_block() gives the same
// bits (Λ, u, iterations, residual), every method, on the pyramid and a random problem; and
// refuses a G of the wrong length.
TEST(SolverDriver, SolvePreparedIsBitIdenticalToSolve) {
  for (const ContactProblem& problem : {small_problem(), pyramid_problem()}) {
    std::vector<Matrix3> G;
    for (const auto& c : problem.contacts) {
      G.push_back(grbd::contact::delassus_block(c, problem.M_inv));
    }
    for (const Method method : kAllMethods) {
      SCOPED_TRACE(name(method));
      ContactSolver solver(method, quick(method));
      ContactSolution a;
      ContactSolution b;
      const SolverResult ra = solver.solve(problem, a);
      const SolverResult rb = solver.solve_prepared(problem, G, b);
      EXPECT_GT(ra.iterations, 1);
      EXPECT_EQ(ra.iterations, rb.iterations);
      EXPECT_EQ(ra.residual, rb.residual);
      EXPECT_TRUE(same_bits(a.lambda, b.lambda));
      EXPECT_TRUE(same_bits(a.u, b.u));
      // And the free function agrees with both.
      ContactSolution c;
      const SolverResult rc = solve(method, problem, c, quick(method));
      EXPECT_EQ(rc.iterations, ra.iterations);
      EXPECT_TRUE(same_bits(c.lambda, a.lambda));
      std::vector<Matrix3> short_G(G.begin(), G.end() - 1);
      ContactSolution d;
      EXPECT_THROW(solver.solve_prepared(problem, short_G, d), grbd::InvalidArgument);
    }
  }
}

// Reference: the declarations: names of the methods, the accessors, and the refusal of bad
// options (once, in the constructor) and of a method outside the enumerators.
TEST(SolverDriver, ConstructorValidatesOnceAndNamesTheMethod) {
  EXPECT_EQ(grbd::contact::method_name(Method::sor), "SOR");
  EXPECT_EQ(grbd::contact::method_name(Method::jor), "JOR");
  EXPECT_EQ(grbd::contact::method_name(Method::apgd), "APGD");
  EXPECT_EQ(grbd::contact::method_name(Method::newton), "Newton");
  SolverOptions o;
  o.alpha = 0.4;
  o.r_strategy = RFactorStrategy::spectral;
  const ContactSolver solver(Method::jor, o);
  EXPECT_EQ(solver.method(), Method::jor);
  EXPECT_EQ(solver.options().alpha, 0.4);
  EXPECT_EQ(solver.options().r_strategy, RFactorStrategy::spectral);
  EXPECT_EQ(SolverOptions{}.r_strategy, RFactorStrategy::automatic);
  SolverOptions bad;
  bad.alpha = 2.0;
  EXPECT_THROW((void)ContactSolver(Method::sor, bad), grbd::InvalidArgument);
  bad = {};
  bad.r_strategy = static_cast<RFactorStrategy>(17);
  EXPECT_THROW((void)ContactSolver(Method::sor, bad), grbd::InvalidArgument);
  EXPECT_THROW((void)ContactSolver(static_cast<Method>(9)), grbd::InvalidArgument);
  EXPECT_THROW(grbd::contact::method_name(static_cast<Method>(9)), grbd::InvalidArgument);
  // Every strategy is accepted by every method.
  const ContactProblem problem = small_problem();
  for (const Method method : kAllMethods) {
    for (const RFactorStrategy s : {RFactorStrategy::per_contact, RFactorStrategy::global,
                                    RFactorStrategy::spectral, RFactorStrategy::automatic}) {
      SolverOptions each;
      each.r_strategy = s;
      each.alpha = 0.3;
      ContactSolution solution;
      EXPECT_NO_THROW(ContactSolver(method, each).solve(problem, solution));
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Safe defaults for JOR
// ---------------------------------------------------------------------------------------------

// Reference: λ_max(G) of the dense G (Eigen). The spectral r satisfies
// α/kSafety ≤ r λ_max(G) ≤ α: the power-iteration estimate never exceeds λ_max and (here) comes
// within the safety factor of it, so r λ_max < 2 for every α < 2. `automatic` in r_factors() is
// SOR's choice, per contact.
TEST(SolverRFactors, SpectralStrategyBoundsTheLargestEigenvalue) {
  for (const ContactProblem& problem : {small_problem(), pyramid_problem()}) {
    const Eigen::MatrixXd G = grbd::test::dense_delassus(problem);
    const double lambda_max = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G).eigenvalues().maxCoeff();
    for (const double alpha : {0.5, 1.0, 1.9}) {
      const auto r = grbd::contact::r_factors(problem, RFactorStrategy::spectral, alpha);
      ASSERT_EQ(r.size(), problem.contacts.size());
      for (const auto& ri : r) {
        EXPECT_EQ(ri.r_N, r[0].r_N);
        EXPECT_EQ(ri.r_T, r[0].r_N);
      }
      EXPECT_GE(r[0].r_N * lambda_max, alpha / grbd::contact::spectral::kSafety * (1 - 1e-12));
      EXPECT_LE(r[0].r_N * lambda_max, alpha * (1 + 1e-12));
      const auto automatic = grbd::contact::r_factors(problem, RFactorStrategy::automatic, alpha);
      const auto per_contact = grbd::contact::r_factors(problem, RFactorStrategy::per_contact, alpha);
      for (std::size_t i = 0; i < r.size(); ++i) {
        EXPECT_EQ(automatic[i].r_N, per_contact[i].r_N);
        EXPECT_EQ(automatic[i].r_T, per_contact[i].r_T);
      }
    }
  }
}

// ‖F(Λ)‖ recomputed from u = u_free + M⁻¹ W Λ and ξ = Wᵀ u + ε ∘ γ_A (problem.hpp), relative to
// ‖c‖ = ‖ξ(0)‖.
double relative_residual(const ContactProblem& problem, const std::vector<Vector3>& lambda) {
  const auto xi = grbd::contact::contact_velocities(
      problem, grbd::contact::velocities_from_percussions(problem, lambda));
  const auto c = grbd::contact::contact_velocities(problem, problem.u_free);
  std::vector<double> mu;
  for (const auto& contact : problem.contacts) mu.push_back(contact.mu);
  double norm_c = 0.0;
  for (const Vector3& x : c) norm_c += x.squaredNorm();
  return grbd::contact::natural_map_residual(lambda, xi, mu) / std::sqrt(norm_c);
}

// Reference: the natural-map residual, recomputed. On small piles of FCC cells (μ = 0.5; 2 × 1 × 1
// cells: 8 spheres, 20 contacts; 1 × 1 × 2: 8 spheres, 18 contacts), JOR with α = 1 and r per
// contact (the default before `automatic`) diverges and says so (measured: after 9350 and 3581
// iterations); JOR with default SolverOptions converges within the default max_iterations
// (measured: 657 and 417), and with the natural-residual criterion to ‖F‖ ≤ 1e-8 ‖c‖. On the
// 2 × 2 × 2 pile (116 contacts) the defaults need more than the default 1000 iterations
// (measured: 3667); with max_iterations raised they converge, and α = 1 per contact diverges.
TEST(SolverJorDefaults, ConvergeOnSpherePilesWhereAlphaOnePerContactDiverges) {
  struct Pile {
    int nx, ny, nz;
    int max_iterations;  // for the default criterion
  };
  for (const Pile& size : {Pile{2, 1, 1, 1000}, Pile{1, 1, 2, 1000}, Pile{2, 2, 2, 20000}}) {
    SCOPED_TRACE("pile " + std::to_string(size.nx) + " x " + std::to_string(size.ny) + " x " +
                 std::to_string(size.nz));
    const grbd::demo::SpherePile pile = grbd::demo::sphere_pile(size.nx, size.ny, size.nz);
    const ContactProblem& problem = pile.problem;
    ASSERT_GE(problem.contacts.size(), 18U);

    SolverOptions old_default;
    old_default.r_strategy = RFactorStrategy::per_contact;
    old_default.max_iterations = 100000;
    ContactSolution diverging;
    const SolverResult old = grbd::contact::solve_jor(problem, diverging, old_default);
    EXPECT_TRUE(old.diverged) << grbd::contact::describe(old);
    EXPECT_FALSE(old.converged);

    SolverOptions defaults;
    defaults.max_iterations = size.max_iterations;
    ContactSolution solution;
    const SolverResult result = grbd::contact::solve_jor(problem, solution, defaults);
    EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
    EXPECT_FALSE(result.diverged);
    EXPECT_LE(relative_residual(problem, solution.lambda), 2e-3);

    SolverOptions natural;
    natural.criterion = Criterion::natural_residual;
    natural.abs_tol = 0.0;
    natural.rel_tol = 1e-8;
    natural.max_iterations = 100000;
    ContactSolution accurate;
    const SolverResult jor = grbd::contact::solve_jor(problem, accurate, natural);
    EXPECT_TRUE(jor.converged) << grbd::contact::describe(jor);
    EXPECT_LE(relative_residual(problem, accurate.lambda), 1e-8 * (1 + 1e-6));
  }
}

// Reference: the natural-map residual recomputed from ξ = W λ + q (local_velocities). On the
// FCLIB problems Capsules-286 and PerioBox-60, where JOR with α = 1 per contact diverges
// (measured: after 1814 and 817 iterations), JOR with the default α and r-strategy converges
// under the natural-residual criterion to ‖F‖ ≤ 1e-6 ‖q‖ (measured: 3514 and 11372 iterations).
// (On Spheres-356 JOR converges with both.)
TEST(SolverJorDefaults, ConvergeOnFclibProblemsWhereAlphaOnePerContactDiverges) {
  for (const char* file :
       {"Capsules-i125-1213.hdf5", "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5"}) {
    SCOPED_TRACE(file);
    const LocalProblem problem = grbd::contact::read_fclib_as_local(fclib_file(file));
    SolverOptions old_default;
    old_default.r_strategy = RFactorStrategy::per_contact;
    old_default.max_iterations = 100000;
    std::vector<Vector3> diverging;
    const SolverResult old = grbd::contact::solve_jor(problem, diverging, old_default);
    EXPECT_TRUE(old.diverged) << grbd::contact::describe(old);

    SolverOptions o;
    o.criterion = Criterion::natural_residual;
    o.abs_tol = 0.0;
    o.rel_tol = 1e-6;
    o.max_iterations = 100000;
    std::vector<Vector3> lambda;
    const SolverResult result = grbd::contact::solve_jor(problem, lambda, o);
    EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
    const std::vector<Vector3> xi = grbd::contact::local_velocities(problem, lambda);
    double norm_q = 0.0;
    for (const Vector3& q : problem.q) norm_q += q.squaredNorm();
    norm_q = std::sqrt(norm_q);
    EXPECT_LE(grbd::contact::natural_map_residual(lambda, xi, problem.mu), 1e-6 * norm_q);
  }
}

}  // namespace
