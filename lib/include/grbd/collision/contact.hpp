#pragma once
/// \file
/// \brief One contact: bodies, points, normal, signed gap, tangent basis, stable feature
/// identifiers; the contact frame and the force directions W_N, W_T (chapter 4).

#include <cstddef>
#include <cstdint>

#include "grbd/collision/shapes.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"

namespace grbd::collision {

/// The geometry of one contact between shapes a and b, in frame I. The normal points from b
/// towards a: separating a along I_n increases the gap. g_N = I_nᵀ(I_r_a − I_r_b) is negative
/// when the shapes overlap. feature_a/feature_b name the touching feature of each shape (the
/// face, edge or vertex of a box or mesh; 0 for a sphere) so that the same contact is recognised
/// from one step to the next.
struct ContactGeometry {
  Vector3 I_n = Vector3::UnitZ();    ///< unit normal, from b towards a
  double g_N = 0.0;                  ///< signed gap [m]
  Vector3 I_r_a = Vector3::Zero();   ///< closest (deepest) point on a [m]
  Vector3 I_r_b = Vector3::Zero();   ///< closest (deepest) point on b [m]
  std::uint64_t feature_a = 0;       ///< feature of a that touches
  std::uint64_t feature_b = 0;       ///< feature of b that touches
};

/// \name Feature identifiers
/// A feature id is a kind tag in bits 62–63 and an index below: a face f is f itself (kind 0),
/// an edge is (1 << 62) | e, a vertex (2 << 62) | v. A box numbers its faces 0–5 as
/// 2 i + (outward normal along +e_i), i ∈ {x, y, z}; its vertices 0–7 as v = [x > 0] + 2 [y > 0]
/// + 4 [z > 0]; its edges 0–11 as e = 4 k + [j > 0] + 2 [l > 0] for the edge parallel to axis k,
/// j < l the other two axes. A mesh names a face by its index f, an edge by its vertex indices
/// i < j as (1 << 62) | (i << 31) | j, a vertex by its index v. Spheres and capsules, which are
/// smooth, have the single feature 0.
///@{

/// The id of face f.
constexpr std::uint64_t face_feature(std::uint64_t f) { return f; }
/// The id of edge e (a box edge 0–11, or a mesh edge from mesh_edge_index()).
constexpr std::uint64_t edge_feature(std::uint64_t e) { return (std::uint64_t{1} << 62) | e; }
/// The id of vertex v.
constexpr std::uint64_t vertex_feature(std::uint64_t v) { return (std::uint64_t{2} << 62) | v; }
/// The index of the mesh edge between vertices i and j (either order; i, j < 2³¹).
constexpr std::uint64_t mesh_edge_index(std::uint64_t i, std::uint64_t j) {
  return i < j ? (i << 31) | j : (j << 31) | i;
}
///@}

/// What identifies a contact from one step to the next: the two colliders and their features.
struct ContactKey {
  std::int32_t collider_a = -1;  ///< index of collider a in the world
  std::int32_t collider_b = -1;  ///< index of collider b in the world
  std::uint64_t feature_a = 0;   ///< feature of a
  std::uint64_t feature_b = 0;   ///< feature of b
  /// Keys are equal when all four members are.
  friend bool operator==(const ContactKey&, const ContactKey&) = default;
};

/// A hash of ContactKey for unordered containers (warm starts).
struct ContactKeyHash {
  /// Mixes the four members.
  std::size_t operator()(const ContactKey& key) const noexcept;
};

/// A contact of the system: geometry, bodies, the tangent basis and the body-frame lever arms.
struct Contact {
  BodyIndex body_a = kStatic;          ///< body of shape a, or kStatic
  BodyIndex body_b = kStatic;          ///< body of shape b, or kStatic
  std::int32_t collider_a = -1;        ///< index of collider a in the world
  std::int32_t collider_b = -1;        ///< index of collider b in the world
  ContactGeometry geometry;            ///< normal, gap, points, features
  Vector3 I_t1 = Vector3::UnitX();     ///< first tangent, I_t1 ⟂ I_n
  Vector3 I_t2 = Vector3::UnitY();     ///< second tangent, I_t2 = I_n × I_t1
  Vector3 K_rho_a = Vector3::Zero();   ///< contact point on a relative to S_a, frame K_a [m]
  Vector3 K_rho_b = Vector3::Zero();   ///< contact point on b relative to S_b, frame K_b [m]
  /// The identity of this contact, stable from step to step: the key of warm starts.
  ContactKey key() const {
    return {collider_a, collider_b, geometry.feature_a, geometry.feature_b};
  }
};

// [tangent basis declaration]
/// \brief <b>Exercise 4.4</b>: a tangent basis of the contact plane.
///
/// Unit vectors t1, t2 with (n, t1, t2) orthonormal and right-handed (t2 = n × t1), for a unit
/// normal n, depending continuously on n everywhere except on one point of the sphere (no
/// continuous tangent field on S² exists), and accurate near that point (Frisvad 2012; Duff et
/// al. 2017). Returns the 3 × 2 matrix [t1 t2].
Eigen::Matrix<double, 3, 2> tangent_basis(const Vector3& n);
// [tangent basis declaration]

/// The generalized force directions of one contact for one body (6 × 3), in u = (I_v_S, K_omega):
/// columns W_N, W_T1, W_T2, such that the body's share of the relative contact velocity is
/// (γ_N, γ_T1, γ_T2) = Wᵀ u.
using ContactJacobian = Eigen::Matrix<double, 6, 3>;

// [contact jacobian declaration]
/// \brief <b>Exercise 4.5</b>: the contact Jacobian of one body.
///
/// For the material point at K_rho of the body with orientation p (unit quaternion) and the
/// contact frame (I_n, I_t1, I_t2): W = J_Pᵀ [n t1 t2] with J_P = (I₃, −A_IK K_ρ̃), i.e. each
/// column is (d, K_rho × A_IKᵀ d) for d = n, t1, t2. Body a contributes +W_a, body b −W_b:
/// γ = W_aᵀ u_a − W_bᵀ u_b is the velocity of a's contact point relative to b's, in the
/// contact frame, and γ_N = ġ_N.
ContactJacobian contact_jacobian(const kinematics::Quaternion& p, const Vector3& K_rho,
                                 const Vector3& I_n, const Vector3& I_t1, const Vector3& I_t2);
// [contact jacobian declaration]

}  // namespace grbd::collision
