#pragma once
/// \file
/// \brief Iterative solvers of the contact problem (chapter 5): projected Jacobi (JOR) and
/// Gauss–Seidel (SOR) prox iterations with r-factor strategies and convergence criteria, an
/// accelerated projected gradient method with adaptive restart (APGD), and a semismooth Newton
/// method on the Alart–Curnier function (newton.hpp), for the body form (ContactProblem) and the
/// local form (LocalProblem) of the problem.
///
/// The four methods share one driver: every iteration is "remember what the stopping test
/// compares; one iteration of the method; the hook SolverHooks::after_iteration; the stopping
/// test, turned into a global verdict by SolverHooks::global_status; stop at max_iterations".
/// ContactSolver keeps the buffers of that loop between solves (a time stepper calls it once per
/// step without allocating); the free functions solve_sor(), solve_jor() and solve_apgd() are
/// one-shot wrappers around it.

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "grbd/contact/compact.hpp"
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

/// The iterative methods.
enum class Method {
  sor,     ///< projected Gauss–Seidel (successive over-relaxation)
  jor,     ///< projected Jacobi (Jacobi over-relaxation)
  apgd,    ///< accelerated projected gradient descent with adaptive restart
  newton,  ///< semismooth Newton on the Alart–Curnier function with a line search
};

/// "SOR", "JOR", "APGD" or "Newton" (SolverResult::solver); throws InvalidArgument for a value
/// outside the enumerators.
std::string_view method_name(Method method);

/// How a solver picks the r-factors.
///
/// Why JOR and SOR need different ones: SOR updates one contact at a time, and each update sees
/// the velocities its predecessors left, so for one contact it is the prox step of a 3 × 3
/// problem, a contraction in the normal direction for r_N G_NN = α < 2 (r_factors()): per-contact
/// r-factors are safe. JOR moves all contacts at once, from the same old velocities: for the
/// frictionless problem it is the projected gradient step λ ← P(λ − r (G λ + c)), a contraction
/// only for r < 2/λ_max(G). A sphere with twelve contacts receives twelve pushes at once, so
/// λ_max(G) is several times max diag G and per-contact r-factors overshoot: JOR with α = 1 and
/// per_contact diverges to ∞ on a sphere pile and on FCLIB problems (the solver then stops at once
/// and reports SolverResult::diverged). Hence the default `automatic`.
enum class RFactorStrategy {
  per_contact,  ///< r_i from r_factors(G_ii, α) for each contact
  global,       ///< one r = α / max_i max_k (G_ii)_kk for every contact and direction
  /// one r = α / λ̂ for every contact and direction, with λ̂ = spectral::kSafety times the
  /// power-iteration estimate of λ_max(G) (spectral::kPowerIterations iterations): with α < 2 JOR is
  /// a contraction on frictionless problems unless the estimate is more than a factor
  /// 2 kSafety / α below λ_max(G). Costs kPowerIterations products with G per solve.
  spectral,
  /// the default: per_contact for SOR, spectral for JOR (APGD takes no r-factors)
  automatic,
};

/// The spectral r-factor strategy (RFactorStrategy::spectral).
namespace spectral {
/// Power iterations for λ_max(G), from a start vector with pseudo-random signs (so that no
/// symmetry of a regular packing makes it orthogonal to the top eigenvector). The estimate
/// ‖G x_k‖ approaches λ_max(G) from below; 50 iterations bring it within the factor kSafety of
/// λ_max on the test problems (random problems, sphere pyramids), for the price of about 50 JOR
/// iterations per solve.
inline constexpr int kPowerIterations = 50;
/// λ̂ = kSafety × estimate: covers the part of λ_max the power iteration has not yet found. Not a
/// proven bound (the power iteration gives none); with α = 1, JOR stays a contraction on
/// frictionless problems as long as the estimate is above λ_max/2.2.
inline constexpr double kSafety = 1.1;
}  // namespace spectral

