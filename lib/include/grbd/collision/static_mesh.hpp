#pragma once
/// \file
/// \brief A static triangle mesh in frame I with an acceleration structure, and the sphere–mesh
/// contacts (chapter 4).

#include <cstdint>
#include <span>
#include <vector>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/core/types.hpp"

namespace grbd::collision {

/// A static triangle mesh (frame I) with a bounding-volume hierarchy of axis-aligned boxes over its
/// triangles, so that a query near a sphere costs O(log F + k) instead of O(F). Open meshes (a
/// chute, a floor) are allowed, and so are edges shared by more than two faces; faces must not be
/// degenerate, and no two faces may lie on the same three points.
class StaticMesh {
 public:
  /// Builds the hierarchy and the face adjacency in O(F log F); throws body::MeshError for an
  /// empty mesh, a non-finite vertex, invalid indices, degenerate faces (zero area), faces whose
  /// normal overflows double, and two faces on the same three vertex positions (the same triangle
  /// twice, in either orientation, or coincident triangles on vertices of their own): the mesh is
  /// two-sided, so a copy would report each of its contacts twice. The message names the face
  /// (or the first pair: the one whose second face has the lowest index).
  explicit StaticMesh(body::TriangleMesh mesh);
  /// The triangles (frame I).
  const body::TriangleMesh& mesh() const { return mesh_; }
  /// Appends the indices of the triangles whose bounding boxes overlap the box
  /// [c − (r + margin), c + (r + margin)].
  void query(const Vector3& c, double r, double margin, std::vector<std::int32_t>& triangles) const;
  /// The indices of the faces that use vertex v, in increasing order; throws
  /// grbd::InvalidArgument unless 0 ≤ v < \#V.
  std::span<const std::int32_t> faces_of_vertex(std::int32_t v) const;
  /// The indices of the faces that hold edge k of face f (from vertex F(f, k) to
  /// F(f, (k + 1) mod 3), either direction), f itself included, in increasing order; throws
  /// grbd::InvalidArgument unless 0 ≤ f < \#F and 0 ≤ k < 3.
  std::span<const std::int32_t> faces_of_edge(std::int32_t f, int k) const;

 private:
  struct Node {
    Eigen::AlignedBox3d box;  // bounds of the node's triangles
    std::int32_t first = 0;   // leaf: first index in order_; inner: index of the left child
    std::int32_t count = 0;   // leaf: number of triangles; inner: 0
  };
  body::TriangleMesh mesh_;
  std::vector<Node> nodes_;
  std::vector<std::int32_t> order_;
  // The faces around each vertex and along each edge (compressed rows): sphere_mesh() needs them
  // to decide whether a contact normal lies in the region of an edge or a vertex.
  std::vector<std::int32_t> vertex_face_start_;
  std::vector<std::int32_t> vertex_faces_;
  std::vector<std::int32_t> face_edges_;  // 3 f + k: the edge of face f from corner k to k + 1
  std::vector<std::int32_t> edge_face_start_;
  std::vector<std::int32_t> edge_faces_;
};

/// Every contact of a sphere (a) with a static mesh (b) within the margin, one per touching feature
/// (a face, or an edge or vertex shared by several faces reported once), with the normal from
/// the feature to the centre. feature_b encodes the feature (face index, or the vertex or edge by
/// its vertex indices, see face_feature()) so that it is stable from step to step. Appends to
/// `out`.
///
/// The mesh is two-sided (no back faces are culled). An edge or vertex contact is kept only when
/// its normal n lies in the feature's region: for an edge, n must not point over any face that
/// shares the edge (nᵀm ≤ τ|m| for the in-plane normal m of the edge pointing into each such
/// face); for a vertex, n must make a right or obtuse angle with every edge leaving it
/// (nᵀ(x_w − x_v) ≤ τ|x_w − x_v|), τ = 1e-9. Otherwise the contact belongs to a neighbouring
/// face or edge, which reports it. An edge or vertex reported by several triangles is decided
/// once, by the first triangle (in the order of the hierarchy's query) that reports it; a centre
/// exactly on the mesh takes that triangle's face normal ((b − a) × (c − a) normalised). The cost
/// is O(k log k) for k triangles within reach plus the faces around the edges and vertices they
/// report, each visited once: no feature is tested twice, however many faces share it.
// [sphere mesh declaration]
void sphere_mesh(const Vector3& c, double r, const StaticMesh& mesh, double margin,
                 std::vector<ContactGeometry>& out);
// [sphere mesh declaration]

}  // namespace grbd::collision
