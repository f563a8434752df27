/// \file
/// \brief The parts of the midpoint step that are not exercises: the "add and normalise" half
/// step and the Zeno time of the bouncing ball.

#include "grbd/timestep/midpoint.hpp"

#include <cmath>

#include "grbd/kinematics/rigid_motion.hpp"

namespace grbd::timestep {

// [add normalize]
Vector7 half_step_add_normalize(const Vector7& q, const Vector6& u, double dt) {
  Vector7 q_next = q + 0.5 * dt * kinematics::q_dot(q, u);
  q_next.tail<4>().normalize();
  return q_next;
}
// [add normalize]

double bouncing_ball_zeno_time(double h0, double g, double eps) {
  // t₁ (1 + 2ε + 2ε² + …) = t₁ (1 + 2ε/(1 − ε)) = t₁ (1 + ε)/(1 − ε); the checks are those of
  // the impact times.
  const double t1 = bouncing_ball_impact_time(1, h0, g, eps);
  return t1 * (1.0 + eps) / (1.0 - eps);
}

}  // namespace grbd::timestep