/// The constants of APGD (solve_apgd()), each with the reason for its value.
namespace apgd {
/// L is doubled at most this many times in one iteration (a factor 2⁶⁰ ≈ 10¹⁸): enough for any
/// underestimate of λ_max(G) by the power iteration, and a bound on the work of one iteration.
inline constexpr int kMaxBacktracking = 60;
/// The De Saxcé cone offset s = μ ‖ξ_T‖ is frozen for at most this many iterations before it is
/// refreshed with a restart: long enough for the accelerated method to make progress on each
/// cycle's convex problem, short enough that a wrong s does not hold it back for long.
inline constexpr int kOffsetCycle = 25;
/// Power iterations for the starting L ≈ λ_max(G): a rough estimate suffices, because
/// backtracking corrects an underestimate and the kShrink decay an overestimate.
inline constexpr int kPowerIterations = 20;
/// L when the power iteration gives 0 (or not a positive number): any positive value works,
/// backtracking doubles it up to the curvature of the problem.
inline constexpr double kFallbackLipschitz = 1.0;
/// L shrinks by this factor after each accepted step, so that it follows the local curvature
/// down after backtracking raised it; at 0.9 it costs at most one extra doubling every
/// ln 2 / ln(1/0.9) ≈ 7 iterations when L is right.
inline constexpr double kShrink = 0.9;
/// Relative slack of the sufficient-decrease test (x − y)ᵀG(x − y) ≤ L ‖x − y‖² (1 + kDecreaseSlack):
/// rounding in the two sides must not count as a failed step and double L.
inline constexpr double kDecreaseSlack = 1e-12;
}  // namespace apgd

/// How the Newton method solves its linear system J d = −Φ in each iteration.
enum class LinearSolver {
  /// direct in the local form (FCLIB), where W is at hand; GMRES in the body and compact forms,
  /// where a sphere packing's J fills in badly under the LU factorization (chapter 5 measures both)
  automatic,
  /// a sparse LU factorization of J = A + B W assembled from W's blocks (Eigen's SparseLU, the
  /// pattern analysed once per solve); in the body and compact forms W = Wᵀ M⁻¹ W is assembled
  /// once per solve (assemble_delassus(), grbd/contact/delassus.hpp)
  direct,
  /// restarted GMRES with J applied as A x + B (W x), W never formed, and the block-diagonal
  /// preconditioner (A_i + B_i W_ii)⁻¹; every form
  gmres,
};

// [newton options]
/// The Newton method's own options (SolverOptions::newton).
struct NewtonOptions {
  LinearSolver linear_solver = LinearSolver::automatic;  ///< how J d = −Φ is solved
  int krylov_restart = 30;          ///< GMRES: Krylov vectors before a restart, >= 1
  int max_linear_iterations = 300;  ///< GMRES: products with J per Newton iteration at most, >= 1
  /// The line search compares with the largest merit ψ of the last this many iterates (a
  /// non-monotone Armijo rule, Grippo, Lampariello and Lucidi 1986); 1, the default, is the
  /// monotone rule.
  int line_search_memory = 1;
  /// When the Newton direction fails (no descent, no step passes the line search, a singular J):
  /// this many SOR sweeps (Alart–Curnier form, SOR's r-factors) instead, >= 1.
  int fallback_sweeps = 5;
  /// The hybrid: SOR sweeps (Alart–Curnier form, SOR's r-factors) first, at most this many, and
  /// Newton from where they stagnate: when ‖F‖ fell by less than the factor hybrid_stagnation
  /// over the last newton::kHybridWindow sweeps, or, with the natural-residual criterion, when
  /// at the rate of the last window SOR would not meet the tolerance within the sweeps left (and
  /// SOR alone where it does). The SOR phase is the solver's first iteration
  /// (the stopping test and the hooks see it as one; max_iterations counts it as one); it ends
  /// early where SOR meets the natural-residual or the percussion criterion (tested at the end
  /// of each window). 0, the default, is Newton from the start.
  int hybrid_sweeps = 0;
  /// The hybrid's stagnation factor, in (0, 1]: 1 runs all hybrid_sweeps sweeps unless SOR
  /// converges first.
  double hybrid_stagnation = 0.99;
};
// [newton options]

