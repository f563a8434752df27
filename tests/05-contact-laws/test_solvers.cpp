// Chapter 5: the iterative contact solvers — projected Gauss–Seidel (SOR), projected Jacobi (JOR)
// and the accelerated projected gradient (APGD), in body form (ContactProblem) and in local form
// (LocalProblem): the contact law at the returned solution, agreement with an independent LCP
// solver and among the methods and forms, warm starts, stopping criteria, r-factor strategies,
// closed forms of statics, and the refusal of bad input.
//
// Independent references:
// - the contact law checked inequality by inequality (Signorini: λ_N ≥ 0, ξ_N ≥ 0,
//   λ_N ξ_N = 0; Coulomb: ‖λ_T‖ ≤ μ λ_N, sticking ⇒ ξ_T = 0, sliding ⇒
//   λ_T = −μ λ_N ξ_T/‖ξ_T‖) with ξ = G λ + c from the dense G = WᵀM⁻¹W and
//   c = Wᵀu_free + ε∘γ_A of grbd_test/contact_problems.hpp, which share no code with the solvers;
// - frictionless problems (G positive definite): the LCP 0 ≤ λ_N ⟂ G_NN λ_N + c_N ≥ 0 solved by
//   enumerating all 2ⁿ complementary index sets (n ≤ 8) and by Murty's least-index principal
//   pivoting method (finite for P-matrices; Murty 1974; Cottle, Pang and Stone, The Linear
//   Complementarity Problem, ch. 4);
// - statics: a column of k spheres on the ground under the impulse −g h carries λ_N = j m g h at
//   the contact below the j-th sphere from the top; a particle on an incline sticks iff
//   μ ≥ tan θ, a solid sphere (Θ = 2/5 m r²) rolls without slipping iff μ ≥ 2/7 tan θ, with the
//   percussions of the one-step statics written out;
// - r-factors from the diagonal of the dense G: r_N = α/G_NN, r_T = α/max(G_T1T1, G_T2T2),
//   global r = α/max diag G.
//
// Tolerances: the solvers run with the natural-residual criterion, ‖F‖ ≤ rel_tol ‖c‖; the
// inequalities of the law are checked to 10 rel_tol ‖c‖ (absolute, in the units of the natural
// map with r = 1, in which λ and ξ enter alike; the worst violation measured is below
// 2 rel_tol ‖c‖), except ‖λ_T‖ ≤ μ λ_N (1 + 1e-9), which every
// prox output satisfies up to rounding. Comparisons of solutions run at rel_tol 1e-12 and compare
// to 1e-8 relative.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <chrono>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/collision/contact.hpp"
#include "grbd/contact/local_problem.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/contact_problems.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/watchdog.hpp"

namespace {

using grbd::Vector2;
using grbd::Vector3;
using grbd::Vector6;
using grbd::contact::ContactProblem;
using grbd::contact::ContactSolution;
using grbd::contact::Criterion;
using grbd::contact::LinearSolver;
using grbd::contact::LocalProblem;
using grbd::contact::ProxForm;
using grbd::contact::RFactorStrategy;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;
using grbd::test::Random;
using grbd::test::RandomProblemSpec;

using Eigen::MatrixXd;
using Eigen::VectorXd;

// The inequalities of the contact law are checked to this many times rel_tol ‖c‖.
constexpr double kLawFactor = 10.0;

enum class Kind { sor, jor, apgd, newton };

// A solver with its settings.
struct Method {
  const char* name;
  Kind kind;
  ProxForm form = ProxForm::alart_curnier;
  RFactorStrategy strategy = RFactorStrategy::per_contact;
  double alpha = 1.0;
  LinearSolver linear = LinearSolver::automatic;  // Newton's
  int hybrid_sweeps = 0;                          // Newton's: the hybrid's SOR phase
};

// Every problem is solved with these. JOR needs a small step: α = 0.3, per contact or with the
// global r = α/max diag G (which is smaller than every per-contact r).
const Method kMethods[] = {
    {"SOR Alart-Curnier", Kind::sor, ProxForm::alart_curnier},
    {"SOR De Saxce", Kind::sor, ProxForm::de_saxce},
    {"JOR Alart-Curnier alpha 0.3", Kind::jor, ProxForm::alart_curnier,
     RFactorStrategy::per_contact, 0.3},
    {"JOR De Saxce alpha 0.3", Kind::jor, ProxForm::de_saxce, RFactorStrategy::per_contact, 0.3},
    {"JOR global r alpha 0.3", Kind::jor, ProxForm::alart_curnier, RFactorStrategy::global, 0.3},
    {"APGD", Kind::apgd},
    // Newton with its default linear solver (direct in local form, GMRES in body form) and with
    // GMRES in both.
    {"Newton", Kind::newton},
    {"Newton GMRES", Kind::newton, ProxForm::alart_curnier, RFactorStrategy::per_contact, 1.0,
     LinearSolver::gmres},
    // The sparse LU of J in both forms (W assembled in the body form), and the hybrid.
    {"Newton LU", Kind::newton, ProxForm::alart_curnier, RFactorStrategy::per_contact, 1.0,
     LinearSolver::direct},
    {"Hybrid", Kind::newton, ProxForm::alart_curnier, RFactorStrategy::per_contact, 1.0,
     LinearSolver::automatic, 200},
};

// Every stopping test.
constexpr Criterion kCriteria[] = {Criterion::percussion_change, Criterion::velocity_change,
                                   Criterion::natural_residual};

// The relaxation of SOR on random frictional problems. The per-contact r-factors α/G_NN and
// α/max G_TT ignore the off-diagonal entries of G_ii; on an isolated sticking contact the prox
// step is then λ ← λ − α D⁻¹(G_ii λ + c), a contraction only if α λ_max(D⁻¹G_ii) < 2. The scaled
// block D^-½ G_ii D^-½ has diagonal entries ≤ 1, so λ_max ≤ 3 and α < 2/3 is always safe. The
// random lever arms (|K_ρ| up to √3, Θ down to 0.1) make G_ii strongly coupled: with α = 1,
// SOR falls into a period-2 cycle on about 1 % of them (measured: 2 of 160 problems of 60 and
// 200 contacts), among them Random(80920) of the sweep below (60 contacts, μ ≤ 1, both prox
// forms), which JOR, APGD and SOR with α ≤ 0.8 solve.
constexpr double kSorAlphaWithFriction = 0.6;

// The methods for a random problem: SOR with α = kSorAlphaWithFriction when it has friction.
std::vector<Method> methods_for(double mu_max) {
  std::vector<Method> methods(std::begin(kMethods), std::end(kMethods));
  if (mu_max > 0.0) {
    for (Method& m : methods) {
      if (m.kind == Kind::sor) m.alpha = kSorAlphaWithFriction;
    }
  }
  return methods;
}

// The natural-residual criterion ‖F‖ ≤ rel_tol ‖c‖.
SolverOptions natural(double rel_tol, int max_iterations = 20000) {
  SolverOptions o;
  o.criterion = Criterion::natural_residual;
  o.abs_tol = 0.0;
  o.rel_tol = rel_tol;
  o.max_iterations = max_iterations;
  return o;
}

SolverOptions with(const Method& m, SolverOptions o) {
  o.form = m.form;
  o.r_strategy = m.strategy;
  o.alpha = m.alpha;
  o.newton.linear_solver = m.linear;
  o.newton.hybrid_sweeps = m.hybrid_sweeps;
  return o;
}

SolverResult solve(const Method& m, const ContactProblem& p, ContactSolution& s,
                   const SolverOptions& options) {
  const SolverOptions o = with(m, options);
  switch (m.kind) {
    case Kind::sor:
      return grbd::contact::solve_sor(p, s, o);
    case Kind::jor:
      return grbd::contact::solve_jor(p, s, o);
    case Kind::apgd:
      return grbd::contact::solve_apgd(p, s, o);
    case Kind::newton:
      return grbd::contact::solve_newton(p, s, o);
  }
  return {};
}

SolverResult solve(const Method& m, const LocalProblem& p, std::vector<Vector3>& lambda,
                   const SolverOptions& options) {
  const SolverOptions o = with(m, options);
  switch (m.kind) {
    case Kind::sor:
      return grbd::contact::solve_sor(p, lambda, o);
    case Kind::jor:
      return grbd::contact::solve_jor(p, lambda, o);
    case Kind::apgd:
      return grbd::contact::solve_apgd(p, lambda, o);
    case Kind::newton:
      return grbd::contact::solve_newton(p, lambda, o);
  }
  return {};
}

const char* expected_name(Kind kind) {
  return kind == Kind::sor    ? "SOR"
         : kind == Kind::jor  ? "JOR"
         : kind == Kind::apgd ? "APGD"
                              : "Newton";
}

std::vector<double> friction(const ContactProblem& problem) {
  std::vector<double> mu;
  for (const auto& c : problem.contacts) mu.push_back(c.mu);
  return mu;
}

// The dense data of a body-form problem, computed once.
struct Dense {
  explicit Dense(const ContactProblem& problem)
      : W(grbd::test::dense_W(problem)),
        M_inv(grbd::test::dense_M_inv(problem)),
        G(grbd::test::dense_delassus(problem)),
        c(grbd::test::dense_free_velocity(problem)),
        u_free(grbd::test::dense_u_free(problem)),
        mu(friction(problem)) {}
  MatrixXd W, M_inv, G;
  VectorXd c, u_free;
  std::vector<double> mu;

