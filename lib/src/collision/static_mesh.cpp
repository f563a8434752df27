/// \file
/// \brief The bounding-volume hierarchy of a static mesh, and the sphere–mesh contacts.

#include "grbd/collision/static_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <Eigen/Geometry>

#include "grbd/collision/narrow_phase.hpp"

namespace grbd::collision {

namespace {

constexpr std::int32_t kLeafSize = 4;  // at most this many triangles per leaf
constexpr double kRegionTolerance = 1e-9;

Vector3 vertex(const body::TriangleMesh& mesh, std::int32_t v) { return mesh.V.row(v).transpose(); }

std::string face_text(const body::TriangleMesh& mesh, Eigen::Index f) {
  return "face " + std::to_string(f) + " (" + std::to_string(mesh.F(f, 0)) + ", " +
         std::to_string(mesh.F(f, 1)) + ", " + std::to_string(mesh.F(f, 2)) + ")";
}

}  // namespace

StaticMesh::StaticMesh(body::TriangleMesh mesh) : mesh_(std::move(mesh)) {
  const Eigen::Index V = mesh_.V.rows();
  const Eigen::Index F = mesh_.F.rows();
  if (V == 0 || F == 0) {
    throw body::MeshError("StaticMesh: expected a mesh with vertices and faces, found " +
                          std::to_string(V) + " vertices and " + std::to_string(F) + " faces");
  }
  if (!mesh_.V.allFinite()) throw body::MeshError("StaticMesh: a vertex is not finite");
  for (Eigen::Index f = 0; f < F; ++f) {
    for (int k = 0; k < 3; ++k) {
      if (mesh_.F(f, k) < 0 || mesh_.F(f, k) >= V) {
        throw body::MeshError("StaticMesh: " + face_text(mesh_, f) + " has an index outside [0, " +
                              std::to_string(V) + ")");
      }
    }
    const Vector3 a = vertex(mesh_, mesh_.F(f, 0));
    const Vector3 b = vertex(mesh_, mesh_.F(f, 1));
    const Vector3 c = vertex(mesh_, mesh_.F(f, 2));
    if ((b - a).cross(c - a).squaredNorm() == 0.0) {
      throw body::MeshError("StaticMesh: " + face_text(mesh_, f) + " is degenerate (zero area)");
    }
  }

  // Faces around each vertex, by a counting sort.
  vertex_face_start_.assign(static_cast<std::size_t>(V) + 1, 0);
  for (Eigen::Index f = 0; f < F; ++f) {
    for (int k = 0; k < 3; ++k) ++vertex_face_start_[static_cast<std::size_t>(mesh_.F(f, k)) + 1];
  }
  std::partial_sum(vertex_face_start_.begin(), vertex_face_start_.end(),
                   vertex_face_start_.begin());
  vertex_faces_.resize(static_cast<std::size_t>(3 * F));
  std::vector<std::int32_t> fill(vertex_face_start_.begin(), vertex_face_start_.end() - 1);
  for (Eigen::Index f = 0; f < F; ++f) {
    for (int k = 0; k < 3; ++k) {
      vertex_faces_[static_cast<std::size_t>(fill[static_cast<std::size_t>(mesh_.F(f, k))]++)] =
          static_cast<std::int32_t>(f);
    }
  }

  // The hierarchy: median split of the centroids along the longest axis of their bounds.
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(F));
  std::vector<Vector3> centroids(static_cast<std::size_t>(F));
  for (Eigen::Index f = 0; f < F; ++f) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) box.extend(vertex(mesh_, mesh_.F(f, k)));
    boxes[static_cast<std::size_t>(f)] = box;
    centroids[static_cast<std::size_t>(f)] = box.center();
  }
  order_.resize(static_cast<std::size_t>(F));
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(static_cast<std::size_t>(2 * F / kLeafSize + 2));
  nodes_.push_back({});
  struct Range {
    std::int32_t node, begin, end;
  };
  std::vector<Range> stack{{0, 0, static_cast<std::int32_t>(F)}};
  while (!stack.empty()) {
    const Range range = stack.back();
    stack.pop_back();
    Eigen::AlignedBox3d box;
    Eigen::AlignedBox3d centre_bounds;
    for (std::int32_t n = range.begin; n < range.end; ++n) {
      box.extend(boxes[static_cast<std::size_t>(order_[static_cast<std::size_t>(n)])]);
      centre_bounds.extend(
          centroids[static_cast<std::size_t>(order_[static_cast<std::size_t>(n)])]);
    }
    nodes_[static_cast<std::size_t>(range.node)].box = box;
    if (range.end - range.begin <= kLeafSize) {
      nodes_[static_cast<std::size_t>(range.node)].first = range.begin;
      nodes_[static_cast<std::size_t>(range.node)].count = range.end - range.begin;
      continue;
    }
    Eigen::Index axis = 0;
    centre_bounds.sizes().maxCoeff(&axis);
    const std::int32_t middle = range.begin + (range.end - range.begin) / 2;
    std::nth_element(order_.begin() + range.begin, order_.begin() + middle,
                     order_.begin() + range.end, [&](std::int32_t i, std::int32_t j) {
                       return centroids[static_cast<std::size_t>(i)][axis] <
                              centroids[static_cast<std::size_t>(j)][axis];
                     });
    const auto left = static_cast<std::int32_t>(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[static_cast<std::size_t>(range.node)].first = left;
    nodes_[static_cast<std::size_t>(range.node)].count = 0;
    stack.push_back({left, range.begin, middle});
    stack.push_back({left + 1, middle, range.end});
  }
}

