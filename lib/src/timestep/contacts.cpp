/// \file
/// \brief Contact detection for a system of bodies in canonical order, and the flat warm-start
/// table.

#include "grbd/timestep/contacts.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/hash.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::timestep {

namespace {

/// One side of a candidate pair: a body (by local index) or a static object (by index).
struct Side {
  bool is_body = true;
  std::size_t index = 0;
};

/// Sorts (code, index) pairs by code, stably: a least-significant-digit radix sort with 16-bit
/// digits, four passes over the array (digits that are equal in every code are skipped).
/// O(m), no comparison; `scratch` is resized to m and `count` to 2¹⁶.
void sort_by_code(std::vector<std::pair<std::uint64_t, std::uint32_t>>& items,
                  std::vector<std::pair<std::uint64_t, std::uint32_t>>& scratch,
                  std::vector<std::uint32_t>& count) {
  constexpr int kBits = 16;
  constexpr std::size_t kBuckets = std::size_t{1} << kBits;
  const std::size_t m = items.size();
  scratch.resize(m);
  std::uint64_t all_or = 0;
  std::uint64_t all_and = ~std::uint64_t{0};
  for (const auto& item : items) {
    all_or |= item.first;
    all_and &= item.first;
  }
  const std::uint64_t varying = all_or ^ all_and;  // bits that differ between some codes
  count.resize(kBuckets);
  for (int shift = 0; shift < 64; shift += kBits) {
    if (((varying >> shift) & (kBuckets - 1)) == 0) continue;
    std::fill(count.begin(), count.end(), 0U);
    for (const auto& item : items) ++count[(item.first >> shift) & (kBuckets - 1)];
    std::uint32_t offset = 0;
    for (std::uint32_t& c : count) {
      const std::uint32_t here = c;
      c = offset;
      offset += here;
    }
    for (const auto& item : items) scratch[count[(item.first >> shift) & (kBuckets - 1)]++] = item;
    items.swap(scratch);
  }
}

/// Reorders a and b in place so that the new element k is the old element p[k]; p is used up
/// (each entry becomes its own index as the cycles are followed).
template <class A, class B>
void permute_in_place(std::vector<std::uint32_t>& p, std::vector<A>& a, std::vector<B>& b) {
  for (std::size_t start = 0; start < p.size(); ++start) {
    if (p[start] == start) continue;
    A held_a = a[start];
    B held_b = b[start];
    std::size_t k = start;
    for (;;) {
      const std::size_t from = p[k];
      p[k] = static_cast<std::uint32_t>(k);
      if (from == start) {
        a[k] = held_a;
        b[k] = held_b;
        break;
      }
      a[k] = a[from];
      b[k] = b[from];
      k = from;
    }
  }
}

}  // namespace

std::uint64_t hash(const ContactKey& key) {
  std::uint64_t h = mix64(key.a);
  h = mix64(h ^ key.b);
  h = mix64(h ^ key.feature_a);
  h = mix64(h ^ key.feature_b);
  return key.image == 0 ? h : mix64(h ^ key.image);
}

