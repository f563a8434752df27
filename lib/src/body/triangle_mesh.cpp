/// \file
/// \brief Topology checks of triangle meshes (closed, oriented 2-manifold) and their rigid
/// (affine) images.

#include "grbd/body/triangle_mesh.hpp"

#include <Eigen/Geometry>  // cross()
#include <Eigen/LU>        // determinant()
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "grbd/core/checks.hpp"

namespace grbd::body {

namespace {

/// One face's traversal of an edge, stored by the edge's smaller vertex index first so that the
/// two traversals of an interior edge sort next to each other.
struct HalfEdge {
  int lo;            ///< smaller vertex index
  int hi;            ///< larger vertex index
  bool forward;      ///< true when the face runs lo → hi, false when it runs hi → lo
  std::size_t face;  ///< the face it belongs to
};

/// The topology counts and the first offence, described for an error message.
struct TopologyReport {
  MeshTopology counts;
  std::string first_offence;  ///< empty when there is none
};

std::string face_text(const TriangleMesh& mesh, std::size_t f) {
  return "face " + std::to_string(f) + " (" + std::to_string(mesh.F(f, 0)) + ", " +
         std::to_string(mesh.F(f, 1)) + ", " + std::to_string(mesh.F(f, 2)) + ")";
}

TopologyReport analyse(const TriangleMesh& mesh) {
  TopologyReport report;
  MeshTopology& counts = report.counts;
  const auto n_vertices = static_cast<int>(mesh.V.rows());
  const auto n_faces = static_cast<std::size_t>(mesh.F.rows());
  auto note = [&report](std::string text) {
    if (report.first_offence.empty()) report.first_offence = std::move(text);
  };

  // Faces whose indices are not usable vertices take no part in the edge count below: their
  // edges are meaningless (out of range) or not edges at all (a repeated index).
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(3 * n_faces);
  for (std::size_t f = 0; f < n_faces; ++f) {
    const std::array<int, 3> v = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    int invalid = 0;
    for (const int i : v) {
      if (i < 0 || i >= n_vertices) ++invalid;
    }
    if (invalid > 0) {
      counts.invalid_indices += static_cast<std::size_t>(invalid);
      note(face_text(mesh, f) + " has a vertex index outside [0, " + std::to_string(n_vertices) +
           ")");
      continue;
    }
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
      ++counts.degenerate_faces;
      note("degenerate " + face_text(mesh, f) + ": a repeated vertex");
      continue;
    }
    const Vector3 a = mesh.V.row(v[0]).transpose();
    const Vector3 b = mesh.V.row(v[1]).transpose();
    const Vector3 c = mesh.V.row(v[2]).transpose();
    if ((b - a).cross(c - a).squaredNorm() == 0.0) {
      // Zero area, exactly (three coincident or collinear points): no normal. Its edges are
      // still edges, so the face is counted below as well.
      ++counts.degenerate_faces;
      note("degenerate " + face_text(mesh, f) + ": zero area");
    }
    for (int k = 0; k < 3; ++k) {
      const int from = v[static_cast<std::size_t>(k)];
      const int to = v[static_cast<std::size_t>((k + 1) % 3)];
      half_edges.push_back({std::min(from, to), std::max(from, to), from < to, f});
    }
  }

  // [require closed oriented]
  // Sort the half-edges so that all traversals of one edge {lo, hi} are adjacent. In a closed,
  // consistently oriented 2-manifold every edge is traversed exactly twice, once in each
  // direction: then the flux terms of the divergence theorem cancel along every edge.
  std::sort(half_edges.begin(), half_edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.hi != y.hi ? x.hi < y.hi : x.face < y.face);
  });
  for (std::size_t first = 0; first < half_edges.size();) {
    std::size_t last = first + 1;
    while (last < half_edges.size() && half_edges[last].lo == half_edges[first].lo &&
           half_edges[last].hi == half_edges[first].hi) {
      ++last;
    }
    const HalfEdge& e = half_edges[first];
    const std::size_t uses = last - first;
    const std::string edge = "edge (" + std::to_string(e.lo) + ", " + std::to_string(e.hi) + ")";
    if (uses == 1) {
      ++counts.boundary_edges;  // a hole: the surface does not close here
      note("boundary " + edge + " of face " + std::to_string(e.face) + " only");
    } else if (uses > 2) {
      ++counts.non_manifold_edges;  // three or more faces meet at one edge
      note("non-manifold " + edge + " shared by " + std::to_string(uses) + " faces");
    } else if (e.forward == half_edges[first + 1].forward) {
      ++counts.inconsistent_edges;  // both faces run the same way: one of them is flipped
      note("inconsistently oriented " + edge + ": faces " + std::to_string(e.face) + " and " +
           std::to_string(half_edges[first + 1].face) + " both traverse it from " +
           std::to_string(e.forward ? e.lo : e.hi) + " to " +
           std::to_string(e.forward ? e.hi : e.lo));
    }
    first = last;
  }
  // [require closed oriented]
  return report;
}

}  // namespace

