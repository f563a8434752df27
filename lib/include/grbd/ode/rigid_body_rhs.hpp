#pragma once
/// \file
/// \brief Right-hand sides of the smooth rigid-body problems over the library's own state types,
/// for the SUNDIALS integrators, and the projection onto |p| = 1 (chapter 3).

#include <functional>

#include <Eigen/Core>

#include "grbd/body/rigid_body.hpp"
#include "grbd/core/types.hpp"
#include "grbd/ode/sundials.hpp"

namespace grbd::ode {

/// The state of one body as one vector y = (q, u) = (I_r_S, p, I_v_S, K_omega) ∈ ℝ¹³.
Eigen::VectorXd pack(const body::State& x);
/// The inverse of pack(); y must have 13 entries.
body::State unpack(const Eigen::Ref<const Eigen::VectorXd>& y);

// [free body rhs declaration]
/// \brief <b>Exercise 3.1</b>: the right-hand side of a rigid body under constant loads.
///
/// For y = (q, u) ∈ ℝ¹³: ẏ = (F(q) u, M⁻¹ h(u)), the kinematic map of chapter 1 and the
/// Newton–Euler equations of chapter 2. Writes the 13 entries of y_dot.
void free_body_rhs(const body::RigidBody& body, const body::Loads& loads,
                   const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> y_dot);
// [free body rhs declaration]

/// free_body_rhs() as a RhsFunction for Cvode and Arkode (the loads are constant in time).
/// Throws grbd::InvalidArgument for a body without positive, finite m and K_Theta, and, when
/// called, for y or y_dot without 13 entries.
RhsFunction free_body(const body::RigidBody& body, const body::Loads& loads = {});

/// A body under the prescribed torque K_M(t) (frame K) and no force: ẏ = (F(q) u, M⁻¹ h(t, u)),
/// K_M evaluated at the time of each call. Checks as free_body(), and K_M must not be empty.
RhsFunction prescribed_torque_body(const body::RigidBody& body,
                                   std::function<Vector3(double t)> K_M);

/// A heavy symmetric top spinning about a fixed point O on its symmetry axis e3, the centre of
/// mass S at K_r_OS = l e3, gravity I_g = (0, 0, −g).
struct HeavyTop {
  double m = 1.0;   ///< mass [kg]
  double l = 0.1;   ///< distance from the fixed point O to S [m]
  double I1 = 1.0;  ///< transverse moment about S [kg m²]
  double I3 = 1.0;  ///< axial moment [kg m²]
  double g = 9.81;  ///< gravitational acceleration [m/s²]
};

/// The heavy top about its fixed point, y = (p, K_omega) ∈ ℝ⁷: ṗ = ½ p (0, ω),
/// Θ_O ω̇ = K_r_OS × (A_IKᵀ m I_g) − ω × Θ_O ω with Θ_O = diag(I1 + m l², I1 + m l², I3).
/// A_IK is the rotation of p/|p|, so that a drift of |p| does not change the weight. Throws
/// grbd::InvalidArgument unless m, I1, I3 > 0 and l, g ≥ 0 (all finite), and, when called, for
/// y or y_dot without 7 entries.
RhsFunction heavy_top(const HeavyTop& top);

// [quaternion projection declaration]
/// \brief <b>Exercise 3.2</b>: the projection onto |p| = 1.
///
/// For the solution y whose entries offset … offset+3 hold a quaternion p, writes the correction
/// that CVODE adds to y: p/|p| − p in those four entries, zero in all others.
void quaternion_projection(Eigen::Index offset, const Eigen::Ref<const Eigen::VectorXd>& y,
                           Eigen::Ref<Eigen::VectorXd> correction);
// [quaternion projection declaration]

/// quaternion_projection() as a ProjectionFunction for Cvode::set_projection(). Throws
/// grbd::InvalidArgument for offset < 0, and, when called, for a quaternion that does not fit
/// into y or has |p| = 0 (or non-finite).
ProjectionFunction quaternion_projection_at(Eigen::Index offset);

}  // namespace grbd::ode
