/// \file
/// \brief The system of bodies and the static geometry.

#include "grbd/timestep/body_system.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "grbd/collision/broad_phase.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/hash.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::timestep {

namespace {

/// New index i takes the element at old index order[i], for i < order.size(), in place, along the
/// cycles of the permutation: swapping v[j] with v[order[j]] puts the right element at j and
/// carries the cycle's first element on, until the cycle closes. `done` has one flag per index.
template <class T>
void permute_in_place(std::vector<T>& v, std::span<const std::int32_t> order,
                      std::vector<std::uint8_t>& done) {
  std::fill(done.begin(), done.end(), std::uint8_t{0});
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (done[i]) continue;
    std::size_t j = i;
    done[j] = 1;
    for (auto k = static_cast<std::size_t>(order[j]); k != i;
         k = static_cast<std::size_t>(order[j])) {
      using std::swap;
      swap(v[j], v[k]);
      j = k;
      done[j] = 1;
    }
  }
}

std::string body_name(GlobalId id) { return "body " + std::to_string(id); }

/// The hash of a ghost's identity (global id, image).
std::uint64_t ghost_hash(GlobalId id, std::uint32_t image) {
  return mix64(mix64(id) ^ (std::uint64_t{image} * 0x9e3779b97f4a7c15ULL));
}

}  // namespace

void BodySystem::reserve(std::size_t bodies) {
  ids_.reserve(bodies);
  states_.reserve(bodies);
  inertia_.reserve(bodies);
  M_inv_.reserve(bodies);
  shapes_.reserve(bodies);
  materials_.reserve(bodies);
  flags_.reserve(bodies);
  bounding_radii_.reserve(bodies);
  images_.reserve(bodies);
}

// Everything add() and add_ghost() refuse; the message (and its allocation) only on failure.
void BodySystem::validate(const BodyRecord& spec, const char* what, std::uint32_t image) const {
  const auto where = [&] { return std::string(what) + " (" + body_name(spec.id) + ")"; };
  if (spec.id >= kStaticTag) {
    throw InvalidArgument(where() + ": expected a global id below 2^63, found " +
                          std::to_string(spec.id));
  }
  if ((spec.flags & ~kDynamic) != 0) {
    throw InvalidArgument(where() + ": expected the flags kDynamic or none, found " +
                          std::to_string(spec.flags) + " (kOwned belongs to the row)");
  }
  if (image == 0 && index_of(spec.id) != npos) {
    throw InvalidArgument(where() + ": the global id " + std::to_string(spec.id) +
                          " is already used by the owned body at local index " +
                          std::to_string(index_of(spec.id)));
  }
  if (size() >= std::numeric_limits<std::int32_t>::max() - 1) {
    throw InvalidArgument(where() + ": a system holds at most 2^31 - 2 bodies");
  }
  const collision::ShapeKind kind = collision::kind(spec.shape);
  if (kind != collision::ShapeKind::sphere && kind != collision::ShapeKind::box &&
      kind != collision::ShapeKind::capsule) {
    throw InvalidArgument(where() +
                          ": expected a sphere, a box or a capsule as the shape of a "
                          "body, found a " +
                          std::string(collision::kind_name(kind)) +
                          " (half-spaces and meshes are static objects)");
  }
  try {
    // The checks get the literal `what`; the body's name goes in only when one of them fails.
    body::require_valid(spec.state, what);
    body::require_valid(spec.inertia, what);
    collision::Shape shape = spec.shape;  // a sphere, box or capsule: copied without allocating
    collision::normalize_and_check(shape, what);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(where() + std::string(e.what()).substr(std::string_view(what).size()));
  }
}

// Writes the row of a valid body (its shape is a sphere, box or capsule, so it is normalized).
void BodySystem::set_row(std::size_t i, const BodyRecord& spec, const Vector3& shift,
                         std::uint32_t image, bool owned) {
  ids_[i] = spec.id;
  states_[i] = spec.state;
  states_[i].q.head<3>() += shift;
  if (!spec.dynamic()) states_[i].u.setZero();
  inertia_[i] = spec.inertia;
  M_inv_[i] = spec.dynamic() ? contact::inverse_mass(spec.inertia)
                             : contact::InverseMass{0.0, Vector3::Zero()};
  bounding_radii_[i] = collision::bounding_radius(spec.shape);
  shapes_[i] = spec.shape;
  materials_[i] = spec.material;
  flags_[i] = static_cast<std::uint8_t>((spec.dynamic() ? kDynamic : 0) | (owned ? kOwned : 0));
  images_[i] = image;
}

