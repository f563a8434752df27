// Chapter 5: ContactSolver keeps its buffers between solves. After a first solve, a second solve
// of a problem of the same or smaller size performs no heap allocation, with every method and
// every stopping criterion, in the body form (solve, solve_prepared, with hooks set) and in the
// local form.
//
// Reference: a counting replacement of the global operator new, all its forms
// (grbd_demo/allocation_counter.hpp, shared with chapter 6). It lives in
// this executable of its own, so that it counts no other test. The counter is checked to work:
// a std::vector of the test's own counts.

#include <gtest/gtest.h>

#include <span>
#include <vector>

#include "grbd/contact/local_problem.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd_test/contact_problems.hpp"
#include "grbd_test/random.hpp"
#include "grbd_demo/allocation_counter.hpp"


namespace {

using grbd::Matrix3;
using grbd::Vector3;
using grbd::Vector6;
using grbd::contact::ContactProblem;
using grbd::contact::ContactSolution;
using grbd::contact::ContactSolver;
using grbd::contact::Criterion;
using grbd::contact::IterationStatus;
using grbd::contact::LocalProblem;
using grbd::contact::Method;
using grbd::contact::SolverHooks;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

/// Heap allocations made by `call`.
template <class F>
long allocations_of(F&& call) {
  const long before = grbd::demo::allocations();
  call();
  return grbd::demo::allocations() - before;
}

ContactProblem random_problem(int contacts, std::uint64_t seed) {
  grbd::test::Random rng(seed);
  grbd::test::RandomProblemSpec spec;
  spec.contacts = contacts;
  spec.bodies = contacts + contacts / 4 + 1;
  spec.mu_max = 0.8;
  return grbd::test::random_problem(rng, spec);
}

TEST(SolverAllocations, TheCounterCounts) {
  EXPECT_GE(allocations_of([] { std::vector<double> v(100); v[3] = 1.0; }), 1);
}

TEST(SolverAllocations, SecondSolveOfTheSameOrSmallerSizeAllocatesNothing) {
  // 5 spheres, 12 contacts: smaller than `big` (51 bodies, 40 contacts).
  const ContactProblem pyramid =
      grbd::test::sphere_pyramid(2, 0.1, 0.3, 9.81 * 0.01, {0.5, 0.0, 0.0}).problem;
  const ContactProblem big = random_problem(40, 6200);
  const ContactProblem smaller = random_problem(25, 6201);
  std::vector<Matrix3> G;
  for (const auto& c : big.contacts) G.push_back(grbd::contact::delassus_block(c, big.M_inv));
  ASSERT_LT(pyramid.contacts.size(), big.contacts.size());
  ASSERT_LT(pyramid.M_inv.size(), big.M_inv.size());
  const LocalProblem local = grbd::test::to_local_form(big);
  const LocalProblem local_smaller = grbd::test::to_local_form(smaller);

  for (const Method method : {Method::sor, Method::jor, Method::apgd}) {
    for (const Criterion criterion :
         {Criterion::percussion_change, Criterion::velocity_change, Criterion::natural_residual}) {
      SCOPED_TRACE(std::string(grbd::contact::method_name(method)) + ", criterion " +
                   std::to_string(static_cast<int>(criterion)));
      SolverOptions o;
      o.criterion = criterion;
      o.max_iterations = 300;
      int calls = 0;
      bool verdicts = false;
      SolverHooks hooks;
      hooks.after_iteration = [&calls](int, std::span<Vector3>, std::span<Vector6>) { ++calls; };
      hooks.global_status = [&verdicts](IterationStatus local) {
        verdicts = verdicts || local == IterationStatus::converged;
        return local;
      };
      ContactSolver solver(method, o, hooks);
      ContactSolution solution;
      SolverResult result;
      solver.solve(big, solution);  // the first solve sizes the workspace
      solution.lambda.clear();      // a cold start again; the capacity stays
      EXPECT_EQ(allocations_of([&] { result = solver.solve(big, solution); }), 0);
      EXPECT_GT(result.iterations, 1);
      EXPECT_GT(calls, result.iterations);  // the hooks ran during the counted solve
      // Warm from the previous solution, through solve_prepared().
      EXPECT_EQ(allocations_of([&] { result = solver.solve_prepared(big, G, solution); }), 0);
      // A smaller problem and the pyramid (fewer contacts and bodies).
      solution.lambda.clear();
      EXPECT_EQ(allocations_of([&] { result = solver.solve(smaller, solution); }), 0);
      solution.lambda.clear();
      EXPECT_EQ(allocations_of([&] { result = solver.solve(pyramid, solution); }), 0);

      // The local form.
      ContactSolver local_solver(method, o, hooks);
      std::vector<Vector3> lambda;
      local_solver.solve(local, lambda);
      lambda.clear();
      EXPECT_EQ(allocations_of([&] { result = local_solver.solve(local, lambda); }), 0);
      lambda.clear();
      EXPECT_EQ(allocations_of([&] { result = local_solver.solve(local_smaller, lambda); }), 0);
    }
  }
}

// The free functions build a workspace for every call: they allocate (and so the counter above
// would have seen a workspace that did not keep its buffers).
TEST(SolverAllocations, OneShotSolversAllocateTheirWorkspace) {
  const ContactProblem problem = random_problem(20, 6210);
  ContactSolution solution;
  grbd::contact::solve_sor(problem, solution);
  solution.lambda.clear();
  EXPECT_GT(allocations_of([&] { grbd::contact::solve_sor(problem, solution); }), 0);
}

}  // namespace
