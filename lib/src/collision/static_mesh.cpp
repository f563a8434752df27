/// \file
/// \brief The bounding-volume hierarchy of a static mesh, and the sphere–mesh contacts.

#include "grbd/collision/static_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_set>

#include <Eigen/Geometry>

#include "grbd/collision/narrow_phase.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::collision {

namespace {

constexpr std::int32_t kLeafSize = 4;  // at most this many triangles per leaf
constexpr double kRegionTolerance = 1e-9;

Vector3 vertex(const body::TriangleMesh& mesh, std::int32_t v) { return mesh.V.row(v).transpose(); }

std::string corners_text(const body::TriangleMesh& mesh, Eigen::Index f) {
  std::string text = "(";
  for (int k = 0; k < 3; ++k) text.append(k == 0 ? "" : ", ").append(std::to_string(mesh.F(f, k)));
  return text + ")";
}

std::string face_text(const body::TriangleMesh& mesh, Eigen::Index f) {
  return "face " + std::to_string(f) + " " + corners_text(mesh, f);
}

/// Lexicographic order of vertex positions (x, then y, then z).
bool position_less(const body::TriangleMesh& mesh, std::int32_t i, std::int32_t j) {
  if (i == j) return false;
  for (int k = 0; k < 3; ++k) {
    if (mesh.V(i, k) != mesh.V(j, k)) return mesh.V(i, k) < mesh.V(j, k);
  }
  return false;
}

/// Throws MeshError for the first pair of faces that lie on the same three points (the pair whose
/// second face has the lowest index). O(F log F): each face's corners are sorted by position,
/// then the faces by their sorted corners, so that such faces become neighbours.
void refuse_coincident_faces(const body::TriangleMesh& mesh) {
  struct Corners {
    std::array<std::int32_t, 3> v;  // the face's vertex indices, sorted by position
    std::int32_t face;
  };
  const auto F = static_cast<std::int32_t>(mesh.F.rows());
  std::vector<Corners> faces(static_cast<std::size_t>(F));
  for (std::int32_t f = 0; f < F; ++f) {
    Corners& c = faces[static_cast<std::size_t>(f)];
    c = {{mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)}, f};
    std::sort(c.v.begin(), c.v.end(),
              [&](std::int32_t i, std::int32_t j) { return position_less(mesh, i, j); });
  }
  // -1 when a's corners lie before b's, 1 after, 0 on the same points.
  const auto compare = [&](const Corners& a, const Corners& b) {
    for (std::size_t k = 0; k < 3; ++k) {
      if (position_less(mesh, a.v[k], b.v[k])) return -1;
      if (position_less(mesh, b.v[k], a.v[k])) return 1;
    }
    return 0;
  };
  std::sort(faces.begin(), faces.end(), [&](const Corners& a, const Corners& b) {
    const int order = compare(a, b);
    return order != 0 ? order < 0 : a.face < b.face;
  });
  std::int32_t first = -1;
  std::int32_t second = -1;
  for (std::size_t n = 1; n < faces.size(); ++n) {
    // Within a run of faces on the same points, the first two have the lowest indices.
    const bool starts_run = n == 1 || compare(faces[n - 2], faces[n - 1]) != 0;
    if (starts_run && compare(faces[n - 1], faces[n]) == 0 &&
        (second < 0 || faces[n].face < second)) {
      first = faces[n - 1].face;
      second = faces[n].face;
    }
  }
  if (second < 0) return;
  std::array<std::int32_t, 3> a = {mesh.F(first, 0), mesh.F(first, 1), mesh.F(first, 2)};
  std::array<std::int32_t, 3> b = {mesh.F(second, 0), mesh.F(second, 1), mesh.F(second, 2)};
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  const std::string pair = "faces " + std::to_string(first) + " " + corners_text(mesh, first) +
                           " and " + std::to_string(second) + " " + corners_text(mesh, second);
  throw body::MeshError(
      "StaticMesh: expected no two faces on the same three points, found " + pair +
      (a == b ? ", the same triangle (the same three vertices)"
              : ", coincident triangles (their vertices lie on the same three points)") +
      "; the static mesh is two-sided, so a copy of a triangle, in either orientation, would "
      "report each of its contacts twice: remove one of them");
}

}  // namespace

