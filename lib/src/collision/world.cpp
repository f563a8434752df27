/// \file
/// \brief The collision world: validation of colliders and supported pairs, and contact
/// detection.

#include "grbd/collision/world.hpp"

#include <cmath>
#include <string>

#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::collision {

namespace {

constexpr std::string_view kSupportedPairs =
    "sphere–sphere, sphere–half-space, sphere–box, sphere–capsule, sphere–mesh, "
    "box–half-space, capsule–half-space";

std::string describe(std::int32_t index, const Collider& collider) {
  std::string text = "collider " + std::to_string(index) + " (" +
                     std::string(kind_name(kind(collider.shape))) + ", ";
  text +=
      collider.body == kStatic ? std::string("static") : "body " + std::to_string(collider.body);
  return text + ")";
}

bool same_body(const Collider& a, const Collider& b) {
  return a.body != kStatic && a.body == b.body;
}

}  // namespace

bool supported(ShapeKind a, ShapeKind b) {
  if (a > b) std::swap(a, b);  // ShapeKind order: sphere, box, capsule, half_space, mesh
  if (a == ShapeKind::sphere) return true;
  return b == ShapeKind::half_space && (a == ShapeKind::box || a == ShapeKind::capsule);
}

void CollisionWorld::clear() {
  colliders_.clear();
  representatives_.fill(Representatives{});
}

void CollisionWorld::reserve(std::size_t colliders) { colliders_.reserve(colliders); }

std::int32_t CollisionWorld::add(Collider collider) {
  const auto index = static_cast<std::int32_t>(colliders_.size());
  const std::string where = "CollisionWorld::add (collider " + std::to_string(index) + ")";
  if (collider.body < kStatic) {
    throw InvalidArgument(where + ": expected a body index ≥ 0 or kStatic, found " +
                          std::to_string(collider.body));
  }
  if (!collider.K_r_KC.allFinite() || !kinematics::is_rotation_matrix(collider.A_KC, 1e-9)) {
    throw InvalidArgument(where + ": expected a finite K_r_KC and a rotation matrix A_KC");
  }
  const ShapeKind shape_kind = kind(collider.shape);
  normalize_and_check(collider.shape, where);
  if ((shape_kind == ShapeKind::half_space || shape_kind == ShapeKind::mesh) &&
      collider.body != kStatic) {
    throw InvalidArgument(where + ": a " + std::string(kind_name(shape_kind)) +
                          " is static only, found it attached to body " +
                          std::to_string(collider.body));
  }
  // The pair check in O(1): the first collider that cannot meet this one is, for each kind,
  // the first static collider of that kind or the first moving one on another body, and
  // representatives_ keeps exactly those (the first moving collider of a kind, and the first
  // one on a different body from it). A scene of 10⁶ spheres is assembled in O(N).
  const bool is_static = collider.body == kStatic;
  std::int32_t conflict = -1;
  const auto consider = [&](std::int32_t j) {
    if (j >= 0 && (conflict < 0 || j < conflict)) conflict = j;
  };
  for (int k = 0; k < kShapeKinds; ++k) {
    if (supported(shape_kind, static_cast<ShapeKind>(k))) continue;
    const Representatives& r = representatives_[static_cast<std::size_t>(k)];
    if (!is_static) consider(r.first_static);  // two static colliders never touch
    if (r.first_moving < 0) continue;
    if (is_static || colliders_[static_cast<std::size_t>(r.first_moving)].body != collider.body) {
      consider(r.first_moving);
    } else {
      consider(r.first_moving_other_body);  // parts of one body never touch
    }
  }
  if (conflict >= 0) {
    const Collider& other = colliders_[static_cast<std::size_t>(conflict)];
    const ShapeKind other_kind = kind(other.shape);
    throw InvalidArgument("CollisionWorld::add: " + describe(index, collider) + " cannot meet " +
                          describe(conflict, other) + ": the pair " +
                          std::string(kind_name(shape_kind)) + "–" +
                          std::string(kind_name(other_kind)) +
                          " is not supported; supported pairs: " + std::string(kSupportedPairs));
  }
  Representatives& mine = representatives_[static_cast<std::size_t>(shape_kind)];
  if (is_static) {
    if (mine.first_static < 0) mine.first_static = index;
  } else if (mine.first_moving < 0) {
    mine.first_moving = index;
  } else if (mine.first_moving_other_body < 0 &&
             colliders_[static_cast<std::size_t>(mine.first_moving)].body != collider.body) {
    mine.first_moving_other_body = index;
  }
  colliders_.push_back(std::move(collider));
  return index;
}

