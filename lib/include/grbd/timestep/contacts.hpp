#pragma once
/// \file
/// \brief The contacts of a system of bodies (chapter 6): detection at given states in a
/// canonical order, contact identities built from global ids, and warm starts kept in flat arrays
/// with an open-addressing index.

#include <compare>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "grbd/collision/broad_phase.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/timestep/body_system.hpp"

namespace grbd::timestep {

/// The identity of a contact, independent of where the bodies are stored: the global ids of the
/// two sides (a static object's id tagged with kStaticTag), their features, and the periodic
/// image through which they touch. Side a is the first in the order sphere, box, capsule,
/// half-space, mesh and, between two sides of the same kind, the one with the smaller id; so
/// reordering, removal, restart and (chapter 8) migration keep every key, and two bodies that touch
/// both directly and through a periodic boundary have two keys.
struct ContactKey {
  std::uint64_t a = 0;          ///< global id of side a (kStaticTag | id for a static object)
  std::uint64_t b = 0;          ///< global id of side b
  std::uint64_t feature_a = 0;  ///< feature of a (collision::face_feature() and others)
  std::uint64_t feature_b = 0;  ///< feature of b
  /// The periodic image of side b as side a sees it: relative_image() of the two copies that
  /// touch; 0 without periodic boundaries.
  std::uint64_t image = 0;
  /// Lexicographic in (a, b, feature_a, feature_b, image).
  friend auto operator<=>(const ContactKey&, const ContactKey&) = default;
};

/// A warm start as a row of a checkpoint or of a message between processes: its contact's key and
/// percussion (trivially copyable).
struct WarmRow {
  ContactKey key;    ///< the contact
  double lambda[3];  ///< its percussion Λ [N s]
};

/// A contact as detection finds it: the two sides as the contact problem sees them, their
/// materials, and the geometry at the detected states (normal from b towards a, gap, the two
/// closest points, features), and the rows of the two sides in the BodySystem. 120 bytes: no
/// tangent basis, no lever arms in body frames (the stepper forms the compact problem of
/// contact::CompactProblem from it).
struct DetectedContact {
  /// a dynamic body's local index, or collision::kStatic (a static object or a fixed body)
  collision::BodyIndex body_a = collision::kStatic;
  collision::BodyIndex body_b = collision::kStatic;  ///< as body_a, for side b
  /// The row of side a in the BodySystem, fixed bodies included; −1 for a static object.
  std::int32_t row_a = -1;
  std::int32_t row_b = -1;              ///< as row_a, for side b
  MaterialId material_a = 0;            ///< material of side a
  MaterialId material_b = 0;            ///< material of side b
  collision::ContactGeometry geometry;  ///< n, g_N, points, features
};

/// Contact detection for a BodySystem and its StaticGeometry. Every buffer is a member and keeps
/// its capacity, so that detection in a settled system allocates nothing.
///
/// Pairs of spheres go through the CellGrid of chapter 4; boxes and capsules meet the other
/// bodies whose bounding spheres they touch; every dynamic body meets every static object.
/// Fixed bodies meet dynamic ones only. With ghosts in the system (BodySystem), a pair needs an
/// owned side: two ghosts, or a ghost and a static object, are another process's pair. The
/// contacts come out in a canonical order: along the
/// Morton curve of their points, ties broken by key, so that the order, and everything the
/// solver computes from it, does not depend on how the bodies are stored.
class ContactDetector {
 public:
  /// All contacts with g_N ≤ margin at the states of `system` and their keys (same length); both
  /// vectors are overwritten, written in place and then put in canonical order in place (no
  /// second copy of the contacts). A fixed body enters its contacts as collision::kStatic (it
  /// does not move), with its global id in the key and its material.
  void detect(const BodySystem& system, const StaticGeometry& statics, double margin,
              std::vector<DetectedContact>& contacts, std::vector<ContactKey>& keys);

