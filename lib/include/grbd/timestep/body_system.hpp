#pragma once
/// \file
/// \brief The system of bodies (chapter 6): one owner of every per-body array, indexed by a local
/// body index and moved together by append, remove and permute; every body carries a stable
/// 64-bit global id. The bodies a process owns come first, ghost copies of other processes' bodies
/// (or shifted periodic images) after them. The static geometry (walls, floors, obstacles) is
/// kept apart, each object with its own stable id. Chapters 7 (scene files, restart) and 8 (MPI
/// migration, ghosts) build on both.

#include <array>
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
#include "grbd/timestep/body_record.hpp"

namespace grbd::timestep {

/// The image code of a periodic shift s ∈ {−1, 0, 1}³ (in periods along each axis): 0 for no shift,
/// else 1 + (s_x + 1) + 3 (s_y + 1) + 9 (s_z + 1). A ghost's (global id, image) is its identity
/// (chapter 8). Throws InvalidArgument for a component outside {−1, 0, 1}.
std::uint32_t image_code(const std::array<int, 3>& shift);
/// The shift of an image code (the inverse of image_code()); throws InvalidArgument for a code
/// that is not one.
std::array<int, 3> image_shift(std::uint32_t code);
/// The image of a copy with code `b` as seen from a copy with code `a`: the code of the shift
/// s_b − s_a (0 when both are the same image). Throws InvalidArgument when that shift is not
/// in {−1, 0, 1}³.
std::uint32_t relative_image(std::uint32_t a, std::uint32_t b);

/// The bodies of a simulation as parallel arrays ("structure of arrays"): entry i of every array
/// belongs to the body with local index i. Local indices change when bodies are removed or
/// reordered; global ids never do. Every operation moves all arrays together.
///
/// The arrays a time step reads and writes (states, inverse masses) are contiguous, so that the
/// step streams through them; the system is reordered along a Morton curve every few steps
/// (reorder_morton) so that bodies close in space are close in memory.
///
/// **Owned bodies and ghosts.** Rows [0, owned_count()) hold the bodies this process owns: it
/// integrates them, writes them and reports their energy. Rows [owned_count(), size()) hold
/// ghosts: copies of bodies that another process owns, or images of any body shifted by a
/// periodic boundary, present so that contacts with owned bodies are found and solved here. A
/// ghost has its own lookup by (global id, image), so a body and its shifted image can both be
/// present; index_of() finds owned bodies only. Without ghosts (a serial run) every row is owned.
class BodySystem {
 public:
  /// Appends an owned body and returns its local index, owned_count() − 1. Throws
  /// InvalidArgument, naming the body's id, for an id already owned or ≥ kStaticTag, an invalid
  /// state (body::require_valid) or inertia, and a shape that is not a valid sphere, box or
  /// capsule. O(1) amortised (with ghosts present, the first ghost moves to the end to make
  /// room); allocates nothing when the arrays have room.
  std::size_t add(const BodyRecord& spec);
  /// Appends a ghost: a copy of a body owned elsewhere, or (image ≠ 0) a periodic image of any
  /// body, its position moved by `shift` [m]; returns its local index, size() − 1. The pair
  /// (id, image) must be new among the ghosts, and a ghost with image 0 must not be owned here
  /// (else InvalidArgument); otherwise checked as add(). O(1) amortised.
  std::size_t add_ghost(const BodyRecord& spec, const Vector3& shift = Vector3::Zero(),
                        std::uint32_t image = 0);
  /// Removes every ghost, in O(ghosts); the owned bodies keep their rows.
  void clear_ghosts();
  /// Reserves room for `bodies` bodies (owned and ghosts) in every array.
  void reserve(std::size_t bodies);
  /// Removes the owned bodies with the given local indices (any order, no duplicates, each
  /// < owned_count(), else InvalidArgument); the others keep their relative order, ghosts
  /// included. O(N).
  void remove(std::span<const std::size_t> indices);
  /// Reorders the owned bodies: the body at new index i is the one at old index order[i].
  /// `order` must be a permutation of 0 … owned_count() − 1 (else InvalidArgument); ghosts keep
  /// their rows. O(N), in place: it allocates nothing once the system has seen one permutation of
  /// its size.
  void permute(std::span<const std::int32_t> order);
  /// Reorders the owned bodies along the Morton (Z-order) curve of their centres on cells of edge
  /// `cell_size`, ties broken by global id: the same positions give the same order whatever the
  /// current order (collision::morton_codes(), whose InvalidArgument it passes on). O(N log N);
  /// allocates nothing once it has run at this size.
  void reorder_morton(double cell_size);