void BodySystem::resize_rows(std::size_t n) {
  ids_.resize(n);
  states_.resize(n);
  inertia_.resize(n);
  M_inv_.resize(n);
  shapes_.resize(n);
  materials_.resize(n);
  flags_.resize(n);
  bounding_radii_.resize(n);
  images_.resize(n);
}

void BodySystem::move_row(std::size_t from, std::size_t to) {
  ids_[to] = ids_[from];
  states_[to] = states_[from];
  inertia_[to] = inertia_[from];
  M_inv_[to] = M_inv_[from];
  shapes_[to] = shapes_[from];
  materials_[to] = materials_[from];
  flags_[to] = flags_[from];
  bounding_radii_[to] = bounding_radii_[from];
  images_[to] = images_[from];
}

BodyRecord BodySystem::record(std::size_t i) const {
  BodyRecord spec;
  spec.id = ids_[i];
  spec.state = states_[i];
  spec.inertia = inertia_[i];
  spec.shape = shapes_[i];
  spec.material = materials_[i];
  spec.flags = flags_[i] & kDynamic;
  return spec;
}

// [add owned]
std::size_t BodySystem::add(const BodyRecord& spec) {
  validate(spec, "BodySystem::add", 0);
  if (ghost_count() > 0 && ghost_index_of(spec.id, 0) != npos) {
    throw InvalidArgument("BodySystem::add (" + body_name(spec.id) +
                          "): a ghost of it is present "
                          "at local index " +
                          std::to_string(ghost_index_of(spec.id, 0)) +
                          "; clear the ghosts before a body becomes owned here");
  }
  const std::size_t index = owned_count_;
  const std::size_t last = size();
  resize_rows(last + 1);
  if (last > index) {
    // Ghosts follow the owned bodies: the first ghost moves to the new last row, in O(1).
    const std::size_t slot = ghost_slot(ids_[index], images_[index]);
    move_row(index, last);
    ghost_slots_[slot] = static_cast<std::uint32_t>(last + 1);
  }
  set_row(index, spec, Vector3::Zero(), 0, true);
  ++owned_count_;
  ++layout_version_;
  // Grow the table at a load factor of 1/2; otherwise insert in O(1).
  if (2 * owned_count_ > slots_.size()) {
    rebuild_index();
  } else {
    insert_index(spec.id, index);
  }
  return index;
}
// [add owned]

std::size_t BodySystem::add_ghost(const BodyRecord& spec, const Vector3& shift,
                                  std::uint32_t image) {
  validate(spec, "BodySystem::add_ghost", image);
  if (!shift.allFinite()) {
    throw InvalidArgument("BodySystem::add_ghost (" + body_name(spec.id) +
                          "): expected a finite shift");
  }
  if (ghost_index_of(spec.id, image) != npos) {
    throw InvalidArgument("BodySystem::add_ghost (" + body_name(spec.id) +
                          "): its ghost with "
                          "image " +
                          std::to_string(image) + " is present already at local index " +
                          std::to_string(ghost_index_of(spec.id, image)));
  }
  const std::size_t index = size();
  resize_rows(index + 1);
  set_row(index, spec, shift, image, false);
  ++layout_version_;
  if (2 * ghost_count() > ghost_slots_.size()) {
    rebuild_ghost_index();
  } else {
    insert_ghost_index(index);
  }
  return index;
}

void BodySystem::clear_ghosts() {
  if (ghost_count() == 0) return;
  // Every entry goes, so each ghost's probe run from its home slot is emptied up to the first
  // empty slot: whatever a run skips was emptied by an earlier run. O(ghosts).
  const std::size_t mask = ghost_slots_.size() - 1;
  for (std::size_t i = owned_count_; i < size(); ++i) {
    for (std::size_t slot = ghost_hash(ids_[i], images_[i]) & mask; ghost_slots_[slot] != 0;
         slot = (slot + 1) & mask) {
      ghost_slots_[slot] = 0;
    }
  }
  resize_rows(owned_count_);
  ++layout_version_;
}

