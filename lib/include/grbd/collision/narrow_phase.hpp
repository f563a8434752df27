#pragma once
/// \file
/// \brief Narrow phase: the contact geometry of each supported pair of shapes, in frame I
/// (chapter 4). Every function returns the geometry whatever the distance; the caller keeps the
/// contacts with g_N ≤ margin. Multi-contact pairs return every contact within the margin.

#include <cstdint>
#include <vector>

#include "grbd/collision/contact.hpp"
#include "grbd/collision/shapes.hpp"
#include "grbd/core/types.hpp"

namespace grbd::collision {

/// A shape placed in frame I: position of its origin and orientation of its frame C.
struct Placement {
  Vector3 I_r = Vector3::Zero();       ///< origin of the shape frame C in I [m]
  Matrix3 A_IC = Matrix3::Identity();  ///< orientation of C: x_I = I_r + A_IC x_C
};

// [sphere sphere declaration]
/// \brief <b>Exercise 4.1</b>: the contact of two spheres.
///
/// Centres c_a, c_b, radii r_a, r_b: n = (c_a − c_b)/|c_a − c_b|, g_N = |c_a − c_b| − r_a − r_b,
/// r_a = c_a − r_a n, r_b = c_b + r_b n. For coincident centres the normal is e_z (any direction
/// is correct; a fixed one keeps the result deterministic).
ContactGeometry sphere_sphere(const Vector3& c_a, double r_a, const Vector3& c_b, double r_b);
// [sphere sphere declaration]

// [sphere half space declaration]
/// \brief <b>Exercise 4.2</b>: the contact of a sphere (a) with a half-space (b).
///
/// n = I_n of the half-space, g_N = nᵀc − offset − r, r_a = c − r n, r_b = c − (nᵀc − offset) n.
ContactGeometry sphere_half_space(const Vector3& c, double r, const HalfSpace& half_space);
// [sphere half space declaration]

/// Which feature of a triangle (a, b, c) is closest to a point.
enum class TriangleFeature : std::uint8_t {
  vertex_a, vertex_b, vertex_c,  ///< one of the corners
  edge_ab, edge_bc, edge_ca,     ///< the interior of an edge
  face,                          ///< the interior of the triangle
};

/// The closest point of a triangle and the feature it lies on.
struct TrianglePoint {
  Vector3 point = Vector3::Zero();             ///< closest point of the triangle [m]
  TriangleFeature feature = TriangleFeature::face;  ///< where it lies
};

// [closest point declaration]
/// \brief <b>Exercise 4.3</b>: the closest point on a triangle.
///
/// The point of the triangle (a, b, c) closest to x, by the Voronoi regions of its vertices, edges
/// and face (Ericson, Real-Time Collision Detection, §5.1.5); exact feature classification,
/// including points exactly on an edge or a vertex.
TrianglePoint closest_point_on_triangle(const Vector3& x, const Vector3& a, const Vector3& b,
                                        const Vector3& c);
// [closest point declaration]

/// A sphere (a) against a box (b) placed by `box_placement`: the closest point of the solid box;
/// a centre inside the box is pushed out through the nearest face. feature_b encodes the face,
/// edge or vertex of the box.
ContactGeometry sphere_box(const Vector3& c, double r, const Box& box, const Placement& box_placement);

/// A sphere (a) against a capsule (b): the sphere against the capsule's segment.
ContactGeometry sphere_capsule(const Vector3& c, double r, const Capsule& capsule,
                               const Placement& capsule_placement);

/// A box (a) against a half-space (b): one contact per box vertex with g_N ≤ margin (up to 4 for
/// a resting face, 2 for an edge); feature_a is the vertex index 0–7. Appends to `out`.
void box_half_space(const Box& box, const Placement& box_placement, const HalfSpace& half_space,
                    double margin, std::vector<ContactGeometry>& out);

/// A capsule (a) against a half-space (b): one contact per end of the segment with g_N ≤ margin
/// (two when the capsule lies parallel to the plane); feature_a is 0 or 1. Appends to `out`.
void capsule_half_space(const Capsule& capsule, const Placement& capsule_placement,
                        const HalfSpace& half_space, double margin,
                        std::vector<ContactGeometry>& out);

/// The narrow phase of any supported pair (supported()), shapes a and b placed by `pa` and `pb`,
/// with kind(a) ≤ kind(b) in the order sphere, box, capsule, half-space, mesh (so that the sphere
/// comes first and the half-space or mesh last, as the kernels take them). Appends every contact
/// geometry the kernel returns, whatever its gap, except that multi-contact kernels (box and
/// capsule on a half-space, sphere on a mesh) leave out those beyond `margin`; the caller keeps
/// those with g_N ≤ margin. Throws InvalidArgument for an unsupported pair or the wrong order.
void collide(const Shape& a, const Placement& pa, const Shape& b, const Placement& pb,
             double margin, std::vector<ContactGeometry>& out);

}  // namespace grbd::collision