MeshTopology analyse_topology(const TriangleMesh& mesh) { return analyse(mesh).counts; }

void require_closed_oriented(const TriangleMesh& mesh, std::string_view source) {
  const std::string where(source);
  if (mesh.F.rows() == 0) {
    throw MeshError(where + ": expected a closed triangle mesh, found no faces (" +
                    std::to_string(mesh.V.rows()) + " vertices)");
  }
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    if (!mesh.V.row(i).allFinite()) {
      throw MeshError(where + ": expected finite vertex coordinates, found vertex " +
                      std::to_string(i) + " = (" + format_number(mesh.V(i, 0)) + ", " +
                      format_number(mesh.V(i, 1)) + ", " + format_number(mesh.V(i, 2)) + ")");
    }
  }
  const TopologyReport report = analyse(mesh);
  const MeshTopology& t = report.counts;
  if (!t.closed_oriented_manifold()) {
    throw MeshError(where + ": expected a closed, consistently oriented 2-manifold, found " +
                    std::to_string(t.boundary_edges) + " boundary edges, " +
                    std::to_string(t.non_manifold_edges) + " non-manifold edges, " +
                    std::to_string(t.inconsistent_edges) + " inconsistently oriented edges, " +
                    std::to_string(t.degenerate_faces) + " degenerate faces and " +
                    std::to_string(t.invalid_indices) + " invalid vertex indices (#V = " +
                    std::to_string(mesh.V.rows()) + ", #F = " + std::to_string(mesh.F.rows()) +
                    "); first: " + report.first_offence);
  }
  // Closed and consistently oriented: either every normal points out (V > 0) or every one in.
  // The signed volume is summed here directly, not with the exercise function of chapter 2, so
  // that the check works in the exercise build too.
  double six_volume = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Vector3 a = mesh.V.row(mesh.F(f, 0)).transpose();
    const Vector3 b = mesh.V.row(mesh.F(f, 1)).transpose();
    const Vector3 c = mesh.V.row(mesh.F(f, 2)).transpose();
    six_volume += a.dot(b.cross(c));
  }
  if (!std::isfinite(six_volume)) {
    // Finite coordinates, a sum that is not: some triple product a·(b × c) overflowed (inf, or
    // inf − inf = NaN). Its sign says nothing about the orientation.
    Eigen::Index row = 0;
    Eigen::Index col = 0;
    const double largest = mesh.V.cwiseAbs().maxCoeff(&row, &col);
    throw MeshError(where +
                    ": coordinates too large: the signed volume Σ a·(b × c)/6 overflows "
                    "double (it is not finite) with vertex coordinates up to " +
                    format_number(largest) + " in magnitude (vertex " + std::to_string(row) +
                    ", coordinate " + "xyz"[col] +
                    "); expected magnitudes whose cubes fit in a double (below about 5e102)");
  }
  if (!(six_volume > 0.0)) {
    throw MeshError(where +
                    ": expected outward-oriented faces (counter-clockwise seen from outside) "
                    "enclosing a positive volume, found the closed surface's signed volume " +
                    format_number(six_volume / 6.0) +
                    (six_volume < 0.0 ? " (the faces are oriented inward)" : ""));
  }
}

TriangleMesh transformed(const TriangleMesh& mesh, const Matrix3& A, const Vector3& r) {
  const double det = A.determinant();
  if (!(det > 0.0) || !std::isfinite(det) || !r.allFinite()) {
    throw InvalidArgument(
        "transformed: expected a finite A with det A > 0 and a finite r (a reflection would turn "
        "the faces inward), found det A = " +
        format_number(det) + ", r = (" + format_number(r.x()) + ", " + format_number(r.y()) + ", " +
        format_number(r.z()) + ")");
  }
  TriangleMesh image;
  // Row i of V is the point x_iᵀ, so the image rows are x_iᵀ Aᵀ + rᵀ.
  image.V = (mesh.V * A.transpose()).rowwise() + r.transpose();
  image.F = mesh.F;
  return image;
}

}  // namespace grbd::body