// [detect]
void CollisionWorld::detect(std::span<const body::State> states, double margin,
                            std::vector<Contact>& contacts) {
  contacts.clear();
  if (!(margin >= 0.0 && std::isfinite(margin))) {
    throw InvalidArgument("CollisionWorld::detect: expected a finite margin ≥ 0, found " +
                          format_number(margin));
  }
  const std::size_t n = colliders_.size();
  // World placement of every collider: I_r = I_r_S + A_IK K_r_KC, A_IC = A_IK A_KC. The buffers
  // are members: after the first call, detection allocates nothing but the contacts that grow.
  placements_.resize(n);
  A_IK_.resize(n);
  std::vector<Placement>& placements = placements_;
  std::vector<Matrix3>& A_IK = A_IK_;
  for (std::size_t i = 0; i < n; ++i) {
    const Collider& collider = colliders_[i];
    if (collider.body == kStatic) {
      placements[i] = {collider.K_r_KC, collider.A_KC};
      A_IK[i].setIdentity();
      continue;
    }
    if (static_cast<std::size_t>(collider.body) >= states.size()) {
      throw InvalidArgument(
          "CollisionWorld::detect: " + describe(static_cast<std::int32_t>(i), collider) +
          " needs body " + std::to_string(collider.body) + ", found " +
          std::to_string(states.size()) + " body states");
    }
    const auto b = static_cast<std::size_t>(collider.body);
    // Finite, with a unit quaternion: a quaternion of norm 2 would place the collider and scale
    // the lever arms wrongly without any sign of it.
    body::require_valid(states[b], "CollisionWorld::detect", b);
    const Vector7& q = states[b].q;
    A_IK[i] = kinematics::rotation_matrix(kinematics::orientation(q));
    placements[i] = {kinematics::position(q) + A_IK[i] * collider.K_r_KC, A_IK[i] * collider.A_KC};
  }

  // Adds the contact of shapes a and b with the frame and the lever arms of both bodies.
  const auto emit = [&](std::size_t a, std::size_t b, const ContactGeometry& geometry) {
    Contact contact;
    contact.collider_a = static_cast<std::int32_t>(a);
    contact.collider_b = static_cast<std::int32_t>(b);
    contact.body_a = colliders_[a].body;
    contact.body_b = colliders_[b].body;
    contact.geometry = geometry;
    const Eigen::Matrix<double, 3, 2> T = tangent_basis(geometry.I_n);
    contact.I_t1 = T.col(0);
    contact.I_t2 = T.col(1);
    if (contact.body_a != kStatic) {
      const Vector3 I_r_S =
          kinematics::position(states[static_cast<std::size_t>(contact.body_a)].q);
      contact.K_rho_a = A_IK[a].transpose() * (geometry.I_r_a - I_r_S);
    }
    if (contact.body_b != kStatic) {
      const Vector3 I_r_S =
          kinematics::position(states[static_cast<std::size_t>(contact.body_b)].q);
      contact.K_rho_b = A_IK[b].transpose() * (geometry.I_r_b - I_r_S);
    }
    contacts.push_back(contact);
  };

  // The narrow phase of one pair, in the argument order of the kernels (the sphere first, the
  // half-space last).
  std::vector<ContactGeometry>& found = found_;
  const auto narrow = [&](std::size_t i, std::size_t j) {
    if (kind(colliders_[j].shape) < kind(colliders_[i].shape)) std::swap(i, j);
    const Shape& si = colliders_[i].shape;
    const Shape& sj = colliders_[j].shape;
    const Placement& pi = placements[i];
    const Placement& pj = placements[j];
    found.clear();
    collide(si, pi, sj, pj, margin, found);
    for (const ContactGeometry& geometry : found) {
      if (geometry.g_N <= margin) emit(i, j, geometry);
    }
  };

  // Moving spheres against each other: the cell grid.
  centres_.clear();
  radii_.clear();
  sphere_colliders_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const Collider& collider = colliders_[i];
    if (collider.body == kStatic || kind(collider.shape) != ShapeKind::sphere) continue;
    centres_.push_back(placements[i].I_r);
    radii_.push_back(std::get<Sphere>(collider.shape).radius);
    sphere_colliders_.push_back(static_cast<std::int32_t>(i));
  }
  if (sphere_colliders_.size() >= 2) {
    grid_.build(centres_, radii_, margin);
    grid_.find_pairs(pairs_);
    for (const auto& [i, j] : pairs_) {
      const auto a = static_cast<std::size_t>(sphere_colliders_[static_cast<std::size_t>(i)]);
      const auto b = static_cast<std::size_t>(sphere_colliders_[static_cast<std::size_t>(j)]);
      if (same_body(colliders_[a], colliders_[b])) continue;
      narrow(std::min(a, b), std::max(a, b));
    }
  }

  // Every moving collider against every static one, and the moving non-spheres against the
  // other moving colliders (once per pair, when their bounding spheres overlap): with index lists
  // this costs O(moving × (static + non-sphere)), so a scene of N spheres stays O(N).
  statics_.clear();
  moving_.clear();
  moving_non_spheres_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const Collider& collider = colliders_[i];
    if (collider.body == kStatic) {
      statics_.push_back(i);
    } else {
      moving_.push_back(i);
      if (kind(collider.shape) != ShapeKind::sphere) moving_non_spheres_.push_back(i);
    }
  }
  for (const std::size_t i : moving_) {
    for (const std::size_t j : statics_) narrow(i, j);
  }
  for (const std::size_t i : moving_non_spheres_) {
    const Collider& moving = colliders_[i];
    for (const std::size_t j : moving_) {
      const Collider& other = colliders_[j];
      // A pair of two non-spheres is visited from its smaller index only.
      if (j == i || (kind(other.shape) != ShapeKind::sphere && j < i)) continue;
      if (same_body(moving, other)) continue;
      const double reach = bounding_radius(moving.shape) + bounding_radius(other.shape) + margin;
      if ((placements[i].I_r - placements[j].I_r).squaredNorm() <= reach * reach) {
        narrow(std::min(i, j), std::max(i, j));
      }
    }
  }
}
// [detect]

}  // namespace grbd::collision
