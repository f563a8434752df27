#pragma once
/// \file
/// \brief The semismooth Newton method of chapter 5: the Alart–Curnier function of one contact
/// and an element of its generalized Jacobian, the generalized Jacobians of the prox onto ℝ₊ and
/// onto the disk it is built from, and the restarted GMRES that solves the Newton systems of the
/// body form without forming W = Hᵀ M⁻¹ H.
///
/// The solver itself is Method::newton of solver.hpp (ContactSolver, solve_newton()): it finds
/// Λ with Φ(Λ) = 0, where per contact
///
///   Φ_N = λ_N − max(0, λ_N − ρ_N ξ_N),
///   Φ_T = λ_T − P_D(μ max(0, λ_N − ρ_N ξ_N)) (λ_T − ρ_T ξ_T),
///
/// ξ = W Λ + q, P_D(r) the prox onto the disk of radius r (Alart and Curnier 1991): Φ(Λ) = 0
/// exactly when Λ and ξ satisfy Coulomb's law, and Φ = Λ − the Alart–Curnier prox update of SOR.
/// Φ is piecewise smooth, so Newton's method takes, at each iterate, one element J = A + B W of
/// its generalized Jacobian, with A = ∂Φ/∂Λ and B = ∂Φ/∂ξ block diagonal (3 × 3 per contact).

#include <span>
#include <vector>

#include "grbd/core/types.hpp"

