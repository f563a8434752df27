// Chapter 4: the static mesh — its bounding-volume hierarchy and the sphere–mesh contacts.
//
// Independent references: the query against the brute-force overlap test of every triangle's
// bounding box; the analytic contact of a sphere resting on a flat floor (one contact, g = z − r,
// n = e_z), on edges and vertices of a box mesh (exact normals and gaps by hand); on a bumpy
// floor, the deepest contact against the minimum distance over every triangle.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd_test/random.hpp"

namespace {

using grbd::Vector3;
using grbd::body::TriangleMesh;
using grbd::collision::ContactGeometry;
using grbd::collision::StaticMesh;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// An n × n grid of squares of edge h on [−nh/2, nh/2]², two triangles each, z = height(x, y),
// counter-clockwise seen from +z. Vertex (i, j) is i (n + 1) + j.
template <class Height>
TriangleMesh grid_floor(int n, double h, Height height) {
  TriangleMesh mesh;
  mesh.V.resize((n + 1) * (n + 1), 3);
  mesh.F.resize(2 * n * n, 3);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double x = (i - n / 2) * h, y = (j - n / 2) * h;
      mesh.V.row(i * (n + 1) + j) << x, y, height(x, y);
    }
  }
  int f = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int v00 = i * (n + 1) + j, v10 = v00 + n + 1, v01 = v00 + 1, v11 = v10 + 1;
      mesh.F.row(f++) << v00, v10, v11;
      mesh.F.row(f++) << v00, v11, v01;
    }
  }
  return mesh;
}

// The 200 × 200 flat floor z = 0 of 80 000 triangles, edge 0.25 (dyadic: exact coordinates).
const StaticMesh& large_floor() {
  static const StaticMesh mesh(grid_floor(200, 0.25, [](double, double) { return 0.0; }));
  return mesh;
}

}  // namespace

// Reference: brute force, the overlap test of every triangle's bounding box with the query box.
// Seeded random queries; also checks that a query returns few triangles (≤ 64 of 80 000).
TEST(StaticMesh, QueryReturnsExactlyTheOverlappingTriangles) {
  const StaticMesh& mesh = large_floor();
  const TriangleMesh& m = mesh.mesh();
  grbd::test::Random rng(4601);
  std::vector<std::int32_t> found;
  for (int k = 0; k < 20; ++k) {
    const Vector3 c(rng.uniform(-26.0, 26.0), rng.uniform(-26.0, 26.0), rng.uniform(-0.3, 0.3));
    const double r = rng.uniform(0.05, 0.3), margin = 0.01;
    found.clear();
    mesh.query(c, r, margin, found);
    std::vector<std::int32_t> expected;
    for (int f = 0; f < m.F.rows(); ++f) {
      Eigen::AlignedBox3d box;
      for (int i = 0; i < 3; ++i) box.extend(Vector3(m.V.row(m.F(f, i)).transpose()));
      const Vector3 reach = Vector3::Constant(r + margin);
      if (box.intersects(Eigen::AlignedBox3d(c - reach, c + reach))) expected.push_back(f);
    }
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected);
    EXPECT_LE(found.size(), 64U);
  }
}

// Reference: the analytic contact of a sphere above a flat floor: exactly one contact, n = e_z,
// g = c_z − r, point (c_x, c_y, 0), whether the centre is over a face, exactly over an edge or
// exactly over a vertex (then feature_b names the edge or vertex). Tolerance 4 ε.
TEST(SphereMesh, SphereOnALargeFlatFloorHasOneAnalyticContact) {
  using grbd::collision::edge_feature;
  using grbd::collision::mesh_edge_index;
  using grbd::collision::vertex_feature;
  const StaticMesh& mesh = large_floor();
  grbd::test::Random rng(4602);
  std::vector<ContactGeometry> out;
  for (int k = 0; k < 300; ++k) {
    Vector3 c(rng.uniform(-24.0, 24.0), rng.uniform(-24.0, 24.0), rng.uniform(0.1, 0.5));
    if (k % 3 == 1) c.x() = std::round(4.0 * c.x()) / 4.0;  // on a grid line x = const
    if (k % 3 == 2) c.head<2>() = (4.0 * c.head<2>()).array().round() / 4.0;  // over a vertex
    const double r = 0.3;
    out.clear();
    grbd::collision::sphere_mesh(c, r, mesh, 0.25, out);
    const bool touching = c.z() - r <= 0.25;
    ASSERT_EQ(out.size(), touching ? 1U : 0U) << "c = " << c.transpose();
    if (!touching) continue;
    EXPECT_EQ(out[0].I_n, Vector3::UnitZ());
    EXPECT_NEAR(out[0].g_N, c.z() - r, 4 * kEps);
    EXPECT_EQ(out[0].I_r_b, Vector3(c.x(), c.y(), 0.0));
    if (k % 3 == 2) {
      const int i = static_cast<int>(std::lround(c.x() / 0.25)) + 100;
      const int j = static_cast<int>(std::lround(c.y() / 0.25)) + 100;
      EXPECT_EQ(out[0].feature_b, vertex_feature(static_cast<std::uint64_t>(i * 201 + j)));
    } else if (k % 3 == 1) {
      EXPECT_EQ(out[0].feature_b >> 62, edge_feature(0) >> 62);  // an edge, reported once
    }
  }
}

