/// \file
/// \brief Chapter 5 exercises on the contact laws: the prox onto ℝ₊, the disk and the Coulomb
/// cone, Newton's impact law, and one SOR contact update. The prox updates of Alart–Curnier and
/// De Saxcé and the natural map are built from them here, in the same file, so that the compiler
/// can inline the whole contact update into the hot loop.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "grbd/contact/compact.hpp"
#include "grbd/contact/detail/compact_kernels.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/norms.hpp"

namespace grbd::contact {

// [prox nonnegative]
double prox_nonnegative(double x) {
  // BEGIN EXERCISE 5.1: the prox onto ℝ₊
  // Hint: the closest point of [0, ∞) to x: x itself when x ≥ 0, otherwise the boundary point.
  // Hint: avoid tricks like (x + |x|)/2: the tests pass x = −∞, and −∞ + ∞ is NaN.
  return x > 0.0 ? x : 0.0;
  // END EXERCISE 5.1
}
// [prox nonnegative]

// [prox disk]
Vector2 prox_disk(const Vector2& x, double radius) {
  // BEGIN EXERCISE 5.2: the prox onto the disk of radius ρ
  // Hint: compare ‖x‖² with ρ² first: no square root (and no division) when x is inside.
  // Hint: count ‖x‖ = ρ as inside, or x = 0 in the disk of radius 0 becomes 0/0.
  // Hint: ‖x‖² overflows for |x| ≳ 10¹⁵⁴ (and ρ² for ρ ≳ 10¹⁵⁴) although ‖x‖ does not: outside
  //   the normal range of doubles, compare ‖x‖ from grbd::norm2d with ρ instead.
  const double norm2 = x.squaredNorm();
  const double radius2 = radius * radius;
  if (norm2 >= std::numeric_limits<double>::min() &&
      std::max(norm2, radius2) <= std::numeric_limits<double>::max()) {
    return norm2 <= radius2 ? x : Vector2((radius / std::sqrt(norm2)) * x);
  }
  const double norm = norm2d(x(0), x(1));
  return norm <= radius ? x : Vector2((radius / norm) * x);
  // END EXERCISE 5.2
}
// [prox disk]

// [prox cone]
Vector3 prox_cone(const Vector3& x, double mu) {
  // BEGIN EXERCISE 5.3: the prox onto the Coulomb cone
  // Hint: three cases: x in K_μ; x in the polar cone {μ‖x_T‖ ≤ −x_N}; otherwise the surface.
  // Hint: for μ = 0, ‖x_T‖ ≤ μx_N alone accepts (−1, 0, 0); only the surface divides by ‖x_T‖.
  // Hint: take ‖x_T‖ from grbd::norm2d: x_T² overflows for |x_T| ≳ 10¹⁵⁴.
  const double x_N = x(0);
  const double norm_T = norm2d(x(1), x(2));  // sqrt(x₁² + x₂²) would overflow for |x| ≳ 10¹⁵⁴
  // x_N ≥ 0 matters for μ = 0, where 0 ≤ μ x_N would also accept the negative axis.
  if (norm_T <= mu * x_N && x_N >= 0.0) return x;
  if (mu * norm_T <= -x_N) return Vector3::Zero();
  const double y_N = (x_N + mu * norm_T) / (1.0 + mu * mu);
  // norm_T > 0 here: norm_T = 0 falls in one of the two cases above.
  const double scale = mu * y_N / norm_T;
  return {y_N, scale * x(1), scale * x(2)};
  // END EXERCISE 5.3
}
// [prox cone]

// [alart curnier]
Vector3 alart_curnier_update(const Vector3& lambda, const Vector3& xi, double r_N, double r_T,
                             double mu) {
  const double lambda_N = prox_nonnegative(lambda(0) - r_N * xi(0));
  const Vector2 lambda_T =
      prox_disk(lambda.tail<2>() - r_T * xi.tail<2>(), mu * lambda_N);
  return {lambda_N, lambda_T(0), lambda_T(1)};
}
// [alart curnier]

// [de saxce]
Vector3 de_saxce_update(const Vector3& lambda, const Vector3& xi, double r, double mu) {
  Vector3 augmented = xi;
  augmented(0) += mu * norm2d(xi(1), xi(2));
  return prox_cone(lambda - r * augmented, mu);
}
// [de saxce]

Vector3 natural_map(const Vector3& lambda, const Vector3& xi, double mu) {
  return lambda - de_saxce_update(lambda, xi, 1.0, mu);
}

double natural_map_residual(std::span<const Vector3> lambda, std::span<const Vector3> xi,
                            std::span<const double> mu) {
  if (lambda.size() != xi.size() || lambda.size() != mu.size()) {
    throw InvalidArgument("natural_map_residual: lambda, xi and mu must have one entry per "
                          "contact; found " + std::to_string(lambda.size()) + ", " +
                          std::to_string(xi.size()) + " and " + std::to_string(mu.size()));
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    sum += natural_map(lambda[i], xi[i], mu[i]).squaredNorm();
  }
  if (sum >= std::numeric_limits<double>::min() && sum <= std::numeric_limits<double>::max()) {
    return std::sqrt(sum);
  }
  // The sum of squares overflowed or underflowed (or an entry is not finite): euclidean_norm()
  // rescales; the rare case alone pays for the copy.
  std::vector<double> F;
  F.reserve(3 * lambda.size());
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    const Vector3 F_i = natural_map(lambda[i], xi[i], mu[i]);
    F.insert(F.end(), F_i.data(), F_i.data() + 3);
  }
  return euclidean_norm(F);
}

