#pragma once
/// \file
/// \brief Fixed-size Eigen types shared by every module.
///
/// Shapes are part of the name: `Vector7` is q ∈ ℝ⁷, `Vector6` is u ∈ ℝ⁶, `Matrix76` is F(q).

#include <Eigen/Dense>

namespace grbd {

using Vector2 = Eigen::Vector2d;                 ///< 2 × 1, e.g. a tangential percussion λ_T
using Vector3 = Eigen::Vector3d;                 ///< 3 × 1, e.g. I_r_S, K_omega
using Vector4 = Eigen::Vector4d;                 ///< 4 × 1, quaternion coordinates K(P)
using Vector6 = Eigen::Matrix<double, 6, 1>;     ///< 6 × 1, velocities u = (I_v_S, K_omega)
using Vector7 = Eigen::Matrix<double, 7, 1>;     ///< 7 × 1, coordinates q = (I_r_S, p)
using Matrix3 = Eigen::Matrix3d;                 ///< 3 × 3, e.g. A_IK, inertia tensors
using Matrix4 = Eigen::Matrix4d;                 ///< 4 × 4, e.g. phi_L(P), phi_R(Q)
using Matrix43 = Eigen::Matrix<double, 4, 3>;    ///< 4 × 3, e.g. the quaternion rate matrix
using Matrix6 = Eigen::Matrix<double, 6, 6>;     ///< 6 × 6, e.g. the mass matrix M
using Matrix36 = Eigen::Matrix<double, 3, 6>;    ///< 3 × 6, e.g. the Jacobian of a material point
using Matrix76 = Eigen::Matrix<double, 7, 6>;    ///< 7 × 6, the kinematic map F(q)

}  // namespace grbd
