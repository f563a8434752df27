#pragma once
/// \file
/// \brief The pieces of Moreau's midpoint step for one body (chapter 6): the half steps of the
/// positions, the free velocity, the contact velocity at the start of the step, the energy of a
/// system, and the closed form of the bouncing ball the stepper is checked against.

#include <span>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/core/types.hpp"

namespace grbd::timestep {

// [half step declaration]
/// \brief <b>Exercise 6.1</b>: the half step of the positions.
///
/// q + (Δt/2) F(q) u with the orientation moved along the exponential map, as in chapter 2:
/// I_r_S ← I_r_S + (Δt/2) I_v_S and p ← p exp_S3((Δt/4) K_omega), so |p| stays 1. The midpoint
/// step uses it twice: q_M = half_step(q_S, u_S, Δt) at the beginning, q_E = half_step(q_M, u_E,
/// Δt) at the end.
Vector7 half_step(const Vector7& q, const Vector6& u, double dt);
// [half step declaration]

/// The variant of the lecture and of GRSFramework: q + (Δt/2) F(q) u added in ℝ⁷ (explicit
/// Euler on the quaternion), then p ← p/|p|. First order in the rotation angle; compared with
/// half_step() in the chapter.
Vector7 half_step_add_normalize(const Vector7& q, const Vector6& u, double dt);

// [free velocity declaration]
/// \brief <b>Exercise 6.2</b>: the free velocity.
///
/// u_free = u_S + Δt M⁻¹ h(q_M, u_S): the velocity at the end of the step without contact
/// percussions, with h = (I_F, K_M − K_ω × Θ K_ω) evaluated with the loads at the midpoint and
/// the velocity at the start (chapter 2's newton_euler_u_dot gives M⁻¹h).
Vector6 free_velocity(const body::RigidBody& body, const Vector6& u_S, const body::Loads& loads,
                      double dt);
// [free velocity declaration]

// [active declaration]
/// \brief <b>Exercise 6.3</b>: the active set.
///
/// Moreau's choice of the contacts that enter the step: those closed at the midpoint,
/// g_N(q_M) ≤ 0, here g_N(q_M) ≤ tolerance with a tolerance ≥ 0 of round-off size (a box
/// resting on a face keeps its four corners against gaps of 10⁻¹⁷ m). Returns true for an active
/// contact; a NaN gap is never active.
bool is_active(const collision::ContactGeometry& geometry, double tolerance);
// [active declaration]

// [gamma start declaration]
/// \brief <b>Exercise 6.4</b>: the contact velocity at the start of the step.
///
/// γ_S = W_aᵀ u_S,a − W_bᵀ u_S,b with the force directions W evaluated at the midpoint q_M and
/// the velocities at the start of the step; Newton's impact law restitutes ε γ_S. A static side
/// (nullptr) contributes nothing.
Vector3 start_contact_velocity(const collision::ContactJacobian* W_a, const Vector6* u_a,
                               const collision::ContactJacobian* W_b, const Vector6* u_b);
// [gamma start declaration]

// [energy declaration]
/// \brief <b>Exercise 6.5</b>: the mechanical energy of a system.
///
/// E = Σ_i (½ u_iᵀ M_i u_i − m_i I_gᵀ I_r_S,i) over the bodies (kinetic energy plus the potential
/// of gravity I_g, zero at the origin). The spans have one entry per body.
double mechanical_energy(std::span<const body::RigidBody> bodies,
                         std::span<const body::State> states, const Vector3& I_g);
// [energy declaration]

// [impact time declaration]
/// \brief <b>Exercise 6.6</b>: the impact times of the bouncing ball.
///
/// A ball dropped from rest at height h₀ (gap above the floor) under gravity g with Newton's law
/// ε ∈ [0, 1): the time of its k-th impact (k = 1, 2, …),
/// t_k = t₁ (1 + 2 ε + 2 ε² + … + 2 ε^(k−1)) with t₁ = √(2h₀/g); the impacts accumulate at the
/// Zeno time t_∞ = t₁ (1 + ε)/(1 − ε), after which the ball rests. Throws InvalidArgument for
/// k < 1, h₀ < 0, g ≤ 0 or ε ∉ [0, 1).
double bouncing_ball_impact_time(int k, double h0, double g, double eps);
// [impact time declaration]

/// The Zeno time t₁ (1 + ε)/(1 − ε) of the bouncing ball (same arguments and checks).
double bouncing_ball_zeno_time(double h0, double g, double eps);

}  // namespace grbd::timestep