  /// Number of rows: owned bodies and ghosts.
  std::size_t size() const { return ids_.size(); }
  /// Number of owned bodies: rows [0, owned_count()).
  std::size_t owned_count() const { return owned_count_; }
  /// Number of ghosts: rows [owned_count(), size()).
  std::size_t ghost_count() const { return size() - owned_count_; }
  /// True when row i holds an owned body.
  bool owned(std::size_t i) const { return i < owned_count_; }
  /// The local index of the owned body with global id `id`, or npos. O(1) expected.
  std::size_t index_of(GlobalId id) const;
  /// The local index of the ghost of body `id` with image `image`, or npos. O(1) expected.
  std::size_t ghost_index_of(GlobalId id, std::uint32_t image = 0) const;
  /// "No such body".
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  /// \name The arrays, indexed by local body index
  ///@{
  std::span<const GlobalId> ids() const { return ids_; }           ///< stable global ids
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
  std::span<const std::uint8_t> flags() const { return flags_; }        ///< BodyFlags bits
  /// Radius of the bounding sphere of each body's shape about S [m].
  std::span<const double> bounding_radii() const { return bounding_radii_; }
  /// The image of each row: 0 for owned bodies and plain ghosts, the periodic image of a shifted
  /// ghost as add_ghost() was given it.
  std::span<const std::uint32_t> images() const { return images_; }
  ///@}
  /// The record of the body in row i, as add() or add_ghost() would take it (a ghost's position
  /// includes its shift).
  BodyRecord record(std::size_t i) const;
  /// True when body i is dynamic.
  bool dynamic(std::size_t i) const { return (flags_[i] & kDynamic) != 0; }
  /// Increases whenever bodies are added, removed or reordered (what depends on local indices,
  /// e.g. a contact list, is stale when it changed).
  std::uint64_t layout_version() const { return layout_version_; }

 private:
  void validate(const BodyRecord& spec, const char* what, std::uint32_t image) const;
  void set_row(std::size_t i, const BodyRecord& spec, const Vector3& shift, std::uint32_t image,
               bool owned);
  void resize_rows(std::size_t n);
  void move_row(std::size_t from, std::size_t to);
  void rebuild_index();
  void rebuild_ghost_index();
  void insert_index(GlobalId id, std::size_t index);
  void insert_ghost_index(std::size_t index);
  std::size_t ghost_slot(GlobalId id, std::uint32_t image) const;  // the slot, or npos

  std::vector<GlobalId> ids_;
  std::vector<body::State> states_;
  std::vector<body::RigidBody> inertia_;
  std::vector<contact::InverseMass> M_inv_;
  std::vector<collision::Shape> shapes_;
  std::vector<MaterialId> materials_;
  std::vector<std::uint8_t> flags_;
  std::vector<double> bounding_radii_;
  std::vector<std::uint32_t> images_;
  std::size_t owned_count_ = 0;
  std::uint64_t layout_version_ = 0;
  // Open addressing with linear probing, global id → local index + 1 (0: empty slot), for the
  // owned bodies; and (global id, image) → local index + 1 for the ghosts.
  std::vector<std::uint32_t> slots_;
  std::vector<std::uint32_t> ghost_slots_;
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
  GlobalId id = 0;            ///< stable identity among static objects, < kStaticTag
  collision::Shape shape;     ///< the geometry (a sphere is allowed too)
  collision::Placement pose;  ///< where its frame C sits in I (ignored by a half-space)
  MaterialId material = 0;    ///< row of the material table
};

/// The static geometry of a scene, apart from the bodies: static objects never move and never
/// touch each other.
class StaticGeometry {
 public:
  /// Appends an object and returns its index, in O(1) (the ids are hashed). Throws
  /// InvalidArgument, naming the id, for an id used twice or ≥ kStaticTag, a non-finite pose, a
  /// rotation that is not one, or a bad shape. A half-space is stored with a unit normal.
  std::size_t add(StaticObject object);
  /// Removes the object with this id (the others keep their order), in O(objects); false when
  /// there is none. Contacts with it are no longer found from the next detection on.
  bool remove(std::uint64_t id);
  /// The objects in the order they were added.
  std::span<const StaticObject> objects() const { return objects_; }
  /// Number of objects.
  std::size_t size() const { return objects_.size(); }

 private:
  std::vector<StaticObject> objects_;
  std::unordered_set<std::uint64_t> ids_;
};

}  // namespace grbd::timestep
