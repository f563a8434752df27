/// \file
/// \brief The compact (world-frame) contact problem that the stepper solves, checked against the
/// body form of chapter 5 (validated there on closed forms and FCLIB problems): the same contact
/// velocities, Delassus blocks and solutions for bodies of any inertia and orientation; the
/// isotropic fast path; divergence caught inside the sweep; validation messages.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "grbd/contact/compact.hpp"
#include "grbd/contact/delassus.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::contact {
namespace {

/// A random compact problem: `bodies` bodies with distinct principal moments (or equal ones when
/// `isotropic`), random orientations, velocities and contacts, some against the static world.
struct Random {
  CompactProblem problem;
  std::vector<InverseMass> M_inv;  // principal frame
  std::vector<Matrix3> A_IK;
};

Random random_problem(int bodies, int contacts, bool isotropic, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> positive(0.5, 2.0);
  const auto vec = [&] { return Vector3(unit(rng), unit(rng), unit(rng)); };
  Random out;
  for (int b = 0; b < bodies; ++b) {
    InverseMass M;
    M.inv_m = positive(rng);
    M.K_Theta_inv = isotropic ? Vector3::Constant(positive(rng))
                              : Vector3(positive(rng), positive(rng), positive(rng));
    kinematics::Quaternion p(unit(rng), unit(rng), unit(rng), unit(rng));
    p = p.normalized();
    const Matrix3 A = kinematics::rotation_matrix(p);
    out.M_inv.push_back(M);
    out.A_IK.push_back(A);
    out.problem.M_inv.push_back(world_inverse_mass(M, A));
    Vector6 u;
    u << vec(), vec();
    out.problem.u_free.push_back(u);
  }
  std::uniform_int_distribution<int> pick(-1, bodies - 1);
  for (int k = 0; k < contacts; ++k) {
    CompactContact c;
    do {
      c.body_a = pick(rng);
      c.body_b = pick(rng);
    } while (c.body_a == c.body_b || c.body_a == kStatic);
    c.n = vec().normalized();
    c.t1 = c.n.cross(vec()).normalized();
    c.r_a = vec();
    c.r_b = vec();
    c.xi_A = 0.1 * vec();
    c.mu = 0.3 * positive(rng);
    out.problem.contacts.push_back(c);
  }
  out.problem.isotropic = isotropic;
  return out;
}

TEST(CompactProblem, HasTheContactVelocitiesAndDelassusBlocksOfTheBodyForm) {
  const Random r = random_problem(6, 20, false, 3);
  validate(r.problem);
  const ContactProblem body = body_form(r.problem, r.M_inv, r.A_IK);
  validate(body);
  // Body velocities with ω in frame K for the body form, in frame I for the compact form.
  std::vector<Vector6> u_K(r.problem.u_free.size());
  for (std::size_t b = 0; b < u_K.size(); ++b) {
    u_K[b] << r.problem.u_free[b].head<3>(), r.A_IK[b].transpose() * r.problem.u_free[b].tail<3>();
  }
  const std::vector<Vector3> xi_body = contact_velocities(body, u_K);
  for (std::size_t i = 0; i < r.problem.contacts.size(); ++i) {
    const CompactContact& c = r.problem.contacts[i];
    const Vector3 xi = contact_velocity(c, r.problem.u_free) + c.xi_A;
    EXPECT_LE((xi - xi_body[i]).norm(), 1e-13) << "contact " << i;
    const Matrix3 G = delassus_block(c, r.problem.M_inv);
    const Matrix3 G_body = delassus_block(body.contacts[i], body.M_inv);
    EXPECT_LE((G - G_body).norm(), 1e-13 * G_body.norm()) << "contact " << i;
    EXPECT_LE((G - G.transpose()).norm(), 1e-15 * G.norm());
    EXPECT_LE((delassus_diagonal(c, r.problem.M_inv) - G.diagonal()).norm(), 1e-14 * G.norm());
  }
  // The assembled W of both forms: one matrix, block by block (the body form's W is checked
  // against the bodies' velocity response in chapter 5's tests).
  grbd::contact::BlockSparseMatrix W_compact, W_body;
  grbd::contact::assemble_delassus(r.problem, W_compact);
  grbd::contact::assemble_delassus(body, W_body);
  ASSERT_EQ(W_compact.row_start, W_body.row_start);
  ASSERT_EQ(W_compact.column, W_body.column);
  ASSERT_EQ(W_compact.diagonal, W_body.diagonal);
  for (std::size_t k = 0; k < W_body.blocks.size(); ++k) {
    EXPECT_LE((W_compact.blocks[k] - W_body.blocks[k]).norm(), 1e-13 * (1.0 + W_body.blocks[k].norm()))
        << "block " << k;
  }
}

TEST(CompactProblem, SolvesToTheSolutionOfTheBodyFormWithEveryMethod) {
  const Random r = random_problem(8, 24, false, 5);
  const ContactProblem body = body_form(r.problem, r.M_inv, r.A_IK);
  SolverOptions options;
  options.abs_tol = 1e-14;
  options.rel_tol = 1e-12;
  options.max_iterations = 200000;
  options.criterion = Criterion::natural_residual;
  // Newton three ways: GMRES (W never formed), the sparse LU of the assembled W, the hybrid.
  struct Variant {
    Method method;
    grbd::contact::LinearSolver linear = grbd::contact::LinearSolver::automatic;
    int hybrid_sweeps = 0;
  };
  for (const Variant variant :
       {Variant{Method::sor}, Variant{Method::jor}, Variant{Method::apgd},
        Variant{Method::newton, grbd::contact::LinearSolver::gmres},
        Variant{Method::newton, grbd::contact::LinearSolver::direct},
        Variant{Method::newton, grbd::contact::LinearSolver::automatic, 100}}) {
    const Method method = variant.method;
    options.newton.linear_solver = variant.linear;
    options.newton.hybrid_sweeps = variant.hybrid_sweeps;
    if (method == Method::newton) options.max_iterations = 200;
    ContactSolution compact_solution;
    ContactSolution body_solution;
    ContactSolver compact_solver(method, options);
    ContactSolver body_solver(method, options);
    const SolverResult a = compact_solver.solve(r.problem, compact_solution);
    const SolverResult b = body_solver.solve(body, body_solution);
    ASSERT_TRUE(a.converged) << describe(a);
    ASSERT_TRUE(b.converged) << describe(b);
    // Both meet the same natural-map residual in their own form ...
    EXPECT_LE(a.residual, options.abs_tol + options.rel_tol * a.norm_c) << method_name(method);
    // ... and the two forms' ξ of the compact solution agree: one problem, two coordinates.
    std::vector<Vector6> u_K(compact_solution.u.size());
    for (std::size_t k = 0; k < u_K.size(); ++k) {
      u_K[k] << compact_solution.u[k].head<3>(),
          r.A_IK[k].transpose() * compact_solution.u[k].tail<3>();
    }
    const std::vector<Vector6> u_from_body_form =
        velocities_from_percussions(body, compact_solution.lambda);
    for (std::size_t k = 0; k < u_K.size(); ++k) {
      EXPECT_LE((u_K[k] - u_from_body_form[k]).norm(), 1e-12) << method_name(method);
    }
    std::vector<double> mu;
    for (const CompactContact& c : r.problem.contacts) mu.push_back(c.mu);
    const double body_residual =
        natural_map_residual(compact_solution.lambda, contact_velocities(body, u_K), mu);
    EXPECT_LE(body_residual, 1e-10 * a.norm_c) << method_name(method);
  }
}

TEST(CompactProblem, TheIsotropicSweepIsTheGeneralOneForSpheres) {
  Random r = random_problem(10, 30, true, 7);
  validate(r.problem);
  CompactProblem general = r.problem;
  general.isotropic = false;
  std::vector<RFactors> rf;
  for (const CompactContact& c : r.problem.contacts) {
    rf.push_back(r_factors(delassus_block(c, r.problem.M_inv), 1.0));
  }
  std::vector<Vector6> u1 = r.problem.u_free;
  std::vector<Vector6> u2 = r.problem.u_free;
  std::vector<Vector3> l1(r.problem.contacts.size(), Vector3::Zero());
  std::vector<Vector3> l2 = l1;
  for (int k = 0; k < 20; ++k) {
    EXPECT_TRUE(sor_sweep(r.problem, rf, ProxForm::alart_curnier, u1, l1).finite);
    EXPECT_TRUE(sor_sweep(general, rf, ProxForm::alart_curnier, u2, l2).finite);
  }
  for (std::size_t i = 0; i < l1.size(); ++i) EXPECT_LE((l1[i] - l2[i]).norm(), 1e-13);
  for (std::size_t b = 0; b < u1.size(); ++b) EXPECT_LE((u1[b] - u2[b]).norm(), 1e-13);
  // A non-isotropic body in a problem marked isotropic is refused.
  r.problem.M_inv[3].I_Theta_inv(0, 1) = r.problem.M_inv[3].I_Theta_inv(1, 0) = 0.1;
  EXPECT_THROW(validate(r.problem), InvalidArgument);
}

TEST(CompactProblem, TheSweepReportsANonFinitePercussionAndTheSolverStopsAsDiverged) {
  Random r = random_problem(4, 6, false, 9);
  std::vector<RFactors> rf(r.problem.contacts.size(), RFactors{1.0, 1.0});
  std::vector<Vector6> u = r.problem.u_free;
  std::vector<Vector3> lambda(r.problem.contacts.size(), Vector3::Zero());
  EXPECT_TRUE(sor_sweep(r.problem, rf, ProxForm::alart_curnier, u, lambda).finite);
  lambda[2](1) = std::numeric_limits<double>::infinity();
  lambda[2](0) = 1.0;
  const SweepReport report = sor_sweep(r.problem, rf, ProxForm::alart_curnier, u, lambda);
  EXPECT_FALSE(report.finite);
  EXPECT_FALSE(report.settled);  // a NaN change never counts as settled
  // Masses of 10³⁰⁰ kg (r-factors of 10³⁰⁰ kg) and velocities of 10³⁰⁰ m/s: λ = r ξ overflows in
  // the first sweep, and SOR stops there, diverged.
  for (Vector6& v : r.problem.u_free) v *= 1e300;
  for (WorldInverseMass& M : r.problem.M_inv) {
    M.inv_m *= 1e-300;
    M.I_Theta_inv *= 1e-300;
  }
  SolverOptions options;
  options.max_iterations = 50;
  ContactSolution solution;
  ContactSolver solver(Method::sor, options);
  const SolverResult result = solver.solve(r.problem, solution);
  EXPECT_TRUE(result.diverged);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 1);
}

