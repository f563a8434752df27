#pragma once
/// \file
/// \brief Iterative solvers of the contact problem (chapter 5): projected Jacobi (JOR) and
/// Gauss–Seidel (SOR) prox iterations with r-factor strategies and convergence criteria, and an
/// accelerated projected gradient method with adaptive restart (APGD), for the body form
/// (ContactProblem) and the local form (LocalProblem) of the problem.

#include <span>
#include <string>
#include <vector>

#include "grbd/contact/local_problem.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/core/types.hpp"

namespace grbd::contact {

// [r factors declaration]
/// \brief <b>Exercise 5.6</b>: the r-factors of one contact.
///
/// r_N = α / G_NN and r_T = α / max(G_T1T1, G_T2T2) for the Delassus block G (normal first) and
/// the relaxation α ∈ (0, 2). For an isolated contact whose block G is diagonal, α < 2 makes the
/// prox map a contraction (the step never overshoots beyond the mirror image of the solution);
/// with normal–tangential coupling in G it needs α λ_max(D⁻¹G) < 2, D = diag(G), and since
/// λ_max(D⁻¹G) ≤ 3, α < 2/3 is always safe. Throws InvalidArgument if a diagonal entry of G is
/// not positive or α is outside (0, 2).
RFactors r_factors(const Matrix3& G, double alpha);
// [r factors declaration]

// [converged declaration]
/// \brief <b>Exercise 5.8</b>: the convergence test of an iteration.
///
/// True when every component k satisfies |x_k − x_old,k| ≤ abs_tol + rel_tol |x_k|, the mixed
/// absolute/relative test of the prox iterations, applied to percussions or velocities. The two
/// arrays have the same length.
bool has_converged(std::span<const double> x_old, std::span<const double> x, double abs_tol,
                   double rel_tol);
// [converged declaration]

/// How a solver picks the r-factors.
enum class RFactorStrategy {
  per_contact,  ///< r_i from r_factors(G_ii, α) for each contact
  global,       ///< one r = α / max_i max_k (G_ii)_kk for every contact and direction
};

/// What a solver watches to stop.
enum class Criterion {
  percussion_change,  ///< has_converged on all λ between two iterations
  velocity_change,    ///< has_converged on the body velocities u (local form: ξ)
  natural_residual,   ///< ‖F‖ ≤ abs_tol + rel_tol ‖c‖ with F the natural map, c = free ξ
};

/// Options of every solver. Defaults suit a time step of a granular simulation. The solvers
/// refuse (InvalidArgument) iteration counts outside 0 ≤ min_iterations ≤ max_iterations,
/// max_iterations ≥ 1 (INT_MAX is allowed), tolerances that are negative or not finite, α ∉ (0, 2)
/// and enum values outside their enumerators.
struct SolverOptions {
  int min_iterations = 1;           ///< iterations always done
  int max_iterations = 1000;        ///< iterations at most; stopping there is non-convergence
  double abs_tol = 1e-12;           ///< absolute tolerance of the criterion
  double rel_tol = 1e-6;            ///< relative tolerance of the criterion
  Criterion criterion = Criterion::percussion_change;  ///< stopping test
  RFactorStrategy r_strategy = RFactorStrategy::per_contact;  ///< r-factors of JOR and SOR
  double alpha = 1.0;               ///< relaxation α ∈ (0, 2) of the r-factors
  ProxForm form = ProxForm::alart_curnier;  ///< prox update of JOR and SOR
  bool record_history = false;      ///< store the natural-map residual after every iteration
};

/// What a solver did. Non-convergence is not an exception: `converged` is false and the numbers
/// say how far it got (describe() words it).
struct SolverResult {
  std::string solver;            ///< "SOR", "JOR" or "APGD"
  bool converged = false;        ///< the criterion was met within max_iterations
  /// an iterate or the residual was not finite (∞ or NaN): the solver stopped at once; never
  /// together with `converged`
  bool diverged = false;
  int iterations = 0;            ///< iterations done
  double residual = 0.0;         ///< natural-map residual ‖F‖ of the returned λ
  double norm_c = 0.0;           ///< ‖c‖, the free contact velocities (FCLIB: ‖q‖)
  double norm_max = 0.0;         ///< max(‖c‖, ‖λ‖, ‖ξ‖) of the returned λ
  double seconds = 0.0;          ///< wall time of the solve
  std::vector<double> history;   ///< ‖F‖ after each iteration, when record_history
  /// ‖F‖/‖c‖ (FCLIB's classic measure); ‖F‖ when ‖c‖ = 0.
  double relative_residual() const { return norm_c > 0.0 ? residual / norm_c : residual; }
  /// ‖F‖/max(‖c‖, ‖λ‖, ‖ξ‖) (current Siconos measure); ‖F‖ when the maximum is 0.
  double scaled_residual() const { return norm_max > 0.0 ? residual / norm_max : residual; }
};

/// One line: solver, converged or not, iterations, residuals, time.
std::string describe(const SolverResult& result);

/// The state a body-form solver works on and returns: percussions per contact and the body
/// velocities u = u_free + M⁻¹ W Λ that go with them. On entry `lambda` is the initial guess
/// (warm start; empty means zero); `u` is recomputed from it.
struct ContactSolution {
  std::vector<Vector3> lambda;  ///< percussion per contact [N s]
  std::vector<Vector6> u;       ///< end velocity per body
};

/// The r-factors of every contact of `problem` for `strategy` and relaxation α. Throws
/// InvalidArgument for a problem that validate() refuses or α outside (0, 2).
std::vector<RFactors> r_factors(const ContactProblem& problem, RFactorStrategy strategy,
                                double alpha);

// [sor sweep declaration]
/// One Gauss–Seidel sweep: sor_contact_update() for contacts 0, 1, …, n − 1 in order, each
/// seeing the velocities its predecessors left. The hot loop of SOR, exposed for benchmarks and
/// for the parallel solver of chapter 8. Throws InvalidArgument unless r and lambda have one entry
/// per contact and u one per body (O(1)); the body indices of the contacts are not re-checked
/// in every sweep: `problem` must be one that validate() accepted.
void sor_sweep(const ContactProblem& problem, std::span<const RFactors> r, ProxForm form,
               std::span<Vector6> u, std::span<Vector3> lambda);
// [sor sweep declaration]

/// \name Body-form solvers
/// Each validates the problem and the options first (InvalidArgument), then iterates.
///@{

/// Projected Gauss–Seidel: sweeps the contacts in order with sor_contact_update().
SolverResult solve_sor(const ContactProblem& problem, ContactSolution& solution,
                       const SolverOptions& options = {});
/// Projected Jacobi: all contacts see the velocities of the previous iteration.
SolverResult solve_jor(const ContactProblem& problem, ContactSolution& solution,
                       const SolverOptions& options = {});
/// Accelerated projected gradient (Nesterov) with adaptive restart on the De Saxcé form: step
/// α/L with L from a power-iteration estimate of λ_max(G), doubled by backtracking when a step
/// fails the sufficient-decrease test and shrunk by 10 % after each accepted one; the cone
/// offset s = μ ‖ξ_T‖ is frozen for a cycle and refreshed at every restart and at least every 25
/// iterations (Mazhar et al. 2015 solve the convex relaxation; this solves Coulomb's law).
SolverResult solve_apgd(const ContactProblem& problem, ContactSolution& solution,
                        const SolverOptions& options = {});
///@}

/// \name Local-form solvers (FCLIB)
/// `lambda` is the initial guess on entry (empty means zero) and the result on return.
///@{

/// Projected Gauss–Seidel on block rows of W.
SolverResult solve_sor(const LocalProblem& problem, std::vector<Vector3>& lambda,
                       const SolverOptions& options = {});
/// Projected Jacobi.
SolverResult solve_jor(const LocalProblem& problem, std::vector<Vector3>& lambda,
                       const SolverOptions& options = {});
/// Accelerated projected gradient with adaptive restart.
SolverResult solve_apgd(const LocalProblem& problem, std::vector<Vector3>& lambda,
                        const SolverOptions& options = {});
///@}

}  // namespace grbd::contact
