#pragma once
/// \file
/// \brief Generalized coordinates q = (I_r_S, p) ∈ ℝ⁷ and velocities u = (I_v_S, K_omega) ∈ ℝ⁶
/// of a rigid body, the kinematic map q̇ = F(q) u, and the motion of material points (chapter 1).

#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"

namespace grbd::kinematics {

/// q = (I_r_S, p) from the position of the centre of mass S in frame I and the orientation p of
/// the body frame K (7 × 1).
Vector7 make_q(const Vector3& I_r_S, const Quaternion& p);
/// u = (I_v_S, K_omega) (6 × 1): velocity of S in frame I, angular velocity in body frame K.
Vector6 make_u(const Vector3& I_v_S, const Vector3& K_omega);

/// I_r_S, the first three coordinates of q.
inline Vector3 position(const Vector7& q) { return q.head<3>(); }
/// p, the last four coordinates of q.
inline Quaternion orientation(const Vector7& q) { return Quaternion(Vector4(q.tail<4>())); }
/// I_v_S, the first three coordinates of u.
inline Vector3 linear_velocity(const Vector6& u) { return u.head<3>(); }
/// K_omega, the last three coordinates of u.
inline Vector3 angular_velocity(const Vector6& u) { return u.tail<3>(); }

// [kinematic map declaration]
/// \brief <b>Exercise 1.8</b>: the kinematic map F(q).
///
/// The kinematic map F(q) (7 × 6) with q̇ = F(q) u:
/// \f[ \mathbf F(\mathbf q) = \begin{pmatrix} \mathbf I_{3} & \mathbf 0
///     \\ \mathbf 0 & \tfrac12\,\varphi_L(p)\,\mathbf E \end{pmatrix}, \qquad
///     \mathbf E = \begin{pmatrix} \mathbf 0^\mathsf{T} \\ \mathbf I_3 \end{pmatrix} \in \mathbb R^{4\times 3}, \f]
/// that is İ_r_S = I_v_S and ṗ = ½ p (0, K_ω). F(q)ᵀ F(q) = diag(I₃, ¼|p|² I₃), and pᵀ ṗ = 0.
Matrix76 kinematic_map(const Vector7& q);
// [kinematic map declaration]

/// q̇ = F(q) u (7 × 1).
Vector7 q_dot(const Vector7& q, const Vector6& u);

/// The position I_r_P = I_r_S + A_IK K_rho of the material point P at body-fixed offset K_rho from
/// the centre of mass (3 × 1, frame I). A_IK = R(p) for the unit quaternion p of q.
Vector3 point_position(const Vector7& q, const Vector3& K_rho);

// [point velocity declaration]
/// \brief <b>Exercise 1.9</b>: the velocity of a material point.
///
/// The velocity of the material point P at body-fixed offset K_rho (3 × 1,
/// frame I): \f$ {}_I\mathbf v_P = {}_I\mathbf v_S + \mathbf A_{IK}\,({}_K\boldsymbol\omega \times {}_K\boldsymbol\rho) \f$.
Vector3 point_velocity(const Vector7& q, const Vector6& u, const Vector3& K_rho);
// [point velocity declaration]

/// One explicit Euler step q ← q + h F(q) u for constant u. It leaves the unit sphere: the step
/// multiplies |p|² by exactly 1 + h²|K_omega|²/4.
Vector7 explicit_euler_step(const Vector7& q, const Vector6& u, double h);

/// One exponential-map step for constant u: I_r_S ← I_r_S + h I_v_S, p ← p exp_S3(h K_omega / 2).
/// Exact for constant I_v_S and K_omega, and |p| is kept to round-off.
Vector7 exp_map_step(const Vector7& q, const Vector6& u, double h);

}  // namespace grbd::kinematics