// The sweep's own percussion test is has_converged() (chapter 5) of Λ before and after it, sweep
// by sweep, through the run from Λ = 0 to convergence; the solver that relies on it takes the
// same iterations and returns bit-identical percussions as the one that keeps a copy of Λ (a
// hook forces the copy).
TEST(CompactProblem, TheSweepAppliesThePercussionCriterionToItsOwnChange) {
  const Random r = random_problem(8, 24, false, 13);
  std::vector<RFactors> rf;
  for (const CompactContact& c : r.problem.contacts) {
    rf.push_back(r_factors(delassus_block(c, r.problem.M_inv), 1.0));
  }
  const double abs_tol = 1e-9;
  const double rel_tol = 1e-6;
  std::vector<Vector6> u = r.problem.u_free;
  std::vector<Vector3> lambda(r.problem.contacts.size(), Vector3::Zero());
  int settled = 0;
  int unsettled = 0;
  for (int k = 0; k < 400; ++k) {
    const std::vector<Vector3> before = lambda;
    const SweepReport report =
        sor_sweep(r.problem, rf, ProxForm::alart_curnier, u, lambda, abs_tol, rel_tol);
    const bool expected = has_converged(
        std::span<const double>(before.data()->data(), 3 * before.size()),
        std::span<const double>(lambda.data()->data(), 3 * lambda.size()), abs_tol, rel_tol);
    ASSERT_EQ(report.settled, expected) << "sweep " << k;
    (report.settled ? settled : unsettled) += 1;
  }
  EXPECT_GT(settled, 0);
  EXPECT_GT(unsettled, 0);

  SolverOptions options;
  options.abs_tol = abs_tol;
  options.rel_tol = rel_tol;
  options.max_iterations = 10000;
  options.criterion = Criterion::percussion_change;
  ContactSolution in_sweep;
  ContactSolution copied;
  ContactSolver plain(Method::sor, options);
  SolverHooks hooks;
  hooks.after_iteration = [](int, std::span<Vector3>, std::span<Vector6>) {};
  ContactSolver hooked(Method::sor, options, hooks);
  const SolverResult a = plain.solve(r.problem, in_sweep);
  const SolverResult b = hooked.solve(r.problem, copied);
  ASSERT_TRUE(a.converged) << describe(a);
  EXPECT_GT(a.iterations, 2);
  EXPECT_EQ(a.iterations, b.iterations);
  for (std::size_t i = 0; i < in_sweep.lambda.size(); ++i) {
    EXPECT_EQ(in_sweep.lambda[i], copied.lambda[i]) << "contact " << i;
  }
}

