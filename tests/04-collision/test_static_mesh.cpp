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
#include <string>
#include <vector>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd/core/error.hpp"
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

// A "book" of `pages` triangles (0, 1, k + 2) that all share the spine, the edge (0, 1) from
// (0, 0, 0) to (1, 0, 0). Page k has its third vertex at (0.5, cos θ_k, sin θ_k).
template <class Angle>
TriangleMesh book(int pages, Angle angle) {
  TriangleMesh mesh;
  mesh.V.resize(pages + 2, 3);
  mesh.F.resize(pages, 3);
  mesh.V.row(0) << 0.0, 0.0, 0.0;
  mesh.V.row(1) << 1.0, 0.0, 0.0;
  for (int k = 0; k < pages; ++k) {
    const double theta = angle(k);
    mesh.V.row(k + 2) << 0.5, std::cos(theta), std::sin(theta);
    mesh.F.row(k) << 0, 1, k + 2;
  }
  return mesh;
}

/// The message of the exception of type E that `call` throws, or a failure if it throws none.
template <class E, class F>
std::string error_message(F&& call) {
  try {
    call();
  } catch (const E& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an exception, none was thrown";
  return {};
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

// Reference: issue 11 (fuzzing): faces_of_vertex indexed its arrays without a check, so a bad
// vertex index read out of bounds. Every accessor that takes an index must throw
// grbd::InvalidArgument naming the argument, the valid range and the value.
TEST(StaticMesh, AccessorsRefuseIndicesOutOfRange) {
  const StaticMesh mesh(grbd::body::box_mesh(Vector3::Ones()));  // 8 vertices, 12 faces
  for (const std::int32_t v : {-1, 8, std::numeric_limits<std::int32_t>::max(),
                               std::numeric_limits<std::int32_t>::min()}) {
    const std::string message =
        error_message<grbd::InvalidArgument>([&] { (void)mesh.faces_of_vertex(v); });
    EXPECT_EQ(message, "StaticMesh::faces_of_vertex: expected a vertex index v in [0, 8), found " +
                           std::to_string(v))
        << message;
  }
  for (const std::int32_t f : {-1, 12}) {
    const std::string message =
        error_message<grbd::InvalidArgument>([&] { (void)mesh.faces_of_edge(f, 0); });
    EXPECT_EQ(message, "StaticMesh::faces_of_edge: expected a face index f in [0, 12), found " +
                           std::to_string(f))
        << message;
  }
  for (const int k : {-1, 3}) {
    const std::string message =
        error_message<grbd::InvalidArgument>([&] { (void)mesh.faces_of_edge(0, k); });
    EXPECT_EQ(message, "StaticMesh::faces_of_edge: expected an edge k of face 0 in [0, 3), found " +
                           std::to_string(k))
        << message;
  }
}

// Reference: the definitions, checked by brute force over every face: faces_of_vertex(v) lists
// the faces holding v, faces_of_edge(f, k) those holding both ends of edge k of face f, each in
// increasing order; on a closed box every edge has two faces, on a book the spine has them all.
TEST(StaticMesh, FacesOfVertexAndOfEdgeMatchBruteForce) {
  for (const TriangleMesh& m :
       {grbd::body::box_mesh(Vector3(1, 2, 3)), book(7, [](int k) { return 0.5 + 0.8 * k; })}) {
    const StaticMesh mesh(m);
    for (std::int32_t v = 0; v < m.V.rows(); ++v) {
      std::vector<std::int32_t> expected;
      for (std::int32_t f = 0; f < m.F.rows(); ++f) {
        if ((m.F.row(f).array() == v).any()) expected.push_back(f);
      }
      const auto found = mesh.faces_of_vertex(v);
      EXPECT_EQ(std::vector<std::int32_t>(found.begin(), found.end()), expected) << "vertex " << v;
    }
    for (std::int32_t f = 0; f < m.F.rows(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const int i = m.F(f, k), j = m.F(f, (k + 1) % 3);
        std::vector<std::int32_t> expected;
        for (std::int32_t g = 0; g < m.F.rows(); ++g) {
          if ((m.F.row(g).array() == i).any() && (m.F.row(g).array() == j).any()) {
            expected.push_back(g);
          }
        }
        const auto found = mesh.faces_of_edge(f, k);
        EXPECT_EQ(std::vector<std::int32_t>(found.begin(), found.end()), expected)
            << "face " << f << ", edge " << k;
      }
    }
  }
}

// Reference: issue 11 (fuzzing): an OBJ of 200 000 copies of one triangle took 27.9 s to build
// and query (quadratic in the faces sharing an edge). The static mesh is two-sided, so a copy of
// a triangle, in either orientation or with its vertices repeated at the same positions, only
// reports every contact twice: it is a modelling error, refused with the first duplicate pair
// (the lowest second face index). The check sorts the faces (O(F log F)): 200 000 copies are
// refused at once.
TEST(StaticMesh, RefusesDuplicateAndCoincidentFacesNamingTheFirstPair) {
  constexpr int kCopies = 200000;
  TriangleMesh copies;
  copies.V.resize(3, 3);
  copies.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  copies.F.resize(kCopies, 3);
  for (int f = 0; f < kCopies; ++f) copies.F.row(f) << 0, 1, 2;
  std::string message = error_message<grbd::body::MeshError>([&] { StaticMesh{copies}; });
  EXPECT_NE(message.find("faces 0 (0, 1, 2) and 1 (0, 1, 2)"), std::string::npos) << message;
  EXPECT_NE(message.find("the same triangle"), std::string::npos) << message;

  // A triangle soup: every copy has vertices of its own, at the same three positions.
  TriangleMesh soup;
  soup.V.resize(3 * kCopies, 3);
  soup.F.resize(kCopies, 3);
  for (int f = 0; f < kCopies; ++f) {
    soup.V.row(3 * f) << 0, 0, 0;
    soup.V.row(3 * f + 1) << 1, 0, 0;
    soup.V.row(3 * f + 2) << 0, 1, 0;
    soup.F.row(f) << 3 * f, 3 * f + 1, 3 * f + 2;
  }
  message = error_message<grbd::body::MeshError>([&] { StaticMesh{soup}; });
  EXPECT_NE(message.find("faces 0 (0, 1, 2) and 1 (3, 4, 5)"), std::string::npos) << message;
  EXPECT_NE(message.find("coincident"), std::string::npos) << message;

  // A box with face 5 repeated reversed as face 12, and face 2 repeated as face 13: the first
  // pair is (5, 12).
  TriangleMesh box = grbd::body::box_mesh(Vector3::Ones());
  box.F.conservativeResize(14, 3);
  box.F.row(12) << box.F(5, 0), box.F(5, 2), box.F(5, 1);
  box.F.row(13) = box.F.row(2);
  message = error_message<grbd::body::MeshError>([&] { StaticMesh{box}; });
  EXPECT_NE(message.find("faces 5 ("), std::string::npos) << message;
  EXPECT_NE(message.find(") and 12 ("), std::string::npos) << message;
}

// Reference: issue 11 (fuzzing): vertices at ±1e308 (the tetrahedron of the bad-input OBJ) are
// finite, but every edge vector b − a overflows, so the face normals and the contact normals
// would be NaN. The static mesh refuses them as coordinates too large, naming the face and the
// magnitude.
TEST(StaticMesh, RefusesCoordinatesWhoseNormalsOverflow) {
  TriangleMesh huge;
  huge.V.resize(4, 3);
  huge.V << 1e308, 1e308, 1e308, -1e308, -1e308, 1e308, 1e308, -1e308, -1e308, -1e308, 1e308,
      -1e308;
  huge.F.resize(4, 3);
  huge.F << 0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2;
  const std::string message = error_message<grbd::body::MeshError>([&] { StaticMesh{huge}; });
  EXPECT_EQ(message.rfind("StaticMesh: face 0 (0, 1, 2): coordinates too large", 0), 0U) << message;
  EXPECT_NE(message.find("1e+308"), std::string::npos) << message;
}

// Reference: issue 11 (fuzzing): the region test of an edge walked every face around one of its
// vertices, and was repeated for every face that reported the edge and saw it rejected: for an
// edge shared by F faces, O(F²). Here a book of 1 000 000 pages: the sphere lies near the spine,
// behind every page but the last, which lies under it. Every page but the last reports the
// spine, whose region the last page excludes; the last page reports its face. By hand: exactly
// one contact, on the last face, n = e_z, gap 0.05 − r. (At 40 000 pages the old code took
// 6.1 s; at 1 000 000 it would take hours, far beyond ctest's time limit.)
TEST(SphereMesh, AnEdgeSharedByAMillionFacesIsDecidedOnce) {
  constexpr int kPages = 1000000;
  const StaticMesh mesh(book(kPages, [](int k) {
    // Pages 0 … kPages − 2 between 126° and 229° from +y; the last one along +y.
    return k == kPages - 1 ? 0.0 : 2.2 + 1.8 * k / (kPages - 2);
  }));
  const double r = 0.2;
  std::vector<ContactGeometry> out;
  grbd::collision::sphere_mesh(Vector3(0.5, 0.1, 0.05), r, mesh, 0.01, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].feature_b, grbd::collision::face_feature(kPages - 1));
  EXPECT_LE((out[0].I_n - Vector3::UnitZ()).cwiseAbs().maxCoeff(), 4 * kEps);
  EXPECT_NEAR(out[0].g_N, 0.05 - r, 4 * kEps);
}

// Reference: a face is reported only by itself, so face contacts need no search for duplicates;
// the old code compared each new contact with every earlier one, O(k²) for k contacts. A book of
// 1 000 000 pages fanned over 10⁻⁴ rad, the sphere over all of them within the margin: by hand,
// one face contact per page, each page once, every normal within 10⁻⁴ of the page's own.
TEST(SphereMesh, AMillionNearlyCoplanarFacesGiveOneContactEach) {
  constexpr int kPages = 1000000;
  const StaticMesh mesh(book(kPages, [](int k) { return 1e-4 * k / kPages; }));
  std::vector<ContactGeometry> out;
  grbd::collision::sphere_mesh(Vector3(0.5, 0.3, 0.01), 0.005, mesh, 0.01, out);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(kPages));
  std::vector<bool> seen(kPages, false);
  for (const ContactGeometry& contact : out) {
    ASSERT_LT(contact.feature_b, static_cast<std::uint64_t>(kPages));  // a face feature
    EXPECT_FALSE(seen[contact.feature_b]) << "face " << contact.feature_b << " twice";
    seen[contact.feature_b] = true;
    EXPECT_NEAR(contact.I_n.z(), 1.0, 1e-8);
  }
}