  // ξ = G λ + c.
  std::vector<Vector3> xi(const std::vector<Vector3>& lambda) const {
    return grbd::test::unstack(G * grbd::test::stack(lambda) + c);
  }
  // u = u_free + M⁻¹ W Λ.
  VectorXd u(const std::vector<Vector3>& lambda) const {
    return u_free + M_inv * (W * grbd::test::stack(lambda));
  }
};

VectorXd stack_u(const std::vector<Vector6>& u) {
  VectorXd v(6 * static_cast<Eigen::Index>(u.size()));
  for (std::size_t b = 0; b < u.size(); ++b) v.segment<6>(6 * static_cast<Eigen::Index>(b)) = u[b];
  return v;
}

double max_abs(const VectorXd& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

// The contact law of every contact, for percussions λ and impact-law velocities ξ, to the
// absolute tolerance `tol`:
//   λ_N ≥ 0 and ‖λ_T‖ ≤ μ λ_N (1 + 1e-9)                     (λ ∈ K_μ)
//   ξ_N ≥ −tol                                               (no penetration velocity)
//   min(λ_N, |ξ_N|) ≤ tol                                    (complementarity)
//   ‖λ_T‖ < μ λ_N − tol  ⇒  ‖ξ_T‖ ≤ tol                      (sticking)
//   ‖ξ_T‖ > tol  ⇒  ‖λ_T + μ λ_N ξ_T/‖ξ_T‖‖ ≤ tol + 2 μ λ_N tol/‖ξ_T‖   (sliding; the second term
//                                               bounds the direction error of a ξ_T known to tol)
::testing::AssertionResult satisfies_contact_law(const std::vector<Vector3>& lambda,
                                                 const std::vector<Vector3>& xi,
                                                 const std::vector<double>& mu, double tol) {
  if (lambda.size() != xi.size() || lambda.size() != mu.size()) {
    return ::testing::AssertionFailure() << "sizes differ";
  }
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    const Vector3& l = lambda[i];
    const Vector3& x = xi[i];
    const double lN = l[0];
    const double xN = x[0];
    const Vector2 lT = l.tail<2>();
    const Vector2 xT = x.tail<2>();
    auto fail = [&]() {
      return ::testing::AssertionFailure()
             << "contact " << i << " (mu " << mu[i] << ", lambda " << l.transpose() << ", xi "
             << x.transpose() << ", tol " << tol << "): ";
    };
    if (!l.allFinite() || !x.allFinite()) return fail() << "not finite";
    if (lN < 0.0) return fail() << "lambda_N < 0";
    if (lT.norm() > mu[i] * lN * (1.0 + 1e-9)) return fail() << "lambda outside the cone";
    if (xN < -tol) return fail() << "xi_N < -tol";
    if (std::min(lN, std::abs(xN)) > tol) return fail() << "lambda_N xi_N != 0";
    if (lT.norm() < mu[i] * lN - tol && xT.norm() > tol) {
      return fail() << "sticking (inside the cone) but xi_T != 0";
    }
    if (xT.norm() > tol) {
      const double error = (lT + mu[i] * lN * xT / xT.norm()).norm();
      const double bound = tol + 2.0 * mu[i] * lN * tol / xT.norm();
      if (error > bound) {
        return fail() << "sliding but lambda_T != -mu lambda_N xi_T/|xi_T|: error " << error
                      << " > " << bound;
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// Checks a converged body-form solve against the dense references: the law, the residual, the
// velocities, the bookkeeping of the result.
void expect_solved(const ContactProblem& problem, const Dense& dense,
                   const ContactSolution& solution, const SolverResult& result, Kind kind,
                   double rel_tol) {
  const double norm_c = dense.c.norm();
  EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
  EXPECT_EQ(result.solver, expected_name(kind));
  const std::string line = grbd::contact::describe(result);
  EXPECT_NE(line.find("converged"), std::string::npos) << line;
  EXPECT_EQ(line.find("NOT"), std::string::npos) << line;
  ASSERT_EQ(solution.lambda.size(), problem.contacts.size());
  ASSERT_EQ(solution.u.size(), problem.M_inv.size());
  EXPECT_NEAR(result.norm_c, norm_c, 1e-12 * norm_c);
  // u = u_free + M⁻¹ W Λ, kept in step incrementally over all iterations.
  const VectorXd u = dense.u(solution.lambda);
  EXPECT_LE(max_abs(stack_u(solution.u) - u), 1e-10 * std::max(1.0, max_abs(u)));
  const std::vector<Vector3> xi = dense.xi(solution.lambda);
  EXPECT_LE(result.residual, rel_tol * norm_c);
  const double residual = grbd::contact::natural_map_residual(solution.lambda, xi, dense.mu);
  EXPECT_NEAR(residual, result.residual, 1e-3 * rel_tol * norm_c + 1e-13 * norm_c);
  EXPECT_TRUE(satisfies_contact_law(solution.lambda, xi, dense.mu, kLawFactor * rel_tol * norm_c));
}

// The same for the local form.
void expect_solved(const LocalProblem& local, const Dense& dense,
                   const std::vector<Vector3>& lambda, const SolverResult& result, Kind kind,
                   double rel_tol) {
  const double norm_c = dense.c.norm();
  EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
  EXPECT_EQ(result.solver, expected_name(kind));
  ASSERT_EQ(lambda.size(), local.q.size());
  EXPECT_NEAR(result.norm_c, norm_c, 1e-12 * norm_c);
  const std::vector<Vector3> xi = dense.xi(lambda);
  EXPECT_LE(result.residual, rel_tol * norm_c);
  const double residual = grbd::contact::natural_map_residual(lambda, xi, dense.mu);
  EXPECT_NEAR(residual, result.residual, 1e-3 * rel_tol * norm_c + 1e-13 * norm_c);
  EXPECT_TRUE(satisfies_contact_law(lambda, xi, dense.mu, kLawFactor * rel_tol * norm_c));
}

// The body count of the random problems: n contacts on n + n/4 + 1 bodies.
RandomProblemSpec spec_for(int contacts, double mu_max, bool restitution) {
  RandomProblemSpec spec;
  spec.contacts = contacts;
  spec.bodies = contacts + contacts / 4 + 1;
  spec.mu_max = mu_max;
  spec.restitution = restitution;
  return spec;
}

// The solution z ≥ 0, w = A z + b ≥ 0, zᵀw = 0 of the LCP(A, b) for the index set `basic` of
// free z (the others 0), or false if it is not complementary feasible to `tol`.
bool complementary_solution(const MatrixXd& A, const VectorXd& b, const std::vector<bool>& basic,
                            double tol, VectorXd& z) {
  const Eigen::Index n = b.size();
  std::vector<Eigen::Index> B;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (basic[static_cast<std::size_t>(j)]) B.push_back(j);
  }
  const auto m = static_cast<Eigen::Index>(B.size());
  MatrixXd A_BB(m, m);
  VectorXd b_B(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    b_B[r] = b[B[static_cast<std::size_t>(r)]];
    for (Eigen::Index s = 0; s < m; ++s) {
      A_BB(r, s) = A(B[static_cast<std::size_t>(r)], B[static_cast<std::size_t>(s)]);
    }
  }
  const VectorXd z_B = A_BB.ldlt().solve(-b_B);
  z = VectorXd::Zero(n);
  for (Eigen::Index r = 0; r < m; ++r) z[B[static_cast<std::size_t>(r)]] = z_B[r];
  const VectorXd w = A * z + b;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (basic[static_cast<std::size_t>(j)] ? z[j] < -tol : w[j] < -tol) return false;
  }
  return true;
}

// The LCP by enumerating all 2ⁿ index sets; `solutions` counts the complementary ones.
VectorXd lcp_by_enumeration(const MatrixXd& A, const VectorXd& b, int& solutions) {
  const auto n = static_cast<std::size_t>(b.size());
  const double tol = 1e-12 * (max_abs(b) + 1e-300);
  VectorXd result = VectorXd::Zero(b.size());
  solutions = 0;
  for (std::uint32_t mask = 0; mask < (1U << n); ++mask) {
    std::vector<bool> basic(n);
    for (std::size_t j = 0; j < n; ++j) basic[j] = ((mask >> j) & 1U) != 0;
    VectorXd z;
    if (complementary_solution(A, b, basic, tol, z)) {
      if (solutions == 0) result = z;
      ++solutions;
    }
  }
  return result;
}

// The LCP by Murty's least-index principal pivoting: flip the smallest index whose z (basic) or
// w (non-basic) is negative. Finite for a P-matrix A (here positive definite).
VectorXd lcp_by_murty(const MatrixXd& A, const VectorXd& b, int& pivots) {
  const auto n = static_cast<std::size_t>(b.size());
  const double tol = 1e-12 * (max_abs(b) + 1e-300);
  std::vector<bool> basic(n, false);
  VectorXd z;
  for (pivots = 0; pivots < 100000; ++pivots) {
    complementary_solution(A, b, basic, tol, z);
    const VectorXd w = A * z + b;
    std::size_t j = 0;
    while (j < n && (basic[j] ? z[static_cast<Eigen::Index>(j)] >= -tol
                              : w[static_cast<Eigen::Index>(j)] >= -tol)) {
      ++j;
    }
    if (j == n) return z;
    basic[j] = !basic[j];
  }
  return z;
}

// The normal block G_NN and c_N of a frictionless problem.
void normal_lcp(const Dense& dense, MatrixXd& G_NN, VectorXd& c_N) {
  const Eigen::Index n = dense.c.size() / 3;
  G_NN.resize(n, n);
  c_N.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    c_N[i] = dense.c[3 * i];
    for (Eigen::Index j = 0; j < n; ++j) G_NN(i, j) = dense.G(3 * i, 3 * j);
  }
}

// The message of the grbd::InvalidArgument that `call` throws, or "" when it does not throw.
std::string refusal(const std::function<void()>& call) {
  try {
    call();
  } catch (const grbd::InvalidArgument& error) {
    return error.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The contact law at the returned solution
// ---------------------------------------------------------------------------------------------

// Reference: the contact law written out (satisfies_contact_law) with ξ from the dense G and c.
// Random well-posed problems (G positive definite by construction) of 1 to 200 contacts,
// frictionless and μ ∈ [0, 1], with and without restitution; every method in body and local form.
TEST(SolverContactLaw, RandomProblemsSatisfyTheLawWithEveryMethod) {
  constexpr double kRelTol = 1e-8;
  struct Case {
    int contacts;
    int seeds;
  };
  for (const Case size :
       {Case{1, 3}, Case{2, 3}, Case{5, 2}, Case{20, 2}, Case{60, 1}, Case{200, 1}}) {
    for (const double mu_max : {0.0, 1.0}) {
      for (const bool restitution : {false, true}) {
        for (int seed = 0; seed < size.seeds; ++seed) {
          Random rng(5100 + 97 * static_cast<std::uint64_t>(size.contacts) +
                     static_cast<std::uint64_t>(seed) + (restitution ? 50000 : 0) +
                     (mu_max > 0.0 ? 70000 : 0));
          const ContactProblem problem =
              grbd::test::random_problem(rng, spec_for(size.contacts, mu_max, restitution));
          const Dense dense(problem);
          const LocalProblem local = grbd::test::to_local_form(problem);
          for (const Method& method : methods_for(mu_max)) {
            SCOPED_TRACE(std::string(method.name) + ", " + std::to_string(size.contacts) +
                         " contacts, mu_max " + std::to_string(mu_max) + ", restitution " +
                         std::to_string(restitution) + ", seed " + std::to_string(seed));
            ContactSolution solution;
            const SolverResult body = solve(method, problem, solution, natural(kRelTol));
            expect_solved(problem, dense, solution, body, method.kind, kRelTol);
            std::vector<Vector3> lambda;
            const SolverResult loc = solve(method, local, lambda, natural(kRelTol));
            expect_solved(local, dense, lambda, loc, method.kind, kRelTol);
          }
        }
      }
    }
  }
}

// Reference: the contact law, on hyperstatic pyramids of spheres assembled by the collision world
// (Λ not unique, G only positive semidefinite): 4 layers (30 spheres, 112 contacts)
// frictionless, 2 layers (5 spheres, 12 contacts) with μ = 0.5. Frictional pyramids of 3 and 4
// layers converge too, but slowly (measured: thousands of sweeps to 1e-8), and are left out.
TEST(SolverContactLaw, PyramidsOfSpheresSatisfyTheLaw) {
  constexpr double kRelTol = 1e-8;
  struct Case {
    int layers;
    double mu;
    std::size_t contacts;
  };
  for (const Case pile : {Case{4, 0.0, 16 + 40 + 56}, Case{2, 0.5, 4 + 4 + 4}}) {
    const grbd::test::SphereScene scene =
        grbd::test::sphere_pyramid(pile.layers, 0.1, 0.3, 9.81 * 0.01, {pile.mu, 0.0, 0.0});
    ASSERT_EQ(scene.problem.contacts.size(), pile.contacts);
    const Dense dense(scene.problem);
    for (const Method& method : kMethods) {
      SCOPED_TRACE(std::string(method.name) + ", " + std::to_string(pile.layers) + " layers, mu " +
                   std::to_string(pile.mu));
      ContactSolution solution;
      const SolverResult result = solve(method, scene.problem, solution, natural(kRelTol));
      expect_solved(scene.problem, dense, solution, result, method.kind, kRelTol);
    }
  }
}

// Reference: the problem without contacts is solved by u = u_free at once.
TEST(SolverContactLaw, NoContactsGiveTheFreeVelocities) {
  Random rng(5190);
  const ContactProblem problem = grbd::test::random_problem(rng, spec_for(0, 1.0, false));
  ASSERT_TRUE(problem.contacts.empty());
  for (const Method& method : kMethods) {
    SCOPED_TRACE(method.name);
    ContactSolution solution;
    const SolverResult result = solve(method, problem, solution, natural(1e-8));
    EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
    EXPECT_EQ(result.residual, 0.0);
    EXPECT_TRUE(solution.lambda.empty());
    ASSERT_EQ(solution.u.size(), problem.u_free.size());
    for (std::size_t b = 0; b < problem.u_free.size(); ++b) {
      EXPECT_EQ(solution.u[b], problem.u_free[b]);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Against an independent LCP solver, among the methods, between the forms
// ---------------------------------------------------------------------------------------------

// Reference: frictionless problems are the LCP 0 ≤ λ_N ⟂ G_NN λ_N + c_N ≥ 0, G_NN positive
// definite, unique solution: by enumeration of all 2ⁿ index sets (n ≤ 8, exactly one must be
// complementary) and by Murty's pivoting (which must agree). Every method, both forms, to 1e-8
// relative; λ_T = 0.
TEST(SolverReference, FrictionlessProblemsMatchTheLcpSolution) {
  constexpr double kRelTol = 1e-12;
  for (const int n : {1, 2, 3, 5, 8, 40}) {
    for (const bool restitution : {false, true}) {
      for (int seed = 0; seed < (n <= 8 ? 3 : 1); ++seed) {
        Random rng(5200 + 31 * static_cast<std::uint64_t>(n) + static_cast<std::uint64_t>(seed) +
                   (restitution ? 1000 : 0));
        const ContactProblem problem =
            grbd::test::random_problem(rng, spec_for(n, 0.0, restitution));
        const Dense dense(problem);
        MatrixXd G_NN;
        VectorXd c_N;
        normal_lcp(dense, G_NN, c_N);
        ASSERT_GT(grbd::test::smallest_eigenvalue(G_NN), 0.0);
        int pivots = 0;
        const VectorXd reference = lcp_by_murty(G_NN, c_N, pivots);
        if (n <= 8) {
          int solutions = 0;
          const VectorXd enumerated = lcp_by_enumeration(G_NN, c_N, solutions);
          ASSERT_EQ(solutions, 1) << "n " << n << ", seed " << seed;
          ASSERT_LE(max_abs(enumerated - reference), 1e-12 * max_abs(reference) + 1e-300);
        }
        // λ's natural scale where every contact is separating: ‖c‖∞ / max G_ii.
        const double scale =
            std::max(max_abs(reference), max_abs(c_N) / dense.G.diagonal().maxCoeff());
        const LocalProblem local = grbd::test::to_local_form(problem);
        for (const Method& method : kMethods) {
          SCOPED_TRACE(std::string(method.name) + ", " + std::to_string(n) + " contacts, seed " +
                       std::to_string(seed) + ", restitution " + std::to_string(restitution));
          ContactSolution solution;
          const SolverResult body = solve(method, problem, solution, natural(kRelTol));
          EXPECT_TRUE(body.converged) << grbd::contact::describe(body);
          std::vector<Vector3> lambda;
          const SolverResult loc = solve(method, local, lambda, natural(kRelTol));
          EXPECT_TRUE(loc.converged) << grbd::contact::describe(loc);
          for (std::size_t i = 0; i < problem.contacts.size(); ++i) {
            const auto k = static_cast<Eigen::Index>(i);
            EXPECT_NEAR(solution.lambda[i][0], reference[k], 1e-8 * scale) << "contact " << i;
            EXPECT_EQ(solution.lambda[i].tail<2>().norm(), 0.0) << "contact " << i;
            EXPECT_NEAR(lambda[i][0], reference[k], 1e-8 * scale) << "contact " << i;
            EXPECT_EQ(lambda[i].tail<2>().norm(), 0.0) << "contact " << i;
          }
        }
      }
    }
  }
}

// Reference: the methods against each other. Frictionless: Λ is unique (G positive definite), so
// Λ, u and ξ agree. With friction (μ ∈ [0, 1], restitution) uniqueness is not guaranteed in
// general; on these seeds every method finds the same Λ, u and ξ. Tolerance 1e-8 relative at
// rel_tol 1e-12.
TEST(SolverAgreement, MethodsAgreeOnVelocitiesAndPercussions) {
  constexpr double kRelTol = 1e-12;
  for (const double mu_max : {0.0, 1.0}) {
    for (int seed = 0; seed < 2; ++seed) {
      Random rng(5300 + static_cast<std::uint64_t>(seed) + (mu_max > 0.0 ? 100 : 0));
      const ContactProblem problem = grbd::test::random_problem(rng, spec_for(30, mu_max, true));
      const Dense dense(problem);
      const std::vector<Method> methods = methods_for(mu_max);
      ContactSolution first;
      ASSERT_TRUE(solve(methods[0], problem, first, natural(kRelTol)).converged);
      const VectorXd lambda0 = grbd::test::stack(first.lambda);
      const VectorXd u0 = stack_u(first.u);
      const VectorXd xi0 = grbd::test::stack(dense.xi(first.lambda));
      for (const Method& method : methods) {
        SCOPED_TRACE(std::string(method.name) + ", mu_max " + std::to_string(mu_max) + ", seed " +
                     std::to_string(seed));
        ContactSolution solution;
        const SolverResult result = solve(method, problem, solution, natural(kRelTol));
        EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
        EXPECT_LE(max_abs(stack_u(solution.u) - u0), 1e-8 * max_abs(u0));
        EXPECT_LE(max_abs(grbd::test::stack(dense.xi(solution.lambda)) - xi0), 1e-8 * max_abs(xi0));
        EXPECT_LE(max_abs(grbd::test::stack(solution.lambda) - lambda0), 1e-8 * max_abs(lambda0));
      }
    }
  }
}

// Reference: the body form and its local form ξ = G λ + c (dense G, to_block_sparse) are the same
// problem: every method returns the same Λ and ξ in both, to 1e-8 relative at rel_tol 1e-12.
TEST(SolverAgreement, BodyFormAndLocalFormGiveTheSameSolution) {
  constexpr double kRelTol = 1e-12;
  for (const double mu_max : {0.0, 0.5, 1.0}) {
    Random rng(5400 + static_cast<std::uint64_t>(10 * mu_max));
    const ContactProblem problem = grbd::test::random_problem(rng, spec_for(25, mu_max, true));
    const Dense dense(problem);
    const LocalProblem local = grbd::test::to_local_form(problem);
    for (const Method& method : methods_for(mu_max)) {
      SCOPED_TRACE(std::string(method.name) + ", mu_max " + std::to_string(mu_max));
      ContactSolution solution;
      const SolverResult body = solve(method, problem, solution, natural(kRelTol));
      std::vector<Vector3> lambda;
      const SolverResult loc = solve(method, local, lambda, natural(kRelTol));
      EXPECT_TRUE(body.converged) << grbd::contact::describe(body);
      EXPECT_TRUE(loc.converged) << grbd::contact::describe(loc);
      const VectorXd l_body = grbd::test::stack(solution.lambda);
      EXPECT_LE(max_abs(grbd::test::stack(lambda) - l_body), 1e-8 * max_abs(l_body));
      const VectorXd xi_body = grbd::test::stack(dense.xi(solution.lambda));
      const VectorXd xi_local = grbd::test::stack(grbd::contact::local_velocities(local, lambda));
      EXPECT_LE(max_abs(xi_local - xi_body), 1e-8 * max_abs(xi_body));
      EXPECT_NEAR(loc.norm_c, body.norm_c, 1e-12 * body.norm_c);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Warm starts
// ---------------------------------------------------------------------------------------------

// Reference: a fixed point of the prox map is kept by one more sweep: started from a converged
// solution, SOR stops after at most 2 iterations (natural residual and percussion change).
// Started from a perturbed solution (relative noise 1e-3), SOR and JOR need fewer iterations than
// from zero. Both forms.
TEST(SolverWarmStart, FromTheSolutionAndFromANearbyGuess) {
  Random rng(5500);
  const ContactProblem problem = grbd::test::random_problem(rng, spec_for(60, 1.0, true));
  const LocalProblem local = grbd::test::to_local_form(problem);
  const std::vector<Method> methods = methods_for(1.0);
  const Method sor = methods[0];
  ContactSolution exact;
  ASSERT_TRUE(solve(sor, problem, exact, natural(1e-12)).converged);

  SolverOptions by_change;
  by_change.criterion = Criterion::percussion_change;
  by_change.rel_tol = 1e-8;
  by_change.abs_tol = 1e-14;
  for (const SolverOptions& options : {natural(1e-8), by_change}) {
    ContactSolution warm{exact.lambda, {}};
    const SolverResult result = solve(sor, problem, warm, options);
    EXPECT_TRUE(result.converged);
    EXPECT_LE(result.iterations, 2);
    std::vector<Vector3> lambda = exact.lambda;
    const SolverResult loc = solve(sor, local, lambda, options);
    EXPECT_TRUE(loc.converged);
    EXPECT_LE(loc.iterations, 2);
  }

  std::vector<Vector3> nearby = exact.lambda;
  for (Vector3& l : nearby) l *= 1.0 + 1e-3 * rng.uniform();
  for (const Method& method : {methods[0], methods[1], methods[2]}) {
    SCOPED_TRACE(method.name);
    ContactSolution cold;
    const SolverResult from_zero = solve(method, problem, cold, natural(1e-8));
    ContactSolution warm{nearby, {}};
    const SolverResult from_nearby = solve(method, problem, warm, natural(1e-8));
    EXPECT_TRUE(from_zero.converged);
    EXPECT_TRUE(from_nearby.converged);
    EXPECT_LT(from_nearby.iterations, from_zero.iterations);
    std::vector<Vector3> lambda_cold;
    std::vector<Vector3> lambda_warm = nearby;
    EXPECT_LT(solve(method, local, lambda_warm, natural(1e-8)).iterations,
              solve(method, local, lambda_cold, natural(1e-8)).iterations);
  }
}

// ---------------------------------------------------------------------------------------------
// Stopping criteria, iteration limits, history
// ---------------------------------------------------------------------------------------------

// Reference: the definitions of the criteria. Percussion change and velocity change (rel_tol
// 1e-10) stop well before max_iterations, with a solution whose natural residual is small (1e-6
// ‖c‖); every method, both forms.
TEST(SolverCriteria, EveryCriterionStops) {
  Random rng(5600);
  const ContactProblem problem = grbd::test::random_problem(rng, spec_for(20, 1.0, true));
  const Dense dense(problem);
  const LocalProblem local = grbd::test::to_local_form(problem);
  const double norm_c = dense.c.norm();
  for (const Criterion criterion : kCriteria) {
    SolverOptions options;
    options.criterion = criterion;
    options.abs_tol = 1e-14;
    options.rel_tol = 1e-10;
    options.max_iterations = 20000;
    for (const Method& method : methods_for(1.0)) {
      SCOPED_TRACE(std::string(method.name) + ", criterion " +
                   std::to_string(static_cast<int>(criterion)));
      ContactSolution solution;
      const SolverResult body = solve(method, problem, solution, options);
      EXPECT_TRUE(body.converged) << grbd::contact::describe(body);
      EXPECT_LT(body.iterations, options.max_iterations);
      EXPECT_LE(body.residual, 1e-6 * norm_c);
      EXPECT_TRUE(satisfies_contact_law(solution.lambda, dense.xi(solution.lambda), dense.mu,
                                        1e-5 * norm_c));
      std::vector<Vector3> lambda;
      const SolverResult loc = solve(method, local, lambda, options);
      EXPECT_TRUE(loc.converged) << grbd::contact::describe(loc);
      EXPECT_LT(loc.iterations, options.max_iterations);
      EXPECT_LE(loc.residual, 1e-6 * norm_c);
    }
  }
}

// Reference: the definition of min_iterations: a problem that converges in fewer iterations still
// runs min_iterations of them, and then stops at once.
TEST(SolverCriteria, MinIterationsAreDone) {
  Random rng(5610);
  const ContactProblem problem = grbd::test::random_problem(rng, spec_for(10, 0.5, false));
  const LocalProblem local = grbd::test::to_local_form(problem);
  for (const Method& method : methods_for(0.5)) {
    SCOPED_TRACE(method.name);
    ContactSolution free_run;
    const SolverResult plain = solve(method, problem, free_run, natural(1e-6));
    ASSERT_TRUE(plain.converged);
    SolverOptions options = natural(1e-6);
    options.min_iterations = plain.iterations + 25;
    ContactSolution solution;
    const SolverResult result = solve(method, problem, solution, options);
    EXPECT_TRUE(result.converged);
    EXPECT_EQ(result.iterations, options.min_iterations);
    std::vector<Vector3> lambda;
    const SolverResult loc = solve(method, local, lambda, options);
    EXPECT_TRUE(loc.converged);
    EXPECT_EQ(loc.iterations, options.min_iterations);
  }
}

// Reference: the definition of max_iterations: a solver stopped there reports non-convergence
// (converged false, iterations = max, the residual of what it returns > 0, describe() says "did
// NOT converge"), and the returned u still goes with the returned Λ.
TEST(SolverCriteria, MaxIterationsReachedIsReportedAsNonConvergence) {
  Random rng(5620);
  const ContactProblem problem = grbd::test::random_problem(rng, spec_for(40, 1.0, true));
  const Dense dense(problem);
  const LocalProblem local = grbd::test::to_local_form(problem);
  SolverOptions options = natural(1e-15, 3);
  for (const Method& method : kMethods) {
    // The hybrid's first iteration is its whole SOR phase, which solves this problem to 1e-15.
    if (method.hybrid_sweeps > 0) continue;
    SCOPED_TRACE(method.name);
    ContactSolution solution;
    const SolverResult result = solve(method, problem, solution, options);
    EXPECT_FALSE(result.converged);
    EXPECT_EQ(result.iterations, 3);
    EXPECT_GT(result.residual, 0.0);
    EXPECT_GT(result.relative_residual(), 1e-15);
    const std::string line = grbd::contact::describe(result);
    EXPECT_TRUE(contains(line, "did NOT converge")) << line;
    EXPECT_TRUE(contains(line, expected_name(method.kind))) << line;
    EXPECT_TRUE(contains(line, "3 iterations")) << line;
    const VectorXd u = dense.u(solution.lambda);
    EXPECT_LE(max_abs(stack_u(solution.u) - u), 1e-12 * std::max(1.0, max_abs(u)));
    EXPECT_NEAR(
        result.residual,
        grbd::contact::natural_map_residual(solution.lambda, dense.xi(solution.lambda), dense.mu),
        1e-12 * dense.c.norm());
    std::vector<Vector3> lambda;
    const SolverResult loc = solve(method, local, lambda, options);
    EXPECT_FALSE(loc.converged);
    EXPECT_EQ(loc.iterations, 3);
    EXPECT_GT(loc.residual, 0.0);
    EXPECT_TRUE(contains(grbd::contact::describe(loc), "did NOT converge"));
  }
}

// Reference: the definition of record_history: one ‖F‖ per iteration, the last one the residual
// reported; nothing without it. On a well-conditioned frictionless problem the SOR history falls
// monotonically (each entry ≤ the previous one, up to rounding 1e-12 ‖c‖).
TEST(SolverCriteria, HistoryHasOneEntryPerIteration) {
  Random rng(5630);
  const ContactProblem problem = grbd::test::random_problem(rng, spec_for(30, 1.0, true));
  const LocalProblem local = grbd::test::to_local_form(problem);
  SolverOptions options = natural(1e-10);
  options.record_history = true;
  for (const Method& method : methods_for(1.0)) {
    SCOPED_TRACE(method.name);
    ContactSolution solution;
    const SolverResult result = solve(method, problem, solution, options);
    ASSERT_TRUE(result.converged);
    ASSERT_EQ(result.history.size(), static_cast<std::size_t>(result.iterations));
    EXPECT_NEAR(result.history.back(), result.residual, 1e-12 * result.norm_c);
    for (const double h : result.history) EXPECT_GE(h, 0.0);
    std::vector<Vector3> lambda;
    const SolverResult loc = solve(method, local, lambda, options);
    EXPECT_EQ(loc.history.size(), static_cast<std::size_t>(loc.iterations));
    ContactSolution quiet;
    EXPECT_TRUE(solve(method, problem, quiet, natural(1e-10)).history.empty());
  }

  Random calm(5631);
  RandomProblemSpec spec = spec_for(30, 0.0, false);
  const ContactProblem frictionless = grbd::test::random_problem(calm, spec);
  ContactSolution solution;
  const SolverResult sor = solve(kMethods[0], frictionless, solution, options);
  ASSERT_TRUE(sor.converged);
  ASSERT_GE(sor.history.size(), 3U);
  for (std::size_t k = 1; k < sor.history.size(); ++k) {
    EXPECT_LE(sor.history[k], sor.history[k - 1] + 1e-12 * sor.norm_c) << "iteration " << k + 1;
  }
}

// ---------------------------------------------------------------------------------------------
// r-factors and relaxation
// ---------------------------------------------------------------------------------------------

// Reference: the r-factors from the diagonal of the dense G: per contact r_N = α/G_NN,
// r_T = α/max(G_T1T1, G_T2T2); global r = α/max diag G for all. Tolerance 1e-13 relative.
TEST(SolverRFactors, StrategiesFollowTheDiagonalOfG) {
  Random rng(5700);
  const ContactProblem problem = grbd::test::random_problem(rng, spec_for(15, 1.0, false));
  const Dense dense(problem);
  for (const double alpha : {0.3, 1.0, 1.7}) {
    const auto per_contact = grbd::contact::r_factors(problem, RFactorStrategy::per_contact, alpha);
    const auto global = grbd::contact::r_factors(problem, RFactorStrategy::global, alpha);
    ASSERT_EQ(per_contact.size(), problem.contacts.size());
    ASSERT_EQ(global.size(), problem.contacts.size());
    const double r_global = alpha / dense.G.diagonal().maxCoeff();
    for (std::size_t i = 0; i < problem.contacts.size(); ++i) {
      const auto k = 3 * static_cast<Eigen::Index>(i);
      const double r_N = alpha / dense.G(k, k);
      const double r_T = alpha / std::max(dense.G(k + 1, k + 1), dense.G(k + 2, k + 2));
      EXPECT_NEAR(per_contact[i].r_N, r_N, 1e-13 * r_N);
      EXPECT_NEAR(per_contact[i].r_T, r_T, 1e-13 * r_T);
      EXPECT_NEAR(global[i].r_N, r_global, 1e-13 * r_global);
      EXPECT_NEAR(global[i].r_T, r_global, 1e-13 * r_global);
    }
  }
}

// Reference: the contact law. Both strategies converge for SOR and JOR (JOR per contact with
// α = 0.3), both prox forms, on a random frictional problem and on the frictionless pyramid.
TEST(SolverRFactors, BothStrategiesConverge) {
  constexpr double kRelTol = 1e-8;
  Random rng(5710);
  const ContactProblem random = grbd::test::random_problem(rng, spec_for(50, 1.0, true));
  const grbd::test::SphereScene pyramid =
      grbd::test::sphere_pyramid(3, 0.1, 0.3, 9.81 * 0.01, {0.0, 0.0, 0.0});
  for (const ContactProblem* problem : {&random, &pyramid.problem}) {
    const Dense dense(*problem);
    for (const Kind kind : {Kind::sor, Kind::jor}) {
      for (const ProxForm form : {ProxForm::alart_curnier, ProxForm::de_saxce}) {
        for (const RFactorStrategy strategy :
             {RFactorStrategy::per_contact, RFactorStrategy::global}) {
          const double alpha =
              kind == Kind::jor && strategy == RFactorStrategy::per_contact ? 0.3 : 1.0;
          const Method method{"", kind, form, strategy, alpha};
          SCOPED_TRACE(std::string(expected_name(kind)) + ", form " +
                       std::to_string(static_cast<int>(form)) + ", strategy " +
                       std::to_string(static_cast<int>(strategy)));
          ContactSolution solution;
          const SolverResult result = solve(method, *problem, solution, natural(kRelTol));
          expect_solved(*problem, dense, solution, result, kind, kRelTol);
        }
      }
    }
  }
}

// Reference: the measured effect of the relaxation on projected SOR for the frictionless column
// of 8 spheres (a tridiagonal G_NN, the model problem of SOR theory): under-relaxation α = 0.5
// needs more sweeps than Gauss–Seidel α = 1, and over-relaxation α = 1.5 fewer (the optimal ω of
// the unprojected tridiagonal problem is 2/(1 + sin(π/(k+1))) ≈ 1.5).
TEST(SolverRFactors, RelaxationChangesTheIterationCount) {
  const grbd::test::SphereScene column =
      grbd::test::sphere_column(8, 0.1, 0.5, 9.81 * 0.01, {0.0, 0.0, 0.0});
  const Dense dense(column.problem);
  int iterations[3] = {};
  const double alphas[3] = {0.5, 1.0, 1.5};
  for (int a = 0; a < 3; ++a) {
    const Method sor{"SOR", Kind::sor, ProxForm::alart_curnier, RFactorStrategy::per_contact,
                     alphas[a]};
    ContactSolution solution;
    const SolverResult result = solve(sor, column.problem, solution, natural(1e-10));
    expect_solved(column.problem, dense, solution, result, Kind::sor, 1e-10);
    iterations[a] = result.iterations;
  }
  EXPECT_GT(iterations[0], iterations[1]);
  EXPECT_LT(iterations[2], iterations[1]);
}

// ---------------------------------------------------------------------------------------------
// Closed forms through the full solver
// ---------------------------------------------------------------------------------------------

// Reference: statics. A column of k = 6 spheres (m = 0.7, r = 0.1) on the ground under the
// gravity impulse g h = 9.81 × 0.01: the contact at height 2 r s (s spheres below it) carries
// λ_N = (k − s) m g h, λ_T = 0, and all end velocities vanish. Frictionless and μ = 0.5, every
// method. Tolerance 1e-9 k m g h.
TEST(SolverClosedForm, ColumnOfSpheresCarriesTheWeightAbove) {
  constexpr int k = 6;
  constexpr double m = 0.7;
  constexpr double r = 0.1;
  constexpr double g_h = 9.81 * 0.01;
  for (const double mu : {0.0, 0.5}) {
    const grbd::test::SphereScene column = grbd::test::sphere_column(k, r, m, g_h, {mu, 0.0, 0.0});
    ASSERT_EQ(column.contacts.size(), static_cast<std::size_t>(k));
    for (const Method& method : kMethods) {
      SCOPED_TRACE(std::string(method.name) + ", mu " + std::to_string(mu));
      ContactSolution solution;
      const SolverResult result = solve(method, column.problem, solution, natural(1e-12));
      EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
      for (std::size_t i = 0; i < column.contacts.size(); ++i) {
        const double height = column.contacts[i].geometry.I_r_a.z();
        const double s = std::round(height / (2.0 * r));
        EXPECT_NEAR(height, 2.0 * r * s, 1e-12);
        EXPECT_NEAR(solution.lambda[i][0], (k - s) * m * g_h, 1e-9 * k * m * g_h)
            << "contact at height " << height;
        EXPECT_LE(solution.lambda[i].tail<2>().norm(), 1e-9 * k * m * g_h);
      }
      for (const Vector6& u : solution.u) EXPECT_LE(u.cwiseAbs().maxCoeff(), 1e-9 * g_h);
    }
  }
}

// Reference: one-step statics on an incline of θ = 30° (gravity impulse −g h e_z, contact frame
// n, t1, t2 of the collision world). A solid sphere (G = diag(1, 7/2, 7/2)/m) rolls without
// slipping iff μ ≥ 2/7 tan θ: then λ_N = m g h cos θ, λ_T = 2/7 m g h Tᵀe_z, ξ = 0; below,
// λ_T = μ λ_N Tᵀe_z/sin θ and ξ_T = −g h (1 − 7/2 μ cot θ) Tᵀe_z. A particle (no lever arm,
// G = I/m) sticks iff μ ≥ tan θ, with λ_T = m g h Tᵀe_z, or slides with
// ξ_T = −g h (1 − μ cot θ) Tᵀe_z. Every method; tolerance 1e-9 m g h (λ), 1e-9 g h (ξ).
TEST(SolverClosedForm, InclineSticksOrSlidesAtTheCoulombThreshold) {
  constexpr double m = 1.5;
  constexpr double r = 0.2;
  constexpr double g_h = 9.81 * 0.01;
  const double theta = std::numbers::pi / 6.0;
  const Vector3 n(-std::sin(theta), 0.0, std::cos(theta));
  const Eigen::Matrix<double, 3, 2> T = grbd::collision::tangent_basis(n);
  for (const bool sphere : {true, false}) {
    const double threshold = (sphere ? 2.0 / 7.0 : 1.0) * std::tan(theta);
    const double G_TT = (sphere ? 3.5 : 1.0) / m;
    for (const double factor : {0.5, 0.9, 1.1, 2.0}) {
      const double mu = factor * threshold;
      ContactProblem problem;
      Eigen::Matrix<double, 3, 2> T_used = T;
      if (sphere) {
        const grbd::test::SphereScene scene =
            grbd::test::sphere_on_incline(n, r, m, g_h, {mu, 0.0, 0.0});
        ASSERT_EQ(scene.contacts.size(), 1U);
        ASSERT_EQ(scene.contacts[0].body_a, 0);
        ASSERT_EQ(scene.contacts[0].body_b, grbd::contact::kStatic);
        ASSERT_LE((scene.contacts[0].geometry.I_n - n).norm(), 1e-15);
        T_used << scene.contacts[0].I_t1, scene.contacts[0].I_t2;
        problem = scene.problem;
      } else {
        problem.M_inv.push_back({1.0 / m, grbd::Vector3::Ones()});
        problem.u_free.push_back((Vector6() << 0.0, 0.0, -g_h, 0.0, 0.0, 0.0).finished());
        grbd::contact::ContactConstraint c;
        c.body_a = 0;
        c.W_a = grbd::collision::contact_jacobian(grbd::kinematics::Quaternion::identity(),
                                                  Vector3::Zero(), n, T.col(0), T.col(1));
        c.mu = mu;
        problem.contacts.push_back(c);
      }
      const Vector2 Tz = T_used.transpose() * Vector3::UnitZ();  // ‖Tz‖ = sin θ
      const bool sticks = mu >= threshold;
      const double lambda_N = m * g_h * std::cos(theta);
      const Vector2 lambda_T =
          sticks ? Vector2(Tz / G_TT * g_h) : Vector2(mu * lambda_N * Tz / std::sin(theta));
      const Vector2 xi_T =
          sticks ? Vector2::Zero() : Vector2(-g_h * (1.0 - G_TT * m * mu / std::tan(theta)) * Tz);
      for (const Method& method : kMethods) {
        SCOPED_TRACE(std::string(method.name) + (sphere ? ", sphere" : ", particle") +
                     ", mu/threshold " + std::to_string(factor));
        ContactSolution solution;
        const SolverResult result = solve(method, problem, solution, natural(1e-13));
        EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
        const Vector3 xi = grbd::contact::contact_velocities(problem, solution.u)[0];
        EXPECT_NEAR(solution.lambda[0][0], lambda_N, 1e-9 * m * g_h);
        EXPECT_LE((solution.lambda[0].tail<2>() - lambda_T).norm(), 1e-9 * m * g_h);
        EXPECT_NEAR(xi[0], 0.0, 1e-9 * g_h);
        EXPECT_LE((xi.tail<2>() - xi_T).norm(), 1e-9 * g_h);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

// Reference: the declarations: every body-form solver validates the options, the problem and the
// initial guess first, and refuses bad ones with grbd::InvalidArgument naming what is wrong.
TEST(SolverInput, BodyFormRefusesBadProblemsOptionsAndGuesses) {
  Random rng(5800);
  const ContactProblem good = grbd::test::random_problem(rng, spec_for(4, 1.0, true));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct BadProblem {
    const char* what;
    std::function<void(ContactProblem&)> spoil;
    const char* named;
  };
  const std::vector<BadProblem> problems{
      {"negative mu", [](ContactProblem& p) { p.contacts[2].mu = -0.1; }, "mu"},
      {"NaN u_free", [nan](ContactProblem& p) { p.u_free[1][4] = nan; }, "u_free"},
      {"NaN W_a", [nan](ContactProblem& p) { p.contacts[1].W_a(3, 2) = nan; }, "W_a"},
      {"NaN gamma_A", [nan](ContactProblem& p) { p.contacts[3].gamma_A[0] = nan; }, "gamma_A"},
      {"zero W",
       [](ContactProblem& p) {
         p.contacts[0].W_a.setZero();
         p.contacts[0].body_b = grbd::contact::kStatic;
       },
       "Delassus"},
      // Regression (issue 11): an infinite diagonal of G passed validate().
      {"infinite Delassus diagonal", [](ContactProblem& p) { p.contacts[2].W_a(0, 0) = 1e200; },
       "Delassus"},
  };
  struct BadOptions {
    const char* what;
    std::function<void(SolverOptions&)> spoil;
    const char* named;
  };
  const std::vector<BadOptions> options{
      {"alpha 0", [](SolverOptions& o) { o.alpha = 0.0; }, "alpha"},
      {"alpha -1", [](SolverOptions& o) { o.alpha = -1.0; }, "alpha"},
      {"alpha 2", [](SolverOptions& o) { o.alpha = 2.0; }, "alpha"},
      {"alpha NaN", [nan](SolverOptions& o) { o.alpha = nan; }, "alpha"},
      {"max < min",
       [](SolverOptions& o) {
         o.min_iterations = 10;
         o.max_iterations = 5;
       },
       "max_iterations"},
      {"max 0", [](SolverOptions& o) { o.max_iterations = 0; }, "max_iterations"},
      {"negative abs_tol", [](SolverOptions& o) { o.abs_tol = -1e-12; }, "abs_tol"},
      {"negative rel_tol", [](SolverOptions& o) { o.rel_tol = -1e-6; }, "rel_tol"},
      // Regression (issue 11): enum values outside the enumerators were accepted.
      {"criterion 7", [](SolverOptions& o) { o.criterion = static_cast<Criterion>(7); },
       "criterion"},
      {"r_strategy -1",
       [](SolverOptions& o) { o.r_strategy = static_cast<RFactorStrategy>(-1); }, "r_strategy"},
      {"form 2", [](SolverOptions& o) { o.form = static_cast<ProxForm>(2); }, "form"},
  };
  for (const Method& method : kMethods) {
    for (const BadProblem& bad : problems) {
      SCOPED_TRACE(std::string(method.name) + ": " + bad.what);
      ContactProblem problem = good;
      bad.spoil(problem);
      ContactSolution solution;
      const std::string message = refusal([&] { solve(method, problem, solution, {}); });
      EXPECT_TRUE(contains(message, bad.named)) << "message: '" << message << "'";
    }
    for (const BadOptions& bad : options) {
      SCOPED_TRACE(std::string(method.name) + ": " + bad.what);
      SolverOptions o = with(method, {});
      bad.spoil(o);
      ContactSolution solution;
      // solve() would overwrite alpha: call the solvers directly.
      const std::string message = refusal([&] {
        switch (method.kind) {
          case Kind::sor:
            grbd::contact::solve_sor(good, solution, o);
            break;
          case Kind::jor:
            grbd::contact::solve_jor(good, solution, o);
            break;
          case Kind::apgd:
            grbd::contact::solve_apgd(good, solution, o);
            break;
          case Kind::newton:
            grbd::contact::solve_newton(good, solution, o);
            break;
        }
      });
      EXPECT_TRUE(contains(message, bad.named)) << "message: '" << message << "'";
    }
    {
      SCOPED_TRACE(std::string(method.name) + ": initial guess of the wrong length");
      ContactSolution solution{std::vector<Vector3>(3, Vector3::Zero()), {}};
      const std::string message = refusal([&] { solve(method, good, solution, {}); });
      EXPECT_TRUE(contains(message, "initial guess")) << "message: '" << message << "'";
      EXPECT_TRUE(contains(message, "3")) << "message: '" << message << "'";
    }
    {
      SCOPED_TRACE(std::string(method.name) + ": NaN initial guess");
      ContactSolution solution{std::vector<Vector3>(4, Vector3::Zero()), {}};
      solution.lambda[2][1] = nan;
      const std::string message = refusal([&] { solve(method, good, solution, {}); });
      EXPECT_TRUE(contains(message, "initial guess")) << "message: '" << message << "'";
      EXPECT_TRUE(contains(message, "contact 2")) << "message: '" << message << "'";
    }
  }
}

// Reference: the declarations: the local-form solvers refuse a NaN in q or W, a negative or NaN
// μ, a non-positive diagonal, a bad initial guess, a bad α. (An asymmetric W is accepted:
// local_problem.hpp, FCLIB's Capsules-286.)
TEST(SolverInput, LocalFormRefusesBadProblemsAndGuesses) {
  Random rng(5810);
  const LocalProblem good =
      grbd::test::to_local_form(grbd::test::random_problem(rng, spec_for(4, 1.0, true)));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Bad {
    const char* what;
    std::function<void(LocalProblem&)> spoil;
    const char* named;
  };
  const auto diagonal = [](LocalProblem& p, std::size_t i) -> grbd::Matrix3& {
    return p.W.blocks[static_cast<std::size_t>(p.W.diagonal[i])];
  };
  const std::vector<Bad> problems{
      {"NaN q", [nan](LocalProblem& p) { p.q[1][2] = nan; }, "q"},
      {"negative mu", [](LocalProblem& p) { p.mu[3] = -0.5; }, "mu"},
      {"NaN mu", [nan](LocalProblem& p) { p.mu[0] = nan; }, "mu"},
      {"zero diagonal", [&](LocalProblem& p) { diagonal(p, 1)(1, 1) = 0.0; }, "diagonal"},
      {"negative diagonal", [&](LocalProblem& p) { diagonal(p, 0)(0, 0) = -1.0; }, "diagonal"},
      {"NaN W", [&](LocalProblem& p) { diagonal(p, 3)(2, 2) = nan; }, "W"},
      // Regression (issue 11): an infinite diagonal passed, and APGD ran 1000 NaN iterations.
      {"infinite diagonal",
       [&](LocalProblem& p) { diagonal(p, 2)(0, 0) = std::numeric_limits<double>::infinity(); },
       "W"},
  };
  for (const Method& method : kMethods) {
    for (const Bad& bad : problems) {
      SCOPED_TRACE(std::string(method.name) + ": " + bad.what);
      LocalProblem problem = good;
      bad.spoil(problem);
      std::vector<Vector3> lambda;
      const std::string message = refusal([&] { solve(method, problem, lambda, {}); });
      EXPECT_TRUE(contains(message, bad.named)) << "message: '" << message << "'";
    }
    {
      SCOPED_TRACE(std::string(method.name) + ": initial guess of the wrong length");
      std::vector<Vector3> lambda(5, Vector3::Zero());
      const std::string message = refusal([&] { solve(method, good, lambda, {}); });
      EXPECT_TRUE(contains(message, "initial guess")) << "message: '" << message << "'";
    }
    {
      SCOPED_TRACE(std::string(method.name) + ": NaN initial guess");
      std::vector<Vector3> lambda(4, Vector3::Zero());
      lambda[1][0] = nan;
      const std::string message = refusal([&] { solve(method, good, lambda, {}); });
      EXPECT_TRUE(contains(message, "initial guess")) << "message: '" << message << "'";
    }
    {
      SCOPED_TRACE(std::string(method.name) + ": alpha 2 in local form");
      SolverOptions o;
      o.alpha = 2.0;
      std::vector<Vector3> lambda;
      const std::string message = refusal([&] {
        switch (method.kind) {
          case Kind::sor:
            grbd::contact::solve_sor(good, lambda, o);
            break;
          case Kind::jor:
            grbd::contact::solve_jor(good, lambda, o);
            break;
          case Kind::apgd:
            grbd::contact::solve_apgd(good, lambda, o);
            break;
          case Kind::newton:
            grbd::contact::solve_newton(good, lambda, o);
            break;
        }
      });
      EXPECT_TRUE(contains(message, "alpha")) << "message: '" << message << "'";
    }
  }
}

namespace {

// One contact with W = w I (a 3 × 3 block), q and μ.
LocalProblem one_contact(double w, const Vector3& q, double mu) {
  LocalProblem p;
  p.W.row_start = {0, 1};
  p.W.column = {0};
  p.W.blocks = {w * grbd::Matrix3::Identity()};
  p.W.diagonal = {0};
  p.q = {q};
  p.mu = {mu};
  return p;
}

}  // namespace

// Regression (issue 11): one contact, W = 2I, q = (−1e200, 1e200, −1e200), μ = 0.5. The squared
// norms in prox_disk and in the residual overflowed: λ_T came out 0 and the solvers reported
// "converged" with a NaN residual. Reference: the closed form of a sliding contact with W = 2I:
// ξ_N = 0 gives λ_N = −q_N/2, and λ_T = −μ λ_N q_T/‖q_T‖ (sliding, since ‖q_T‖/2 > μ λ_N);
// the same problem scaled by 10⁻²⁰⁰ has the solution scaled alike.
TEST(SolverRobustness, HugeButFiniteProblemMatchesTheSlidingClosedForm) {
  const double mu = 0.5;
  for (const double s : {1e200, 1.0, 1e-200}) {
    const Vector3 q(-s, s, -s);
    const LocalProblem problem = one_contact(2.0, q, mu);
    const double lambda_N = s / 2.0;
    const Vector2 q_T = q.tail<2>();
    const Vector2 direction = q_T / std::hypot(q_T(0), q_T(1));
    const Vector3 expected(lambda_N, -mu * lambda_N * direction(0),
                           -mu * lambda_N * direction(1));
    for (const Method& method : kMethods) {
      SCOPED_TRACE(std::string(method.name) + ", scale " + std::to_string(s));
      std::vector<Vector3> lambda;
      const SolverResult result = solve(method, problem, lambda, natural(1e-12, 1000));
      EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
      EXPECT_FALSE(result.diverged);
      EXPECT_TRUE(std::isfinite(result.residual)) << grbd::contact::describe(result);
      ASSERT_EQ(lambda.size(), 1U);
      EXPECT_LE((lambda[0] - expected).cwiseAbs().maxCoeff(), 1e-10 * lambda_N)
          << "lambda = " << lambda[0].transpose() << ", expected " << expected.transpose();
    }
  }
}

// Regression (issue 11): a non-finite iterate never met the criterion, so the solvers ran to
// max_iterations, and with max_iterations = INT_MAX the loop counter overflowed and they never
// stopped (ch05_fclib --max-iterations 2147483647). One contact with W = 1e-300 I (a valid,
// positive diagonal) and q_N = −1e10: r_N = 1/W_NN = 1e300 makes λ_N = ∞ in the first iteration.
// Reference: SolverResult's declaration: a non-finite iterate stops the solver at once, as
// divergence, never as convergence. A watchdog turns a hang into a failure.
TEST(SolverRobustness, NonFiniteIterateStopsAtOnceEvenWithIntMaxIterations) {
  const LocalProblem problem = one_contact(1e-300, Vector3(-1e10, 0.0, 0.0), 0.3);
  for (const Method& method : kMethods) {
    for (const Criterion criterion : kCriteria) {
      SCOPED_TRACE(std::string(method.name) + ", criterion " +
                   std::to_string(static_cast<int>(criterion)));
      SolverOptions options;
      options.criterion = criterion;
      options.max_iterations = std::numeric_limits<int>::max();
      std::vector<Vector3> lambda;
      const SolverResult result =
          grbd::test::within(std::chrono::seconds(30), std::string(method.name) + " diverging",
                             [&] { return solve(method, problem, lambda, options); });
      EXPECT_FALSE(result.converged) << grbd::contact::describe(result);
      EXPECT_TRUE(result.diverged) << grbd::contact::describe(result);
      EXPECT_LE(result.iterations, 100) << grbd::contact::describe(result);
      EXPECT_NE(grbd::contact::describe(result).find("DIVERGED"), std::string::npos);
    }
  }
}

// max_iterations = INT_MAX is accepted and changes nothing on a problem that converges.
TEST(SolverRobustness, IntMaxIterationsIsAcceptedAndStopsAtConvergence) {
  Random rng(5820);
  const LocalProblem problem =
      grbd::test::to_local_form(grbd::test::random_problem(rng, spec_for(6, 0.0, false)));
  for (const Method& method : kMethods) {
    SCOPED_TRACE(method.name);
    std::vector<Vector3> lambda;
    const SolverResult result =
        solve(method, problem, lambda, natural(1e-10, std::numeric_limits<int>::max()));
    EXPECT_TRUE(result.converged) << grbd::contact::describe(result);
    EXPECT_LT(result.iterations, 100000);
  }
}

// Regression: APGD with the percussion-change criterion reported "converged" after 2 iterations
// at λ = (0.917, −0.256, −0.102), relative residual 0.07: the fixed point of one cycle with the
// De Saxcé offset s frozen, not a solution of Coulomb's law. Reference: the closed form of one
// sliding contact with W = I, q = (−1, 0.5, 0.2), μ = 0.3: λ_N = −q_N = 1 and
// λ_T = −μ λ_N q_T/‖q_T‖ (‖q_T‖ = 0.539 > μ λ_N). Whatever the criterion, "converged" must
// mean the law holds: every method under every criterion lands within 1e-5 of it.
TEST(SolverRobustness, ConvergedMeansTheLawHoldsUnderEveryCriterion) {
  const Vector3 q(-1.0, 0.5, 0.2);
  const LocalProblem problem = one_contact(1.0, q, 0.3);
  const Vector2 q_T = q.tail<2>();
  const Vector3 expected(1.0, -0.3 * q_T(0) / q_T.norm(), -0.3 * q_T(1) / q_T.norm());
  for (const Method& method : kMethods) {
    for (const Criterion criterion : kCriteria) {
      SCOPED_TRACE(std::string(method.name) + ", criterion " +
                   std::to_string(static_cast<int>(criterion)));
      SolverOptions options;
      options.criterion = criterion;
      std::vector<Vector3> lambda;
      const SolverResult result = solve(method, problem, lambda, options);
      ASSERT_TRUE(result.converged) << grbd::contact::describe(result);
      EXPECT_LE((lambda[0] - expected).cwiseAbs().maxCoeff(), 1e-5)
          << "lambda = " << lambda[0].transpose() << "; " << grbd::contact::describe(result);
    }
  }
}
