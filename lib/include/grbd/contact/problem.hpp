#pragma once
/// \file
/// \brief The contact problem of one time step in percussions, in body form (chapter 5): bodies
/// with their inverse mass and free velocity, contacts with their force directions W_a, W_b,
/// friction and restitution; the Newton impact law, the Delassus blocks G_ii = W_iᵀ M⁻¹ W_i and
/// the SOR contact update that changes λ_i and the velocities of the two bodies it touches.
///
/// The problem is: find percussions Λ = (λ_1 … λ_n) and end velocities
/// u = u_free + M⁻¹ W Λ such that, for every contact i, the velocity of the impact law
/// ξ_i = W_iᵀ u + ε_i ∘ γ_A,i and λ_i satisfy the Coulomb law (λ_i ∈ K_μ and the inclusions of
/// prox.hpp). No global matrix is formed: M is block diagonal, W has two 6 × 3 blocks per contact,
/// and G = WᵀM⁻¹W is needed only through its 3 × 3 diagonal blocks and matrix–vector products.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/core/types.hpp"

namespace grbd::contact {

/// Index of a body in ContactProblem::bodies, or kStatic for the fixed world.
using BodyIndex = collision::BodyIndex;
/// The fixed world: its velocity is zero and its mass infinite.
inline constexpr BodyIndex kStatic = collision::kStatic;
/// "No contact index" for the messages of require_body_indices().
inline constexpr std::size_t kNoIndex = static_cast<std::size_t>(-1);

/// The inverse of a body's mass matrix in u = (I_v_S, K_omega), with K a principal frame (as
/// body::RigidBody): M⁻¹ = diag(1/m, 1/m, 1/m, 1/Θ₁, 1/Θ₂, 1/Θ₃), constant in time because the
/// inertia is expressed in the body frame, and diagonal, which keeps the SOR update cheap.
struct InverseMass {
  double inv_m = 1.0;                        ///< 1/m [1/kg]
  Vector3 K_Theta_inv = Vector3::Ones();     ///< 1/Θ_k, inverse principal moments [1/(kg m²)]
  /// M⁻¹ x for x ∈ ℝ⁶.
  Vector6 apply(const Vector6& x) const {
    // Component by component: with head<3>() and tail<3>() the compiler splits the 16-byte
    // packet (x_2, x_3) and passes the halves through memory, a store-forwarding stall on the
    // path of every SOR contact update (chapter 5).
    return {inv_m * x(0),          inv_m * x(1),          inv_m * x(2),
            K_Theta_inv(0) * x(3), K_Theta_inv(1) * x(4), K_Theta_inv(2) * x(5)};
  }
};

/// The inverse mass of a rigid body (m, K_Θ_S); throws InvalidArgument if m or Θ is not positive.
InverseMass inverse_mass(const body::RigidBody& body);

/// One contact of the problem. γ = W_aᵀ u_a − W_bᵀ u_b is the velocity of a's contact point
/// relative to b's in the contact frame (normal first); a static side contributes nothing.
struct ContactConstraint {
  BodyIndex body_a = kStatic;                         ///< body a, or kStatic
  BodyIndex body_b = kStatic;                         ///< body b, or kStatic
  collision::ContactJacobian W_a = collision::ContactJacobian::Zero();  ///< 6 × 3, enters with +
  collision::ContactJacobian W_b = collision::ContactJacobian::Zero();  ///< 6 × 3, enters with −
  Vector3 gamma_A = Vector3::Zero();  ///< contact velocity at the beginning of the step [m/s]
  double mu = 0.0;                    ///< Coulomb friction coefficient, ≥ 0
  double eps_N = 0.0;                 ///< normal restitution ε_N ∈ [0, 1]
  double eps_T = 0.0;                 ///< tangential restitution ε_T ∈ [-1, 1]
};

/// The contact problem of one step in body form. `keys` is either empty or has one entry per
/// contact: the contact's identity for warm starts (WarmStart).
struct ContactProblem {
  std::vector<InverseMass> M_inv;               ///< one per body
  std::vector<Vector6> u_free;                  ///< velocity of each body without contact forces
  std::vector<ContactConstraint> contacts;      ///< one per contact
  std::vector<collision::ContactKey> keys;      ///< empty, or one per contact
};

/// Throws InvalidArgument, starting with "<where>: contact <index>" (without the contact when
/// `index` is kNoIndex), unless each side of
/// `contact` is kStatic or a body index in [0, bodies), and the two sides are not both static.
/// O(1), and nothing is allocated unless it throws: the checked entry points call it before they
/// index by body.
void require_body_indices(const ContactConstraint& contact, std::size_t bodies,
                          std::string_view where, std::size_t index = kNoIndex);

/// Checks a problem before a solver touches it and throws InvalidArgument naming the first bad
/// entry (its kind and index), what was expected and what was found: body counts that disagree,
/// a body index out of range, a contact between a body and itself or between two static sides,
/// NaN or Inf anywhere, 1/m ≤ 0, an inverse principal moment K_Θ⁻¹ ≤ 0, μ < 0,
/// ε_N ∉ [0, 1], |ε_T| > 1, a Delassus block whose diagonal is not positive, keys of the wrong
/// length.
void validate(const ContactProblem& problem);

// [impact velocity declaration]
/// \brief <b>Exercise 5.4</b>: the velocity of Newton's impact law.
///
/// ξ = γ_E + ε ∘ γ_A with ε = (ε_N, ε_T, ε_T): the contact velocity at the end of the step plus
/// the restituted part of the one at the beginning. The contact law is stated for ξ, so that
/// a closing contact (γ_N,A < 0) leaves with γ_N,E = −ε_N γ_N,A.
Vector3 impact_velocity(const Vector3& gamma_E, const Vector3& gamma_A, double eps_N, double eps_T);
// [impact velocity declaration]

// [delassus block declaration]
/// \brief <b>Exercise 5.5</b>: the Delassus block of one contact.
///
/// G_ii = W_aᵀ M_a⁻¹ W_a + W_bᵀ M_b⁻¹ W_b (3 × 3, symmetric positive semidefinite): how the
/// contact velocity ξ_i responds to its own percussion λ_i. A static side (index kStatic)
/// contributes nothing. `M_inv` is indexed by body.
Matrix3 delassus_block(const ContactConstraint& contact, std::span<const InverseMass> M_inv);
// [delassus block declaration]

/// The r-factors of one contact: r_N for the normal, r_T for the tangential prox.
struct RFactors {
  double r_N = 0.0;  ///< normal r-factor [kg]: percussion per contact velocity
  double r_T = 0.0;  ///< tangential r-factor [kg]
};

/// Which prox update a solver applies to each contact.
enum class ProxForm {
  alart_curnier,  ///< normal first, then tangential on the disk of radius μ λ_N⁺
  de_saxce,       ///< one projection onto the cone with the augmented velocity, r = min(r_N, r_T)
};

// [sor contact update declaration]
/// \brief <b>Exercise 5.7</b>: one SOR contact update.
///
/// For contact `c`: the impact-law velocity ξ = impact_velocity(W_aᵀ u_a − W_bᵀ u_b, γ_A, ε_N,
/// ε_T); the prox update λ⁺ of `form` with r-factors `r`; then the body velocities follow the
/// change Δλ = λ⁺ − λ at once: u_a += M_a⁻¹ W_a Δλ, u_b −= M_b⁻¹ W_b Δλ (static sides are
/// skipped). `lambda` is replaced by λ⁺. `M_inv` and `u` are indexed by body. Returns ξ, the
/// velocity the update saw (before the change).
///
/// An unchecked kernel, the innermost step of SOR: the body indices of `c` must be valid for
/// `M_inv` and `u`. It is reached through sor_sweep() and the solvers, which work on problems
/// that validate() accepted.
Vector3 sor_contact_update(const ContactConstraint& c, const RFactors& r, ProxForm form,
                           std::span<const InverseMass> M_inv, std::span<Vector6> u,
                           Vector3& lambda);
// [sor contact update declaration]

/// The end velocities u = u_free + M⁻¹ W Λ for percussions Λ (one λ per contact). Throws
/// InvalidArgument for a wrong number of percussions or body velocities, or a body index out of
/// range.
std::vector<Vector6> velocities_from_percussions(const ContactProblem& problem,
                                                 std::span<const Vector3> lambda);

/// The impact-law velocities ξ_i = W_iᵀ u + ε_i ∘ γ_A,i of all contacts for body velocities u.
/// Throws InvalidArgument for a wrong number of velocities or a body index out of range.
std::vector<Vector3> contact_velocities(const ContactProblem& problem, std::span<const Vector6> u);

/// Material data of a contact pair for assemble_problem().
struct ContactMaterial {
  double mu = 0.5;     ///< friction coefficient
  double eps_N = 0.0;  ///< normal restitution
  double eps_T = 0.0;  ///< tangential restitution
};

/// Builds the problem of one step from the contacts of a collision world: W_a, W_b from
/// collision::contact_jacobian() at the body orientations of `states`, γ_A from the velocities of
/// `states` (beginning of the step), M⁻¹ from `bodies`, and keys from the contacts.
/// `bodies`, `states` and `u_free` are indexed by body.
ContactProblem assemble_problem(std::span<const collision::Contact> contacts,
                                std::span<const body::RigidBody> bodies,
                                std::span<const body::State> states,
                                std::span<const Vector6> u_free, const ContactMaterial& material);

}  // namespace grbd::contact