/// What a solver watches to stop.
enum class Criterion {
  percussion_change,  ///< has_converged on all λ between two iterations
  velocity_change,    ///< has_converged on the body velocities u (local form: ξ)
  natural_residual,   ///< ‖F‖ ≤ abs_tol + rel_tol ‖c‖ with F the natural map, c = free ξ
};

/// Options of every solver. Defaults suit a time step of a granular simulation and converge with
/// every method (JOR through RFactorStrategy::automatic). The solvers refuse (InvalidArgument)
/// iteration counts outside 0 ≤ min_iterations ≤ max_iterations, max_iterations ≥ 1 (INT_MAX is
/// allowed), tolerances that are negative or not finite, α ∉ (0, 2) and enum values outside their
/// enumerators.
struct SolverOptions {
  int min_iterations = 1;           ///< iterations always done
  int max_iterations = 1000;        ///< iterations at most; stopping there is non-convergence
  double abs_tol = 1e-12;           ///< absolute tolerance of the criterion
  double rel_tol = 1e-6;            ///< relative tolerance of the criterion
  Criterion criterion = Criterion::percussion_change;  ///< stopping test
  RFactorStrategy r_strategy = RFactorStrategy::automatic;  ///< r-factors of JOR and SOR
  double alpha = 1.0;               ///< relaxation α ∈ (0, 2) of the r-factors
  ProxForm form = ProxForm::alart_curnier;  ///< prox update of JOR and SOR
  bool record_history = false;      ///< store the natural-map residual after every iteration
  NewtonOptions newton;             ///< Method::newton only
};

