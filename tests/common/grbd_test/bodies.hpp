#pragma once
/// \file
/// \brief Rigid-body inputs and references shared by the tests: seeded random bodies, states and
/// loads, Euler's equations written out, the inertia of a box and the closed-form torque-free
/// symmetric top.

#include "grbd/body/rigid_body.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace grbd::test {

/// describe() of a body: (m = …, K_Theta = [Θ₁, Θ₂, Θ₃]).
template <>
struct Describer<body::RigidBody> {
  static void put(std::ostream& os, const body::RigidBody& b) {
    os << "(" << describe("m", b.m, "K_Theta", b.K_Theta) << ")";
  }
};

/// describe() of a state: (q = [r, p], u = [v, ω]).
template <>
struct Describer<body::State> {
  static void put(std::ostream& os, const body::State& x) {
    os << "(" << describe("q", x.q, "u", x.u) << ")";
  }
};

/// describe() of loads: (I_F = […], K_M = […]).
template <>
struct Describer<body::Loads> {
  static void put(std::ostream& os, const body::Loads& l) {
    os << "(" << describe("I_F", l.I_F, "K_M", l.K_M) << ")";
  }
};

/// Principal moments of a random mass distribution: the second moments a_k = ∫x_k² dm drawn
/// from [lo/2, hi/2), Θ₁ = a₂ + a₃, Θ₂ = a₃ + a₁, Θ₃ = a₁ + a₂, so that every triple is some
/// body's (Θ_i + Θ_j ≥ Θ_k, which body::require_valid() demands), each in [lo, hi).
inline Vector3 random_moments(Random& rng, double lo, double hi) {
  const Vector3 a(rng.uniform(lo / 2, hi / 2), rng.uniform(lo / 2, hi / 2),
                  rng.uniform(lo / 2, hi / 2));
  return {a(1) + a(2), a(2) + a(0), a(0) + a(1)};
}

/// A random body: mass in [0.5, 3), principal moments of random_moments() in [0.1, 3).
inline body::RigidBody random_body(Random& rng) {
  const double m = rng.uniform(0.5, 3.0);
  return {m, random_moments(rng, 0.1, 3.0)};
}

/// A random state: r ∈ [−1, 1)³, unit p, v and ω ∈ [−2, 2)³.
inline body::State random_state(Random& rng) {
  return {kinematics::make_q(rng.vector3(), rng.unit_quaternion()),
          kinematics::make_u(rng.vector3(-2, 2), rng.vector3(-2, 2))};
}

/// Random loads: force and torque each in [−1, 1)³.
inline body::Loads random_loads(Random& rng) { return {rng.vector3(), rng.vector3()}; }

/// The gyroscopic torque −ω × Θω of Euler's equations written component by component,
/// (Θ_j − Θ_k) ω_j ω_k for (i, j, k) cyclic, so that Θ_i ω̇_i = M_i + (this)_i.
inline Vector3 gyroscopic_torque(const body::RigidBody& body, const Vector3& w) {
  const Vector3& T = body.K_Theta;
  Vector3 torque;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const int k = (i + 2) % 3;
    torque[i] = (T[j] - T[k]) * w[j] * w[k];
  }
  return torque;
}

/// The box table: Θ_S = m/3 diag(b² + c², a² + c², a² + b²) for the half extents h = (a, b, c).
inline Matrix3 box_inertia(const Vector3& h, double mass) {
  const Vector3 s = h.cwiseAbs2();
  return (mass / 3.0 * Vector3(s.y() + s.z(), s.x() + s.z(), s.x() + s.y())).asDiagonal();
}

/// The torque-free symmetric top, Θ = (I⊥, I⊥, I₃), and its closed-form motion (REFERENCES.md)
///   A(t) = exp(t I_L/I⊥) A₀ exp(t ν e₃),  ω(t) = exp(−t ν e₃) A₀ᵀ I_L/I⊥ + ν e₃,
///   ν = ω₃ (1 − I₃/I⊥),
/// with the axis–angle matrices of references.hpp.
struct SymmetricTop {
  /// The top `body` (K_Theta = (I⊥, I⊥, I₃)) with K_omega = omega0 and A_IK = A0 at t = 0.
  SymmetricTop(const body::RigidBody& body, const Vector3& omega0, const Matrix3& A0)
      : body(body), omega0(omega0), A0(A0) {}

  body::RigidBody body;                                        ///< K_Theta = (I⊥, I⊥, I₃)
  Vector3 omega0;                                              ///< K_omega at t = 0
  Matrix3 A0;                                                  ///< A_IK at t = 0
  double I_perp = body.K_Theta.x();                            ///< I⊥
  Vector3 I_L = A0 * body.K_Theta.cwiseProduct(omega0);        ///< the constant I_L
  double nu = omega0.z() * (1.0 - body.K_Theta.z() / I_perp);  ///< ν

  /// A_IK(t).
  Matrix3 A(double t) const {
    return axis_angle_matrix(t * I_L / I_perp) * A0 * axis_angle_matrix(t * nu * Vector3::UnitZ());
  }
  /// K_omega(t).
  Vector3 omega(double t) const {
    return axis_angle_matrix(-t * nu * Vector3::UnitZ()) * A0.transpose() * I_L / I_perp +
           nu * Vector3::UnitZ();
  }
};

}  // namespace grbd::test
