/// \file
/// \brief Chapter 5 exercises on the semismooth Newton method: the generalized Jacobians of the
/// prox onto ℝ₊ and onto the disk. The Alart–Curnier function and its Jacobian are built from
/// them here, in the same file, as the prox updates are built from the proxes in prox.cpp.

#include <cmath>
#include <limits>

#include "grbd/contact/newton.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/norms.hpp"

namespace grbd::contact {

// [prox nonnegative jacobian]
double prox_nonnegative_jacobian(double x) {
  // BEGIN EXERCISE 5.9: the generalized Jacobian of the prox onto ℝ₊
  // Hint: max(x, 0) has slope 1 to the right of the kink and 0 to the left; at x = 0 take 0.
  return x > 0.0 ? 1.0 : 0.0;
  // END EXERCISE 5.9
}
// [prox nonnegative jacobian]

// [prox disk jacobian]
DiskJacobian prox_disk_jacobian(const Vector2& x, double radius) {
  // BEGIN EXERCISE 5.10: the generalized Jacobian of the prox onto the disk
  // Hint: decide inside or outside as prox_disk() does, the boundary counted as inside.
  // Hint: take ‖x‖ from grbd::norm2d, which neither overflows nor underflows.
  DiskJacobian J;
  const double norm = norm2d(x(0), x(1));
  if (norm <= radius) {
    J.d_x.setIdentity();
    return J;
  }
  const Vector2 t = x / norm;
  J.d_x = (radius / norm) * (Eigen::Matrix2d::Identity() - t * t.transpose());
  J.d_radius = t;
  return J;
  // END EXERCISE 5.10
}
// [prox disk jacobian]

// [alart curnier jacobian]
AlartCurnierJacobian alart_curnier_jacobian(const Vector3& lambda, const Vector3& xi, double rho_N,
                                            double rho_T, double mu) {
  const double sigma_N = lambda(0) - rho_N * xi(0);
  const double s = prox_nonnegative_jacobian(sigma_N);
  const double radius = mu * prox_nonnegative(sigma_N);
  const Vector2 sigma_T = lambda.tail<2>() - rho_T * xi.tail<2>();
  const DiskJacobian P = prox_disk_jacobian(sigma_T, radius);
  AlartCurnierJacobian J;
  J.phi(0) = lambda(0) - prox_nonnegative(sigma_N);
  J.phi.tail<2>() = lambda.tail<2>() - prox_disk(sigma_T, radius);
  // Normal row: Φ_N = λ_N − max(σ_N, 0).
  J.A(0, 0) = 1.0 - s;
  J.B(0, 0) = rho_N * s;
  // Tangential rows: Φ_T = λ_T − P(σ_T, μ max(σ_N, 0)), through σ_T and through the radius.
  J.A.block<2, 1>(1, 0) = -mu * s * P.d_radius;
  J.B.block<2, 1>(1, 0) = mu * s * rho_N * P.d_radius;
  J.A.block<2, 2>(1, 1) = Eigen::Matrix2d::Identity() - P.d_x;
  J.B.block<2, 2>(1, 1) = rho_T * P.d_x;
  return J;
}
// [alart curnier jacobian]

Vector3 alart_curnier_function(const Vector3& lambda, const Vector3& xi, double rho_N,
                               double rho_T, double mu) {
  return lambda - alart_curnier_update(lambda, xi, rho_N, rho_T, mu);
}

}  // namespace grbd::contact
