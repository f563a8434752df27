/// \file
/// \brief The right-hand sides of chapter 3 that are not exercises: packing a body's state into
/// one vector, the free body and the body under a prescribed torque as RhsFunctions, the heavy
/// symmetric top about its fixed point, and the projection onto |p| = 1 as a ProjectionFunction.

#include "grbd/ode/rigid_body_rhs.hpp"

#include <Eigen/Geometry>  // cross()
#include <cmath>
#include <string>
#include <utility>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::ode {

namespace {

/// Throws InvalidArgument unless y and y_dot both have `expected` entries.
void require_sizes(Eigen::Index y, Eigen::Index y_dot, Eigen::Index expected, const char* where) {
  if (y != expected || y_dot != expected) {
    throw InvalidArgument(std::string(where) + ": y and y_dot must have " +
                          std::to_string(expected) + " entries, but they have " +
                          std::to_string(y) + " and " + std::to_string(y_dot));
  }
}

}  // namespace

Eigen::VectorXd pack(const body::State& x) {
  Eigen::VectorXd y(13);
  y << x.q, x.u;
  return y;
}

body::State unpack(const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (y.size() != 13) {
    throw InvalidArgument("unpack: a body's state y = (q, u) has 13 entries, but y has " +
                          std::to_string(y.size()));
  }
  return {y.head<7>(), y.tail<6>()};
}

RhsFunction free_body(const body::RigidBody& body, const body::Loads& loads) {
  body::require_valid(body, "free_body");
  return [body, loads](double /*t*/, const Eigen::Ref<const Eigen::VectorXd>& y,
                       Eigen::Ref<Eigen::VectorXd> y_dot) {
    require_sizes(y.size(), y_dot.size(), 13, "free_body");
    free_body_rhs(body, loads, y, y_dot);
  };
}

RhsFunction prescribed_torque_body(const body::RigidBody& body,
                                   std::function<Vector3(double t)> K_M) {
  body::require_valid(body, "prescribed_torque_body");
  if (!K_M) throw InvalidArgument("prescribed_torque_body: the torque function K_M is empty");
  return [body, K_M = std::move(K_M)](double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                                      Eigen::Ref<Eigen::VectorXd> y_dot) {
    require_sizes(y.size(), y_dot.size(), 13, "prescribed_torque_body");
    // Within one evaluation of f the torque is a constant load: the same right-hand side.
    free_body_rhs(body, body::Loads{Vector3::Zero(), K_M(t)}, y, y_dot);
  };
}

RhsFunction heavy_top(const HeavyTop& top) {
  require_positive_finite("heavy_top", "m", top.m);
  require_positive_finite("heavy_top", "I1", top.I1);
  require_positive_finite("heavy_top", "I3", top.I3);
  if (!(top.l >= 0.0) || !std::isfinite(top.l) || !(top.g >= 0.0) || !std::isfinite(top.g)) {
    throw InvalidArgument("heavy_top: l and g must be finite and >= 0, but l = " +
                          format_number(top.l) + " and g = " + format_number(top.g));
  }
  // [heavy top rhs]
  // Θ_O: Steiner's theorem moves the transverse moments from S to O, a distance l along e3.
  const double I1_O = top.I1 + top.m * top.l * top.l;
  const Vector3 Theta_O(I1_O, I1_O, top.I3);
  const Vector3 K_r_OS(0.0, 0.0, top.l);
  const Vector3 I_F(0.0, 0.0, -top.m * top.g);  // the weight m I_g, acting at S
  return [Theta_O, K_r_OS, I_F](double /*t*/, const Eigen::Ref<const Eigen::VectorXd>& y,
                                Eigen::Ref<Eigen::VectorXd> y_dot) {
    require_sizes(y.size(), y_dot.size(), 7, "heavy_top");
    const kinematics::Quaternion p(Vector4(y.head<4>()));
    const Vector3 K_omega = y.tail<3>();
    // The kinematics of chapter 1: ṗ = ½ p (0, K_omega).
    y_dot.head<4>() = 0.5 * (p * kinematics::Quaternion::pure(K_omega)).coeffs();
    // rotation_matrix(p) is |p|² A_IK off the unit sphere: divide, so that the weight keeps its
    // size while an integrator without projection lets |p| drift.
    const Matrix3 A_IK = kinematics::rotation_matrix(p) / p.squared_norm();
    const Vector3 K_F = A_IK.transpose() * I_F;
    // Euler's equations about the fixed point O: Θ_O ω̇ = K_r_OS × K_F − ω × Θ_O ω.
    const Vector3 K_L_O = Theta_O.cwiseProduct(K_omega);
    y_dot.tail<3>() = (K_r_OS.cross(K_F) - K_omega.cross(K_L_O)).cwiseQuotient(Theta_O);
  };
  // [heavy top rhs]
}

ProjectionFunction quaternion_projection_at(Eigen::Index offset) {
  if (offset < 0) {
    throw InvalidArgument("quaternion_projection_at: the offset must be >= 0, but it is " +
                          std::to_string(offset));
  }
  return [offset](double /*t*/, const Eigen::Ref<const Eigen::VectorXd>& y,
                  Eigen::Ref<Eigen::VectorXd> correction) {
    if (offset + 4 > y.size() || correction.size() != y.size()) {
      throw InvalidArgument("quaternion_projection_at: the quaternion at offset " +
                            std::to_string(offset) + " does not fit into y (" +
                            std::to_string(y.size()) + " entries) and correction (" +
                            std::to_string(correction.size()) + " entries)");
    }
    const double norm = y.segment<4>(offset).norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) {
      throw InvalidArgument("quaternion_projection_at: cannot project p with |p| = " +
                            format_number(norm) + " onto the unit sphere");
    }
    quaternion_projection(offset, y, correction);
  };
}

}  // namespace grbd::ode