// [detect system]
void ContactDetector::detect(const BodySystem& system, const StaticGeometry& statics, double margin,
                             std::vector<DetectedContact>& contacts,
                             std::vector<ContactKey>& keys) {
  if (!(margin >= 0.0 && std::isfinite(margin))) {
    throw InvalidArgument("ContactDetector::detect: expected a finite margin >= 0, found " +
                          format_number(margin));
  }
  const std::size_t n = system.size();
  const auto states = system.states();
  const auto shapes = system.shapes();
  const auto ids = system.ids();
  const auto objects = statics.objects();
  placements_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vector7& q = states[i].q;
    if (!q.allFinite()) {
      throw InvalidArgument(
          "ContactDetector::detect: expected finite positions and orientations, "
          "found q = (" +
          format_number(q[0]) + ", " + format_number(q[1]) + ", " + format_number(q[2]) +
          ", …) for body " + std::to_string(ids[i]));
    }
    placements_[i] = {kinematics::position(q),
                      kinematics::rotation_matrix(kinematics::orientation(q))};
  }
  contacts.clear();
  keys.clear();
  const auto materials = system.materials();

  const auto shape_of = [&](const Side& s) -> const collision::Shape& {
    return s.is_body ? shapes[s.index] : objects[s.index].shape;
  };
  const auto placement_of = [&](const Side& s) -> const collision::Placement& {
    return s.is_body ? placements_[s.index] : objects[s.index].pose;
  };
  const auto id_of = [&](const Side& s) {
    return s.is_body ? ids[s.index] : (kStaticTag | objects[s.index].id);
  };
  const auto images = system.images();
  const auto image_of = [&](const Side& s) { return s.is_body ? images[s.index] : 0u; };
  // Side a: the first in the kind order sphere, box, capsule, half-space, mesh (the kernels'
  // argument order); between equal kinds, the smaller id. Neither depends on storage order.
  const auto pair = [&](Side x, Side y) {
    const collision::ShapeKind kx = collision::kind(shape_of(x));
    const collision::ShapeKind ky = collision::kind(shape_of(y));
    if (ky < kx || (ky == kx && id_of(y) < id_of(x))) std::swap(x, y);
    found_.clear();
    collision::collide(shape_of(x), placement_of(x), shape_of(y), placement_of(y), margin, found_);
    for (const collision::ContactGeometry& g : found_) {
      if (!(g.g_N <= margin)) continue;
      DetectedContact c;
      c.geometry = g;
      const auto side = [&](const Side& s, collision::BodyIndex& body, std::int32_t& row,
                            MaterialId& material) {
        body = s.is_body && system.dynamic(s.index) ? static_cast<collision::BodyIndex>(s.index)
                                                    : collision::kStatic;
        row = s.is_body ? static_cast<std::int32_t>(s.index) : -1;
        material = s.is_body ? materials[s.index] : objects[s.index].material;
      };
      side(x, c.body_a, c.row_a, c.material_a);
      side(y, c.body_b, c.row_b, c.material_b);
      contacts.push_back(c);
      const std::uint32_t ix = image_of(x), iy = image_of(y);
      keys.push_back(
          {id_of(x), id_of(y), g.feature_a, g.feature_b, ix == iy ? 0u : relative_image(ix, iy)});
    }
  };

  // Spheres against spheres: the cell grid of chapter 4.
  centres_.clear();
  radii_.clear();
  sphere_bodies_.clear();
  others_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (const auto* sphere = std::get_if<collision::Sphere>(&shapes[i])) {
      centres_.push_back(placements_[i].I_r);
      radii_.push_back(sphere->radius);
      sphere_bodies_.push_back(static_cast<std::int32_t>(i));
    } else {
      others_.push_back(i);
    }
  }
  if (sphere_bodies_.size() >= 2) {
    if (!list_is_valid(system, margin)) {
      // The grid's test is strict, |c_i − c_j| < r_i + r_j + margin; a margin wider by 10⁻⁹ r_max
      // lets touching spheres (g_N = 0 exactly: a column at rest, a cradle) reach the narrow
      // phase, which keeps g_N ≤ margin. The skin widens it for the steps the list is kept.
      const double r_max = *std::max_element(radii_.begin(), radii_.end());
      grid_.build(centres_, radii_, margin + 1e-9 * r_max + skin_);
      grid_.find_pairs(pairs_);
      candidates_.clear();
      for (const auto& [i, j] : pairs_) {
        const auto a = static_cast<std::size_t>(sphere_bodies_[static_cast<std::size_t>(i)]);
        const auto b = static_cast<std::size_t>(sphere_bodies_[static_cast<std::size_t>(j)]);
        if (!system.dynamic(a) && !system.dynamic(b)) continue;
        if (!system.owned(a) && !system.owned(b)) continue;  // two ghosts: another process's pair
        candidates_.emplace_back(a, b);
      }
      built_centres_.assign(centres_.begin(), centres_.end());
      built_layout_ = system.layout_version();
      built_margin_ = margin;
      ++list_builds_;
    }
    for (const auto& [a, b] : candidates_) pair({true, a}, {true, b});
  }
  // Boxes and capsules against every other body whose bounding sphere they touch; a pair of two
  // non-spheres is visited from the smaller index only.
  const auto radii = system.bounding_radii();
  for (const std::size_t i : others_) {
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i || (j < i && !std::holds_alternative<collision::Sphere>(shapes[j]))) continue;
      if (!system.dynamic(i) && !system.dynamic(j)) continue;
      if (!system.owned(i) && !system.owned(j)) continue;
      const double reach = radii[i] + radii[j] + margin;
      if ((placements_[i].I_r - placements_[j].I_r).squaredNorm() <= reach * reach) {
        pair({true, i}, {true, j});
      }
    }
  }
  // Every dynamic body against every static object; bounded objects only when the bounding
  // spheres touch (a mesh has its own hierarchy, a half-space is unbounded).
  for (std::size_t s = 0; s < objects.size(); ++s) {
    const collision::ShapeKind kind = collision::kind(objects[s].shape);
    const bool bounded =
        kind != collision::ShapeKind::half_space && kind != collision::ShapeKind::mesh;
    const double r_s = bounded ? collision::bounding_radius(objects[s].shape) : 0.0;
    const auto* half_space = std::get_if<collision::HalfSpace>(&objects[s].shape);
    for (std::size_t i = 0; i < n; ++i) {
      if (!system.dynamic(i) || !system.owned(i)) continue;
      // A half-space (frame I) is skipped by the height of the bounding sphere above it: most
      // bodies of a pile are far from most walls, and the test costs one dot product.
      if (half_space != nullptr &&
          half_space->I_n.dot(placements_[i].I_r) - half_space->offset - radii[i] > margin) {
        continue;
      }
      if (bounded) {
        const double reach = radii[i] + r_s + margin;
        if ((placements_[i].I_r - objects[s].pose.I_r).squaredNorm() > reach * reach) continue;
      }
      pair({true, i}, {false, s});
    }
  }

  // The canonical order: along the Morton curve of the contact points (the midpoint of the two
  // closest points), on the finest grid of their bounding box, 2²¹ cells along its longest axis,
  // ties broken by key.
  const std::size_t m = contacts.size();
  midpoints_.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    midpoints_[k] = 0.5 * (contacts[k].geometry.I_r_a + contacts[k].geometry.I_r_b);
  }
  codes_.resize(m);
  collision::morton_codes(midpoints_, std::numeric_limits<double>::min(), codes_);
  order_.resize(m);
  for (std::size_t k = 0; k < m; ++k) order_[k] = {codes_[k], static_cast<std::uint32_t>(k)};
  sort_by_code(order_, scratch_, counts_);
  // Equal codes (two contacts of one pair, or points closer than a cell): by key.
  for (std::size_t lo = 0; lo < m;) {
    std::size_t hi = lo + 1;
    while (hi < m && order_[hi].first == order_[lo].first) ++hi;
    if (hi - lo > 1) {
      std::sort(order_.begin() + static_cast<std::ptrdiff_t>(lo),
                order_.begin() + static_cast<std::ptrdiff_t>(hi),
                [&](const auto& x, const auto& y) { return keys[x.second] < keys[y.second]; });
    }
    lo = hi;
  }
  // Contact k of the canonical order is found contact order_[k]: moved in place along the
  // cycles of the permutation.
  permutation_.resize(m);
  for (std::size_t k = 0; k < m; ++k) permutation_[k] = order_[k].second;
  permute_in_place(permutation_, contacts, keys);
}
// [detect system]