void BodySystem::insert_index(GlobalId id, std::size_t index) {
  const std::size_t mask = slots_.size() - 1;
  std::size_t slot = mix64(id) & mask;
  while (slots_[slot] != 0) slot = (slot + 1) & mask;
  slots_[slot] = static_cast<std::uint32_t>(index + 1);
}

void BodySystem::rebuild_index() {
  const std::size_t wanted = std::bit_ceil(std::max<std::size_t>(16, 2 * owned_count_));
  if (slots_.size() < wanted) slots_.resize(wanted);
  std::fill(slots_.begin(), slots_.end(), 0U);
  for (std::size_t i = 0; i < owned_count_; ++i) insert_index(ids_[i], i);
}

void BodySystem::insert_ghost_index(std::size_t index) {
  const std::size_t mask = ghost_slots_.size() - 1;
  std::size_t slot = ghost_hash(ids_[index], images_[index]) & mask;
  while (ghost_slots_[slot] != 0) slot = (slot + 1) & mask;
  ghost_slots_[slot] = static_cast<std::uint32_t>(index + 1);
}

void BodySystem::rebuild_ghost_index() {
  const std::size_t wanted = std::bit_ceil(std::max<std::size_t>(16, 2 * ghost_count()));
  if (ghost_slots_.size() < wanted) ghost_slots_.resize(wanted);
  std::fill(ghost_slots_.begin(), ghost_slots_.end(), 0U);
  for (std::size_t i = owned_count_; i < size(); ++i) insert_ghost_index(i);
}

std::size_t BodySystem::index_of(GlobalId id) const {
  if (slots_.empty()) return npos;
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t slot = mix64(id) & mask;; slot = (slot + 1) & mask) {
    const std::uint32_t entry = slots_[slot];
    if (entry == 0) return npos;
    if (ids_[entry - 1] == id) return entry - 1;
  }
}

std::size_t BodySystem::ghost_slot(GlobalId id, std::uint32_t image) const {
  if (ghost_slots_.empty()) return npos;
  const std::size_t mask = ghost_slots_.size() - 1;
  for (std::size_t slot = ghost_hash(id, image) & mask;; slot = (slot + 1) & mask) {
    const std::uint32_t entry = ghost_slots_[slot];
    if (entry == 0) return npos;
    if (ids_[entry - 1] == id && images_[entry - 1] == image) return slot;
  }
}

std::size_t BodySystem::ghost_index_of(GlobalId id, std::uint32_t image) const {
  const std::size_t slot = ghost_slot(id, image);
  return slot == npos ? npos : ghost_slots_[slot] - 1;
}

void BodySystem::remove(std::span<const std::size_t> indices) {
  done_.assign(size(), 0);
  for (const std::size_t i : indices) {
    if (i >= owned_count_) {
      throw InvalidArgument("BodySystem::remove: expected local indices of owned bodies, below " +
                            std::to_string(owned_count_) + ", found " + std::to_string(i));
    }
    if (done_[i]) {
      throw InvalidArgument("BodySystem::remove: local index " + std::to_string(i) +
                            " is given twice");
    }
    done_[i] = 1;
  }
  // Stable compaction of every array with the same mask.
  const auto compact = [&](auto& v) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!done_[i]) {
        if (kept != i) v[kept] = std::move(v[i]);
        ++kept;
      }
    }
    v.erase(v.begin() + static_cast<std::ptrdiff_t>(kept), v.end());
  };
  compact(ids_);
  compact(states_);
  compact(inertia_);
  compact(M_inv_);
  compact(shapes_);
  compact(materials_);
  compact(flags_);
  compact(bounding_radii_);
  compact(images_);
  owned_count_ -= indices.size();
  ++layout_version_;
  rebuild_index();
  if (ghost_count() > 0) rebuild_ghost_index();
}

