/// \file
/// \brief Chapter 4 exercises on the contact frame: a tangent basis of the contact plane and the
/// contact Jacobian W of one body.

#include "grbd/collision/contact.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rotation.hpp"

#include <Eigen/Geometry>  // cross()

namespace grbd::collision {

// [tangent basis]
Eigen::Matrix<double, 3, 2> tangent_basis(const Vector3& n) {
  // BEGIN EXERCISE 4.4: a tangent basis of the contact plane
  // Hint: start from Frisvad's basis (2012), continuous everywhere but at n = −e_z; t2 = n × t1.
  // Hint: near n = −e_z, 1 + n_z cancels; for a unit n it equals (n_x² + n_y²)/(1 − n_z).
  const double s = n.x() * n.x() + n.y() * n.y();
  // a = 1/(1 + n_z), written without cancellation on either half of the sphere; the two
  // expressions agree for a unit n, so the basis stays continuous across n_z = 0. It is singular
  // only at n = −e_z (s = 0, n_z < 0), where we return the limit along n_x → 0⁺, n_y = 0.
  double a = 0.0;
  if (n.z() >= 0.0) {
    a = 1.0 / (1.0 + n.z());
  } else if (s > 0.0) {
    a = (1.0 - n.z()) / s;
  } else {
    Eigen::Matrix<double, 3, 2> T;
    T << -1.0, 0.0, 0.0, 1.0, 0.0, 0.0;
    return T;
  }
  const double b = -a * n.x() * n.y();
  Eigen::Matrix<double, 3, 2> T;
  T.col(0) << 1.0 - a * n.x() * n.x(), b, -n.x();
  T.col(1) << b, 1.0 - a * n.y() * n.y(), -n.y();
  return T;
  // END EXERCISE 4.4
}
// [tangent basis]

// [contact jacobian]
ContactJacobian contact_jacobian(const kinematics::Quaternion& p, const Vector3& K_rho,
                                 const Vector3& I_n, const Vector3& I_t1, const Vector3& I_t2) {
  // BEGIN EXERCISE 4.5: the contact Jacobian of one body
  // Hint: W = J_Pᵀ [n t1 t2] with the point Jacobian J_P = (I₃, −A_IK K_ρ̃) of Exercise 2.3.
  // Hint: the transpose of −A_IK K_ρ̃ maps a direction d to K_rho × (A_IKᵀ d).
  const Matrix3 A_IK = kinematics::rotation_matrix(p);
  ContactJacobian W;
  const Vector3* directions[3] = {&I_n, &I_t1, &I_t2};
  for (int k = 0; k < 3; ++k) {
    const Vector3& d = *directions[k];
    W.col(k) << d, K_rho.cross(A_IK.transpose() * d);
  }
  return W;
  // END EXERCISE 4.5
}
// [contact jacobian]

}  // namespace grbd::collision
