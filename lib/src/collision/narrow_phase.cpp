/// \file
/// \brief The narrow phase for boxes and capsules: sphere–box, sphere–capsule, box–half-space and
/// capsule–half-space. The sphere–sphere and sphere–half-space kernels and the closest point on a
/// triangle are exercises (solutions/04-collision/narrow_phase.cpp).

#include "grbd/collision/narrow_phase.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "grbd/collision/static_mesh.hpp"
#include "grbd/core/error.hpp"

namespace grbd::collision {

// [sphere box]
ContactGeometry sphere_box(const Vector3& c, double r, const Box& box,
                           const Placement& box_placement) {
  const Vector3& h = box.half_extents;
  const Vector3 x_C = box_placement.A_IC.transpose() * (c - box_placement.I_r);  // centre in C
  const Vector3 q_C = x_C.cwiseMax(-h).cwiseMin(h);  // closest point of the solid box
  const Vector3 d_C = x_C - q_C;
  const double distance = d_C.norm();

  ContactGeometry contact;
  Vector3 n_C;
  if (distance > 0.0) {
    // Outside: the clamped coordinates name the feature (one: a face, two: an edge, three: a
    // vertex), with s_i = ±1 the side of each clamped coordinate.
    n_C = d_C / distance;
    contact.g_N = distance - r;
    int clamped = 0;
    int free_axis = 0;
    std::uint64_t face = 0;
    std::uint64_t vertex = 0;
    for (int i = 0; i < 3; ++i) {
      if (x_C[i] > h[i]) {
        ++clamped;
        face = 2 * i + 1;
        vertex |= std::uint64_t{1} << i;
      } else if (x_C[i] < -h[i]) {
        ++clamped;
        face = 2 * i;
      } else {
        free_axis = i;
      }
    }
    if (clamped == 1) {
      contact.feature_b = face_feature(face);
    } else if (clamped == 3) {
      contact.feature_b = vertex_feature(vertex);
    } else {
      // The edge parallel to the free axis k, with the sides of the other two axes j < l.
      const int j = free_axis == 0 ? 1 : 0;
      const int l = free_axis == 2 ? 1 : 2;
      const std::uint64_t e = 4 * static_cast<std::uint64_t>(free_axis) + ((vertex >> j) & 1U) +
                              2 * ((vertex >> l) & 1U);
      contact.feature_b = edge_feature(e);
    }
  } else {
    // The centre is inside the box (or on its surface): push it out through the nearest face,
    // the first axis on a tie, the + side when the centre is on the mid-plane.
    int axis = 0;
    double depth = h[0] - std::abs(x_C[0]);
    for (int i = 1; i < 3; ++i) {
      const double depth_i = h[i] - std::abs(x_C[i]);
      if (depth_i < depth) {
        depth = depth_i;
        axis = i;
      }
    }
    const double side = x_C[axis] >= 0.0 ? 1.0 : -1.0;
    n_C = side * Vector3::Unit(axis);
    contact.g_N = -depth - r;
    Vector3 on_face = x_C;
    on_face[axis] = side * h[axis];
    contact.feature_b = face_feature(2 * static_cast<std::uint64_t>(axis) + (side > 0.0 ? 1 : 0));
    contact.I_r_b = box_placement.I_r + box_placement.A_IC * on_face;
    contact.I_n = box_placement.A_IC * n_C;
    contact.I_r_a = c - r * contact.I_n;
    return contact;
  }
  contact.I_n = box_placement.A_IC * n_C;
  contact.I_r_b = box_placement.I_r + box_placement.A_IC * q_C;
  contact.I_r_a = c - r * contact.I_n;
  return contact;
}
// [sphere box]

ContactGeometry sphere_capsule(const Vector3& c, double r, const Capsule& capsule,
                               const Placement& capsule_placement) {
  // The closest point of the axis segment, then two spheres; the capsule is smooth (feature 0).
  const Vector3 axis = capsule_placement.A_IC.col(2);
  const double t =
      std::clamp(axis.dot(c - capsule_placement.I_r), -capsule.half_length, capsule.half_length);
  return sphere_sphere(c, r, capsule_placement.I_r + t * axis, capsule.radius);
}

void box_half_space(const Box& box, const Placement& box_placement, const HalfSpace& half_space,
                    double margin, std::vector<ContactGeometry>& out) {
  const Vector3& n = half_space.I_n;
  for (std::uint64_t v = 0; v < 8; ++v) {
    const Vector3 x_C((v & 1U) ? box.half_extents.x() : -box.half_extents.x(),
                      (v & 2U) ? box.half_extents.y() : -box.half_extents.y(),
                      (v & 4U) ? box.half_extents.z() : -box.half_extents.z());
    const Vector3 x = box_placement.I_r + box_placement.A_IC * x_C;
    const double g_N = n.dot(x) - half_space.offset;
    if (g_N > margin) continue;
    ContactGeometry contact;
    contact.I_n = n;
    contact.g_N = g_N;
    contact.I_r_a = x;
    contact.I_r_b = x - g_N * n;
    contact.feature_a = v;  // the vertex index 0–7, as the header says
    out.push_back(contact);
  }
}

void capsule_half_space(const Capsule& capsule, const Placement& capsule_placement,
                        const HalfSpace& half_space, double margin,
                        std::vector<ContactGeometry>& out) {
  // Each end of the segment is a sphere of the capsule's radius; a capsule of zero length has a
  // single end.
  const int ends = capsule.half_length > 0.0 ? 2 : 1;
  for (int e = 0; e < ends; ++e) {
    const double t = e == 0 ? -capsule.half_length : capsule.half_length;
    const Vector3 end = capsule_placement.I_r + t * capsule_placement.A_IC.col(2);
    ContactGeometry contact = sphere_half_space(end, capsule.radius, half_space);
    if (contact.g_N > margin) continue;
    contact.feature_a = static_cast<std::uint64_t>(e);
    out.push_back(contact);
  }
}

// [collide]
void collide(const Shape& a, const Placement& pa, const Shape& b, const Placement& pb,
             double margin, std::vector<ContactGeometry>& out) {
  if (const auto* sphere = std::get_if<Sphere>(&a)) {
    if (const auto* other = std::get_if<Sphere>(&b)) {
      out.push_back(sphere_sphere(pa.I_r, sphere->radius, pb.I_r, other->radius));
    } else if (const auto* box = std::get_if<Box>(&b)) {
      out.push_back(sphere_box(pa.I_r, sphere->radius, *box, pb));
    } else if (const auto* capsule = std::get_if<Capsule>(&b)) {
      out.push_back(sphere_capsule(pa.I_r, sphere->radius, *capsule, pb));
    } else if (const auto* half_space = std::get_if<HalfSpace>(&b)) {
      out.push_back(sphere_half_space(pa.I_r, sphere->radius, *half_space));
    } else {
      sphere_mesh(pa.I_r, sphere->radius, *std::get<std::shared_ptr<const StaticMesh>>(b), margin,
                  out);
    }
    return;
  }
  if (const auto* half_space = std::get_if<HalfSpace>(&b)) {
    if (const auto* box = std::get_if<Box>(&a)) {
      box_half_space(*box, pa, *half_space, margin, out);
      return;
    }
    if (const auto* capsule = std::get_if<Capsule>(&a)) {
      capsule_half_space(*capsule, pa, *half_space, margin, out);
      return;
    }
  }
  throw InvalidArgument("collide: the pair " + std::string(kind_name(kind(a))) + "–" +
                        std::string(kind_name(kind(b))) +
                        " is not supported in this order (supported pairs: sphere first with "
                        "any shape; box or capsule first with a half-space)");
}
// [collide]

}  // namespace grbd::collision
