/// \file
/// \brief Chapter 3 exercise on closed-form references: the angular velocity of the torque-free
/// asymmetric body in Jacobi elliptic functions.

#include "grbd/ode/references.hpp"
#include "grbd/core/error.hpp"

#include <boost/math/special_functions/jacobi_elliptic.hpp>
#include <cmath>

namespace grbd::ode {

Vector3 euler_top_omega(const EulerTop& top, double t) {
  // BEGIN EXERCISE 3.4: the elliptic solution of Euler's equations
  // Hint: euler_top() has done the work: λ, m, A, the signs and t0 are all in `top`.
  // Hint: Boost returns sn and writes cn and dn through the two pointers.
  const double tau = top.lambda * (t - top.t0);
  double cn = 0.0;
  double dn = 0.0;
  const double sn = boost::math::jacobi_elliptic(std::sqrt(top.m), tau, &cn, &dn);
  return top.sign.cwiseProduct(top.A).cwiseProduct(Vector3(cn, sn, dn));
  // END EXERCISE 3.4
}

}  // namespace grbd::ode