// Reference: by hand on the closed box mesh [−1, 1]³: a sphere touching the edge x = z = 1, the
// corner (1, 1, 1) and the middle of the face x = 1, each exactly (g = 0): one contact each, with
// the normal of the edge (1, 0, 1)/√2, of the corner (1, 1, 1)/√3, of the face e_x. Tolerance 4 ε.
TEST(SphereMesh, SphereExactlyOnAnEdgeOrAVertexGivesOneContact) {
  const StaticMesh mesh(grbd::body::box_mesh(Vector3::Ones()));
  const double r = 0.5;
  struct Case {
    Vector3 n;
    std::uint64_t kind;
  };
  const Case cases[] = {{Vector3(1.0, 0.0, 1.0).normalized(), 1},
                        {Vector3(1.0, 1.0, 1.0).normalized(), 2},
                        {Vector3::UnitX(), 0}};
  const Vector3 touch[] = {Vector3(1.0, 0.0, 1.0), Vector3(1.0, 1.0, 1.0), Vector3(1.0, 0.3, -0.6)};
  for (int k = 0; k < 3; ++k) {
    std::vector<ContactGeometry> out;
    grbd::collision::sphere_mesh(touch[k] + r * cases[k].n, r, mesh, 0.0, out);
    ASSERT_EQ(out.size(), 1U) << "case " << k;
    EXPECT_LE((out[0].I_n - cases[k].n).cwiseAbs().maxCoeff(), 4 * kEps);
    EXPECT_NEAR(out[0].g_N, 0.0, 4 * kEps);
    EXPECT_LE((out[0].I_r_b - touch[k]).cwiseAbs().maxCoeff(), 4 * kEps);
    EXPECT_EQ(out[0].feature_b >> 62, cases[k].kind);
  }
}

// Reference: testing every triangle: on a bumpy floor (60 × 60 cells, z = 0.2 sin x cos 1.3y),
// the deepest contact has the minimum over all triangles of |c − closest point| − r, every
// contact lies within the margin, and no contact is reported twice.
TEST(SphereMesh, DeepestContactMatchesEveryTriangleOnABumpyFloor) {
  const StaticMesh mesh(grid_floor(
      60, 0.1, [](double x, double y) { return 0.2 * std::sin(x) * std::cos(1.3 * y); }));
  const TriangleMesh& m = mesh.mesh();
  grbd::test::Random rng(4603);
  std::vector<ContactGeometry> out;
  int with_contacts = 0;
  for (int k = 0; k < 100; ++k) {
    const Vector3 c(rng.uniform(-2.5, 2.5), rng.uniform(-2.5, 2.5), rng.uniform(0.0, 0.6));
    const double r = rng.uniform(0.1, 0.4), margin = 0.05;
    out.clear();
    grbd::collision::sphere_mesh(c, r, mesh, margin, out);
    double expected = std::numeric_limits<double>::infinity();
    for (int f = 0; f < m.F.rows(); ++f) {
      const auto p = grbd::collision::closest_point_on_triangle(c, m.V.row(m.F(f, 0)).transpose(),
                                                                m.V.row(m.F(f, 1)).transpose(),
                                                                m.V.row(m.F(f, 2)).transpose());
      expected = std::min(expected, (c - p.point).norm() - r);
    }
    double deepest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < out.size(); ++i) {
      EXPECT_LE(out[i].g_N, margin);
      deepest = std::min(deepest, out[i].g_N);
      for (std::size_t j = 0; j < i; ++j) EXPECT_NE(out[i].feature_b, out[j].feature_b);
    }
    if (expected <= margin) {
      ++with_contacts;
      EXPECT_NEAR(deepest, expected, 1e-14) << "c = " << c.transpose();
    } else {
      EXPECT_TRUE(out.empty());
    }
  }
  EXPECT_GT(with_contacts, 20);
}

// Reference: the declaration: an empty mesh, an index out of range and a zero-area face are
// refused with body::MeshError.
TEST(StaticMesh, RefusesEmptyMeshesBadIndicesAndDegenerateFaces) {
  EXPECT_THROW(StaticMesh(TriangleMesh{}), grbd::body::MeshError);
  TriangleMesh bad = grbd::body::box_mesh(Vector3::Ones());
  bad.F(3, 1) = 8;
  EXPECT_THROW(StaticMesh{bad}, grbd::body::MeshError);
  TriangleMesh degenerate = grbd::body::box_mesh(Vector3::Ones());
  degenerate.F(2, 1) = degenerate.F(2, 0);
  EXPECT_THROW(StaticMesh{degenerate}, grbd::body::MeshError);
}
