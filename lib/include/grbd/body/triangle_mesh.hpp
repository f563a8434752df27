#pragma once
/// \file
/// \brief Closed triangle meshes: the data, a strict Wavefront OBJ reader and writer, topology
/// checks, and generators for the meshes of the book (chapter 2).

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"

namespace grbd::body {

/// Vertex positions, one point per row (\#V × 3), in the mesh's own frame M [m].
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// Triangles, three zero-based vertex indices per row (\#F × 3), counter-clockwise seen from
/// outside, so that (b − a) × (c − a) is an outward normal.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// A triangle mesh: vertices V (\#V × 3) and faces F (\#F × 3).
struct TriangleMesh {
  Vertices V;  ///< \#V × 3 vertex positions in frame M [m]
  Faces F;     ///< \#F × 3 vertex indices, outward (counter-clockwise) orientation
};

/// A mesh that cannot be used: a malformed file, or a surface that does not bound a solid. The
/// message names the file (and line) or the offending edges and faces.
class MeshError : public Error {
 public:
  using Error::Error;
};

/// Reads a Wavefront OBJ file. Understood: `v x y z [w]` (w is checked, not used) and
/// `f i j k ...` with indices in any of the forms `i`, `i/t`, `i//n`, `i/t/n`; a positive index
/// counts from 1 at the first vertex of the file, a negative one back from the latest vertex read
/// (−1), and either must name a vertex read before the `f` line. Polygons v0 v1 … with more than
/// three vertices are split into the fan (v0, v_k, v_k+1), which keeps their orientation.
/// Ignored: comments (`#` to the end of a line), `vt`, `vn`, `vp`, `o`, `g`, `s`, `usemtl`,
/// `mtllib`; Windows line ends and a UTF-8 byte order mark are accepted. A number is read
/// correctly rounded to double; one below the smallest subnormal (such as 1e-400) rounds to ±0 and
/// is accepted as such. Anything else (an unknown statement, a malformed or non-finite number, one
/// that overflows double, a face with fewer than three vertices, an index out of range, a file
/// with no faces) throws MeshError with the message "FILE:LINE: expected …, found '…'". A file
/// that does not exist, cannot be examined or opened (with the system's reason), is not a regular
/// file (a FIFO or a device is refused from its type, without being opened) or fails to read is a
/// MeshError naming it. Coordinates too large for the volume integrals are found later, by
/// require_closed_oriented() and mass_properties().
TriangleMesh read_obj(const std::filesystem::path& path);

/// Writes `mesh` as a Wavefront OBJ file (`comment` as `#` lines, then `v` and `f` lines, 1-based
/// indices, 17 significant digits so that read_obj() gives back the same numbers). Throws
/// MeshError naming the file if it cannot be written, or if read_obj() could not read it back (no
/// faces, a non-finite coordinate, an index outside [0, \#V)).
void write_obj(const TriangleMesh& mesh, const std::filesystem::path& path,
               std::string_view comment = {});

/// The counts that decide whether a triangle mesh bounds a solid.
struct MeshTopology {
  std::size_t boundary_edges = 0;      ///< edges used by exactly one face (holes)
  std::size_t non_manifold_edges = 0;  ///< edges used by three or more faces
  std::size_t inconsistent_edges = 0;  ///< edges traversed in the same direction by two faces
  std::size_t degenerate_faces = 0;    ///< faces with a repeated vertex index or zero area
  std::size_t invalid_indices = 0;     ///< face indices outside [0, \#V)
  /// true when the mesh is a closed, consistently oriented 2-manifold without degenerate faces.
  bool closed_oriented_manifold() const {
    return boundary_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0 &&
           degenerate_faces == 0 && invalid_indices == 0;
  }
};

/// Counts boundary, non-manifold and inconsistently oriented edges and degenerate faces;
/// O(\#F log \#F). A face with an invalid or a repeated index has no edges to count; a face of
/// exactly zero area (coincident or collinear vertices) is degenerate, but its edges count.
MeshTopology analyse_topology(const TriangleMesh& mesh);

/// Throws MeshError unless `mesh` is a closed, consistently oriented 2-manifold whose enclosed
/// volume is positive (outward normals). The message starts with `source` (a file name or a
/// description), gives the counts of MeshTopology and names the first offending edge by its two
/// vertex indices (or the first offending face). Coordinates so large that the signed volume
/// Σ a·(b × c)/6 overflows (magnitudes beyond about 5e102) are refused as "coordinates too large",
/// with the largest magnitude and its vertex.
void require_closed_oriented(const TriangleMesh& mesh, std::string_view source);

/// The rigid (or general affine) image x ↦ A x + r of every vertex; faces unchanged. A must have
/// a positive determinant to keep the orientation: throws grbd::InvalidArgument for det A ≤ 0 (a
/// reflection would turn every face inward) or non-finite A or r.
TriangleMesh transformed(const TriangleMesh& mesh, const Matrix3& A, const Vector3& r);

/// The box [−a, a] × [−b, b] × [−c, c] for half_extents = (a, b, c): 8 vertices, 12 faces.
///
/// This generator and those below throw grbd::InvalidArgument for sizes that are not finite and
/// positive, and for segment counts outside [3, 2^20].
TriangleMesh box_mesh(const Vector3& half_extents);

/// The tetrahedron with vertices a, b, c, d (4 faces), oriented outward whatever the order of the
/// vertices; throws grbd::InvalidArgument if they are not finite or coplanar to round-off (6 |V|
/// at most 64 ε times the product of the lengths of the edges from a).
TriangleMesh tetrahedron_mesh(const Vector3& a, const Vector3& b, const Vector3& c,
                              const Vector3& d);

/// A sphere of the given radius about the origin: the icosahedron, subdivided `subdivisions`
/// times (each time every triangle into four), vertices projected onto the sphere.
/// 20·4^subdivisions faces, 10·4^subdivisions + 2 vertices, subdivisions ∈ [0, 10]; the mesh is
/// inscribed, so its volume converges to 4/3 π R³ from below at second order in the edge length.
TriangleMesh icosphere_mesh(double radius, int subdivisions);

/// A torus about the z axis: centre-line radius R, tube radius r < R, with n_major segments around
/// the axis and n_minor around the tube (2·n_major·n_minor faces, vertices on the exact surface;
/// n_major·n_minor ≤ 2^24).
TriangleMesh torus_mesh(double R, double r, int n_major, int n_minor);

/// A closed cylinder about the z axis, z ∈ [−height/2, height/2], with n segments around the axis:
/// the inscribed regular n-gon prism, 2n + 2 vertices (the cap centres included) and 4n faces.
TriangleMesh cylinder_mesh(double radius, double height, int n);

}  // namespace grbd::body
