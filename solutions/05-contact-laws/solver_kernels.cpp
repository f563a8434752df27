/// \file
/// \brief Chapter 5 exercises on the solvers: the Delassus block of one contact, its r-factors,
/// and the convergence test of the prox iterations.

#include <algorithm>
#include <cmath>
#include <string>

#include "grbd/contact/problem.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

// [delassus block]
Matrix3 delassus_block(const ContactConstraint& contact, std::span<const InverseMass> M_inv) {
  require_body_indices(contact, M_inv.size(), "delassus_block");
  // BEGIN EXERCISE 5.5: the Delassus block of one contact
  // Hint: build W_aᵀM_a⁻¹W_a column by column: InverseMass::apply to each column of W_a.
  // Hint: both sides add: the minus sign of W_b appears twice.
  Matrix3 G = Matrix3::Zero();
  if (contact.body_a != kStatic) {
    const InverseMass& Ma = M_inv[contact.body_a];
    for (int k = 0; k < 3; ++k) G.col(k) += contact.W_a.transpose() * Ma.apply(contact.W_a.col(k));
  }
  if (contact.body_b != kStatic) {
    const InverseMass& Mb = M_inv[contact.body_b];
    for (int k = 0; k < 3; ++k) G.col(k) += contact.W_b.transpose() * Mb.apply(contact.W_b.col(k));
  }
  return G;
  // END EXERCISE 5.5
}
// [delassus block]

// [r factors]
RFactors r_factors(const Matrix3& G, double alpha) {
  // BEGIN EXERCISE 5.6: the r-factors of one contact
  // Hint: refuse α ∉ (0, 2) and non-positive (or NaN) diagonal entries with InvalidArgument.
  // Hint: only the diagonal enters; r_T takes the larger of the two tangential entries.
  if (!(alpha > 0.0 && alpha < 2.0)) {
    throw InvalidArgument("r_factors: the relaxation alpha must lie in (0, 2); found " +
                          format_number(alpha));
  }
  for (int k = 0; k < 3; ++k) {
    if (!(G(k, k) > 0.0) || !std::isfinite(G(k, k))) {
      throw InvalidArgument("r_factors: the Delassus block needs a positive, finite diagonal; "
                            "found G(" + std::to_string(k) + "," + std::to_string(k) +
                            ") = " + format_number(G(k, k)));
    }
  }
  return {alpha / G(0, 0), alpha / std::max(G(1, 1), G(2, 2))};
  // END EXERCISE 5.6
}
// [r factors]

// [converged]
bool has_converged(std::span<const double> x_old, std::span<const double> x, double abs_tol,
                   double rel_tol) {
  if (x_old.size() != x.size()) {
    throw InvalidArgument("has_converged: expected x_old and x of the same length; found " +
                          std::to_string(x_old.size()) + " and " + std::to_string(x.size()));
  }
  // BEGIN EXERCISE 5.8: the convergence test of an iteration
  // Hint: a NaN must never count as converged: write the test so that it fails for NaN.
  // Hint: the relative part scales with |x[k]| of the new iterate, and equality counts.
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!(std::abs(x[k] - x_old[k]) <= abs_tol + rel_tol * std::abs(x[k]))) return false;
  }
  return true;
  // END EXERCISE 5.8
}
// [converged]

}  // namespace grbd::contact