namespace grbd::contact {

// [prox nonnegative jacobian declaration]
/// \brief <b>Exercise 5.9</b>: an element of the generalized Jacobian of the prox onto ℝ₊.
///
/// d/dx max(x, 0): 1 for x > 0 and 0 for x < 0; at the kink x = 0 any value in [0, 1] is an
/// element of Clarke's generalized Jacobian, and this function takes 0 (the contact counted as
/// open, which keeps Φ_N = λ_N, the choice of Alart and Curnier).
double prox_nonnegative_jacobian(double x);
// [prox nonnegative jacobian declaration]

// [prox disk jacobian declaration]
/// The derivatives of the prox onto the disk of radius ρ at x: ∂P/∂x (2 × 2) and ∂P/∂ρ (2).
struct DiskJacobian {
  Eigen::Matrix2d d_x = Eigen::Matrix2d::Zero();  ///< ∂P_D(ρ)(x)/∂x
  Vector2 d_radius = Vector2::Zero();             ///< ∂P_D(ρ)(x)/∂ρ
};

/// \brief <b>Exercise 5.10</b>: an element of the generalized Jacobian of the prox onto the disk.
///
/// Inside the disk (‖x‖ ≤ ρ, the boundary counted as inside) P(x) = x: ∂P/∂x = I, ∂P/∂ρ = 0.
/// Outside, P(x) = ρ x/‖x‖: with t = x/‖x‖, ∂P/∂x = (ρ/‖x‖)(I − t tᵀ) and ∂P/∂ρ = t. ρ ≥ 0; for
/// x = 0 (inside any disk) the identity.
DiskJacobian prox_disk_jacobian(const Vector2& x, double radius);
// [prox disk jacobian declaration]

/// Φ of one contact with its Jacobian blocks.
struct AlartCurnierJacobian {
  Vector3 phi = Vector3::Zero();  ///< Φ(λ, ξ)
  Matrix3 A = Matrix3::Zero();    ///< ∂Φ/∂λ
  Matrix3 B = Matrix3::Zero();    ///< ∂Φ/∂ξ
};

/// The Alart–Curnier function of one contact, Φ = λ − alart_curnier_update(λ, ξ, ρ_N, ρ_T, μ),
/// and an element of its generalized Jacobian in λ and ξ, built from prox_nonnegative_jacobian()
/// and prox_disk_jacobian(): with σ_N = λ_N − ρ_N ξ_N, s = prox_nonnegative_jacobian(σ_N),
/// σ_T = λ_T − ρ_T ξ_T and (P_x, P_ρ) = prox_disk_jacobian(σ_T, μ max(σ_N, 0)),
///
///   A = [1 − s, 0; −μ s P_ρ, I − P_x],   B = [ρ_N s, 0; μ s ρ_N P_ρ, ρ_T P_x].
///
/// ρ_N, ρ_T > 0 (the r-factors of SOR serve), μ ≥ 0.
AlartCurnierJacobian alart_curnier_jacobian(const Vector3& lambda, const Vector3& xi, double rho_N,
                                            double rho_T, double mu);

/// Φ alone, without the Jacobian (the line search's trial points).
Vector3 alart_curnier_function(const Vector3& lambda, const Vector3& xi, double rho_N,
                               double rho_T, double mu);

/// The constants of the Newton method (Method::newton), each with the reason for its value.
namespace newton {
/// Armijo's sufficient decrease on the merit ψ = ½‖Φ‖²: a step t is taken when
/// ψ(Λ + t d) ≤ ψ_ref + kArmijo t ∇ψᵀd. The customary 10⁻⁴: any decrease near the full Newton
/// step is accepted, so the method keeps its quadratic rate.
inline constexpr double kArmijo = 1e-4;
/// Halvings of t before the line search gives up (t = 2⁻³⁰ ≈ 10⁻⁹): a direction that needs a
/// smaller step is no use, and the fall-back sweeps take over.
inline constexpr int kMaxHalvings = 30;
/// The Newton system is (J + εI) d = −Φ, regularized as Levenberg and Marquardt do: where W is
/// rank-deficient (more contact directions than the bodies' velocities, as in every hyperstatic
/// packing) J is singular, and ε keeps the step finite. ε starts at kInitialRegularization, is
/// multiplied by kRegularizationDecrease after every full step (t = 1), down to
/// kMinRegularization, so that near a regular solution J itself takes over and the rate is
/// quadratic to within 10⁻⁸ per iteration, and by kRegularizationIncrease, up to
/// kMaxRegularization, whenever the direction fails. J is dimensionless (A is, and B W is with ρ
/// the r-factors ~ 1/W_ii), so ε is too. The floor matters where W is rank-deficient: with ε → 0
/// the percussions drift along W's null space, which changes no velocity, to ever larger values
/// (PerioBox-60 of FCLIB: stuck at ‖F‖/‖q‖ ≈ 3·10⁻⁷ with |λ| ~ 10⁶ |q|, solved in 20 iterations
/// with the floor 10⁻⁸).
inline constexpr double kInitialRegularization = 1e-3;
inline constexpr double kRegularizationDecrease = 0.1;   ///< factor after a full step
inline constexpr double kRegularizationIncrease = 10.0;  ///< factor after a failed direction
inline constexpr double kMinRegularization = 1e-8;       ///< ε at least
inline constexpr double kMaxRegularization = 1.0;        ///< ε at most
/// GMRES stops when its residual is below η_k ‖Φ_k‖ with η_k = min(kMaxForcing, ‖Φ_k‖/‖Φ_0‖):
/// a rough solve far from the solution, an ever more exact one near it, which keeps the rate
/// quadratic (Eisenstat and Walker 1996, choice with exponent 2 in relative terms).
inline constexpr double kMaxForcing = 0.1;
/// The hybrid (NewtonOptions::hybrid_sweeps) compares ‖F‖ every this many SOR sweeps: one
/// evaluation of ξ per window, a twenty-fifth of a sweep's work per sweep, and long enough that
/// the erratic decrease of Gauss–Seidel over a few sweeps averages out (over windows of 10
/// sweeps, SOR that converges in 1600 sweeps on a pile of chapter 5 looked stagnant early on).
inline constexpr int kHybridWindow = 25;
}  // namespace newton

/// The operator of a Newton system, applied without forming it: y = J x.
struct LinearOperator {
  virtual ~LinearOperator() = default;
  virtual void apply(std::span<const double> x, std::span<double> y) const = 0;    ///< y = J x
  virtual void precondition(std::span<const double> x, std::span<double> y) const = 0;  ///< y ≈ J⁻¹ x
};

/// The buffers of gmres(), kept between calls (a Newton solve calls it once per iteration).
struct GmresWorkspace {
  std::vector<double> basis;          ///< (restart + 1) Krylov vectors of size m
  std::vector<double> hessenberg;     ///< (restart + 1) × restart, column-major
  std::vector<double> cs;             ///< cosines of the Givens rotations
  std::vector<double> sn;             ///< sines of the Givens rotations
  std::vector<double> g;              ///< the rotated right-hand side β e_1
  std::vector<double> y;              ///< the least-squares solution of a cycle
  std::vector<double> w;              ///< scratch vector of size m
  std::vector<double> z;              ///< scratch vector of size m
};

/// What gmres() did.
struct GmresResult {
  int iterations = 0;       ///< products with J
  double residual = 0.0;    ///< ‖b − J x‖ estimated by the recursion, at the end
  bool converged = false;   ///< residual ≤ tolerance
};

/// Restarted GMRES(restart) with right preconditioning for J x = b, from x = 0 (Saad and
/// Schultz 1986; Saad, "Iterative Methods for Sparse Linear Systems", algorithm 9.5): stops when
/// the residual is at most `tolerance` (absolute) or after `max_iterations` products with J.
/// x and b have the same size; x receives the solution. Allocates only when `ws` is too small.
GmresResult gmres(const LinearOperator& J, std::span<const double> b, std::span<double> x,
                  double tolerance, int restart, int max_iterations, GmresWorkspace& ws);

}  // namespace grbd::contact