/// What a solver did. Non-convergence is not an exception: `converged` is false and the numbers
/// say how far it got (describe() words it).
struct SolverResult {
  std::string solver;            ///< method_name(): "SOR", "JOR", "APGD" or "Newton"
  bool converged = false;        ///< the criterion was met within max_iterations
  /// an iterate or the residual was not finite (∞ or NaN): the solver stopped at once; never
  /// together with `converged`
  bool diverged = false;
  int iterations = 0;            ///< iterations done
  double residual = 0.0;         ///< natural-map residual ‖F‖ of the returned λ
  double norm_c = 0.0;           ///< ‖c‖, the free contact velocities (FCLIB: ‖q‖)
  double norm_max = 0.0;         ///< max(‖c‖, ‖λ‖, ‖ξ‖) of the returned λ
  double seconds = 0.0;          ///< wall time of the solve
  /// Newton: the linear solver's work, products with J (GMRES) or factorizations (direct)
  int linear_iterations = 0;
  int fallbacks = 0;             ///< Newton: iterations that fell back to SOR sweeps
  /// Newton: the SOR sweeps of the hybrid's first iteration (NewtonOptions::hybrid_sweeps)
  int hybrid_sweeps = 0;
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

/// The r-factors of every contact of `problem` for `strategy` and relaxation α (`automatic` gives
/// SOR's choice, per_contact). Throws InvalidArgument for a problem that validate() refuses or α
/// outside (0, 2).
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

/// The status of a solver after one iteration, ordered so that the global status of several
/// processes is the largest of theirs.
enum class IterationStatus : int {
  converged = 0,  ///< the stopping test is met
  running = 1,    ///< not yet: iterate on
  diverged = 2,   ///< an iterate is not finite: stop
};

/// The natural-residual criterion's reference on many processes (SolverHooks::global_norm_c).
struct GlobalNorm {
  double norm_c = 0.0;  ///< ‖c‖ of the whole problem, (Σ_p ‖c_p‖²)^½
  int processes = 1;    ///< the number of processes P that share the problem
};

/// Where a distributed solver (chapter 8) plugs into the iteration of every method: split-body
/// averaging after each sweep, the tolerance's reference and a global convergence verdict.
/// Empty members are not called.
struct SolverHooks {
  /// Called after every iteration k = 1, 2, …, iterations (1-based), before the stopping test,
  /// with Λ and, in the body form, the body velocities u (empty in the local form). SOR keeps u in
  /// step with Λ anyway; JOR and APGD, which change all of Λ at once, bring u up to date first
  /// only when this hook is set. Changes to u are seen by the next SOR sweep and by the stopping
  /// test; JOR and APGD recompute u from Λ (and do so once more at the end), so for them only
  /// changes to Λ count, and APGD's own buffers (momentum, ξ) do not follow such a change.
  std::function<void(int k, std::span<Vector3> lambda, std::span<Vector6> u)> after_iteration;
  /// Called after every iteration k (1-based), after after_iteration and before the stopping
  /// test, with the body velocities u only: for a hook that changes u and nothing else, such as
  /// the mass splitting of chapter 8, which replaces the velocities of a split body's copies by
  /// their mass-weighted mean. Λ is not shown, so it cannot change, and SOR stays on its fast
  /// path: its sweep keeps testing its own change of Λ and its finiteness, and no copy of Λ is
  /// made per iteration (an after_iteration hook costs both). The next sweep starts from the
  /// changed u. SOR only, in the body and compact forms: ContactSolver refuses it for JOR and
  /// APGD, which recompute u from Λ and would drop the change, and the local form has no u.
  std::function<void(int k, std::span<Vector6> u)> velocities_between_sweeps;
  /// Turns this process's status after an iteration into the global one: with MPI the maximum
  /// over the ranks (MPI_Allreduce with MPI_MAX on the integer values of IterationStatus), so
  /// that every process stops as diverged when one of them diverged, and as converged only when
  /// all of them converged. Called exactly once in every iteration, a divergence included, so that
  /// the collective reduction stays matched across processes: a rank whose iterate is not finite
  /// does not leave the others waiting in their reduction. Locally, `converged` means the
  /// criterion met and k ≥ min_iterations (for APGD also its cone offset consistent), `diverged`
  /// a non-finite iterate. The solver follows what the hook returns; a global `diverged` sets
  /// SolverResult::diverged on every process.
  std::function<IterationStatus(IterationStatus local)> global_status;
  /// For a problem shared by processes: called once per solve, collectively, with this process's
  /// ‖c‖; returns the whole problem's ‖c‖ and the number of processes P. The natural-residual
  /// criterion then holds each process to (abs_tol + rel_tol ‖c‖)/√P, so that the processes'
  /// residuals together, (Σ_p ‖F_p‖²)^½, meet the tolerance of the whole problem — and a process
  /// whose own contacts have c = 0 is not held to ‖F_p‖ = 0. SOR's body and compact forms.
  std::function<GlobalNorm(double norm_c)> global_norm_c;
};

namespace detail {
struct SolverWorkspace;  ///< the buffers of ContactSolver (solver.cpp)
}  // namespace detail

/// A reusable solver: one method, its options and hooks, and a workspace that keeps its
/// capacity. After the first solve, a solve of a problem of the same or smaller size (contacts
/// and bodies) allocates nothing on the heap, unless options().record_history asks for the
/// history, or the caller's ContactSolution must grow, or Newton factorizes J (its direct linear
/// solver: Eigen's sparse LU allocates in every factorization; Newton with GMRES does not).
/// Movable, not copyable.
class ContactSolver {
 public:
  /// Validates the options once (InvalidArgument, as the free functions do).
  explicit ContactSolver(Method method = Method::sor, SolverOptions options = {},
                         SolverHooks hooks = {});
  ~ContactSolver();                                     ///< frees the workspace
  ContactSolver(ContactSolver&&) noexcept;              ///< takes over the workspace
  ContactSolver& operator=(ContactSolver&&) noexcept;   ///< takes over the workspace
  ContactSolver(const ContactSolver&) = delete;
  ContactSolver& operator=(const ContactSolver&) = delete;