// [impact velocity]
Vector3 impact_velocity(const Vector3& gamma_E, const Vector3& gamma_A, double eps_N,
                        double eps_T) {
  // BEGIN EXERCISE 5.4: the velocity of Newton's impact law
  // Hint: the normal component restitutes with ε_N, both tangential ones with ε_T.
  return {gamma_E(0) + eps_N * gamma_A(0), gamma_E(1) + eps_T * gamma_A(1),
          gamma_E(2) + eps_T * gamma_A(2)};
  // END EXERCISE 5.4
}
// [impact velocity]

// [sor contact update]
Vector3 sor_contact_update(const ContactConstraint& c, const RFactors& r, ProxForm form,
                           std::span<const InverseMass> M_inv, std::span<Vector6> u,
                           Vector3& lambda) {
  // BEGIN EXERCISE 5.7: one SOR contact update
  // Hint: γ = W_aᵀu_a − W_bᵀu_b (skip a kStatic side); De Saxcé takes r = min(r.r_N, r.r_T).
  // Hint: u_a += M_a⁻¹W_aΔλ, u_b −= M_b⁻¹W_bΔλ with InverseMass::apply; no 6 × 6 matrix.
  Vector3 gamma_a = Vector3::Zero();
  Vector3 gamma_b = Vector3::Zero();
  if (c.body_a != kStatic) gamma_a = c.W_a.transpose() * u[c.body_a];
  if (c.body_b != kStatic) gamma_b = c.W_b.transpose() * u[c.body_b];
  const Vector3 xi = impact_velocity(gamma_a - gamma_b, c.gamma_A, c.eps_N, c.eps_T);
  const Vector3 updated = form == ProxForm::alart_curnier
                              ? alart_curnier_update(lambda, xi, r.r_N, r.r_T, c.mu)
                              : de_saxce_update(lambda, xi, std::min(r.r_N, r.r_T), c.mu);
  const Vector3 delta = updated - lambda;
  lambda = updated;
  if (delta.isZero(0.0)) return xi;  // Δλ = 0 exactly: the velocities stay as they are
  if (c.body_a != kStatic) u[c.body_a] += M_inv[c.body_a].apply(c.W_a * delta);
  if (c.body_b != kStatic) u[c.body_b] -= M_inv[c.body_b].apply(c.W_b * delta);
  return xi;
  // END EXERCISE 5.7
}
// [sor contact update]

// The sweep lives in this file, next to the update it repeats, so that the compiler can inline
// the update into the loop: `flatten` makes sure it does (on its own GCC keeps the call, and
// with it the arguments passed through memory).
namespace {

/// The O(1) check of a sweep's arguments: one r-factor and one percussion per contact, one
/// velocity per body.
void require_sweep_sizes(std::size_t contacts, std::size_t bodies, std::size_t r,
                         std::size_t lambda, std::size_t u) {
  if (r != contacts || lambda != contacts || u != bodies) {
    throw InvalidArgument("sor_sweep: expected " + std::to_string(contacts) + " r-factors and " +
                          std::to_string(contacts) + " percussions (one per contact) and " +
                          std::to_string(bodies) + " velocities (one per body); found " +
                          std::to_string(r) + ", " + std::to_string(lambda) + " and " +
                          std::to_string(u));
  }
}

/// Software prefetch for piles that do not fit in the caches: the contact `ahead` places ahead
/// of contact i (all its cache lines), and the velocity and inverse mass of body b of the contact
/// ahead / 2 places ahead, whose index is read from a line prefetched before. Body a advances
/// steadily through the Morton order and is left to the hardware prefetcher, as are r and λ.
template <class Contact, class Mass>
inline void prefetch_ahead(const Contact* contacts, std::size_t i, std::size_t n,
                           std::size_t ahead, const Vector6* u, const Mass* M_inv) {
  if (i + ahead < n) {
    const char* next = reinterpret_cast<const char*>(contacts + i + ahead);
    for (std::size_t k = 0; k < sizeof(Contact); k += 64) __builtin_prefetch(next + k);
    __builtin_prefetch(next + sizeof(Contact) - 1);
  }
  if (i + ahead / 2 < n) {
    const BodyIndex b = contacts[i + ahead / 2].body_b;
    if (b != kStatic) {
      __builtin_prefetch(&u[b], 1);
      __builtin_prefetch(reinterpret_cast<const char*>(&u[b] + 1) - 1, 1);
      __builtin_prefetch(&M_inv[b]);
    }
  }
}

}  // namespace

