#pragma once
/// \file
/// \brief Mass, centre of mass and inertia tensor of closed triangle meshes by the divergence
/// theorem, principal axes, and the closed forms of primitive solids (chapter 2).

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/types.hpp"

namespace grbd::body {

/// Volume integrals of a solid B: V = ∫_B dV, the first moments ∫_B x dV (3 × 1) and the second
/// moments ∫_B x xᵀ dV (3 × 3, symmetric), all in the mesh frame M.
struct VolumeIntegrals {
  double volume = 0.0;                  ///< V [m³]
  Vector3 first = Vector3::Zero();      ///< ∫ x dV [m⁴]
  Matrix3 second = Matrix3::Zero();     ///< ∫ x xᵀ dV [m⁵]
  /// Sum of integrals over disjoint (signed) pieces.
  VolumeIntegrals& operator+=(const VolumeIntegrals& other) {
    volume += other.volume;
    first += other.first;
    second += other.second;
    return *this;
  }
};

// [tetrahedron integrals declaration]
/// \brief <b>Exercise 2.1</b>: the volume integrals of one surface triangle.
///
/// The signed integrals over the tetrahedron with vertices 0, a, b, c (3 × 1 each, frame M), which
/// by the divergence theorem are the triangle (a, b, c)'s contribution to the integrals of the
/// closed mesh:
/// \f[ V = \tfrac16\,\mathbf a\cdot(\mathbf b\times\mathbf c), \qquad
///     \int \mathbf x\,dV = \tfrac{V}{4}(\mathbf a+\mathbf b+\mathbf c), \qquad
///     \int \mathbf x\mathbf x^\mathsf{T} dV = \tfrac{V}{20}\bigl(\mathbf a\mathbf a^\mathsf{T}
///     + \mathbf b\mathbf b^\mathsf{T} + \mathbf c\mathbf c^\mathsf{T} + \mathbf s\mathbf s^\mathsf{T}\bigr),
///     \quad \mathbf s = \mathbf a+\mathbf b+\mathbf c. \f]
/// V is negative when (a, b, c) turns clockwise seen from the origin.
VolumeIntegrals tetrahedron_integrals(const Vector3& a, const Vector3& b, const Vector3& c);
// [tetrahedron integrals declaration]

/// The volume integrals of the solid bounded by a closed, outward-oriented mesh: the sum of
/// tetrahedron_integrals() over its faces (exact for the polyhedron, up to round-off).
VolumeIntegrals volume_integrals(const TriangleMesh& mesh);

// [inertia declaration]
/// \brief <b>Exercise 2.2</b>: the inertia tensor about the centre of mass.
///
/// For uniform density ρ: m = ρV, r_S = (∫x dV)/V, the inertia about the origin
/// Θ_O = ρ (tr(J) I − J) with J = ∫ x xᵀ dV, shifted to the centre of mass by Steiner's theorem,
/// \f[ \boldsymbol\Theta_S = \boldsymbol\Theta_O - m\,(\mathbf r_S^\mathsf{T}\mathbf r_S\,\mathbf I
///     - \mathbf r_S\mathbf r_S^\mathsf{T}). \f]
/// Returns Θ_S (3 × 3, symmetric, frame M) [kg m²]; integrals.volume must not be zero.
Matrix3 inertia_about_centre_of_mass(const VolumeIntegrals& integrals, double density);
// [inertia declaration]

/// Mass properties of a solid in its own frame M.
struct MassProperties {
  double volume = 0.0;                 ///< V [m³]
  double mass = 0.0;                   ///< m = ρV [kg]
  Vector3 M_r_S = Vector3::Zero();     ///< centre of mass S in frame M [m]
  Matrix3 M_Theta_S = Matrix3::Zero(); ///< inertia tensor about S, in frame M [kg m²]
};

/// Mass properties of the solid bounded by `mesh` with uniform density ρ [kg/m³] > 0. Checks the
/// mesh with require_closed_oriented(mesh, source) first (MeshError), then the density
/// (grbd::InvalidArgument unless finite and > 0). The integrals are taken about the centre of the
/// mesh's bounding box, so that Steiner's shift to S does not cancel digits for a body far from
/// the origin of M. Integrals that overflow double (a mesh larger than about 1e61) are a
/// MeshError "coordinates too large"; mass or inertia that overflow only with the density are
/// grbd::InvalidArgument.
MassProperties mass_properties(const TriangleMesh& mesh, double density,
                               std::string_view source = "mesh");

/// Principal moments and axes of a symmetric inertia tensor.
struct PrincipalAxes {
  Vector3 K_Theta = Vector3::Zero();  ///< principal moments Θ1 ≤ Θ2 ≤ Θ3 [kg m²]
  Matrix3 A_MK = Matrix3::Identity(); ///< columns: the principal axes in frame M; det = +1
};

/// Relative round-off allowed in the inequalities that every inertia tensor satisfies,
/// Θ1 ≥ 0 and Θ1 + Θ2 ≥ Θ3, measured by the largest principal moment: a thin rod and a flat plate
/// meet them with equality, which a computed tensor meets only up to its round-off.
inline constexpr double kInertiaTolerance = 1e-10;

/// The principal frame K of Θ (3 × 3, symmetric, frame M): Θ = A_MK diag(K_Theta) A_MKᵀ with
/// ascending moments and a right-handed orthonormal A_MK (Eigen's self-adjoint eigensolver).
/// Throws grbd::InvalidArgument for a non-finite Θ (naming the entry), one that is not symmetric
/// to 1e-8 relative, and one that no body has: a negative principal moment, or moments that break
/// the triangle inequality Θ1 + Θ2 ≥ Θ3 (both up to kInertiaTolerance relative; a zero moment
/// passes, RigidBody's require_valid() refuses it). For repeated moments any orthonormal basis of
/// the eigenspace is returned.
PrincipalAxes principal_axes(const Matrix3& M_Theta_S);

/// Closed forms (Mirtich 1996 and any table of moments of inertia), centre of mass at the origin;
/// they throw grbd::InvalidArgument for sizes or a density that are not finite and positive.
/// A solid sphere, Θ = (2/5) m R² I.
MassProperties sphere_mass_properties(double radius, double density);
/// A solid box [−a, a] × [−b, b] × [−c, c]: Θ = m/3 diag(b² + c², a² + c², a² + b²).
MassProperties box_mass_properties(const Vector3& half_extents, double density);
/// A solid cylinder about z: Θ_zz = m R²/2, Θ_xx = Θ_yy = m (3R² + h²)/12.
MassProperties cylinder_mass_properties(double radius, double height, double density);
/// A capsule about z: a cylinder of the given radius and height ≥ 0 (the straight part) capped by
/// two hemispheres of mass m_h each: Θ_zz = m_c R²/2 + (4/5) m_h R²,
/// Θ_xx = Θ_yy = m_c (3R² + h²)/12 + 2 m_h (2R²/5 + h²/4 + 3hR/8).
MassProperties capsule_mass_properties(double radius, double height, double density);
/// A solid torus about z (centre-line radius R, tube radius r): I_axis = m (R² + ¾ r²),
/// I_diam = m (½ R² + ⅝ r²), m = ρ 2π² R r²; needs r ≤ R.
MassProperties torus_mass_properties(double R, double r, double density);

}  // namespace grbd::body
