/// \file
/// \brief Chapter 4 exercises on the narrow phase: the contact of two spheres, of a sphere and a
/// half-space, and the closest point on a triangle.

#include "grbd/collision/narrow_phase.hpp"
#include "grbd/core/error.hpp"

#include <Eigen/Geometry>  // cross()

namespace grbd::collision {

// [sphere sphere]
ContactGeometry sphere_sphere(const Vector3& c_a, double r_a, const Vector3& c_b, double r_b) {
  // BEGIN EXERCISE 4.1: the contact of two spheres
  // Hint: the normal is the unit vector along the line of centres, from b towards a.
  // Hint: coincident centres have no line of centres: pick e_z, as the declaration says.
  const Vector3 d = c_a - c_b;
  const double distance = d.norm();
  ContactGeometry contact;
  // Any unit normal is correct for coincident centres; a fixed one keeps the result reproducible.
  contact.I_n = distance > 0.0 ? Vector3(d / distance) : Vector3::UnitZ();
  contact.g_N = distance - r_a - r_b;
  contact.I_r_a = c_a - r_a * contact.I_n;
  contact.I_r_b = c_b + r_b * contact.I_n;
  return contact;
  // END EXERCISE 4.1
}
// [sphere sphere]

// [sphere half space]
ContactGeometry sphere_half_space(const Vector3& c, double r, const HalfSpace& half_space) {
  // BEGIN EXERCISE 4.2: the contact of a sphere and a half-space
  // Hint: the signed distance of the centre to the boundary plane is nᵀc − offset.
  const Vector3& n = half_space.I_n;
  const double height = n.dot(c) - half_space.offset;  // signed distance of the centre
  ContactGeometry contact;
  contact.I_n = n;
  contact.g_N = height - r;
  contact.I_r_a = c - r * n;
  contact.I_r_b = c - height * n;  // the foot of the centre on the plane
  return contact;
  // END EXERCISE 4.2
}
// [sphere half space]

// [closest point]
TrianglePoint closest_point_on_triangle(const Vector3& x, const Vector3& a, const Vector3& b,
                                        const Vector3& c) {
  // BEGIN EXERCISE 4.3: the closest point on a triangle
  // Hint: test the corner regions first, then the edges, then the face (Ericson §5.1.5).
  // Hint: use ≤ and ≥ in the region tests so that boundary points get the lower feature.
  const Vector3 ab = b - a;
  const Vector3 ac = c - a;
  const Vector3 ap = x - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, TriangleFeature::vertex_a};

  const Vector3 bp = x - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, TriangleFeature::vertex_b};

  // vc, vb, va are the unnormalised barycentric coordinates of the projection of x.
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);  // d1 − d3 = |ab|² > 0
    return {a + v * ab, TriangleFeature::edge_ab};
  }

  const Vector3 cp = x - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, TriangleFeature::vertex_c};

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);  // d2 − d6 = |ac|² > 0
    return {a + w * ac, TriangleFeature::edge_ca};
  }

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), TriangleFeature::edge_bc};
  }

  // Inside the face: va, vb, vc > 0 are proportional to the barycentric coordinates.
  const double denominator = 1.0 / (va + vb + vc);
  return {a + (vb * denominator) * ab + (vc * denominator) * ac, TriangleFeature::face};
  // END EXERCISE 4.3
}
// [closest point]

}  // namespace grbd::collision