// The sweep's own natural-map residual (SweepReport::residual) is, contact by contact, the natural
// map of λ_i and ξ_i as the sweep found them — recomputed here from a copy of the state before
// each update — and zero at a solution. The natural-residual criterion reads it first and pays
// for ‖F‖ only where it met the tolerance: SOR stops converged, with ‖F‖ within the tolerance,
// no earlier than the first sweep whose ‖F‖ meets it (from the residual history, which evaluates
// ‖F‖ after every sweep), and at most a few sweeps later.
TEST(CompactProblem, TheSweepSumsItsNaturalResidualAndTheCriterionReadsIt) {
  const Random r = random_problem(8, 24, false, 19);
  std::vector<RFactors> rf;
  for (const CompactContact& c : r.problem.contacts) {
    rf.push_back(r_factors(delassus_block(c, r.problem.M_inv), 1.0));
  }
  std::vector<Vector6> u = r.problem.u_free;
  std::vector<Vector3> lambda(r.problem.contacts.size(), Vector3::Zero());
  for (int k = 0; k < 5; ++k) {
    // The sweep by hand: contact i sees the velocities its predecessors left.
    std::vector<Vector6> u_hand = u;
    std::vector<Vector3> lambda_hand = lambda;
    double sum = 0.0;
    for (std::size_t i = 0; i < lambda.size(); ++i) {
      const CompactContact& c = r.problem.contacts[i];
      const Vector3 xi = contact_velocity(c, u_hand) + c.xi_A;
      sum += natural_map(lambda_hand[i], xi, c.mu).squaredNorm();
      std::span<Vector6> one_u(u_hand);
      CompactProblem single = r.problem;
      single.contacts = {c};
      std::vector<RFactors> one_r{rf[i]};
      std::vector<Vector3> one_l{lambda_hand[i]};
      sor_sweep(single, one_r, ProxForm::alart_curnier, one_u, one_l);
      lambda_hand[i] = one_l[0];
    }
    const SweepReport report = sor_sweep(r.problem, rf, ProxForm::alart_curnier, u, lambda,
                                         std::numeric_limits<double>::infinity(), 0.0, true);
    EXPECT_NEAR(report.residual, std::sqrt(sum), 1e-12 * std::sqrt(sum)) << "sweep " << k;
    const SweepReport silent = sor_sweep(r.problem, rf, ProxForm::alart_curnier, u_hand,
                                         lambda_hand);
    EXPECT_EQ(silent.residual, -1.0);
  }

  SolverOptions options;
  options.abs_tol = 0.0;
  options.rel_tol = 1e-10;
  options.max_iterations = 100000;
  options.criterion = Criterion::natural_residual;
  SolverOptions history = options;
  history.record_history = true;
  ContactSolution a, b;
  const SolverResult plain = ContactSolver(Method::sor, options).solve(r.problem, a);
  const SolverResult every = ContactSolver(Method::sor, history).solve(r.problem, b);
  ASSERT_TRUE(plain.converged) << describe(plain);
  ASSERT_TRUE(every.converged) << describe(every);
  const double tolerance = options.rel_tol * plain.norm_c;
  EXPECT_LE(plain.residual, tolerance);
  EXPECT_GT(every.iterations, 20) << "a problem that needs many sweeps";
  EXPECT_GE(plain.iterations, every.iterations);
  EXPECT_LE(plain.iterations, every.iterations + every.iterations / 4 + 2);
  const SweepReport at_solution = sor_sweep(r.problem, rf, ProxForm::alart_curnier, a.u,
                                            a.lambda, std::numeric_limits<double>::infinity(),
                                            0.0, true);
  EXPECT_LE(at_solution.residual, 2.0 * tolerance);
}

