/// \file
/// \brief Mass properties of closed triangle meshes (the sum over faces of the exercise
/// tetrahedron_integrals()), principal axes, and the closed forms of primitive solids.

#include "grbd/body/mass_properties.hpp"

#include <Eigen/Eigenvalues>  // SelfAdjointEigenSolver
#include <Eigen/LU>           // determinant()
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::body {

namespace {

/// Uniform density ρ, mass m = ρV and Θ about the centre of mass at the origin.
MassProperties centred(double volume, double density, const Vector3& diagonal_per_mass) {
  MassProperties props;
  props.volume = volume;
  props.mass = density * volume;
  props.M_Theta_S = (props.mass * diagonal_per_mass).asDiagonal();
  return props;
}

}  // namespace

// [volume integrals]
VolumeIntegrals volume_integrals(const TriangleMesh& mesh) {
  // Divergence theorem: the solid is the signed sum of the tetrahedra (0, a, b, c) over its
  // faces. Their parts outside the solid are covered once positively and once negatively, so
  // they cancel exactly as the mesh is closed and consistently oriented.
  VolumeIntegrals integrals;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    integrals += tetrahedron_integrals(mesh.V.row(mesh.F(f, 0)).transpose(),
                                       mesh.V.row(mesh.F(f, 1)).transpose(),
                                       mesh.V.row(mesh.F(f, 2)).transpose());
  }
  return integrals;
}
// [volume integrals]

MassProperties mass_properties(const TriangleMesh& mesh, double density, std::string_view source) {
  require_closed_oriented(mesh, source);
  require_positive_finite("mass_properties (" + std::string(source) + ")", "density", density);
  // Integrate about the centre c of the bounding box, not about the origin of M: for a body far
  // from the origin the moments about the origin are dominated by m|r_S|², and Steiner's shift
  // back to S would cancel most of their digits. Θ_S does not depend on where we integrate.
  const Vector3 c = 0.5 * (mesh.V.colwise().minCoeff() + mesh.V.colwise().maxCoeff()).transpose();
  const TriangleMesh centred_mesh = transformed(mesh, Matrix3::Identity(), -c);
  const VolumeIntegrals integrals = volume_integrals(centred_mesh);
  if (!std::isfinite(integrals.volume) || !integrals.first.allFinite() ||
      !integrals.second.allFinite()) {
    // require_closed_oriented() has seen a finite volume about the origin; the second moments
    // grow with the fifth power of the size of the mesh and overflow first.
    throw MeshError(std::string(source) +
                    ": coordinates too large: the volume integrals ∫ x dV and ∫ x xᵀ dV overflow "
                    "double (they are not finite) for a mesh that extends " +
                    format_number(centred_mesh.V.cwiseAbs().maxCoeff()) +
                    " from the centre of its bounding box; the second moments grow with the "
                    "fifth power of the size: expected sizes below about 1e61");
  }
  MassProperties props;
  props.volume = integrals.volume;
  props.mass = density * integrals.volume;
  props.M_r_S = c + integrals.first / integrals.volume;
  props.M_Theta_S = inertia_about_centre_of_mass(integrals, density);
  if (!std::isfinite(props.mass) || !props.M_r_S.allFinite() || !props.M_Theta_S.allFinite()) {
    // The integrals are finite: the density scales them past the largest double.
    throw InvalidArgument(
        "mass_properties (" + std::string(source) +
        "): the mass properties overflow double for the density ρ = " + format_number(density) +
        ": V = " + format_number(integrals.volume) + ", m = ρV = " + format_number(props.mass) +
        ", max |Θ_S| = " + format_number(props.M_Theta_S.cwiseAbs().maxCoeff()) +
        "; expected a density for which they are finite");
  }
  return props;
}

// [principal axes]
PrincipalAxes principal_axes(const Matrix3& M_Theta_S) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (!std::isfinite(M_Theta_S(i, j))) {
        throw InvalidArgument("principal_axes: expected a finite inertia tensor, found Θ(" +
                              std::to_string(i) + ", " + std::to_string(j) +
                              ") = " + format_number(M_Theta_S(i, j)) + ", which is not finite");
      }
    }
  }
  const double size = M_Theta_S.cwiseAbs().maxCoeff();
  const double asymmetry = (M_Theta_S - M_Theta_S.transpose()).cwiseAbs().maxCoeff();
  if (!(asymmetry <= 1e-8 * size)) {
    throw InvalidArgument(
        "principal_axes: expected a symmetric inertia tensor, found max |Θ − Θᵀ| = " +
        format_number(asymmetry) + " for max |Θ| = " + format_number(size));
  }
  // Eigen's self-adjoint solver returns the eigenvalues in ascending order and orthonormal
  // eigenvectors as the columns of A_MK, so that Θ = A_MK diag(K_Theta) A_MKᵀ.
  const Eigen::SelfAdjointEigenSolver<Matrix3> solver(0.5 * (M_Theta_S + M_Theta_S.transpose()));
  if (solver.info() != Eigen::Success) {
    throw Error("principal_axes: the symmetric eigensolver did not converge");
  }
  PrincipalAxes axes;
  axes.K_Theta = solver.eigenvalues();
  // Θ = ∫ (|x|² I − x xᵀ) dm of any mass distribution has eᵀΘe = ∫ |x − (eᵀx) e|² dm ≥ 0 about
  // every axis e, and Θ1 + Θ2 − Θ3 = 2 ∫ x3² dm ≥ 0 in its principal frame. A thin rod (Θ1 = 0)
  // and a flat plate (Θ1 + Θ2 = Θ3) are the equality cases, met only up to round-off.
  const Vector3& K = axes.K_Theta;
  const double tolerance = kInertiaTolerance * std::max(std::abs(K[0]), std::abs(K[2]));
  const auto moments = [&K] {
    return "(" + format_number(K[0]) + ", " + format_number(K[1]) + ", " + format_number(K[2]) +
           ")";
  };
  if (K[0] < -tolerance) {
    throw InvalidArgument(
        "principal_axes: expected an inertia tensor with non-negative principal moments "
        "(Θ1 ≥ 0 up to 1e-10 relative), found the principal moments " +
        moments());
  }
  if (K[0] + K[1] < K[2] - tolerance) {
    throw InvalidArgument(
        "principal_axes: expected principal moments that satisfy the triangle inequality "
        "Θ1 + Θ2 ≥ Θ3 (up to 1e-10 relative; Θ1 + Θ2 − Θ3 = 2 ∫ x3² dm ≥ 0 for any body), found "
        "the principal moments " +
        moments());
  }
  axes.A_MK = solver.eigenvectors();
  // Each eigenvector is defined up to its sign; flipping the third makes K right-handed, so
  // that A_MK is a rotation (det = +1) and can be turned into a quaternion.
  if (axes.A_MK.determinant() < 0.0) axes.A_MK.col(2) *= -1.0;
  return axes;
}
// [principal axes]

