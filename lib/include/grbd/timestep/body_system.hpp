#pragma once
/// \file
/// \brief The system of bodies (chapter 6): one owner of every per-body array, indexed by a local
/// body index and moved together by append, remove and permute; every body carries a stable
/// 64-bit global id. The static geometry (walls, floors, obstacles) is kept apart, each object
/// with its own stable id. Chapters 7 (scene files, restart) and 8 (MPI migration) build on both.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_set>
#include <vector>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/shapes.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/core/types.hpp"

namespace grbd::timestep {

/// The stable identity of a body (or of a static object): never reused within a run, kept by
/// reordering, removal, restart and, in chapter 8, migration between MPI ranks.
using GlobalId = std::uint64_t;
/// The index of a material in a MaterialTable.
using MaterialId = std::uint32_t;

/// Global ids of static objects are tagged with this bit in contact keys, so that a body and a
/// static object never share an identity. Body ids must stay below it.
inline constexpr GlobalId kStaticTag = GlobalId{1} << 63;

/// Flags of a body, one byte per body.
enum BodyFlags : std::uint8_t {
  kDynamic = 1U << 0,  ///< moves under forces and contacts; without it the body is fixed (u = 0)
  kOwned = 1U << 1,    ///< integrated by this process (chapter 8: remote copies lack it)
};

/// Everything that describes one body when it enters the system.
struct BodySpec {
  GlobalId id = 0;                ///< stable identity, unique in the system, < kStaticTag
  body::State state;              ///< q = (I_r_S, p) with |p| = 1, u = (I_v_S, K_omega)
  body::RigidBody inertia;        ///< mass and principal moments (frame K is principal)
  /// The collision shape, centred at S with its axes along K: a sphere, a box or a capsule.
  collision::Shape shape = collision::Sphere{};
  MaterialId material = 0;        ///< row of the material table
  bool dynamic = true;            ///< false: the body is fixed where it is (infinite mass)
};

/// The bodies of a simulation as parallel arrays ("structure of arrays"): entry i of every array
/// belongs to the body with local index i. Local indices change when bodies are removed or
/// reordered; global ids never do. Every operation moves all arrays together.
///
/// The arrays a time step reads and writes (states, inverse masses) are contiguous, so that the
/// step streams through them; the system is reordered along a Morton curve every few steps
/// (reorder_morton) so that bodies close in space are close in memory.
class BodySystem {
 public:
  /// Appends a body and returns its local index. Throws InvalidArgument, naming the body's id,
  /// for an id already present or ≥ kStaticTag, an invalid state (body::require_valid) or
  /// inertia, and a shape that is not a valid sphere, box or capsule. O(1) amortised.
  std::size_t add(const BodySpec& spec);
  /// Reserves room for `bodies` bodies in every array.
  void reserve(std::size_t bodies);
  /// Removes the bodies with the given local indices (any order, no duplicates, each < size(),
  /// else InvalidArgument); the others keep their relative order. O(N).
  void remove(std::span<const std::size_t> indices);
  /// Reorders the bodies: the body at new index i is the one at old index order[i]. `order` must
  /// be a permutation of 0 … size() − 1 (else InvalidArgument). O(N), in place: it allocates
  /// nothing once the system has seen one permutation of its size.
  void permute(std::span<const std::int32_t> order);
  /// Reorders the bodies along the Morton (Z-order) curve of their centres on cells of edge
  /// `cell_size`, ties broken by global id: the same positions give the same order whatever the
  /// current order (collision::morton_codes(), whose InvalidArgument it passes on). O(N log N);
  /// allocates nothing once it has run at this size.
  void reorder_morton(double cell_size);

  /// Number of bodies.
  std::size_t size() const { return ids_.size(); }
  /// The local index of the body with global id `id`, or npos. O(1) expected.
  std::size_t index_of(GlobalId id) const;
  /// "No such body".
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  /// \name The arrays, indexed by local body index
  ///@{
  std::span<const GlobalId> ids() const { return ids_; }  ///< stable global ids
  std::span<const body::State> states() const { return states_; }  ///< q and u
  /// The states, writable: the time stepper advances them. The caller keeps them finite and
  /// |p| = 1 (the stepper checks what it computes).
  std::span<body::State> states() { return states_; }
  std::span<const body::RigidBody> inertia() const { return inertia_; }  ///< m and K_Θ
  /// M⁻¹ of each body; a fixed body has 1/m = 0 and K_Θ⁻¹ = 0 (it never enters a contact as a
  /// body: the contact problem sees it as the static world).
  std::span<const contact::InverseMass> M_inv() const { return M_inv_; }
  std::span<const collision::Shape> shapes() const { return shapes_; }  ///< collision shapes
  std::span<const MaterialId> materials() const { return materials_; }  ///< material ids
  std::span<const std::uint8_t> flags() const { return flags_; }  ///< BodyFlags bits
  /// Radius of the bounding sphere of each body's shape about S [m].
  std::span<const double> bounding_radii() const { return bounding_radii_; }
  ///@}
  /// True when body i is dynamic.
  bool dynamic(std::size_t i) const { return (flags_[i] & kDynamic) != 0; }
  /// Increases whenever bodies are added, removed or reordered (what depends on local indices,
  /// e.g. a contact list, is stale when it changed).
  std::uint64_t layout_version() const { return layout_version_; }

 private:
  void rebuild_index();
  void insert_index(GlobalId id, std::size_t index);

  std::vector<GlobalId> ids_;
  std::vector<body::State> states_;
  std::vector<body::RigidBody> inertia_;
  std::vector<contact::InverseMass> M_inv_;
  std::vector<collision::Shape> shapes_;
  std::vector<MaterialId> materials_;
  std::vector<std::uint8_t> flags_;
  std::vector<double> bounding_radii_;
  std::uint64_t layout_version_ = 0;
  // Open addressing with linear probing, global id → local index + 1 (0: empty slot).
  std::vector<std::uint32_t> slots_;
  // Scratch of permute() and reorder_morton(), kept to avoid allocation.
  std::vector<std::uint8_t> done_;
  std::vector<Vector3> positions_;
  std::vector<std::uint64_t> codes_;
  std::vector<std::pair<std::uint64_t, GlobalId>> morton_keys_;
  std::vector<std::int32_t> order_;
  std::vector<std::int32_t> position_;
};

/// One object fixed in the world: a half-space, a box, a capsule or a triangle mesh.
struct StaticObject {
  GlobalId id = 0;                 ///< stable identity among static objects, < kStaticTag
  collision::Shape shape;          ///< the geometry (a sphere is allowed too)
  collision::Placement pose;       ///< where its frame C sits in I (ignored by a half-space)
  MaterialId material = 0;         ///< row of the material table
};

/// The static geometry of a scene, apart from the bodies: static objects never move and never
/// touch each other.
class StaticGeometry {
 public:
  /// Appends an object and returns its index, in O(1) (the ids are hashed). Throws
  /// InvalidArgument, naming the id, for an id used twice or ≥ kStaticTag, a non-finite pose, a rotation that is not one, or a bad shape.
  /// A half-space is stored with a unit normal.
  std::size_t add(StaticObject object);
  /// The objects in the order they were added.
  std::span<const StaticObject> objects() const { return objects_; }
  /// Number of objects.
  std::size_t size() const { return objects_.size(); }

 private:
  std::vector<StaticObject> objects_;
  std::unordered_set<std::uint64_t> ids_;
};

}  // namespace grbd::timestep
