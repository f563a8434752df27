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

/// New index i takes the element at old index order[i], in place, along the cycles of the
/// permutation: swapping v[j] with v[order[j]] puts the right element at j and carries the
/// cycle's first element on, until the cycle closes. `done` has one flag per element.
template <class T>
void permute_in_place(std::vector<T>& v, std::span<const std::int32_t> order,
                      std::vector<std::uint8_t>& done) {
  std::fill(done.begin(), done.end(), std::uint8_t{0});
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (done[i]) continue;
    std::size_t j = i;
    done[j] = 1;
    for (auto k = static_cast<std::size_t>(order[j]); k != i; k = static_cast<std::size_t>(order[j])) {
      using std::swap;
      swap(v[j], v[k]);
      j = k;
      done[j] = 1;
    }
  }
}

std::string body_name(GlobalId id) { return "body " + std::to_string(id); }

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
}

std::size_t BodySystem::add(const BodySpec& spec) {
  const std::string where = "BodySystem::add (" + body_name(spec.id) + ")";
  if (spec.id >= kStaticTag) {
    throw InvalidArgument(where + ": expected a global id below 2^63, found " +
                          std::to_string(spec.id));
  }
  if (index_of(spec.id) != npos) {
    throw InvalidArgument(where + ": the global id " + std::to_string(spec.id) +
                          " is already used by the body at local index " +
                          std::to_string(index_of(spec.id)));
  }
  if (size() >= std::numeric_limits<std::int32_t>::max() - 1) {
    throw InvalidArgument(where + ": a system holds at most 2^31 - 2 bodies");
  }
  body::require_valid(spec.state, where);
  body::require_valid(spec.inertia, where);
  collision::Shape shape = spec.shape;
  const collision::ShapeKind kind = collision::kind(shape);
  if (kind != collision::ShapeKind::sphere && kind != collision::ShapeKind::box &&
      kind != collision::ShapeKind::capsule) {
    throw InvalidArgument(where + ": expected a sphere, a box or a capsule as the shape of a body, "
                          "found a " + std::string(collision::kind_name(kind)) +
                          " (half-spaces and meshes are static objects)");
  }
  collision::normalize_and_check(shape, where);

  const std::size_t index = size();
  ids_.push_back(spec.id);
  states_.push_back(spec.state);
  inertia_.push_back(spec.inertia);
  M_inv_.push_back(spec.dynamic ? contact::inverse_mass(spec.inertia)
                                : contact::InverseMass{0.0, Vector3::Zero()});
  bounding_radii_.push_back(collision::bounding_radius(shape));
  shapes_.push_back(std::move(shape));
  materials_.push_back(spec.material);
  flags_.push_back(static_cast<std::uint8_t>((spec.dynamic ? kDynamic : 0) | kOwned));
  if (!spec.dynamic) states_.back().u.setZero();
  ++layout_version_;
  // Grow the table at a load factor of 1/2; otherwise insert in O(1).
  if (2 * size() > slots_.size()) {
    rebuild_index();
  } else {
    insert_index(spec.id, index);
  }
  return index;
}

void BodySystem::insert_index(GlobalId id, std::size_t index) {
  const std::size_t mask = slots_.size() - 1;
  std::size_t slot = mix64(id) & mask;
  while (slots_[slot] != 0) slot = (slot + 1) & mask;
  slots_[slot] = static_cast<std::uint32_t>(index + 1);
}

void BodySystem::rebuild_index() {
  const std::size_t wanted = std::bit_ceil(std::max<std::size_t>(16, 2 * size()));
  if (slots_.size() < wanted) slots_.resize(wanted);
  std::fill(slots_.begin(), slots_.end(), 0U);
  for (std::size_t i = 0; i < size(); ++i) insert_index(ids_[i], i);
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

void BodySystem::remove(std::span<const std::size_t> indices) {
  done_.assign(size(), 0);
  for (const std::size_t i : indices) {
    if (i >= size()) {
      throw InvalidArgument("BodySystem::remove: expected local indices below " +
                            std::to_string(size()) + ", found " + std::to_string(i));
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
  ++layout_version_;
  rebuild_index();
}

void BodySystem::permute(std::span<const std::int32_t> order) {
  const std::size_t n = size();
  if (order.size() != n) {
    throw InvalidArgument("BodySystem::permute: expected a permutation of " + std::to_string(n) +
                          " indices, found " + std::to_string(order.size()) + " entries");
  }
  done_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t k = order[i];
    if (k < 0 || static_cast<std::size_t>(k) >= n || done_[static_cast<std::size_t>(k)]) {
      throw InvalidArgument("BodySystem::permute: entry " + std::to_string(i) + " = " +
                            std::to_string(k) +
                            (k < 0 || static_cast<std::size_t>(k) >= n
                                 ? " is out of range"
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
  const std::size_t n = size();
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

}  // namespace grbd::timestep
