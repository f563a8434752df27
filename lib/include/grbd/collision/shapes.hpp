#pragma once
/// \file
/// \brief Collision shapes and colliders: a shape attached to a body with a local pose, or
/// static in the inertial frame (chapter 4).

#include <cstdint>
#include <memory>
#include <string_view>
#include <variant>

#include "grbd/core/types.hpp"

namespace grbd::collision {

class StaticMesh;

/// A sphere of the given radius about the shape's origin.
struct Sphere {
  double radius = 1.0;  ///< [m] > 0
};

/// A box [−a, a] × [−b, b] × [−c, c] in the shape frame, half_extents = (a, b, c).
struct Box {
  Vector3 half_extents = Vector3::Ones();  ///< [m] > 0 each
};

/// A capsule: the points within `radius` of the segment from −half_length e_z to half_length e_z
/// of the shape frame.
struct Capsule {
  double radius = 0.5;       ///< [m] > 0
  double half_length = 0.5;  ///< [m] ≥ 0
};

/// A half-space, static only: the solid { x : I_nᵀ x ≤ offset } of frame I, whose boundary plane
/// has the outward unit normal I_n.
struct HalfSpace {
  Vector3 I_n = Vector3::UnitZ();  ///< outward unit normal, frame I
  double offset = 0.0;             ///< plane: I_nᵀ x = offset [m]
};

/// Any shape. A StaticMesh is shared, never copied (it may hold millions of triangles).
using Shape = std::variant<Sphere, Box, Capsule, HalfSpace, std::shared_ptr<const StaticMesh>>;

/// The kind of a shape, for messages and the table of supported pairs.
enum class ShapeKind { sphere, box, capsule, half_space, mesh };

/// The kind of `shape`.
ShapeKind kind(const Shape& shape);
/// "sphere", "box", "capsule", "half-space" or "mesh".
std::string_view kind_name(ShapeKind kind);

/// The radius of the sphere about the shape's origin that holds a sphere, box or capsule; 0 for
/// the static-only shapes (half-space, mesh).
double bounding_radius(const Shape& shape);

/// Throws InvalidArgument, starting with `where`, unless the shape is valid: a finite radius and
/// half extents > 0, a finite capsule half length ≥ 0, a finite non-zero half-space normal with a
/// finite offset, a mesh that is not null. A half-space is rescaled to a unit normal (the same
/// plane).
void normalize_and_check(Shape& shape, std::string_view where);

/// Index of a body in the system's body arrays; kStatic for shapes fixed in frame I.
using BodyIndex = std::int32_t;
/// The body index of static shapes (half-spaces, meshes, static boxes).
inline constexpr BodyIndex kStatic = -1;

/// A shape attached to a body (or static): its pose in the body frame K (for a static shape: in
/// frame I), x_K = K_r_KC + A_KC x_C for a point x_C of the shape frame C.
struct Collider {
  Shape shape;                          ///< the geometry
  BodyIndex body = kStatic;             ///< the body it moves with, or kStatic
  Vector3 K_r_KC = Vector3::Zero();     ///< origin of the shape frame C in K (or I) [m]
  Matrix3 A_KC = Matrix3::Identity();   ///< orientation of C relative to K (or I)
};

}  // namespace grbd::collision