// [sor sweep]
[[gnu::flatten]] void sor_sweep(const ContactProblem& problem, std::span<const RFactors> r,
                                ProxForm form, std::span<Vector6> u, std::span<Vector3> lambda) {
  const std::size_t n = problem.contacts.size();
  require_sweep_sizes(n, problem.M_inv.size(), r.size(), lambda.size(), u.size());
  const ContactConstraint* contacts = problem.contacts.data();
  const std::span<const InverseMass> M_inv(problem.M_inv);
  // The contacts are updated one after the other in the order 0 … n − 1; the prefetch looks 32
  // contacts (352 bytes, six cache lines each) ahead.
  for (std::size_t i = 0; i < n; ++i) {
    prefetch_ahead(contacts, i, n, 32, u.data(), M_inv.data());
    sor_contact_update(contacts[i], r[i], form, M_inv, u, lambda[i]);
  }
}
// [sor sweep]

// The sweep of chapter 6's compact problem, here for the same reason: the prox updates it
// repeats are inlined into its loop.
namespace {

using detail::add_point_velocity;
using detail::apply_percussion;
using detail::world_percussion;

// [compact sweep kernel]
/// The sweep of sor_sweep(const CompactProblem&, …), for general or isotropic inverse inertias.
template <bool Isotropic>
[[gnu::flatten]] SweepReport compact_sweep(const CompactProblem& problem,
                                           std::span<const RFactors> r, ProxForm form,
                                           std::span<Vector6> u, std::span<Vector3> lambda,
                                           double abs_tol, double rel_tol, bool residual) {
  const std::size_t n = problem.contacts.size();
  const CompactContact* contacts = problem.contacts.data();
  const WorldInverseMass* M_inv = problem.M_inv.data();
  Vector6* U = u.data();
  double probe = 0.0;     // 0 · λ summed: stays 0 while every λ is finite
  bool unsettled = false;  // some |Δλ_k| > abs_tol + rel_tol |λ_k| (or NaN)
  double F2 = 0.0;         // Σ ‖F_i‖², each at the λ_i and ξ_i the sweep found
  for (std::size_t i = 0; i < n; ++i) {
    prefetch_ahead(contacts, i, n, 16, U, M_inv);  // 136-byte records: 16 ahead
    const CompactContact& c = contacts[i];
    const Vector3 t2 = c.t2();
    // γ = Bᵀ(v_a + ω_a × r_a − v_b − ω_b × r_b), B = [n t1 t2], then ξ = γ + ε ∘ γ_A.
    double w[3] = {0.0, 0.0, 0.0};
    if (c.body_a != kStatic) add_point_velocity(1.0, U[c.body_a].data(), c.r_a, w);
    if (c.body_b != kStatic) add_point_velocity(-1.0, U[c.body_b].data(), c.r_b, w);
    const Vector3 xi(c.n(0) * w[0] + c.n(1) * w[1] + c.n(2) * w[2] + c.xi_A(0),
                     c.t1(0) * w[0] + c.t1(1) * w[1] + c.t1(2) * w[2] + c.xi_A(1),
                     t2(0) * w[0] + t2(1) * w[1] + t2(2) * w[2] + c.xi_A(2));
    Vector3& l = lambda[i];
    if (residual) F2 += natural_map(l, xi, c.mu).squaredNorm();
    const Vector3 updated = form == ProxForm::alart_curnier
                                ? alart_curnier_update(l, xi, r[i].r_N, r[i].r_T, c.mu)
                                : de_saxce_update(l, xi, std::min(r[i].r_N, r[i].r_T), c.mu);
    const Vector3 delta = updated - l;
    l = updated;
    probe += 0.0 * updated(0) + 0.0 * updated(1) + 0.0 * updated(2);
    for (int k = 0; k < 3; ++k) {
      unsettled |= !(std::abs(delta(k)) <= abs_tol + rel_tol * std::abs(updated(k)));
    }
    if (delta.isZero(0.0)) continue;  // Δλ = 0 exactly: the velocities stay as they are
    double P[3];  // the world percussion B ΔΛ
    world_percussion(c, t2, delta, P);
    if (c.body_a != kStatic) {
      apply_percussion<Isotropic>(1.0, M_inv[c.body_a], c.r_a, P, U[c.body_a].data());
    }
    if (c.body_b != kStatic) {
      apply_percussion<Isotropic>(-1.0, M_inv[c.body_b], c.r_b, P, U[c.body_b].data());
    }
  }
  return {probe == 0.0, !unsettled, residual ? std::sqrt(F2) : -1.0};
}
// [compact sweep kernel]

}  // namespace

// [compact sweep]
SweepReport sor_sweep(const CompactProblem& problem, std::span<const RFactors> r, ProxForm form,
                      std::span<Vector6> u, std::span<Vector3> lambda, double abs_tol,
                      double rel_tol, bool residual) {
  require_sweep_sizes(problem.contacts.size(), problem.M_inv.size(), r.size(), lambda.size(),
                      u.size());
  return problem.isotropic
             ? compact_sweep<true>(problem, r, form, u, lambda, abs_tol, rel_tol, residual)
             : compact_sweep<false>(problem, r, form, u, lambda, abs_tol, rel_tol, residual);
}
// [compact sweep]

}  // namespace grbd::contact
