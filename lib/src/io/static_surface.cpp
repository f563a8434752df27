// The static geometry of a scene as one triangle surface (chapter 7's output, for ParaView).

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd/io/output.hpp"

namespace grbd::io {

namespace {

// Segments around a sphere's or capsule's axis; a sphere is an icosphere of this many subdivisions.
constexpr int kAround = 24;
constexpr int kRings = 6;  // per hemisphere of a capsule
constexpr int kSubdivisions = 2;


// The capsule of `radius` about the segment ±half_length e_z: a ring of kAround vertices per
// latitude, kRings latitudes per hemisphere and the two poles; outward faces.
body::TriangleMesh capsule_mesh(double radius, double half_length) {
  const int rings = 2 * kRings;  // latitudes strictly between the poles, the two equators included
  body::TriangleMesh m;
  m.V.resize(rings * kAround + 2, 3);
  int v = 0;
  for (int i = 0; i < rings; ++i) {
    // Polar angle from the top pole; the top hemisphere has rings 0 … kRings-1 (its equator last).
    const bool top = i < kRings;
    const double theta = std::numbers::pi / 2 * (top ? (i + 1.0) / kRings : (i - kRings) * 1.0 / kRings + 1.0);
    const double z = radius * std::cos(theta) + (top ? half_length : -half_length);
    const double rho = radius * std::sin(theta);
    for (int j = 0; j < kAround; ++j, ++v) {
      const double phi = 2 * std::numbers::pi * j / kAround;
      m.V.row(v) << rho * std::cos(phi), rho * std::sin(phi), z;
    }
  }
  const int north = v, south = v + 1;
  m.V.row(north) << 0.0, 0.0, radius + half_length;
  m.V.row(south) << 0.0, 0.0, -radius - half_length;
  m.F.resize(2 * kAround * rings, 3);
  int f = 0;
  auto at = [](int ring, int j) { return ring * kAround + (j % kAround); };
  for (int j = 0; j < kAround; ++j) {
    m.F.row(f++) << north, at(0, j), at(0, j + 1);
    m.F.row(f++) << south, at(rings - 1, j + 1), at(rings - 1, j);
  }
  for (int i = 0; i + 1 < rings; ++i) {
    for (int j = 0; j < kAround; ++j) {
      m.F.row(f++) << at(i, j), at(i + 1, j), at(i + 1, j + 1);
      m.F.row(f++) << at(i, j), at(i + 1, j + 1), at(i, j + 1);
    }
  }
  m.F.conservativeResize(f, 3);
  return m;
}

// The polygon in which the plane nᵀx = offset cuts the box: its corners in counter-clockwise order
// seen from the side n points to (none when the plane misses the box or only touches it).
std::vector<Vector3> plane_in_box(const Vector3& n, double offset, const Eigen::AlignedBox3d& box) {
  std::vector<Vector3> corners;
  for (int c = 0; c < 8; ++c) {
    corners.emplace_back(c & 1 ? box.max().x() : box.min().x(), c & 2 ? box.max().y() : box.min().y(),
                         c & 4 ? box.max().z() : box.min().z());
  }
  std::vector<Vector3> points;
  for (int a = 0; a < 8; ++a) {
    for (int axis = 0; axis < 3; ++axis) {
      const int b = a | (1 << axis);
      if (b == a) continue;  // each edge once, from its lower corner
      const double da = n.dot(corners[a]) - offset, db = n.dot(corners[b]) - offset;
      if ((da < 0) == (db < 0) && da != 0 && db != 0) continue;
      if (da == db) continue;  // the edge lies in the plane: its corners come from other edges
      points.push_back(corners[a] + da / (da - db) * (corners[b] - corners[a]));
    }
  }
  if (points.size() < 3) return {};
  Vector3 centre = Vector3::Zero();
  for (const Vector3& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  // Angles about the centre in the plane's own basis (u, w, n), then duplicates (a plane through a
  // corner meets three of its edges there) removed.
  const Vector3 u = n.unitOrthogonal(), w = n.cross(u);
  std::sort(points.begin(), points.end(), [&](const Vector3& p, const Vector3& q) {
    return std::atan2(w.dot(p - centre), u.dot(p - centre)) <
           std::atan2(w.dot(q - centre), u.dot(q - centre));
  });
  const double tiny = 1e-12 * box.diagonal().norm();
  std::vector<Vector3> polygon;
  for (const Vector3& p : points)
    if (polygon.empty() || (p - polygon.back()).norm() > tiny) polygon.push_back(p);
  while (polygon.size() > 1 && (polygon.front() - polygon.back()).norm() <= tiny) polygon.pop_back();
  if (polygon.size() < 3) return {};
  return polygon;
}

// The part of a convex polygon on the free side of the half-space nᵀx ≤ offset (Sutherland and
// Hodgman's clipping against one plane).
std::vector<Vector3> outside_of(const std::vector<Vector3>& polygon, const Vector3& n,
                                double offset) {
  std::vector<Vector3> kept;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Vector3& a = polygon[i];
    const Vector3& b = polygon[(i + 1) % polygon.size()];
    const double da = n.dot(a) - offset, db = n.dot(b) - offset;
    if (da >= 0) kept.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) kept.push_back(a + da / (da - db) * (b - a));
  }
  return kept.size() >= 3 ? kept : std::vector<Vector3>{};
}

}  // namespace