void ContactDetector::set_skin(double skin) {
  if (!(skin >= 0.0) || !std::isfinite(skin)) {
    throw InvalidArgument("ContactDetector::set_skin: expected a finite skin >= 0 [m], found " +
                          format_number(skin));
  }
  skin_ = skin;
  built_layout_ = ~std::uint64_t{0};  // the next detect() builds the list
}

// [skin list]
// The list holds every pair that was within margin + skin when it was built. A pair outside it
// was then at least r_i + r_j + margin + skin apart; while no sphere has moved more than skin/2,
// it is still at least r_i + r_j + margin apart and cannot be a contact.
bool ContactDetector::list_is_valid(const BodySystem& system, double margin) const {
  if (skin_ == 0.0 || system.layout_version() != built_layout_ || margin > built_margin_ ||
      built_centres_.size() != centres_.size()) {
    return false;
  }
  const double limit = rebuild_distance_squared(skin_);
  for (std::size_t k = 0; k < centres_.size(); ++k) {
    if ((centres_[k] - built_centres_[k]).squaredNorm() > limit) return false;
  }
  return true;
}
// [skin list]

void WarmStartTable::clear() {
  keys_.clear();
  lambda_.clear();
  std::fill(slots_.begin(), slots_.end(), 0U);
}

std::size_t WarmStartTable::find(const ContactKey& key) const {
  if (slots_.empty()) return keys_.size();
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t slot = hash(key) & mask;; slot = (slot + 1) & mask) {
    const std::uint32_t entry = slots_[slot];
    if (entry == 0) return keys_.size();
    if (keys_[entry - 1] == key) return entry - 1;
  }
}

void WarmStartTable::store(std::span<const ContactKey> keys, std::span<const Vector3> lambda) {
  if (keys.size() != lambda.size()) {
    throw InvalidArgument("WarmStartTable::store: expected one percussion per key, found " +
                          std::to_string(lambda.size()) + " percussions for " +
                          std::to_string(keys.size()) + " keys");
  }
  keys_.assign(keys.begin(), keys.end());
  lambda_.assign(lambda.begin(), lambda.end());
  const std::size_t wanted = std::bit_ceil(std::max<std::size_t>(16, 2 * keys_.size()));
  if (slots_.size() < wanted) slots_.resize(wanted);
  std::fill(slots_.begin(), slots_.end(), 0U);
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t k = 0; k < keys_.size(); ++k) {
    std::size_t slot = hash(keys_[k]) & mask;
    while (slots_[slot] != 0 && !(keys_[slots_[slot] - 1] == keys_[k])) slot = (slot + 1) & mask;
    slots_[slot] = static_cast<std::uint32_t>(k + 1);  // a repeated key: the last one wins
  }
}

std::size_t WarmStartTable::initialize(std::span<const ContactKey> keys,
                                       std::span<Vector3> lambda) const {
  if (keys.size() != lambda.size()) {
    throw InvalidArgument("WarmStartTable::initialize: expected one percussion per key, found " +
                          std::to_string(lambda.size()) + " percussions for " +
                          std::to_string(keys.size()) + " keys");
  }
  std::size_t found = 0;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const std::size_t i = find(keys[k]);
    if (i < keys_.size()) {
      lambda[k] = lambda_[i];
      ++found;
    } else {
      lambda[k].setZero();
    }
  }
  return found;
}

}  // namespace grbd::timestep
