#pragma once
/// \file
/// \brief The per-side arithmetic of the compact contact problem, written out component by
/// component so that the loops over contacts that use it (the SOR sweep of
/// solutions/05-contact-laws/prox.cpp and start_solve() of compact.cpp) inline it. Not part of
/// the library's interface.

#include "grbd/contact/compact.hpp"

namespace grbd::contact::detail {

/// w += s (v + ω × r) for a body velocity u = (v, ω).
inline void add_point_velocity(double s, const double* u, const Vector3& r, double* w) {
  w[0] += s * (u[0] + (u[4] * r(2) - u[5] * r(1)));
  w[1] += s * (u[1] + (u[5] * r(0) - u[3] * r(2)));
  w[2] += s * (u[2] + (u[3] * r(1) - u[4] * r(0)));
}

/// u += s M⁻¹ (P, r × P) for the world percussion P at lever arm r; with `Isotropic` the inverse
/// inertia is its (0, 0) entry times I₃.
template <bool Isotropic>
inline void apply_percussion(double s, const WorldInverseMass& M, const Vector3& r, const double* P,
                             double* u) {
  const double sm = s * M.inv_m;
  u[0] += sm * P[0];
  u[1] += sm * P[1];
  u[2] += sm * P[2];
  const double L0 = r(1) * P[2] - r(2) * P[1];
  const double L1 = r(2) * P[0] - r(0) * P[2];
  const double L2 = r(0) * P[1] - r(1) * P[0];
  const Matrix3& T = M.I_Theta_inv;
  if constexpr (Isotropic) {
    const double st = s * T(0, 0);
    u[3] += st * L0;
    u[4] += st * L1;
    u[5] += st * L2;
  } else {
    u[3] += s * (T(0, 0) * L0 + T(0, 1) * L1 + T(0, 2) * L2);
    u[4] += s * (T(1, 0) * L0 + T(1, 1) * L1 + T(1, 2) * L2);
    u[5] += s * (T(2, 0) * L0 + T(2, 1) * L1 + T(2, 2) * L2);
  }
}

/// The world percussion P = n λ_N + t1 λ_T1 + t2 λ_T2 of a contact with frame (n, t1, t2).
inline void world_percussion(const CompactContact& c, const Vector3& t2, const Vector3& lambda,
                             double* P) {
  for (int k = 0; k < 3; ++k) P[k] = c.n(k) * lambda(0) + c.t1(k) * lambda(1) + t2(k) * lambda(2);
}

/// G_kk += 1/m + c_kᵀ I_Θ⁻¹ c_k with c_k = r × f_k for the frame f = (n, t1, t2): one side's part
/// of the diagonal of G_ii. With `Isotropic`, c |r × f|² = c (|r|² − (r · f)²) for a unit f.
template <bool Isotropic>
inline void add_delassus_diagonal(const WorldInverseMass& M, const Vector3& r, const Vector3* f,
                                  double* G) {
  const Matrix3& T = M.I_Theta_inv;
  if constexpr (Isotropic) {
    const double rr = r.squaredNorm();
    for (int k = 0; k < 3; ++k) {
      const double rf = r.dot(f[k]);
      G[k] += M.inv_m + T(0, 0) * (rr - rf * rf);
    }
  } else {
    for (int k = 0; k < 3; ++k) {
      const Vector3 ck = r.cross(f[k]);
      G[k] += M.inv_m + ck.dot(T * ck);
    }
  }
}

/// The diagonal of G_ii of contact c: add_delassus_diagonal() over its dynamic sides.
template <bool Isotropic>
inline Vector3 delassus_diagonal(const CompactContact& c, const WorldInverseMass* M_inv) {
  const Vector3 f[3] = {c.n, c.t1, c.t2()};
  double G[3] = {0.0, 0.0, 0.0};
  if (c.body_a != kStatic) add_delassus_diagonal<Isotropic>(M_inv[c.body_a], c.r_a, f, G);
  if (c.body_b != kStatic) add_delassus_diagonal<Isotropic>(M_inv[c.body_b], c.r_b, f, G);
  return {G[0], G[1], G[2]};
}

}  // namespace grbd::contact::detail