StaticMesh::StaticMesh(body::TriangleMesh mesh) : mesh_(std::move(mesh)) {
  const Eigen::Index V = mesh_.V.rows();
  const Eigen::Index F = mesh_.F.rows();
  if (V == 0 || F == 0) {
    throw body::MeshError("StaticMesh: expected a mesh with vertices and faces, found " +
                          std::to_string(V) + " vertices and " + std::to_string(F) + " faces");
  }
  // The compressed rows index 3F face slots with std::int32_t.
  constexpr Eigen::Index kMaxFaces = std::numeric_limits<std::int32_t>::max() / 3;
  if (F > kMaxFaces || V > std::numeric_limits<std::int32_t>::max()) {
    throw body::MeshError("StaticMesh: expected at most " + std::to_string(kMaxFaces) +
                          " faces and 2147483647 vertices, found " + std::to_string(F) +
                          " faces and " + std::to_string(V) + " vertices");
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
    const Vector3 normal = (b - a).cross(c - a);
    const double squared = normal.squaredNorm();
    if (!std::isfinite(squared)) {
      throw body::MeshError(
          "StaticMesh: " + face_text(mesh_, f) +
          ": coordinates too large: its squared normal |(b − a) × (c − a)|² "
          "overflows double (vertex coordinates up to " +
          format_number(std::max(
              {a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff()})) +
          " in magnitude)");
    }
    if (squared == 0.0) {
      throw body::MeshError("StaticMesh: " + face_text(mesh_, f) +
                            (normal.isZero(0.0) ? " is degenerate (zero area)"
                                                : " is too small: its squared normal "
                                                  "|(b − a) × (c − a)|² underflows to 0"));
    }
  }
  refuse_coincident_faces(mesh_);

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

  // Faces along each edge, in O(F + V): the edges {lo, hi} are numbered vertex by vertex, from
  // the faces around lo, with `neighbour_edge` mapping hi to its edge while lo is visited.
  face_edges_.assign(static_cast<std::size_t>(3 * F), -1);
  std::vector<std::int32_t> edge_size;
  std::vector<std::int32_t> neighbour_edge(static_cast<std::size_t>(V), -1);
  for (std::int32_t lo = 0; lo < V; ++lo) {
    const auto around = faces_of_vertex(lo);
    for (const std::int32_t f : around) {
      for (int k = 0; k < 3; ++k) {
        const std::int32_t i = mesh_.F(f, k);
        const std::int32_t j = mesh_.F(f, (k + 1) % 3);
        if (std::min(i, j) != lo) continue;
        std::int32_t& edge = neighbour_edge[static_cast<std::size_t>(std::max(i, j))];
        if (edge < 0) {
          edge = static_cast<std::int32_t>(edge_size.size());
          edge_size.push_back(0);
        }
        face_edges_[static_cast<std::size_t>(3 * f + k)] = edge;
        ++edge_size[static_cast<std::size_t>(edge)];
      }
    }
    for (const std::int32_t f : around) {
      for (int k = 0; k < 3; ++k) neighbour_edge[static_cast<std::size_t>(mesh_.F(f, k))] = -1;
    }
  }
  edge_face_start_.assign(edge_size.size() + 1, 0);
  std::partial_sum(edge_size.begin(), edge_size.end(), edge_face_start_.begin() + 1);
  edge_faces_.resize(static_cast<std::size_t>(3 * F));
  fill.assign(edge_face_start_.begin(), edge_face_start_.end() - 1);
  for (std::size_t slot = 0; slot < face_edges_.size(); ++slot) {  // faces in increasing order
    edge_faces_[static_cast<std::size_t>(fill[static_cast<std::size_t>(face_edges_[slot])]++)] =
        static_cast<std::int32_t>(slot / 3);
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

std::span<const std::int32_t> StaticMesh::faces_of_vertex(std::int32_t v) const {
  const auto count = static_cast<std::int64_t>(vertex_face_start_.size()) - 1;
  if (v < 0 || v >= count) {
    throw InvalidArgument("StaticMesh::faces_of_vertex: expected a vertex index v in [0, " +
                          std::to_string(count) + "), found " + std::to_string(v));
  }
  const auto i = static_cast<std::size_t>(v);
  return {vertex_faces_.data() + vertex_face_start_[i],
          vertex_faces_.data() + vertex_face_start_[i + 1]};
}

std::span<const std::int32_t> StaticMesh::faces_of_edge(std::int32_t f, int k) const {
  const auto count = static_cast<std::int64_t>(face_edges_.size() / 3);
  if (f < 0 || f >= count) {
    throw InvalidArgument("StaticMesh::faces_of_edge: expected a face index f in [0, " +
                          std::to_string(count) + "), found " + std::to_string(f));
  }
  if (k < 0 || k >= 3) {
    throw InvalidArgument("StaticMesh::faces_of_edge: expected an edge k of face " +
                          std::to_string(f) + " in [0, 3), found " + std::to_string(k));
  }
  const auto edge = static_cast<std::size_t>(face_edges_[static_cast<std::size_t>(3 * f + k)]);
  return {edge_faces_.data() + edge_face_start_[edge],
          edge_faces_.data() + edge_face_start_[edge + 1]};
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

// true when n lies in the region of edge k of face f, from vertex i to vertex j: it does not
// point over a face that shares the edge. O(faces along the edge).
bool in_edge_region(const StaticMesh& mesh, std::int32_t f, int k, std::int32_t i, std::int32_t j,
                    const Vector3& n) {
  const body::TriangleMesh& m = mesh.mesh();
  const Vector3 x_i = vertex(m, i);
  const Vector3 e = (vertex(m, j) - x_i).normalized();
  for (const std::int32_t g : mesh.faces_of_edge(f, k)) {
    const auto other = static_cast<std::int32_t>(std::int64_t{m.F(g, 0)} + m.F(g, 1) + m.F(g, 2) -
                                                 i - j);  // the third vertex of g
    const Vector3 to_other = vertex(m, other) - x_i;
    const Vector3 inward = to_other - e.dot(to_other) * e;  // in the face's plane, into the face
    if (n.dot(inward) > kRegionTolerance * inward.norm()) return false;
  }
  return true;
}

// true when n makes a right or obtuse angle with every edge leaving vertex v. O(faces around v).
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

/// The edges and vertices already decided in one query (kept or rejected): a short list while
/// there are few, a hash set past kLinear, so that a query touching many shared features stays
/// linear.
class DecidedFeatures {
 public:
  explicit DecidedFeatures(std::vector<std::uint64_t>& list) : list_(list) { list_.clear(); }
  /// true when `feature` was decided before; records it otherwise.
  bool seen_before(std::uint64_t feature) {
    if (!many_.empty()) return !many_.insert(feature).second;
    if (std::find(list_.begin(), list_.end(), feature) != list_.end()) return true;
    list_.push_back(feature);
    if (list_.size() > kLinear) many_.insert(list_.begin(), list_.end());
    return false;
  }

 private:
  static constexpr std::size_t kLinear = 16;
  std::vector<std::uint64_t>& list_;
  std::unordered_set<std::uint64_t> many_;  // allocates only when used
};

}  // namespace

// [sphere mesh]
void sphere_mesh(const Vector3& c, double r, const StaticMesh& mesh, double margin,
                 std::vector<ContactGeometry>& out) {
  const body::TriangleMesh& m = mesh.mesh();
  thread_local std::vector<std::int32_t> candidates;
  thread_local std::vector<std::uint64_t> decided_list;
  candidates.clear();
  mesh.query(c, r, margin, candidates);
  // A face is reported by its own triangle only, which the query returns once; an edge or a
  // vertex may be reported by every face around it, and is decided by the first of them.
  DecidedFeatures decided(decided_list);
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
    int edge_k = -1;  // edge k of face f runs from ids[k] to ids[(k + 1) % 3]
    std::int32_t corner = -1;
    switch (closest.feature) {
      case TriangleFeature::face:
        feature = face_feature(static_cast<std::uint64_t>(f));
        break;
      case TriangleFeature::edge_ab:
        edge_k = 0;
        break;
      case TriangleFeature::edge_bc:
        edge_k = 1;
        break;
      case TriangleFeature::edge_ca:
        edge_k = 2;
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
    const std::int32_t edge_i = edge_k >= 0 ? ids[edge_k] : -1;
    const std::int32_t edge_j = edge_k >= 0 ? ids[(edge_k + 1) % 3] : -1;
    if (edge_k >= 0) {
      feature = edge_feature(
          mesh_edge_index(static_cast<std::uint64_t>(edge_i), static_cast<std::uint64_t>(edge_j)));
    } else if (corner >= 0) {
      feature = vertex_feature(static_cast<std::uint64_t>(corner));
    }
    if ((edge_k >= 0 || corner >= 0) && decided.seen_before(feature)) continue;

    // A centre on the mesh has no direction to the feature: use the face normal.
    const Vector3 n =
        distance > 0.0 ? Vector3(d / distance) : Vector3((b - a).cross(cc - a).normalized());
    if (edge_k >= 0 && !in_edge_region(mesh, f, edge_k, edge_i, edge_j, n)) continue;
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
