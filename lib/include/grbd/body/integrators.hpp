#pragma once
/// \file
/// \brief Time integrators for one rigid body over (q, u), selectable at run time (chapter 2).
///
/// | scheme | order | keeps | cost |
/// |---|---|---|---|
/// | explicit_exp_map | 1 | \|p\| = 1 | one h evaluation, one exp |
/// | symplectic_exp_map | 1 | \|p\| = 1 | one h evaluation, one exp |
/// | explicit_euler_normalized | 1 | \|p\| = 1 only by projection | one h evaluation, one normalisation |
/// | lie_poisson | 2 | \|p\| = 1, \|L\| and I_L exactly; energy error bounded | five axis rotations |
/// | implicit_gyroscopic | 1 | \|p\| = 1; no energy gain if axisymmetric | one 3 × 3 solve |

#include <span>
#include <string_view>

#include "grbd/body/rigid_body.hpp"

namespace grbd::body {

/// The integrators of this chapter.
enum class Integrator {
  explicit_exp_map,           ///< (a) the lecture's scheme: u and q from the start of the step
  symplectic_exp_map,         ///< (b) semi-implicit Euler: u first, then q with the new u
  explicit_euler_normalized,  ///< (c) explicit Euler on q̇ = F(q)u, then p ← p/|p| (baseline)
  lie_poisson,                ///< (d) symmetric Lie–Poisson splitting of the free rotation
  implicit_gyroscopic,        ///< (e) the gyroscopic term implicit, one Newton step
};

/// What the documentation and the command line say about an integrator.
struct IntegratorInfo {
  Integrator scheme;         ///< which one
  std::string_view name;     ///< its run-time name, e.g. "lie_poisson"
  int order;                 ///< global order of convergence
  std::string_view keeps;    ///< invariants it keeps
};

/// Every integrator, in the order of the enumeration.
std::span<const IntegratorInfo> integrators();

/// The run-time name of a scheme, e.g. "explicit_exp_map".
std::string_view integrator_name(Integrator scheme);

/// The scheme with the given run-time name; throws grbd::InvalidArgument listing the valid names
/// for any other string.
Integrator parse_integrator(std::string_view name);

// [explicit exp map declaration]
/// \brief <b>Exercise 2.5</b>: one step of the lecture's scheme (explicit velocity update and
/// exponential-map orientation update).
///
/// With u = (v, ω) at the start of the step:
/// \f[ \mathbf u^+ = \mathbf u + h\,\mathbf M^{-1}\mathbf h(\mathbf u), \quad
///     {}_I\mathbf r_S^+ = {}_I\mathbf r_S + h\,\mathbf v, \quad
///     p^+ = p\,\exp_{S^3}(\tfrac h2\,\boldsymbol\omega). \f]
/// First order; |p| stays 1 to round-off.
State explicit_exp_map_step(const RigidBody& body, const State& x, const Loads& loads, double h);
// [explicit exp map declaration]

/// (b) Semi-implicit (symplectic) Euler with the exponential map: u⁺ = u + h M⁻¹ h(u), then
/// r⁺ = r + h v⁺, p⁺ = p exp_S3(h ω⁺/2). First order. Euler's equations do not involve q, so for
/// the free rotation its velocities, and its energy gain, are exactly those of (a); the gain is
/// in the translation under position-dependent forces (loads evaluated at the start of the
/// step), where it is symplectic Euler: for a spring it keeps a modified energy exactly.
State symplectic_exp_map_step(const RigidBody& body, const State& x, const Loads& loads, double h);

/// (c) Explicit Euler on q̇ = F(q)u and on M u̇ = h, then the projection p ← p/|p|: the naive
/// baseline. First order.
State explicit_euler_normalized_step(const RigidBody& body, const State& x, const Loads& loads,
                                     double h);

// [free rotation declaration]
/// \brief <b>Exercise 2.6</b>: the exact free rotation about one principal axis.
///
/// The exact flow, over time t, of the part T_i = L_i²/(2Θ_i) of the kinetic energy, with
/// L = Θ K_omega the body-frame angular momentum: the body turns about its principal axis e_i at
/// the constant rate φ̇ = L_i/Θ_i, so p⁺ = p exp_S3(½ t φ̇ e_i), while the body-frame components
/// of L turn the opposite way, L⁺ = exp_SO3(−t φ̇ e_i) L; K_omega⁺ = Θ⁻¹ L⁺. Position and
/// velocity of S are unchanged. axis ∈ {0, 1, 2}.
State free_rotation_about_axis(const RigidBody& body, const State& x, int axis, double t);
// [free rotation declaration]

/// (d) Symmetric Lie–Poisson splitting (McLachlan 1993; Dullweber, Leimkuhler, McLachlan 1997):
/// a half kick with the loads, then the free rotations R₁(h/2) R₂(h/2) R₃(h) R₂(h/2) R₁(h/2) and
/// the drift r⁺ = r + h v, then a second half kick. Second order; torque-free it keeps |L| and
/// I_L exactly and the energy error bounded, with no drift.
State lie_poisson_step(const RigidBody& body, const State& x, const Loads& loads, double h);

/// (e) The implicit gyroscopic step of interactive physics (Catto 2015): solve
/// Θ(ω⁺ − ω) + h ω⁺ × Θω⁺ = h K_M for ω⁺ with one Newton step from ω, v⁺ = v + h I_F/m, then
/// r⁺ = r + h v⁺, p⁺ = p exp_S3(h ω⁺/2). First order; stable for fast-spinning, elongated bodies
/// where (a) and (b) gain energy. Torque-free, the exact root never gains energy; the one Newton
/// step keeps that for axisymmetric bodies (observed at every h) and for asymmetric ones while
/// h|ω| ≲ 0.1, but beyond, a nearly singular Jacobian can make a step gain energy.
State implicit_gyroscopic_step(const RigidBody& body, const State& x, const Loads& loads, double h);

/// One step of the chosen scheme.
State step(const RigidBody& body, const State& x, const Loads& loads, double h, Integrator scheme);

}  // namespace grbd::body