// The solver's report of a compact solve, computed in one pass from the returned (Λ, u), is the
// natural-map residual of Λ with u recomputed from Λ (velocities_from_percussions), and ‖c‖ that
// of the free contact velocities, to rounding.
TEST(CompactProblem, TheReportIsTheResidualOfTheReturnedPercussions) {
  const Random r = random_problem(8, 24, false, 17);
  std::vector<double> mu;
  std::vector<Vector3> c;
  for (const CompactContact& k : r.problem.contacts) {
    mu.push_back(k.mu);
    c.push_back(contact_velocity(k, r.problem.u_free) + k.xi_A);
  }
  for (const Method method : {Method::sor, Method::jor, Method::apgd}) {
    SolverOptions options;
    options.min_iterations = options.max_iterations = 7;  // far from converged: residual ≫ 0
    ContactSolution solution;
    ContactSolver solver(method, options);
    const SolverResult result = solver.solve(r.problem, solution);
    std::vector<Vector6> u;
    velocities_from_percussions(r.problem, solution.lambda, u);
    std::vector<Vector3> xi;
    for (const CompactContact& k : r.problem.contacts)
      xi.push_back(contact_velocity(k, u) + k.xi_A);
    const double expected = natural_map_residual(solution.lambda, xi, mu);
    EXPECT_GT(expected, 1e-6) << method_name(method);
    EXPECT_NEAR(result.residual, expected, 1e-12 * expected) << method_name(method);
    double sum = 0.0;
    for (const Vector3& v : c) sum += v.squaredNorm();
    EXPECT_NEAR(result.norm_c, std::sqrt(sum), 1e-14 * std::sqrt(sum)) << method_name(method);
  }
  // A caller's reference (the stepper's, without the look-ahead's gap rates) is the criterion's:
  // the same solve held to 10⁻⁶ of a reference a thousand times smaller needs more sweeps.
  Random held = r;
  SolverOptions options;
  options.criterion = Criterion::natural_residual;
  options.rel_tol = 1e-6;
  options.max_iterations = 100000;
  ContactSolution plain_solution, held_solution;
  const SolverResult plain = ContactSolver(Method::sor, options).solve(r.problem, plain_solution);
  held.problem.reference_norm = 1e-3 * plain.norm_c;
  const SolverResult tight = ContactSolver(Method::sor, options).solve(held.problem, held_solution);
  EXPECT_EQ(tight.norm_c, held.problem.reference_norm);
  ASSERT_TRUE(plain.converged && tight.converged);
  EXPECT_LE(tight.residual, 1e-6 * tight.norm_c);
  EXPECT_GT(plain.residual, 1e-6 * tight.norm_c) << "the plain solve stopped earlier";
  EXPECT_GT(tight.iterations, plain.iterations);
}

