/// \file
/// \brief Chapter 2 exercises on mass properties: the volume integrals of one surface triangle
/// (divergence theorem) and the inertia tensor about the centre of mass (Steiner's theorem).

#include "grbd/body/mass_properties.hpp"
#include "grbd/core/error.hpp"

#include <Eigen/Geometry>  // cross()

namespace grbd::body {

VolumeIntegrals tetrahedron_integrals(const Vector3& a, const Vector3& b, const Vector3& c) {
  // BEGIN EXERCISE 2.1: the volume integrals of one surface triangle
  // Hint: the signed volume of the tetrahedron (0, a, b, c) is a triple product.
  // Hint: the fourth vertex 0 adds nothing to the vertex sums of the formulas in the header.
  const double volume = a.dot(b.cross(c)) / 6.0;
  const Vector3 s = a + b + c;
  VolumeIntegrals integrals;
  integrals.volume = volume;
  // The centroid of the tetrahedron is (0 + a + b + c)/4.
  integrals.first = (volume / 4.0) * s;
  // Every entry of a aᵀ is a product a_i a_j = a_j a_i, so the result is exactly symmetric.
  integrals.second = (volume / 20.0) * (a * a.transpose() + b * b.transpose() + c * c.transpose() +
                                        s * s.transpose());
  return integrals;
  // END EXERCISE 2.1
}

Matrix3 inertia_about_centre_of_mass(const VolumeIntegrals& integrals, double density) {
  // BEGIN EXERCISE 2.2: the inertia tensor about the centre of mass
  // Hint: Θ_O = ∫ ρ (xᵀx I − x xᵀ) dV needs only the trace of J and J itself.
  // Hint: Steiner's theorem moves an inertia tensor from S to O by adding m (r_Sᵀr_S I − r_S r_Sᵀ).
  const double mass = density * integrals.volume;
  const Vector3 r_S = integrals.first / integrals.volume;
  const Matrix3 J = density * integrals.second;
  const Matrix3 Theta_O = J.trace() * Matrix3::Identity() - J;
  return Theta_O - mass * (r_S.squaredNorm() * Matrix3::Identity() - r_S * r_S.transpose());
  // END EXERCISE 2.2
}

}  // namespace grbd::body