MassProperties sphere_mass_properties(double radius, double density) {
  require_positive_finite("sphere_mass_properties", "radius", radius);
  require_positive_finite("sphere_mass_properties", "density", density);
  const double volume = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  return centred(volume, density, Vector3::Constant(0.4 * radius * radius));
}

MassProperties box_mass_properties(const Vector3& half_extents, double density) {
  require_positive_finite("box_mass_properties", "half extent a", half_extents.x());
  require_positive_finite("box_mass_properties", "half extent b", half_extents.y());
  require_positive_finite("box_mass_properties", "half extent c", half_extents.z());
  require_positive_finite("box_mass_properties", "density", density);
  const Vector3 s = half_extents.cwiseAbs2();  // (a², b², c²)
  return centred(8.0 * half_extents.prod(), density,
                 Vector3(s.y() + s.z(), s.x() + s.z(), s.x() + s.y()) / 3.0);
}

MassProperties cylinder_mass_properties(double radius, double height, double density) {
  require_positive_finite("cylinder_mass_properties", "radius", radius);
  require_positive_finite("cylinder_mass_properties", "height", height);
  require_positive_finite("cylinder_mass_properties", "density", density);
  const double R2 = radius * radius;
  const double transverse = (3.0 * R2 + height * height) / 12.0;
  return centred(std::numbers::pi * R2 * height, density,
                 Vector3(transverse, transverse, 0.5 * R2));
}

MassProperties capsule_mass_properties(double radius, double height, double density) {
  require_positive_finite("capsule_mass_properties", "radius", radius);
  if (!(height >= 0.0) || !std::isfinite(height)) {
    throw InvalidArgument(
        "capsule_mass_properties: expected a finite height ≥ 0 of the straight part, found " +
        format_number(height));
  }
  require_positive_finite("capsule_mass_properties", "density", density);
  const double R = radius;
  const double h = height;
  const double m_cylinder = density * std::numbers::pi * R * R * h;
  const double m_hemisphere = density * 2.0 / 3.0 * std::numbers::pi * R * R * R;
  // Each hemisphere has (2/5) m_h R² about any axis through the centre of its flat face; its
  // centroid lies 3R/8 beyond that face, (h/2 + 3R/8) from S, and two Steiner shifts (to its
  // centroid and out to S) give m_h (2R²/5 + h²/4 + 3hR/8) about a transverse axis through S.
  const double axial = 0.5 * m_cylinder * R * R + 2.0 * 0.4 * m_hemisphere * R * R;
  const double transverse = m_cylinder * (3.0 * R * R + h * h) / 12.0 +
                            2.0 * m_hemisphere * (0.4 * R * R + 0.25 * h * h + 0.375 * h * R);
  MassProperties props;
  props.volume = std::numbers::pi * R * R * (h + 4.0 / 3.0 * R);
  props.mass = m_cylinder + 2.0 * m_hemisphere;
  props.M_Theta_S = Vector3(transverse, transverse, axial).asDiagonal();
  return props;
}

MassProperties torus_mass_properties(double R, double r, double density) {
  require_positive_finite("torus_mass_properties", "centre-line radius R", R);
  require_positive_finite("torus_mass_properties", "tube radius r", r);
  require_positive_finite("torus_mass_properties", "density", density);
  if (!(r <= R)) {
    // For r > R the tube overlaps itself near the axis and Pappus's volume counts it twice.
    throw InvalidArgument("torus_mass_properties: expected a tube radius r ≤ R, found r = " +
                          format_number(r) + ", R = " + format_number(R));
  }
  const double diametral = 0.5 * R * R + 0.625 * r * r;
  return centred(2.0 * std::numbers::pi * std::numbers::pi * R * r * r, density,
                 Vector3(diametral, diametral, R * R + 0.75 * r * r));
}

}  // namespace grbd::body