  /// Validates the problem (contact::validate(), InvalidArgument) and the initial guess
  /// (`solution.lambda`: empty means zero), computes the Delassus blocks G_ii and the r-factors
  /// once, and solves; `solution.u` receives the end velocities.
  SolverResult solve(const ContactProblem& problem, ContactSolution& solution);
  /// The same for a problem the caller has already validated (contact::validate()) and whose
  /// diagonal Delassus blocks it has computed, G[i] = delassus_block(contacts[i], M_inv): the
  /// problem is neither validated nor G recomputed; only the sizes are checked (O(1)) and the
  /// initial guess (O(n)). What a time stepper calls once per step. Gives bit-identical results
  /// to solve().
  SolverResult solve_prepared(const ContactProblem& problem, std::span<const Matrix3> G,
                              ContactSolution& solution);
  /// The compact form of chapter 6 (world-frame velocities: `solution.u` is (I_v, I_ω) per body):
  /// validates the problem (contact::validate(const CompactProblem&)), then solves as
  /// solve_prepared() does.
  SolverResult solve(const CompactProblem& problem, ContactSolution& solution);
  /// The compact form for a problem the caller has already validated: only the sizes and the
  /// initial guess are checked. G_ii is formed from the frame and lever arms when the r-factors
  /// need it (once per solve), and SOR tests for divergence inside its sweep. What
  /// timestep::MoreauStepper calls once per step.
  SolverResult solve_prepared(const CompactProblem& problem, ContactSolution& solution);
  /// The local form (FCLIB): validates the problem, then solves; `lambda` is the initial guess on
  /// entry (empty means zero) and the result on return. after_iteration gets an empty u.
  SolverResult solve(const LocalProblem& problem, std::vector<Vector3>& lambda);

  const SolverOptions& options() const { return options_; }  ///< the validated options
  Method method() const { return method_; }                  ///< the method
  const SolverHooks& hooks() const { return hooks_; }         ///< the hooks

 private:
  Method method_;
  SolverOptions options_;
  SolverHooks hooks_;
  std::unique_ptr<detail::SolverWorkspace> workspace_;
};

/// \name Body-form solvers
/// Each validates the problem and the options first (InvalidArgument), then iterates: a
/// ContactSolver used once.
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
/// iterations (Mazhar et al. 2015 solve the convex relaxation; this solves Coulomb's law). The
/// numbers are the constants of namespace apgd. r_strategy does not apply.
SolverResult solve_apgd(const ContactProblem& problem, ContactSolution& solution,
                        const SolverOptions& options = {});
/// Semismooth Newton on the Alart–Curnier function Φ (newton.hpp) with SOR's r-factors as ρ:
/// each iteration solves J d = −Φ (options.newton.linear_solver; the body form with GMRES, W
/// never formed) and takes the step t d with the largest t = 1, ½, ¼, … that passes a
/// non-monotone Armijo test on ψ = ½‖Φ‖²; where the direction fails, SOR sweeps instead. Its
/// iterates go on moving at the rounding level of velocities that are zero at the solution, so
/// the change criteria (percussion_change, velocity_change) need abs_tol > 0 with it.
SolverResult solve_newton(const ContactProblem& problem, ContactSolution& solution,
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
/// Semismooth Newton on the Alart–Curnier function, by default with a sparse LU of J.
SolverResult solve_newton(const LocalProblem& problem, std::vector<Vector3>& lambda,
                          const SolverOptions& options = {});
///@}

}  // namespace grbd::contact
