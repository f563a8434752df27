#pragma once
/// \file
/// \brief Proximal-point operators of the contact laws (chapter 5): the prox onto ℝ₊, onto the
/// friction disk and onto the Coulomb cone, the Alart–Curnier and De Saxcé prox updates of one
/// contact, and the natural-map residual that measures how far a pair (λ, ξ) is from satisfying
/// the contact law.
///
/// Per contact the percussion λ = (λ_N, λ_T1, λ_T2) and the contact velocity
/// ξ = (ξ_N, ξ_T1, ξ_T2) are ordered normal first, like FCLIB. The Coulomb cone of friction
/// coefficient μ is K_μ = {λ : ‖λ_T‖ ≤ μ λ_N}.

#include <span>

#include "grbd/core/types.hpp"

namespace grbd::contact {

// [prox nonnegative declaration]
/// \brief <b>Exercise 5.1</b>: the prox onto ℝ₊.
///
/// prox_ℝ₊(x) = argmin_{y ≥ 0} |y − x| = max(x, 0): the unilateral contact law
/// −ξ_N ∈ N_ℝ₊(λ_N) is equivalent to λ_N = prox_ℝ₊(λ_N − r ξ_N) for every r > 0.
double prox_nonnegative(double x);
// [prox nonnegative declaration]

// [prox disk declaration]
/// \brief <b>Exercise 5.2</b>: the prox onto the disk of radius ρ.
///
/// The point of C_T = {y ∈ ℝ² : ‖y‖ ≤ ρ} closest to x: x itself when ‖x‖ ≤ ρ, otherwise
/// ρ x/‖x‖. With ρ = μ λ_N this is the prox of spatial Coulomb friction. ρ ≥ 0; for ρ = 0 the
/// result is 0.
Vector2 prox_disk(const Vector2& x, double radius);
// [prox disk declaration]

// [prox cone declaration]
/// \brief <b>Exercise 5.3</b>: the prox onto the Coulomb cone.
///
/// The Euclidean projection of x = (x_N, x_T) onto K_μ = {‖y_T‖ ≤ μ y_N}, μ ≥ 0: x itself when
/// x ∈ K_μ; 0 when x lies in the polar cone (μ ‖x_T‖ ≤ −x_N); otherwise the point of the cone's
/// surface y_N = (x_N + μ ‖x_T‖)/(1 + μ²), y_T = μ y_N x_T/‖x_T‖.
Vector3 prox_cone(const Vector3& x, double mu);
// [prox cone declaration]

/// The Alart–Curnier prox update of one contact, normal first, then tangential:
/// λ_N⁺ = prox_ℝ₊(λ_N − r_N ξ_N), λ_T⁺ = prox_disk(μ λ_N⁺)(λ_T − r_T ξ_T). A fixed point of this
/// map (for any r_N, r_T > 0) satisfies unilateral contact and spatial Coulomb friction.
Vector3 alart_curnier_update(const Vector3& lambda, const Vector3& xi, double r_N, double r_T,
                             double mu);

/// The De Saxcé prox update of one contact with the augmented (modified) velocity:
/// λ⁺ = prox_K_μ(λ − r (ξ + μ ‖ξ_T‖ e_N)). Its fixed points (for any r > 0) are exactly the
/// solutions of the Coulomb law written as the bipotential inclusion of De Saxcé and Feng.
Vector3 de_saxce_update(const Vector3& lambda, const Vector3& xi, double r, double mu);

/// The local natural-map residual of the Coulomb law (De Saxcé form, r = 1), as FCLIB and
/// Siconos measure it: F = λ − prox_K_μ(λ − (ξ + μ ‖ξ_T‖ e_N)). F = 0 exactly when (λ, ξ)
/// satisfy the law.
Vector3 natural_map(const Vector3& lambda, const Vector3& xi, double mu);

/// The natural-map residual of a whole problem: ‖F‖₂ = (Σ_i ‖natural_map(λ_i, ξ_i, μ_i)‖²)^½.
/// The three spans have one entry per contact.
double natural_map_residual(std::span<const Vector3> lambda, std::span<const Vector3> xi,
                            std::span<const double> mu);

}  // namespace grbd::contact
