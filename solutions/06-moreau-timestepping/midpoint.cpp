/// \file
/// \brief Chapter 6 exercises: the pieces of Moreau's midpoint step (half step, free velocity,
/// active set, contact velocity at the start), the energy of a system and the impact times of
/// the bouncing ball.

#include "grbd/timestep/midpoint.hpp"

#include <cmath>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"

namespace grbd::timestep {

// [half step]
Vector7 half_step(const Vector7& q, const Vector6& u, double dt) {
  // BEGIN EXERCISE 6.1: the half step of the positions
  // Hint: chapter 1 has a function that moves q with a constant u exactly, over any time.
  return kinematics::exp_map_step(q, u, 0.5 * dt);
  // END EXERCISE 6.1
}
// [half step]

// [free velocity]
Vector6 free_velocity(const body::RigidBody& body, const Vector6& u_S, const body::Loads& loads,
                      double dt) {
  // BEGIN EXERCISE 6.2: the free velocity
  // Hint: one explicit Euler step of M u̇ = h over the whole step Δt, from u_S.
  return u_S + dt * body::newton_euler_u_dot(body, u_S, loads);
  // END EXERCISE 6.2
}
// [free velocity]

// [active]
bool is_active(const collision::ContactGeometry& geometry, double tolerance) {
  // BEGIN EXERCISE 6.3: the active set
  // Hint: write the comparison so that a NaN gap gives false.
  return geometry.g_N <= tolerance;
  // END EXERCISE 6.3
}
// [active]

// [gamma start]
Vector3 start_contact_velocity(const collision::ContactJacobian* W_a, const Vector6* u_a,
                               const collision::ContactJacobian* W_b, const Vector6* u_b) {
  // BEGIN EXERCISE 6.4: the contact velocity at the start of the step
  // Hint: side a adds, side b subtracts; a null pointer is a static side.
  Vector3 gamma = Vector3::Zero();
  if (W_a != nullptr) gamma += W_a->transpose() * *u_a;
  if (W_b != nullptr) gamma -= W_b->transpose() * *u_b;
  return gamma;
  // END EXERCISE 6.4
}
// [gamma start]

// [energy]
double mechanical_energy(std::span<const body::RigidBody> bodies,
                         std::span<const body::State> states, const Vector3& I_g) {
  if (bodies.size() != states.size()) {
    throw InvalidArgument("mechanical_energy: expected one state per body, found " +
                          std::to_string(states.size()) + " states for " +
                          std::to_string(bodies.size()) + " bodies");
  }
  // BEGIN EXERCISE 6.5: the mechanical energy of a system
  // Hint: chapter 2 has the kinetic energy of one body; the potential is −m gᵀr (g points down).
  double energy = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    energy += body::kinetic_energy(bodies[i], states[i].u) -
              bodies[i].m * I_g.dot(kinematics::position(states[i].q));
  }
  return energy;
  // END EXERCISE 6.5
}
// [energy]

namespace {
void require_ball(const char* where, double h0, double g, double eps) {
  if (!(h0 >= 0.0) || !std::isfinite(h0) || !(g > 0.0) || !std::isfinite(g) ||
      !(eps >= 0.0 && eps < 1.0)) {
    throw InvalidArgument(std::string(where) +
                          ": expected a finite h0 >= 0, a finite g > 0 and eps in [0, 1); found "
                          "h0 = " + format_number(h0) + ", g = " + format_number(g) +
                          ", eps = " + format_number(eps));
  }
}
}  // namespace

// [impact time]
double bouncing_ball_impact_time(int k, double h0, double g, double eps) {
  require_ball("bouncing_ball_impact_time", h0, g, eps);
  if (k < 1) {
    throw InvalidArgument("bouncing_ball_impact_time: expected an impact number k >= 1, found " +
                          std::to_string(k));
  }
  // BEGIN EXERCISE 6.6: the impact times of the bouncing ball
  // Hint: the ball leaves impact j with ε^j times the first impact speed √(2 g h₀); each flight
  //   after it lasts 2 ε^j t₁.
  const double t1 = std::sqrt(2.0 * h0 / g);
  double t = t1;
  double flight = 2.0 * t1;
  for (int j = 1; j < k; ++j) {
    flight *= eps;
    t += flight;
  }
  return t;
  // END EXERCISE 6.6
}
// [impact time]

}  // namespace grbd::timestep
