#pragma once
/// \file
/// \brief The collision world: the colliders of a scene, checked for supported pairs when the
/// scene is assembled, and contact detection for given body states (chapter 4).

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/broad_phase.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/shapes.hpp"

namespace grbd::collision {

/// true when the narrow phase handles the pair (in either order): sphere–sphere,
/// sphere–half-space, sphere–box, sphere–capsule, sphere–mesh, box–half-space, capsule–half-space.
bool supported(ShapeKind a, ShapeKind b);

/// The colliders of a scene and their contact detection.
///
/// Pairs of moving spheres go through the CellGrid broad phase; every moving collider is tested
/// against every static one (half-spaces directly, meshes through their hierarchy); other moving
/// pairs are tested when their bounding spheres overlap. Two static colliders never touch.
class CollisionWorld {
 public:
  /// Adds a collider and returns its index. Throws grbd::InvalidArgument for a bad shape (a
  /// non-positive size, a zero normal, a half-space or mesh attached to a body) and, naming both
  /// colliders, their kinds and the supported pairs, for a kind that cannot meet an existing
  /// collider: an unsupported pair is refused when the scene is assembled, never skipped later.
  /// O(1): the pair check looks at one representative collider per shape kind, the first one
  /// that could meet the new collider, so 10⁶ spheres are added in O(N).
  std::int32_t add(Collider collider);
  /// Removes every collider (the buffers keep their capacity).
  void clear();
  /// Reserves room for `colliders` colliders.
  void reserve(std::size_t colliders);
  /// The colliders, in the order they were added.
  std::span<const Collider> colliders() const { return colliders_; }
  /// All contacts with g_N ≤ margin for the body states `states` (indexed by BodyIndex), each with
  /// its tangent basis and lever arms; `contacts` is cleared first.
  void detect(std::span<const body::State> states, double margin, std::vector<Contact>& contacts);

 private:
  static constexpr int kShapeKinds = 5;  // the enumerators of ShapeKind
  /// For one shape kind: the first static collider, the first moving one, and the first moving
  /// one on a body other than that one's (-1: none), all add() needs to find a conflict.
  struct Representatives {
    std::int32_t first_static = -1;
    std::int32_t first_moving = -1;
    std::int32_t first_moving_other_body = -1;
  };
  std::vector<Collider> colliders_;
  std::array<Representatives, kShapeKinds> representatives_{};
  std::vector<Placement> placements_;
  std::vector<Matrix3> A_IK_;
  std::vector<ContactGeometry> found_;
  CellGrid grid_;
  std::vector<Vector3> centres_;
  std::vector<double> radii_;
  std::vector<std::int32_t> sphere_colliders_;
  std::vector<IndexPair> pairs_;
  std::vector<std::size_t> statics_;             // colliders fixed in frame I
  std::vector<std::size_t> moving_;              // colliders attached to bodies
  std::vector<std::size_t> moving_non_spheres_;  // the moving colliders that are not spheres
};

}  // namespace grbd::collision