// [bvh query]
void StaticMesh::query(const Vector3& c, double r, double margin,
                       std::vector<std::int32_t>& triangles) const {
  const Vector3 reach = Vector3::Constant(r + margin);
  const Eigen::AlignedBox3d probe(c - reach, c + reach);
  // Depth-first descent; the tree is balanced, so 64 levels are never reached.
  std::int32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
    if (!node.box.intersects(probe)) continue;
    if (node.count > 0) {
      // A leaf: test the bounding box of each of its triangles.
      for (std::int32_t n = node.first; n < node.first + node.count; ++n) {
        const std::int32_t f = order_[static_cast<std::size_t>(n)];
        Eigen::AlignedBox3d box(vertex(mesh_, mesh_.F(f, 0)));
        box.extend(vertex(mesh_, mesh_.F(f, 1)));
        box.extend(vertex(mesh_, mesh_.F(f, 2)));
        if (box.intersects(probe)) triangles.push_back(f);
      }
    } else {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
}
// [bvh query]

namespace {

// true when n lies in the region of the edge (i, j): it does not point over a face that shares
// the edge.
bool in_edge_region(const StaticMesh& mesh, std::int32_t i, std::int32_t j, const Vector3& n) {
  const body::TriangleMesh& m = mesh.mesh();
  const Vector3 x_i = vertex(m, i);
  const Vector3 e = (vertex(m, j) - x_i).normalized();
  for (const std::int32_t f : mesh.faces_of_vertex(i)) {
    if (m.F(f, 0) != j && m.F(f, 1) != j && m.F(f, 2) != j) continue;  // f does not hold the edge
    const auto other = static_cast<std::int32_t>(std::int64_t{m.F(f, 0)} + m.F(f, 1) + m.F(f, 2) -
                                                 i - j);  // the third vertex of f
    const Vector3 to_other = vertex(m, other) - x_i;
    const Vector3 inward = to_other - e.dot(to_other) * e;  // in the face's plane, into the face
    if (n.dot(inward) > kRegionTolerance * inward.norm()) return false;
  }
  return true;
}

// true when n makes a right or obtuse angle with every edge leaving vertex v.
bool in_vertex_region(const StaticMesh& mesh, std::int32_t v, const Vector3& n) {
  const body::TriangleMesh& m = mesh.mesh();
  const Vector3 x_v = vertex(m, v);
  for (const std::int32_t f : mesh.faces_of_vertex(v)) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t w = m.F(f, k);
      if (w == v) continue;
      const Vector3 edge = vertex(m, w) - x_v;
      if (n.dot(edge) > kRegionTolerance * edge.norm()) return false;
    }
  }
  return true;
}

}  // namespace

// [sphere mesh]
void sphere_mesh(const Vector3& c, double r, const StaticMesh& mesh, double margin,
                 std::vector<ContactGeometry>& out) {
  const body::TriangleMesh& m = mesh.mesh();
  thread_local std::vector<std::int32_t> candidates;
  candidates.clear();
  mesh.query(c, r, margin, candidates);
  const std::size_t first_new = out.size();
  for (const std::int32_t f : candidates) {
    const std::int32_t ids[3] = {m.F(f, 0), m.F(f, 1), m.F(f, 2)};
    const Vector3 a = vertex(m, ids[0]);
    const Vector3 b = vertex(m, ids[1]);
    const Vector3 cc = vertex(m, ids[2]);
    const TrianglePoint closest = closest_point_on_triangle(c, a, b, cc);
    const Vector3 d = c - closest.point;
    const double distance = d.norm();
    if (distance - r > margin) continue;

    // The global identity of the feature: an edge or vertex shared by several faces is the same
    // feature whichever face found it.
    std::uint64_t feature = 0;
    std::int32_t edge_i = -1;
    std::int32_t edge_j = -1;
    std::int32_t corner = -1;
    switch (closest.feature) {
      case TriangleFeature::face:
        feature = face_feature(static_cast<std::uint64_t>(f));
        break;
      case TriangleFeature::edge_ab:
        edge_i = ids[0], edge_j = ids[1];
        break;
      case TriangleFeature::edge_bc:
        edge_i = ids[1], edge_j = ids[2];
        break;
      case TriangleFeature::edge_ca:
        edge_i = ids[2], edge_j = ids[0];
        break;
      case TriangleFeature::vertex_a:
        corner = ids[0];
        break;
      case TriangleFeature::vertex_b:
        corner = ids[1];
        break;
      case TriangleFeature::vertex_c:
        corner = ids[2];
        break;
    }
    if (edge_i >= 0) {
      feature = edge_feature(
          mesh_edge_index(static_cast<std::uint64_t>(edge_i), static_cast<std::uint64_t>(edge_j)));
    } else if (corner >= 0) {
      feature = vertex_feature(static_cast<std::uint64_t>(corner));
    }
    const bool seen = std::any_of(out.begin() + static_cast<std::ptrdiff_t>(first_new), out.end(),
                                  [&](const ContactGeometry& g) { return g.feature_b == feature; });
    if (seen) continue;

    // A centre on the mesh has no direction to the feature: use the face normal.
    const Vector3 n =
        distance > 0.0 ? Vector3(d / distance) : Vector3((b - a).cross(cc - a).normalized());
    if (edge_i >= 0 && !in_edge_region(mesh, edge_i, edge_j, n)) continue;
    if (corner >= 0 && !in_vertex_region(mesh, corner, n)) continue;

    ContactGeometry contact;
    contact.I_n = n;
    contact.g_N = distance - r;
    contact.I_r_a = c - r * n;
    contact.I_r_b = closest.point;
    contact.feature_b = feature;
    out.push_back(contact);
  }
}
// [sphere mesh]

}  // namespace grbd::collision
