#pragma once
/// \file
/// \brief The exponential and logarithm on the unit quaternions S³ and on SO(3), Rodrigues'
/// formula, and rotation vectors (chapter 1).

#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"

namespace grbd::kinematics {

// [exp declaration]
/// \brief <b>Exercise 1.5</b>: the exponential on S³.
///
/// The quaternion exponential of the pure quaternion (0, v), v ∈ ℝ³:
/// \f[ \exp(0, \mathbf v) = \Bigl(\cos|\mathbf v|,\ \frac{\sin|\mathbf v|}{|\mathbf v|}\,\mathbf v\Bigr)
///     \in S^3, \f]
/// accurate to round-off also for |v| → 0 (where sin|v|/|v| → 1). The rotation by the rotation
/// vector θ is exp_S3(θ/2).
Quaternion exp_S3(const Vector3& v);
// [exp declaration]

// [log declaration]
/// \brief <b>Exercise 1.6</b>: the logarithm on S³.
///
/// The principal logarithm on S³: the v ∈ ℝ³ with |v| ∈ [0, π] and
/// exp_S3(v) = p, for a unit quaternion p,
/// \f[ \log p = \operatorname{atan2}(|\mathbf p_r|, p_0)\,\frac{\mathbf p_r}{|\mathbf p_r|}. \f]
/// Accurate near p = 1 (|v| → 0) and near p = −1 (|v| → π); at p = −1 exactly every axis is a
/// logarithm and π e_x is returned.
Vector3 log_S3(const Quaternion& p);
// [log declaration]

// [rodrigues declaration]
/// \brief <b>Exercise 1.7</b>: Rodrigues' formula, the exponential on SO(3).
///
/// Rodrigues' formula: the exponential on SO(3) of the rotation vector θ,
/// \f[ \exp(\tilde{\boldsymbol\theta}) = \mathbf I + \frac{\sin\theta}{\theta}\,\tilde{\boldsymbol\theta}
///     + \frac{1 - \cos\theta}{\theta^2}\,\tilde{\boldsymbol\theta}^2, \qquad \theta = |\boldsymbol\theta|, \f]
/// the rotation by the angle θ about θ/|θ| (3 × 3), accurate to round-off also for θ → 0.
Matrix3 exp_SO3(const Vector3& theta);
// [rodrigues declaration]

/// The principal logarithm on SO(3): the rotation vector θ, |θ| ∈ [0, π], with exp_SO3(θ) = R.
Vector3 log_SO3(const Matrix3& R);

/// The unit quaternion of the rotation vector θ: exp_S3(θ/2).
Quaternion quaternion_from_rotation_vector(const Vector3& theta);

/// The rotation vector θ, |θ| ∈ [0, π], of the unit quaternion p (of p or −p, whichever has
/// p0 ≥ 0): 2 log_S3(±p).
Vector3 rotation_vector(const Quaternion& p);

}  // namespace grbd::kinematics
