#pragma once
/// \file
/// \brief A rigid body in its principal frame: mass matrix, kinetic energy, angular momentum,
/// the Jacobian of a material point, and the Newton–Euler equations M u̇ = h (chapter 2).

#include <cstddef>
#include <string_view>

#include "grbd/body/mass_properties.hpp"
#include "grbd/core/types.hpp"

namespace grbd::body {

/// The inertial data of a rigid body whose body frame K is a principal frame with origin at the
/// centre of mass S: the mass matrix in u = (I_v_S, K_omega) is M = diag(m I₃, diag(K_Theta)).
struct RigidBody {
  double m = 1.0;                      ///< mass [kg] > 0
  Vector3 K_Theta = Vector3::Ones();   ///< principal moments of inertia about S [kg m²] > 0
};

/// Throws InvalidArgument unless m and the three principal moments K_Theta are positive and
/// finite, and the moments satisfy the triangle inequality Θ_i + Θ_j ≥ Θ_k of every body (up to
/// kInertiaTolerance relative; a rod or a plate meets it with equality): M must be symmetric
/// positive definite for u̇ = M⁻¹h and T = ½ uᵀMu to make sense, and (1, 1, 5) is no body's
/// inertia. The message starts with `where`, the name of the checking function.
void require_valid(const RigidBody& body, std::string_view where);

/// The state of one body: q = (I_r_S, p) ∈ ℝ⁷ with |p| = 1, and u = (I_v_S, K_omega) ∈ ℝ⁶.
struct State {
  Vector7 q;  ///< 7 × 1: position of S in I [m], orientation quaternion of K
  Vector6 u;  ///< 6 × 1: velocity of S in I [m/s], angular velocity in K [rad/s]
};

/// How far |p| of a State's orientation may be from 1: 10⁻⁶. The exponential map keeps |p| = 1 to
/// round-off (10⁻¹⁵ per step), so only a quaternion that was never normalised (rounded input,
/// a typo, a zero) fails; it would scale every lever arm A_IK ρ by |p|².
inline constexpr double kUnitQuaternionTolerance = 1e-6;

/// Throws InvalidArgument unless the state is finite and its orientation p is a unit quaternion
/// (| |p| − 1 | ≤ kUnitQuaternionTolerance). The message reads "<where>: body <index>: …"
/// ("<where>: …" for the default index, a single body) and shows the offending numbers. The
/// functions that take states (the integrators, collision detection, the assembly of the
/// contact problem) call it once per body and call.
void require_valid(const State& x, std::string_view where,
                   std::size_t index = static_cast<std::size_t>(-1));

/// External loads, constant over a time step: a force through S and a torque about S.
struct Loads {
  Vector3 I_F = Vector3::Zero();  ///< resultant force, frame I [N] (gravity: m I_g)
  Vector3 K_M = Vector3::Zero();  ///< resultant torque about S, frame K [N m]
};

/// Throws InvalidArgument, starting with `where`, unless the force and the torque are finite.
void require_finite(const Loads& loads, std::string_view where);

/// A rigid body made from a mesh: its principal-frame data, and where the frame K sits in the
/// mesh frame M (a mesh point M_x has body coordinates K_x = A_MKᵀ (M_x − M_r_S)).
struct BodyFromMesh {
  RigidBody body;                       ///< mass and principal moments
  Vector3 M_r_S = Vector3::Zero();      ///< centre of mass in frame M [m]
  Matrix3 A_MK = Matrix3::Identity();   ///< principal axes (columns) in frame M, det = +1
};

/// Mass properties and principal frame of the solid bounded by `mesh` with density ρ [kg/m³].
BodyFromMesh rigid_body_from_mesh(const TriangleMesh& mesh, double density,
                                  std::string_view source = "mesh");

/// The mass matrix M = diag(m I₃, diag(K_Theta)) (6 × 6) in u = (I_v_S, K_omega).
Matrix6 mass_matrix(const RigidBody& body);

/// The kinetic energy T = ½ uᵀ M u = ½ m |I_v_S|² + ½ K_omegaᵀ Θ K_omega [J].
double kinetic_energy(const RigidBody& body, const Vector6& u);

/// The angular momentum about S in the inertial frame, I_L = A_IK Θ K_omega (3 × 1) [kg m²/s];
/// constant for a torque-free body.
Vector3 I_angular_momentum(const RigidBody& body, const State& x);

// [point jacobian declaration]
/// \brief <b>Exercise 2.3</b>: the Jacobian of a material point.
///
/// The 3 × 6 matrix J_P(q) with I_v_P = J_P u for the material point at body-fixed offset K_rho
/// from S:
/// \f[ \mathbf J_P = \begin{pmatrix} \mathbf I_3 & -\mathbf A_{IK}\,{}_K\tilde{\boldsymbol\rho}
///     \end{pmatrix}. \f]
/// Its transpose maps a force I_F at P to the generalized force J_Pᵀ I_F = (I_F, K_rho × A_IKᵀ I_F).
Matrix36 point_jacobian(const Vector7& q, const Vector3& K_rho);
// [point jacobian declaration]

/// The generalized force J_P(q)ᵀ I_F (6 × 1) of a force I_F [N] (frame I) at the material point
/// K_rho.
Vector6 generalized_force(const Vector7& q, const Vector3& K_rho, const Vector3& I_F);

// [newton euler declaration]
/// \brief <b>Exercise 2.4</b>: the right-hand side of the Newton–Euler equations.
///
/// M u̇ = h with
/// \f[ \mathbf h(\mathbf u) = \begin{pmatrix} {}_I\mathbf F \\ {}_K\mathbf M
///     - {}_K\boldsymbol\omega \times \boldsymbol\Theta\,{}_K\boldsymbol\omega \end{pmatrix} \f]
/// (6 × 1): Newton's law for S in frame I and Euler's equations in the body frame with the
/// gyroscopic term. Θ = diag(K_Theta).
Vector6 newton_euler_h(const RigidBody& body, const Vector6& u, const Loads& loads);
// [newton euler declaration]

/// The acceleration u̇ = M⁻¹ h (6 × 1).
Vector6 newton_euler_u_dot(const RigidBody& body, const Vector6& u, const Loads& loads);

}  // namespace grbd::body
