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

}  // namespace

std::uint64_t hash(const ContactKey& key) {
  std::uint64_t h = mix64(key.a);
  h = mix64(h ^ key.b);
  h = mix64(h ^ key.feature_a);
  return mix64(h ^ key.feature_b);
}

// [detect system]
void ContactDetector::detect(const BodySystem& system, const StaticGeometry& statics,
                             double margin, std::vector<collision::Contact>& contacts,
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
    placements_[i] = {kinematics::position(q),
                      kinematics::rotation_matrix(kinematics::orientation(q))};
  }
  unsorted_.clear();
  unsorted_keys_.clear();

  const auto shape_of = [&](const Side& s) -> const collision::Shape& {
    return s.is_body ? shapes[s.index] : objects[s.index].shape;
  };
  const auto placement_of = [&](const Side& s) -> const collision::Placement& {
    return s.is_body ? placements_[s.index] : objects[s.index].pose;
  };
  const auto id_of = [&](const Side& s) {
    return s.is_body ? ids[s.index] : (kStaticTag | objects[s.index].id);
  };
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
      collision::Contact c;
      c.geometry = g;
      const Eigen::Matrix<double, 3, 2> T = collision::tangent_basis(g.I_n);
      c.I_t1 = T.col(0);
      c.I_t2 = T.col(1);
      const auto side = [&](const Side& s, const Vector3& I_r, collision::BodyIndex& body,
                            std::int32_t& collider, Vector3& K_rho) {
        if (!s.is_body) {
          body = collision::kStatic;
          collider = static_cast<std::int32_t>(s.index);
          return;
        }
        collider = -1;
        if (!system.dynamic(s.index)) {
          body = collision::kStatic;
          return;
        }
        body = static_cast<collision::BodyIndex>(s.index);
        const collision::Placement& p = placements_[s.index];
        K_rho = p.A_IC.transpose() * (I_r - p.I_r);
      };
      side(x, g.I_r_a, c.body_a, c.collider_a, c.K_rho_a);
      side(y, g.I_r_b, c.body_b, c.collider_b, c.K_rho_b);
      unsorted_.push_back(c);
      unsorted_keys_.push_back({id_of(x), id_of(y), g.feature_a, g.feature_b});
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
    // The grid's test is strict, |c_i − c_j| < r_i + r_j + margin; a margin wider by 10⁻⁹ r_max
    // lets touching spheres (g_N = 0 exactly: a column at rest, a cradle) reach the narrow phase,
    // which keeps g_N ≤ margin.
    const double r_max = *std::max_element(radii_.begin(), radii_.end());
    grid_.build(centres_, radii_, margin + 1e-9 * r_max);
    grid_.find_pairs(pairs_);
    for (const auto& [i, j] : pairs_) {
      const auto a = static_cast<std::size_t>(sphere_bodies_[static_cast<std::size_t>(i)]);
      const auto b = static_cast<std::size_t>(sphere_bodies_[static_cast<std::size_t>(j)]);
      if (!system.dynamic(a) && !system.dynamic(b)) continue;
      pair({true, a}, {true, b});
    }
  }
  // Boxes and capsules against every other body whose bounding sphere they touch; a pair of two
  // non-spheres is visited from the smaller index only.
  const auto radii = system.bounding_radii();
  for (const std::size_t i : others_) {
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i || (j < i && !std::holds_alternative<collision::Sphere>(shapes[j]))) continue;
      if (!system.dynamic(i) && !system.dynamic(j)) continue;
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
    const bool bounded = kind != collision::ShapeKind::half_space &&
                         kind != collision::ShapeKind::mesh;
    const double r_s = bounded ? collision::bounding_radius(objects[s].shape) : 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!system.dynamic(i)) continue;
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
  const std::size_t m = unsorted_.size();
  midpoints_.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    midpoints_[k] = 0.5 * (unsorted_[k].geometry.I_r_a + unsorted_[k].geometry.I_r_b);
  }
  codes_.resize(m);
  collision::morton_codes(midpoints_, std::numeric_limits<double>::min(), codes_);
  order_.resize(m);
  for (std::size_t k = 0; k < m; ++k) order_[k] = {codes_[k], static_cast<std::uint32_t>(k)};
  std::sort(order_.begin(), order_.end(), [&](const auto& x, const auto& y) {
    if (x.first != y.first) return x.first < y.first;
    return unsorted_keys_[x.second] < unsorted_keys_[y.second];
  });
  contacts.resize(m);
  keys.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    contacts[k] = unsorted_[order_[k].second];
    keys[k] = unsorted_keys_[order_[k].second];
  }
}
// [detect system]

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
