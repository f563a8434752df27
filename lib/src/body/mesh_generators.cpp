/// \file
/// \brief Closed, outward-oriented triangle meshes of the solids of the book: box, tetrahedron,
/// icosphere, torus and cylinder.

#include <Eigen/Geometry>  // cross()
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <unordered_map>
#include <vector>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/checks.hpp"

namespace grbd::body {

namespace {

/// Meshes stay well below the range of the int indices of Faces (and of memory).
constexpr std::int64_t kMaxVertices = std::int64_t{1} << 24;

void require_segments(const char* function, const char* name, int n) {
  if (n < 3 || n > (1 << 20)) {
    throw InvalidArgument(std::string(function) + ": expected " + name + " in [3, 2^20], found " +
                          std::to_string(n));
  }
}

}  // namespace

TriangleMesh box_mesh(const Vector3& half_extents) {
  require_positive_finite("box_mesh", "half extent a", half_extents.x());
  require_positive_finite("box_mesh", "half extent b", half_extents.y());
  require_positive_finite("box_mesh", "half extent c", half_extents.z());
  TriangleMesh mesh;
  mesh.V.resize(8, 3);
  // Vertex i has the signs (bit 0 → x, bit 1 → y, bit 2 → z) of its corner.
  for (int i = 0; i < 8; ++i) {
    mesh.V.row(i) << ((i & 1) ? 1.0 : -1.0) * half_extents.x(),
        ((i & 2) ? 1.0 : -1.0) * half_extents.y(), ((i & 4) ? 1.0 : -1.0) * half_extents.z();
  }
  // Two triangles per side, counter-clockwise seen from outside.
  mesh.F.resize(12, 3);
  mesh.F << 0, 4, 6, 0, 6, 2,  // x = −a
      1, 3, 7, 1, 7, 5,        // x = +a
      0, 1, 5, 0, 5, 4,        // y = −b
      2, 6, 7, 2, 7, 3,        // y = +b
      0, 2, 3, 0, 3, 1,        // z = −c
      4, 5, 7, 4, 7, 6;        // z = +c
  return mesh;
}

TriangleMesh tetrahedron_mesh(const Vector3& a, const Vector3& b, const Vector3& c,
                              const Vector3& d) {
  const Vector3 ab = b - a;
  const Vector3 ac = c - a;
  const Vector3 ad = d - a;
  const double six_volume = ab.dot(ac.cross(ad));
  // Coplanar up to round-off: |6V| is at most a few ulps of the product of the edge lengths.
  const double scale = ab.norm() * ac.norm() * ad.norm();
  if (!std::isfinite(six_volume) ||
      !(std::abs(six_volume) > 64.0 * std::numeric_limits<double>::epsilon() * scale)) {
    throw InvalidArgument(
        "tetrahedron_mesh: expected four finite points that are not coplanar, found the signed "
        "volume 6V = (b − a)·((c − a) × (d − a)) = " +
        format_number(six_volume));
  }
  TriangleMesh mesh;
  mesh.V.resize(4, 3);
  mesh.V << a.transpose(), b.transpose(), c.transpose(), d.transpose();
  // For 6V > 0, d lies on the side of (a, b, c) that (b − a) × (c − a) points to, so (a, c, b)
  // is seen counter-clockwise from outside; the other three faces follow by the edge rule.
  mesh.F.resize(4, 3);
  mesh.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  if (six_volume < 0.0) mesh.F.col(1).swap(mesh.F.col(2));  // mirror image: flip every face
  return mesh;
}

TriangleMesh icosphere_mesh(double radius, int subdivisions) {
  require_positive_finite("icosphere_mesh", "radius", radius);
  if (subdivisions < 0 || subdivisions > 10) {
    throw InvalidArgument("icosphere_mesh: expected subdivisions in [0, 10], found " +
                          std::to_string(subdivisions));
  }
  // The regular icosahedron: the 12 cyclic permutations of (0, ±1, ±φ), counter-clockwise faces.
  const double t = std::numbers::phi;
  std::vector<Vector3> vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                   {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                   {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vector3& v : vertices) v.normalize();
  std::vector<std::array<int, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    // Each edge gets one midpoint, shared by its two faces: a key per undirected edge.
    std::unordered_map<std::uint64_t, int> midpoints;
    midpoints.reserve(3 * faces.size() / 2);
    auto midpoint = [&](int i, int j) {
      const auto key = (static_cast<std::uint64_t>(std::min(i, j)) << 32) |
                       static_cast<std::uint64_t>(std::max(i, j));
      const auto [it, inserted] = midpoints.try_emplace(key, static_cast<int>(vertices.size()));
      if (inserted) {
        const auto ui = static_cast<std::size_t>(i);
        const auto uj = static_cast<std::size_t>(j);
        vertices.push_back((vertices[ui] + vertices[uj]).normalized());
      }
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    finer.reserve(4 * faces.size());
    for (const auto& [a, b, c] : faces) {
      const int ab = midpoint(a, b);
      const int bc = midpoint(b, c);
      const int ca = midpoint(c, a);
      finer.push_back({a, ab, ca});
      finer.push_back({b, bc, ab});
      finer.push_back({c, ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces.swap(finer);
  }
  TriangleMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    mesh.V.row(static_cast<Eigen::Index>(i)) = radius * vertices[i].transpose();
  }
  mesh.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    mesh.F.row(static_cast<Eigen::Index>(f)) << faces[f][0], faces[f][1], faces[f][2];
  }
  return mesh;
}

TriangleMesh torus_mesh(double R, double r, int n_major, int n_minor) {
  require_positive_finite("torus_mesh", "centre-line radius R", R);
  require_positive_finite("torus_mesh", "tube radius r", r);
  if (!(r < R)) {
    throw InvalidArgument("torus_mesh: expected a tube radius r < R, found r = " +
                          format_number(r) + ", R = " + format_number(R));
  }
  require_segments("torus_mesh", "n_major", n_major);
  require_segments("torus_mesh", "n_minor", n_minor);
  if (std::int64_t{n_major} * n_minor > kMaxVertices) {
    throw InvalidArgument("torus_mesh: expected n_major · n_minor ≤ 2^24, found " +
                          std::to_string(std::int64_t{n_major} * n_minor));
  }
  // Vertex (i, j) at angle θ_i = 2πi/n_major about the z axis and φ_j = 2πj/n_minor about the
  // tube: ((R + r cos φ) cos θ, (R + r cos φ) sin θ, r sin φ).
  TriangleMesh mesh;
  mesh.V.resize(Eigen::Index{n_major} * n_minor, 3);
  auto index = [n_major, n_minor](int i, int j) { return (i % n_major) * n_minor + (j % n_minor); };
  for (int i = 0; i < n_major; ++i) {
    const double theta = 2.0 * std::numbers::pi * i / n_major;
    for (int j = 0; j < n_minor; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / n_minor;
      const double rho = R + r * std::cos(phi);
      mesh.V.row(index(i, j)) << rho * std::cos(theta), rho * std::sin(theta), r * std::sin(phi);
    }
  }
  // ∂x/∂θ × ∂x/∂φ points out of the tube, so (i, j) → (i+1, j) → (i+1, j+1) → (i, j+1) runs
  // counter-clockwise seen from outside.
  mesh.F.resize(2 * Eigen::Index{n_major} * n_minor, 3);
  Eigen::Index f = 0;
  for (int i = 0; i < n_major; ++i) {
    for (int j = 0; j < n_minor; ++j) {
      const int a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      mesh.F.row(f++) << a, b, c;
      mesh.F.row(f++) << a, c, d;
    }
  }
  return mesh;
}

TriangleMesh cylinder_mesh(double radius, double height, int n) {
  require_positive_finite("cylinder_mesh", "radius", radius);
  require_positive_finite("cylinder_mesh", "height", height);
  require_segments("cylinder_mesh", "n", n);
  // Vertices: 0 the centre of the bottom, 1 the centre of the top, then the rings: bottom
  // vertex 2 + 2i and top vertex 3 + 2i at angle 2πi/n.
  TriangleMesh mesh;
  mesh.V.resize(2 * Eigen::Index{n} + 2, 3);
  const double z = 0.5 * height;
  mesh.V.row(0) << 0.0, 0.0, -z;
  mesh.V.row(1) << 0.0, 0.0, z;
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / n;
    const double x = radius * std::cos(angle);
    const double y = radius * std::sin(angle);
    mesh.V.row(2 + 2 * i) << x, y, -z;
    mesh.V.row(3 + 2 * i) << x, y, z;
  }
  mesh.F.resize(4 * Eigen::Index{n}, 3);
  Eigen::Index f = 0;
  for (int i = 0; i < n; ++i) {
    const int b0 = 2 + 2 * i, t0 = b0 + 1;
    const int b1 = 2 + 2 * ((i + 1) % n), t1 = b1 + 1;
    mesh.F.row(f++) << 0, b1, b0;   // bottom, seen from below
    mesh.F.row(f++) << 1, t0, t1;   // top, seen from above
    mesh.F.row(f++) << b0, b1, t1;  // side
    mesh.F.row(f++) << b0, t1, t0;
  }
  return mesh;
}

}  // namespace grbd::body