StaticSurface static_surface(const scene::Scene& scene) {
  StaticSurface surface;
  // Where the bodies can be: the outlet's box, else every region and position of the body groups
  // and the finite static objects, with a margin.
  Eigen::AlignedBox3d bounds;  // empty
  double largest_body = 0.0;
  for (const scene::BodyGroup& group : scene.groups) {
    const scene::GeneratorSpec& g = group.generator;
    if (g.kind == scene::GeneratorKind::list) {
      for (const Vector3& p : g.positions) bounds.extend(p);
    } else {
      bounds.extend(g.region.min).extend(g.region.max);
    }
    const double size = group.shape == collision::ShapeKind::box
                            ? group.half_extents.norm()
                            : group.radius.max() + (group.shape == collision::ShapeKind::capsule
                                                        ? group.half_length
                                                        : 0.0);
    largest_body = std::max(largest_body, size);
  }
  auto add_finite = [&](const Vector3& lo, const Vector3& hi) { bounds.extend(lo).extend(hi); };
  for (const scene::StaticSpec& s : scene.statics) {
    const collision::Placement& pose = s.pose;
    if (const auto* sphere = std::get_if<collision::Sphere>(&s.shape)) {
      add_finite(pose.I_r.array() - sphere->radius, pose.I_r.array() + sphere->radius);
    } else if (const auto* box = std::get_if<collision::Box>(&s.shape)) {
      const Vector3 reach = pose.A_IC.cwiseAbs() * box->half_extents;
      add_finite(pose.I_r - reach, pose.I_r + reach);
    } else if (const auto* capsule = std::get_if<collision::Capsule>(&s.shape)) {
      const Vector3 axis = capsule->half_length * pose.A_IC.col(2);
      add_finite(pose.I_r - axis.cwiseAbs() - Vector3::Constant(capsule->radius),
                 pose.I_r + axis.cwiseAbs() + Vector3::Constant(capsule->radius));
    } else if (const auto* mesh = std::get_if<std::shared_ptr<const collision::StaticMesh>>(&s.shape)) {
      const body::Vertices& V = (*mesh)->mesh().V;
      if (V.rows() > 0) add_finite(V.colwise().minCoeff().transpose(), V.colwise().maxCoeff().transpose());
    }
  }
  if (scene.domain.enabled) {
    bounds = Eigen::AlignedBox3d(scene.domain.box.min, scene.domain.box.max);
  } else if (!bounds.isEmpty()) {
    const double margin = std::max(0.05 * bounds.sizes().maxCoeff(), 2.0 * largest_body);
    bounds.min().array() -= margin;
    bounds.max().array() += margin;
  }
  if (bounds.isEmpty() || !(bounds.sizes().array() > 0).all()) {
    // Nothing to size the planes by (or a flat box): a cube of 1 m about what there is.
    const Vector3 centre = bounds.isEmpty() ? Vector3::Zero() : Vector3(bounds.center());
    bounds = Eigen::AlignedBox3d(Vector3(centre.array() - 0.5), Vector3(centre.array() + 0.5));
  }
  surface.bounds = {bounds.min(), bounds.max()};

  auto append = [&](const body::TriangleMesh& m, const Matrix3& A, const Vector3& r,
                    std::uint32_t object) {
    const std::uint64_t first = surface.points.size();
    for (Eigen::Index i = 0; i < m.V.rows(); ++i)
      surface.points.push_back(r + A * m.V.row(i).transpose());
    for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
      surface.triangles.push_back({first + static_cast<std::uint64_t>(m.F(f, 0)),
                                   first + static_cast<std::uint64_t>(m.F(f, 1)),
                                   first + static_cast<std::uint64_t>(m.F(f, 2))});
      surface.object.push_back(object);
    }
  };
  for (std::size_t k = 0; k < scene.statics.size(); ++k) {
    const scene::StaticSpec& s = scene.statics[k];
    const auto object = static_cast<std::uint32_t>(k);
    const collision::Placement& pose = s.pose;
    if (const auto* sphere = std::get_if<collision::Sphere>(&s.shape)) {
      append(body::icosphere_mesh(sphere->radius, kSubdivisions), pose.A_IC, pose.I_r, object);
    } else if (const auto* box = std::get_if<collision::Box>(&s.shape)) {
      append(body::box_mesh(box->half_extents), pose.A_IC, pose.I_r, object);
    } else if (const auto* capsule = std::get_if<collision::Capsule>(&s.shape)) {
      append(capsule_mesh(capsule->radius, capsule->half_length), pose.A_IC, pose.I_r, object);
    } else if (const auto* mesh = std::get_if<std::shared_ptr<const collision::StaticMesh>>(&s.shape)) {
      append((*mesh)->mesh(), Matrix3::Identity(), Vector3::Zero(), object);
    } else if (const auto* plane = std::get_if<collision::HalfSpace>(&s.shape)) {
      // The free space is the intersection of the half-spaces' outsides: each plane is drawn
      // where it bounds it (a silo's floor between its walls, the walls above the floor).
      std::vector<Vector3> polygon = plane_in_box(plane->I_n, plane->offset, bounds);
      for (const scene::StaticSpec& other : scene.statics) {
        const auto* cut = std::get_if<collision::HalfSpace>(&other.shape);
        if (cut != nullptr && cut != plane) polygon = outside_of(polygon, cut->I_n, cut->offset);
      }
      const std::uint64_t first = surface.points.size();
      for (const Vector3& p : polygon) surface.points.push_back(p);
      for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
        surface.triangles.push_back({first, first + i, first + i + 1});
        surface.object.push_back(object);
      }
    }
  }
  return surface;
}

}  // namespace grbd::io