  /// The skin of the candidate list of sphere pairs [m] (a Verlet list; 0, the default: no list,
  /// the cell grid runs at every detect()). With a skin s > 0, the grid finds the pairs within
  /// margin + s and detect() keeps testing that list until some sphere has moved more than s/2
  /// from where it was when the list was built, or the bodies were added, removed or reordered
  /// (BodySystem::layout_version), or the margin grew: two spheres absent from the list are then
  /// still more than the margin apart, and the contacts are exactly those of detection from
  /// scratch, bit for bit. Throws InvalidArgument unless s ≥ 0 and finite.
  void set_skin(double skin);
  /// The skin [m].
  double skin() const { return skin_; }
  /// How often the candidate list was built (every detect() with skin 0).
  std::uint64_t list_builds() const { return list_builds_; }

 private:
  bool list_is_valid(const BodySystem& system, double margin) const;

  collision::CellGrid grid_;
  std::vector<Vector3> centres_;
  std::vector<double> radii_;
  std::vector<std::int32_t> sphere_bodies_;
  std::vector<collision::IndexPair> pairs_;
  // The candidate list: sphere pairs as body indices, and what it was built for.
  double skin_ = 0.0;
  std::vector<std::pair<std::size_t, std::size_t>> candidates_;
  std::vector<Vector3> built_centres_;  // of sphere_bodies_, when the list was built
  std::uint64_t built_layout_ = ~std::uint64_t{0};
  double built_margin_ = -1.0;
  std::uint64_t list_builds_ = 0;
  std::vector<std::size_t> others_;  // dynamic non-spheres and fixed bodies
  std::vector<collision::Placement> placements_;
  std::vector<collision::ContactGeometry> found_;
  std::vector<Vector3> midpoints_;
  std::vector<std::uint64_t> codes_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order_, scratch_;
  std::vector<std::uint32_t> permutation_;
  std::vector<std::uint32_t> counts_;  // radix-sort buckets
};

/// The percussions of the previous step, keyed by ContactKey, in flat arrays: store() copies
/// keys and percussions and rebuilds an open-addressing index (linear probing, load ≤ 1/2);
/// initialize() looks every key up in O(1) expected. Once the arrays have grown to the largest
/// contact count, neither allocates.
class WarmStartTable {
 public:
  /// Replaces what is stored (same lengths, else InvalidArgument). A key given twice keeps the
  /// last percussion.
  void store(std::span<const ContactKey> keys, std::span<const Vector3> lambda);
  /// Writes the stored percussion of each key into `lambda` (same length as keys, else
  /// InvalidArgument), zero for a new contact; returns how many keys were found.
  std::size_t initialize(std::span<const ContactKey> keys, std::span<Vector3> lambda) const;
  /// The stored keys and percussions (for checkpoints, chapter 7).
  std::span<const ContactKey> keys() const { return keys_; }   ///< the stored keys
  std::span<const Vector3> lambda() const { return lambda_; }  ///< their percussions
  /// Number of stored contacts.
  std::size_t size() const { return keys_.size(); }
  /// Forgets everything (keeps the capacity).
  void clear();

 private:
  std::size_t find(const ContactKey& key) const;  // index into keys_, or size()
  std::vector<ContactKey> keys_;
  std::vector<Vector3> lambda_;
  std::vector<std::uint32_t> slots_;  // index + 1, 0 = empty
};

/// The squared displacement beyond which a candidate list, or ghosts, built with a skin s must be
/// rebuilt: (s/2)², half the skin less a relative 10⁻¹², so that the rounding of a displacement
/// never keeps one a step too long.
inline double rebuild_distance_squared(double skin) {
  const double half = 0.5 * skin * (1.0 - 1e-12);
  return half * half;
}

/// Keeps the contacts for which keep(contact) is true, and their keys with them, in their order,
/// in place (the stepper's active set, a parallel run's contacts of this process).
template <class Keep>
void keep_contacts_if(std::vector<DetectedContact>& contacts, std::vector<ContactKey>& keys,
                      Keep keep) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (!keep(contacts[k])) continue;
    if (kept != k) {
      contacts[kept] = contacts[k];
      keys[kept] = keys[k];
    }
    ++kept;
  }
  contacts.resize(kept);
  keys.resize(kept);
}

/// A 64-bit hash of a key (splitmix64 finalisers of its words; the image only when it is not 0).
std::uint64_t hash(const ContactKey& key);

}  // namespace grbd::timestep
