/// \file
/// \brief The integrators of chapter 2 that are not exercises: the table of schemes and their
/// names, the symplectic exponential-map step, the normalised explicit Euler baseline, the
/// Lie–Poisson splitting, the implicit gyroscopic step, and the run-time dispatch.

#include "grbd/body/integrators.hpp"

#include <Eigen/Geometry>  // cross()
#include <Eigen/LU>        // partialPivLu()
#include <array>
#include <cmath>
#include <cstddef>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/skew.hpp"

namespace grbd::body {

namespace {

/// The table behind integrators(), in the order of the enumeration.
constexpr std::array<IntegratorInfo, 5> kIntegrators{{
    {Integrator::explicit_exp_map, "explicit_exp_map", 1, "|p| = 1"},
    {Integrator::symplectic_exp_map, "symplectic_exp_map", 1, "|p| = 1"},
    {Integrator::explicit_euler_normalized, "explicit_euler_normalized", 1,
     "|p| = 1 only by projection"},
    {Integrator::lie_poisson, "lie_poisson", 2,
     "|p| = 1, |L| and I_L exactly; energy error bounded"},
    {Integrator::implicit_gyroscopic, "implicit_gyroscopic", 1,
     "|p| = 1; no energy gain if axisymmetric"},
}};

/// Throws InvalidArgument unless the step size h is positive and finite and the body, the
/// state (finite, unit quaternion) and the loads are valid (rigid_body.hpp). Comparisons and
/// one 4-vector norm: the hot path allocates nothing.
void require_valid(const RigidBody& body, const State& x, const Loads& loads, double h,
                   const char* where) {
  if (!(h > 0.0) || !std::isfinite(h)) {
    throw InvalidArgument(
        std::string(where) +
        ": the step size h must be positive and finite, but h = " + format_number(h));
  }
  require_valid(body, where);
  require_valid(x, where);
  require_finite(loads, where);
}

/// The kick of duration t by constant loads: v ← v + t I_F/m, K_omega ← K_omega + t Θ⁻¹ K_M.
void kick(const RigidBody& body, const Loads& loads, double t, State& x) {
  x.u.head<3>() += (t / body.m) * loads.I_F;
  x.u.tail<3>() += t * loads.K_M.cwiseQuotient(body.K_Theta);
}

}  // namespace

std::span<const IntegratorInfo> integrators() { return kIntegrators; }

std::string_view integrator_name(Integrator scheme) {
  const auto index = static_cast<std::size_t>(scheme);
  if (index >= kIntegrators.size()) {
    throw InvalidArgument("integrator_name: no integrator has the number " +
                          std::to_string(static_cast<int>(scheme)));
  }
  return kIntegrators[index].name;
}

Integrator parse_integrator(std::string_view name) {
  for (const IntegratorInfo& info : kIntegrators) {
    if (info.name == name) return info.scheme;
  }
  std::string message = "unknown integrator '";
  message.append(name).append("': expected one of ");
  for (std::size_t i = 0; i < kIntegrators.size(); ++i) {
    message.append(i == 0 ? "" : ", ").append(kIntegrators[i].name);
  }
  throw InvalidArgument(message);
}

// [symplectic exp map step]
State symplectic_exp_map_step(const RigidBody& body, const State& x, const Loads& loads, double h) {
  require_valid(body, x, loads, h, "symplectic_exp_map_step");
  // The only change from (a): the velocities are updated first, and q moves with u⁺. For the
  // translation this is the symplectic Euler method; q⁺ is again an exact exp-map motion.
  const Vector6 u = x.u + h * newton_euler_u_dot(body, x.u, loads);
  return {kinematics::exp_map_step(x.q, u, h), u};
}
// [symplectic exp map step]

// [explicit euler normalized step]
State explicit_euler_normalized_step(const RigidBody& body, const State& x, const Loads& loads,
                                     double h) {
  require_valid(body, x, loads, h, "explicit_euler_normalized_step");
  // A straight step in ℝ⁷ leaves S³ (|p|² grows by 1 + h²|ω|²/4, chapter 1); the projection back
  // onto S³ hides the drift but turns by 2 atan(h|ω|/2) instead of h|ω|.
  State next{kinematics::explicit_euler_step(x.q, x.u, h),
             x.u + h * newton_euler_u_dot(body, x.u, loads)};
  next.q.tail<4>().normalize();
  return next;
}
// [explicit euler normalized step]

// [lie poisson step]
State lie_poisson_step(const RigidBody& body, const State& x, const Loads& loads, double h) {
  require_valid(body, x, loads, h, "lie_poisson_step");
  // Strang splitting of H = (kinetic energy of translation) + T₁ + T₂ + T₃ + (the loads): every
  // piece is solved exactly, and the palindromic order makes the composition symmetric, hence of
  // order 2. Each free rotation keeps |L| and I_L = A_IK Θ ω, so their composition does too.
  State y = x;
  kick(body, loads, 0.5 * h, y);
  y = free_rotation_about_axis(body, y, 0, 0.5 * h);
  y = free_rotation_about_axis(body, y, 1, 0.5 * h);
  y = free_rotation_about_axis(body, y, 2, h);
  y = free_rotation_about_axis(body, y, 1, 0.5 * h);
  y = free_rotation_about_axis(body, y, 0, 0.5 * h);
  y.q.head<3>() += h * y.u.head<3>();  // the drift of S, exact for constant v
  kick(body, loads, 0.5 * h, y);
  return y;
}
// [lie poisson step]

// [implicit gyroscopic step]
State implicit_gyroscopic_step(const RigidBody& body, const State& x, const Loads& loads,
                               double h) {
  require_valid(body, x, loads, h, "implicit_gyroscopic_step");
  // Backward Euler on Euler's equations, f(ω⁺) = Θ(ω⁺ − ω) + h ω⁺ × Θω⁺ − h K_M = 0, linearised
  // once at ω⁺ = ω (Catto 2015): the Jacobian of a × Θa is ãΘ − (Θa)~, so
  //   (Θ + h(ω̃Θ − (Θω)~)) Δω = −f(ω) = h (K_M − ω × Θω).
  // The exact root never gains energy (torque-free, dot the equation with ω⁺ and use
  // Cauchy–Schwarz in the Θ inner product). One Newton step keeps that for axisymmetric bodies
  // (observed at every h) and for asymmetric ones while h|ω| ≲ 0.1, where the explicit schemes
  // already gain energy; at larger h|ω| a nearly singular J can make an asymmetric body gain.
  const Vector3 K_omega = kinematics::angular_velocity(x.u);
  const Vector3 K_L = body.K_Theta.cwiseProduct(K_omega);
  const Matrix3 Theta = body.K_Theta.asDiagonal();
  const Matrix3 J = Theta + h * (kinematics::skew(K_omega) * Theta - kinematics::skew(K_L));
  const Vector3 residual = h * (K_omega.cross(K_L) - loads.K_M);  // f(ω)
  const Vector3 K_omega_plus = K_omega - J.partialPivLu().solve(residual);
  const Vector6 u = kinematics::make_u(x.u.head<3>() + (h / body.m) * loads.I_F, K_omega_plus);
  return {kinematics::exp_map_step(x.q, u, h), u};
}
// [implicit gyroscopic step]

State step(const RigidBody& body, const State& x, const Loads& loads, double h, Integrator scheme) {
  switch (scheme) {
    case Integrator::explicit_exp_map:
      // The exercise checks nothing itself; the dispatch checks for it.
      require_valid(body, x, loads, h, "step(explicit_exp_map)");
      return explicit_exp_map_step(body, x, loads, h);
    case Integrator::symplectic_exp_map:
      return symplectic_exp_map_step(body, x, loads, h);
    case Integrator::explicit_euler_normalized:
      return explicit_euler_normalized_step(body, x, loads, h);
    case Integrator::lie_poisson:
      return lie_poisson_step(body, x, loads, h);
    case Integrator::implicit_gyroscopic:
      return implicit_gyroscopic_step(body, x, loads, h);
  }
  throw InvalidArgument("step: no integrator has the number " +
                        std::to_string(static_cast<int>(scheme)));
}

}  // namespace grbd::body
