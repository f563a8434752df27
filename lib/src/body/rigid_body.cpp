/// \file
/// \brief The rigid body in its principal frame: the body of a mesh, mass matrix, kinetic energy,
/// angular momentum, generalized forces and the accelerations of the Newton–Euler equations (the
/// non-exercise part of chapter 2's rigid body; point_jacobian and newton_euler_h are exercises).

#include "grbd/body/rigid_body.hpp"

#include <Eigen/Geometry>  // cross()
#include <cmath>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/norms.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::body {

void require_valid(const RigidBody& body, std::string_view where) {
  // The step divides by m and K_Θ: a subnormal value is positive but its inverse overflows.
  const auto invertible = [](double x) { return x > 0.0 && std::isfinite(x) && std::isfinite(1.0 / x); };
  if (!invertible(body.m)) {
    throw InvalidArgument(std::string(where) +
                          ": the mass m must be positive and finite with a finite inverse, but m = " +
                          format_number(body.m));
  }
  for (int i = 0; i < 3; ++i) {
    if (!invertible(body.K_Theta[i])) {
      throw InvalidArgument(std::string(where) + ": the principal moment K_Theta[" +
                            std::to_string(i) +
                            "] must be positive and finite with a finite inverse, but it is " +
                            format_number(body.K_Theta[i]));
    }
  }
  // Θ_k = ∫(x_i² + x_j²) dm ≤ ∫(x_j² + x_k²) dm + ∫(x_k² + x_i²) dm = Θ_i + Θ_j.
  const double largest = body.K_Theta.maxCoeff();
  const double others = body.K_Theta.sum() - largest;
  if (others < largest * (1.0 - kInertiaTolerance)) {
    throw InvalidArgument(std::string(where) + ": the principal moments K_Theta = (" +
                          format_number(body.K_Theta[0]) + ", " + format_number(body.K_Theta[1]) +
                          ", " + format_number(body.K_Theta[2]) +
                          ") break the triangle inequality: the largest exceeds the sum of the "
                          "other two, which no mass distribution does");
  }
}

namespace {

std::string numbers(const auto& v) {
  std::string text = "(";
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    text += (k == 0 ? "" : ", ") + format_number(v[k]);
  }
  return text + ")";
}

}  // namespace

void require_valid(const State& x, std::string_view where, std::size_t index) {
  const auto refuse = [&](const std::string& what) {
    const bool single = index == static_cast<std::size_t>(-1);
    throw InvalidArgument(std::string(where) + (single ? "" : ": body " + std::to_string(index)) +
                          ": " + what);
  };
  if (!x.q.head<3>().allFinite()) refuse("the position is not finite: " + numbers(x.q.head<3>()));
  if (!x.u.allFinite()) refuse("the velocity u is not finite: " + numbers(x.u));
  const Vector4 p = x.q.tail<4>();
  const double norm = euclidean_norm(std::span<const double>(p.data(), 4));
  if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance)) {
    refuse("expected a unit orientation quaternion (| |p| - 1 | <= 1e-6), found p = " +
           numbers(p) + " with |p| = " + format_number(norm) +
           (std::isfinite(norm) && norm > 0.0 ? " (normalise it)" : ""));
  }
}

void require_finite(const Loads& loads, std::string_view where) {
  if (!loads.I_F.allFinite() || !loads.K_M.allFinite()) {
    throw InvalidArgument(std::string(where) + ": expected finite loads, found the force I_F = " +
                          numbers(loads.I_F) + " and the torque K_M = " + numbers(loads.K_M));
  }
}

// [rigid body from mesh]
BodyFromMesh rigid_body_from_mesh(const TriangleMesh& mesh, double density,
                                  std::string_view source) {
  // mass_properties() checks the mesh (closed, outward) and the density; Θ_S = A_MK diag(Θ) A_MKᵀ
  // then makes K the principal frame, with origin S: K_x = A_MKᵀ (M_x − M_r_S).
  const MassProperties properties = mass_properties(mesh, density, source);
  const PrincipalAxes axes = principal_axes(properties.M_Theta_S);
  BodyFromMesh result{RigidBody{properties.mass, axes.K_Theta}, properties.M_r_S, axes.A_MK};
  // A degenerate solid (a needle, a sliver) can leave a principal moment at zero up to round-off.
  require_valid(result.body, source);
  return result;
}
// [rigid body from mesh]

Matrix6 mass_matrix(const RigidBody& body) {
  require_valid(body, "mass_matrix");
  Vector6 diagonal;
  diagonal << Vector3::Constant(body.m), body.K_Theta;
  return Matrix6(diagonal.asDiagonal());
}

double kinetic_energy(const RigidBody& body, const Vector6& u) {
  require_valid(body, "kinetic_energy");  // a negative mass would make T indefinite
  // ½ uᵀ M u with M diagonal, without forming M.
  const Vector3 K_omega = kinematics::angular_velocity(u);
  return 0.5 * body.m * kinematics::linear_velocity(u).squaredNorm() +
         0.5 * K_omega.dot(body.K_Theta.cwiseProduct(K_omega));
}

Vector3 I_angular_momentum(const RigidBody& body, const State& x) {
  // K_L = Θ K_omega in the body frame, taken to frame I by A_IK = R(p).
  return kinematics::rotation_matrix(kinematics::orientation(x.q)) *
         body.K_Theta.cwiseProduct(kinematics::angular_velocity(x.u));
}

// [generalized force]
Vector6 generalized_force(const Vector7& q, const Vector3& K_rho, const Vector3& I_F) {
  // J_Pᵀ I_F = (I_F, −(A_IK K_ρ̃)ᵀ I_F) = (I_F, K_ρ̃ A_IKᵀ I_F): the force acts on S unchanged and
  // adds the moment K_rho × K_F about S, with the force taken to frame K. Written out rather than
  // through point_jacobian(): no 3 × 6 product for what is one rotation and one cross product.
  const Vector3 K_F = kinematics::rotation_matrix(kinematics::orientation(q)).transpose() * I_F;
  Vector6 f;
  f << I_F, K_rho.cross(K_F);
  return f;
}
// [generalized force]

// [newton euler u dot]
Vector6 newton_euler_u_dot(const RigidBody& body, const Vector6& u, const Loads& loads) {
  require_valid(body, "newton_euler_u_dot");
  // M is diagonal in the principal frame: M⁻¹ h is a division per coordinate, no solve.
  const Vector6 h = newton_euler_h(body, u, loads);
  Vector6 u_dot;
  u_dot << h.head<3>() / body.m, h.tail<3>().cwiseQuotient(body.K_Theta);
  return u_dot;
}
// [newton euler u dot]

}  // namespace grbd::body
