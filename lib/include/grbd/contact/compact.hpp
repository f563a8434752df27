#pragma once
/// \file
/// \brief The compact form of the contact problem (chapter 6): what a time step of many bodies
/// solves. The same problem as ContactProblem, written in the world frame so that a contact
/// stores its frame and two lever arms (136 bytes) instead of two 6 × 3 Jacobians (352 bytes).
///
/// The body velocities are u = (I_v_S, I_ω): the angular velocity in the world frame I, not in
/// the body frame K as in ContactProblem. Then the contact Jacobian of side a with lever arm
/// I_r_a (from the centre of mass S_a to the contact point) and frame B = [n t1 t2] is
/// W_a = [B; I_r̃_a B], known from B and r_a alone, and the contact velocity is
/// γ = Bᵀ (v_a + ω_a × r_a − v_b − ω_b × r_b): one frame product per contact. The price is a
/// world-frame inverse inertia I_Θ⁻¹ = A_IK K_Θ⁻¹ A_IKᵀ per body, a full symmetric 3 × 3 matrix
/// (c·I for a sphere), recomputed when the orientation changes, i.e. once per step.

#include <limits>
#include <span>
#include <vector>

#include "grbd/contact/problem.hpp"
#include "grbd/core/types.hpp"

namespace grbd::contact {

/// The inverse mass of a body in the world frame: M⁻¹ = diag(1/m I₃, I_Θ⁻¹).
struct WorldInverseMass {
  double inv_m = 1.0;                          ///< 1/m [1/kg]
  Matrix3 I_Theta_inv = Matrix3::Identity();   ///< A_IK K_Θ⁻¹ A_IKᵀ [1/(kg m²)]
};

/// The world-frame inverse mass of a body with inverse mass `M_inv` (principal frame K) and
/// orientation A_IK. A body with three equal principal moments (a sphere) gets exactly
/// (1/Θ) I₃, without the rounding of the rotation.
WorldInverseMass world_inverse_mass(const InverseMass& M_inv, const Matrix3& A_IK);

/// One contact in the compact form. γ = Bᵀ(v_a + ω_a × r_a) − Bᵀ(v_b + ω_b × r_b), B = [n t1 t2]
/// with t2 = n × t1; a static side contributes nothing (its lever arm is not read).
struct CompactContact {
  BodyIndex body_a = kStatic;          ///< body a, or kStatic
  BodyIndex body_b = kStatic;          ///< body b, or kStatic
  Vector3 n = Vector3::UnitZ();        ///< unit normal, from b towards a
  Vector3 t1 = Vector3::UnitX();       ///< first tangent, ⟂ n; the second is t2 = n × t1
  Vector3 r_a = Vector3::Zero();       ///< lever arm of a, S_a → contact point, frame I [m]
  Vector3 r_b = Vector3::Zero();       ///< lever arm of b, S_b → contact point, frame I [m]
  /// ε ∘ γ_A, the restituted start velocity of Newton's law: ξ = γ_E + xi_A [m/s]
  Vector3 xi_A = Vector3::Zero();
  double mu = 0.0;                     ///< Coulomb friction coefficient, ≥ 0
  /// t2 = n × t1.
  Vector3 t2() const { return n.cross(t1); }
};

/// The contact problem of one step in compact form. u_free and the solution's u are
/// (I_v_S, I_ω) per body.
struct CompactProblem {
  std::vector<WorldInverseMass> M_inv;  ///< one per body
  std::vector<Vector6> u_free;          ///< velocity of each body without contact forces
  std::vector<CompactContact> contacts; ///< one per contact
  /// Every I_Θ⁻¹ is a multiple of I₃ (a system of spheres): the sweep then multiplies by its
  /// (0, 0) entry instead of the matrix, 24 fewer operations per contact update. validate()
  /// checks it.
  bool isotropic = false;
  /// The reference ‖c‖ of the natural-residual criterion when the caller sets it (> 0): the
  /// stepper's, which leaves out the look-ahead's gap rates g_N/Δt of xi_A (chapter 6, \ref
  /// ch06_gap_law) — a length over a step, not a velocity of the motion. 0: ‖Wᵀu_free + xi_A‖.
  double reference_norm = 0.0;
};

/// Checks a compact problem before a solver touches it: body counts that agree, body indices in
/// range and not both static nor equal, finite entries, 1/m > 0, I_Θ⁻¹ symmetric with a positive
/// diagonal, a unit normal and a unit tangent ⟂ n (to 10⁻⁹), μ ≥ 0. Throws InvalidArgument
/// naming the first bad entry, what was expected and what was found.
void validate(const CompactProblem& problem);

/// The Delassus block G_ii = Σ_sides W_sᵀ M_s⁻¹ W_s of one compact contact (3 × 3, symmetric):
/// (1/m) I₃ + Cᵀ I_Θ⁻¹ C per dynamic side, with C = [r × n, r × t1, r × t2].
Matrix3 delassus_block(const CompactContact& contact, std::span<const WorldInverseMass> M_inv);

/// The diagonal of delassus_block(): G_kk = Σ_sides 1/m + c_kᵀ I_Θ⁻¹ c_k with c_k = r × f_k for
/// the frame f = (n, t1, t2), all the r-factors read (chapter 5's r_factors()), at a third of
/// the cost of the block.
Vector3 delassus_diagonal(const CompactContact& contact, std::span<const WorldInverseMass> M_inv);

/// γ = W_aᵀ u_a − W_bᵀ u_b of one compact contact for world-frame body velocities u.
Vector3 contact_velocity(const CompactContact& contact, std::span<const Vector6> u);

/// The generalised percussion W_s λ of side s of a compact contact: (F λ, r_s × F λ), frame I.
Vector6 side_percussion(const CompactContact& contact, const Vector3& r_side, const Vector3& lambda);

/// v_a += M_a⁻¹ W_a λ and v_b −= M_b⁻¹ W_b λ for the percussion λ of one compact contact (static
/// sides skipped): what a percussion does to the world-frame body velocities v.
void add_percussion(const CompactContact& contact, const Vector3& lambda,
                    std::span<const WorldInverseMass> M_inv, std::span<Vector6> v);

/// u = u_free + M⁻¹ W Λ for percussions Λ (one per contact), into `u` (resized to one entry per
/// body, its capacity reused). The indices of the contacts are not checked: `problem` must be one
/// that validate() accepted.
void velocities_from_percussions(const CompactProblem& problem, std::span<const Vector3> lambda,
                                 std::vector<Vector6>& u);

/// What a solver does before its first iteration, in one pass over the contacts with the bodies
/// of the contacts ahead prefetched: u = u_free + M⁻¹ W Λ for the initial percussions Λ (u
/// resized to one entry per body); when r is not empty (one entry per contact), the per-contact
/// r-factors r_factors(G_ii, α) from delassus_diagonal(); and the sum of squares of the free
/// contact velocities c_i = W_iᵀ u_free + xi_A, returned, from which ‖c‖ follows. Contacts are not
/// re-checked: `problem` must be one that validate() accepted.
double start_solve(const CompactProblem& problem, std::span<const Vector3> lambda, double alpha,
                   std::span<RFactors> r, std::vector<Vector6>& u);

/// The same problem in the body form of chapter 5, for bodies with principal-frame inverse masses
/// `M_inv` and orientations `A_IK` (those the compact problem was built with, one per body):
/// W_s = [F; A_IKᵀ (r_s × F)], u_free with ω in frame K, γ_A = xi_A with ε_N = ε_T = 1. The
/// reference the compact solver is tested against, and the baseline of the benchmarks. Throws
/// InvalidArgument for sizes that do not match.
ContactProblem body_form(const CompactProblem& problem, std::span<const InverseMass> M_inv,
                         std::span<const Matrix3> A_IK);

// [compact sweep declaration]
/// What one compact sweep saw (sor_sweep()).
struct SweepReport {
  /// Every updated percussion is finite: the test of divergence, folded into the sweep (a
  /// non-finite component makes 0 · λ a NaN) instead of a second pass over Λ.
  bool finite = true;
  /// Every component of every λ moved by at most abs_tol + rel_tol |λ_new|: has_converged() of
  /// the sweep's own change, without a copy of Λ (always true with the default tolerances).
  bool settled = true;
  /// With `residual` asked: the natural-map residual of the sweep, (Σ_i ‖F(λ_i, ξ_i)‖²)^½ with
  /// each contact's λ_i and ξ_i as the sweep found them before updating it (the contacts before
  /// it updated, those after it not yet) — not the residual of any one iterate, but zero exactly
  /// at a solution and tending to zero with ‖F‖, at the cost of one cone projection per contact;
  /// −1 when not asked.
  double residual = -1.0;
};

/// One Gauss–Seidel sweep over a compact problem: for contacts 0, 1, …, n − 1 in order, the
/// contact velocity seen now, ξ = γ + xi_A, the prox update of `form` (as sor_contact_update()
/// of chapter 5), and the body velocities follow the change at once. Reports whether every
/// updated percussion is finite and whether the change of each stayed within
/// abs_tol + rel_tol |λ_new| (the percussion criterion of the solvers, evaluated in the sweep),
/// and, with `residual`, the natural-map residual of the sweep (SweepReport::residual).
/// Throws InvalidArgument unless r and lambda have one entry per contact and u one per body
/// (O(1)); the contacts themselves are not re-checked: `problem` must be one that validate()
/// accepted.
SweepReport sor_sweep(const CompactProblem& problem, std::span<const RFactors> r, ProxForm form,
                      std::span<Vector6> u, std::span<Vector3> lambda,
                      double abs_tol = std::numeric_limits<double>::infinity(),
                      double rel_tol = 0.0, bool residual = false);
// [compact sweep declaration]

}  // namespace grbd::contact