TEST(CompactProblem, ValidationNamesTheBadEntry) {
  const auto message = [](const CompactProblem& p) {
    try {
      validate(p);
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const Random r = random_problem(3, 4, false, 11);
  CompactProblem p = r.problem;
  p.contacts[1].body_b = 7;
  EXPECT_NE(message(p).find("contact 1: body_b = 7"), std::string::npos) << message(p);
  p = r.problem;
  p.contacts[2].n *= 2.0;
  EXPECT_NE(message(p).find("contact 2: expected a unit normal"), std::string::npos);
  p = r.problem;
  p.contacts[0].mu = -0.1;
  EXPECT_NE(message(p).find("contact 0: expected a finite friction coefficient"),
            std::string::npos);
  p = r.problem;
  p.M_inv[1].inv_m = 0.0;
  EXPECT_NE(message(p).find("body 1: expected a finite 1/m > 0"), std::string::npos);
  p = r.problem;
  p.u_free.pop_back();
  EXPECT_NE(message(p).find("M_inv has 3 bodies but u_free has 2"), std::string::npos);
  p = r.problem;
  p.contacts[3].body_a = p.contacts[3].body_b = kStatic;
  EXPECT_NE(message(p).find("contact 3: both sides are static"), std::string::npos);
}

}  // namespace
}  // namespace grbd::contact