void BodySystem::permute(std::span<const std::int32_t> order) {
  const std::size_t n = owned_count_;
  if (order.size() != n) {
    throw InvalidArgument("BodySystem::permute: expected a permutation of the " +
                          std::to_string(n) + " owned bodies, found " +
                          std::to_string(order.size()) + " entries");
  }
  done_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t k = order[i];
    if (k < 0 || static_cast<std::size_t>(k) >= n || done_[static_cast<std::size_t>(k)]) {
      throw InvalidArgument(
          "BodySystem::permute: entry " + std::to_string(i) + " = " + std::to_string(k) +
          (k < 0 || static_cast<std::size_t>(k) >= n ? " is out of range"
                                                     : " appears twice: expected a permutation"));
    }
    done_[static_cast<std::size_t>(k)] = 1;
  }
  permute_in_place(ids_, order, done_);
  permute_in_place(states_, order, done_);
  permute_in_place(inertia_, order, done_);
  permute_in_place(M_inv_, order, done_);
  permute_in_place(shapes_, order, done_);
  permute_in_place(materials_, order, done_);
  permute_in_place(flags_, order, done_);
  permute_in_place(bounding_radii_, order, done_);
  ++layout_version_;
  rebuild_index();
}

// [reorder morton]
void BodySystem::reorder_morton(double cell_size) {
  const std::size_t n = owned_count_;
  positions_.resize(n);
  for (std::size_t i = 0; i < n; ++i) positions_[i] = states_[i].q.head<3>();
  codes_.resize(n);
  collision::morton_codes(positions_, cell_size, codes_);
  if (n == 0) return;
  morton_keys_.resize(n);
  for (std::size_t i = 0; i < n; ++i) morton_keys_[i] = {codes_[i], ids_[i]};
  // Sorting (code, id) pairs and looking the ids up keeps the order independent of the current
  // one: two systems with the same bodies get the same layout.
  std::sort(morton_keys_.begin(), morton_keys_.end());
  order_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    order_[i] = static_cast<std::int32_t>(index_of(morton_keys_[i].second));
  }
  permute(order_);
}
// [reorder morton]

std::size_t StaticGeometry::add(StaticObject object) {
  const std::string where = "StaticGeometry::add (static object " + std::to_string(object.id) + ")";
  if (object.id >= kStaticTag) {
    throw InvalidArgument(where + ": expected an id below 2^63, found " +
                          std::to_string(object.id));
  }
  if (ids_.contains(object.id)) {
    throw InvalidArgument(where + ": the id " + std::to_string(object.id) + " is used twice");
  }
  if (!object.pose.I_r.allFinite() || !kinematics::is_rotation_matrix(object.pose.A_IC, 1e-9)) {
    throw InvalidArgument(where + ": expected a finite position and a rotation matrix A_IC");
  }
  collision::normalize_and_check(object.shape, where);
  ids_.insert(object.id);
  objects_.push_back(std::move(object));
  return objects_.size() - 1;
}

bool StaticGeometry::remove(std::uint64_t id) {
  if (ids_.erase(id) == 0) return false;
  std::erase_if(objects_, [id](const StaticObject& object) { return object.id == id; });
  return true;
}

std::uint32_t image_code(const std::array<int, 3>& s) {
  for (const int c : s) {
    if (c < -1 || c > 1) {
      throw InvalidArgument("image_code: expected shifts of −1, 0 or 1 period, found " +
                            std::to_string(c));
    }
  }
  if (s[0] == 0 && s[1] == 0 && s[2] == 0) return 0;
  return static_cast<std::uint32_t>(1 + (s[0] + 1) + 3 * (s[1] + 1) + 9 * (s[2] + 1));
}

std::array<int, 3> image_shift(std::uint32_t code) {
  if (code == 0) return {0, 0, 0};
  if (code > 27 || code == 14) {
    throw InvalidArgument("image_shift: " + std::to_string(code) + " is not an image code");
  }
  const int k = static_cast<int>(code) - 1;
  return {k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1};
}

std::uint32_t relative_image(std::uint32_t a, std::uint32_t b) {
  const std::array<int, 3> sa = image_shift(a), sb = image_shift(b);
  return image_code({sb[0] - sa[0], sb[1] - sa[1], sb[2] - sa[2]});
}

}  // namespace grbd::timestep
