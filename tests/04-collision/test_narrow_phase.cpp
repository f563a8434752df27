// Chapter 4: the narrow phase — the contact of two spheres, of a sphere and a half-space, and the
// closest point on a triangle (Exercises 4.1–4.3); sphere–box, sphere–capsule, box–half-space and
// capsule–half-space.
//
// Independent references: hand-computed gaps, normals and points of analytic configurations
// (exact in binary floating point where the test says "exact"); Eigen::Hyperplane for the
// half-space; for the triangle, the minimum over the projections onto its plane, its three edges
// and its three corners, and a dense sampling of the triangle; rigid motions of the whole
// configuration for the box.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "grbd/collision/narrow_phase.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::Matrix3;
using grbd::Vector3;
using grbd::collision::Box;
using grbd::collision::Capsule;
using grbd::collision::ContactGeometry;
using grbd::collision::HalfSpace;
using grbd::collision::Placement;
using grbd::collision::TriangleFeature;
using grbd::test::describe;
using grbd::test::WorstCase;

constexpr double kEps = std::numeric_limits<double>::epsilon();

double max_diff(const Vector3& a, const Vector3& b) { return (a - b).cwiseAbs().maxCoeff(); }

// The closest point of the segment [p, q] to x (clamped projection).
Vector3 closest_on_segment(const Vector3& x, const Vector3& p, const Vector3& q) {
  const double t = std::clamp((x - p).dot(q - p) / (q - p).squaredNorm(), 0.0, 1.0);
  return p + t * (q - p);
}

// Reference: the nearest of the projection onto the plane (when inside the triangle by its
// barycentric coordinates), the three edges and the three corners.
Vector3 reference_closest(const Vector3& x, const Vector3& a, const Vector3& b, const Vector3& c) {
  std::vector<Vector3> candidates{a,
                                  b,
                                  c,
                                  closest_on_segment(x, a, b),
                                  closest_on_segment(x, b, c),
                                  closest_on_segment(x, c, a)};
  const Vector3 n = (b - a).cross(c - a);
  const Vector3 p = x - n.dot(x - a) / n.squaredNorm() * n;
  const double area = n.norm();
  const double u = (c - b).cross(p - b).dot(n) / (area * area);
  const double v = (a - c).cross(p - c).dot(n) / (area * area);
  if (u >= 0.0 && v >= 0.0 && u + v <= 1.0) candidates.push_back(p);
  Vector3 best = a;
  for (const Vector3& y : candidates) {
    if ((y - x).squaredNorm() < (best - x).squaredNorm()) best = y;
  }
  return best;
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 4.1: the contact of two spheres
// ----------------------------------------------------------------------------------------------

// Reference: by hand; every number is exact in binary floating point. Tolerance 0.
TEST(Exercise4_1, GapNormalAndPointsOfSeparatedSpheresAreExact) {
  const ContactGeometry g =
      grbd::collision::sphere_sphere(Vector3(3.0, 0.0, 0.0), 1.0, Vector3::Zero(), 1.5);
  EXPECT_EQ(g.I_n, Vector3(1.0, 0.0, 0.0));
  EXPECT_EQ(g.g_N, 0.5);
  EXPECT_EQ(g.I_r_a, Vector3(2.0, 0.0, 0.0));
  EXPECT_EQ(g.I_r_b, Vector3(1.5, 0.0, 0.0));
}

// Reference: by hand, a 3–4–5 triangle of centres, overlapping: |c_a − c_b| = 5, g = 5 − 6 = −1,
// n = (0.6, 0.8, 0). Tolerance 2 ε.
TEST(Exercise4_1, OverlappingSpheresHaveNegativeGap) {
  const ContactGeometry g =
      grbd::collision::sphere_sphere(Vector3(4.0, 5.0, 1.0), 2.5, Vector3(1.0, 1.0, 1.0), 3.5);
  EXPECT_LE(max_diff(g.I_n, Vector3(0.6, 0.8, 0.0)), 2 * kEps);
  EXPECT_NEAR(g.g_N, -1.0, 8 * kEps);
  EXPECT_LE(max_diff(g.I_r_a, Vector3(4.0, 5.0, 1.0) - 2.5 * Vector3(0.6, 0.8, 0.0)), 8 * kEps);
  EXPECT_LE(max_diff(g.I_r_b, Vector3(1.0, 1.0, 1.0) + 3.5 * Vector3(0.6, 0.8, 0.0)), 8 * kEps);
}

// Reference: the declaration: coincident centres take n = e_z; g = −(r_a + r_b). Exact.
TEST(Exercise4_1, CoincidentCentresTakeTheNormalEz) {
  const Vector3 c(0.25, -1.0, 2.0);
  const ContactGeometry g = grbd::collision::sphere_sphere(c, 0.5, c, 0.75);
  EXPECT_EQ(g.I_n, Vector3::UnitZ());
  EXPECT_EQ(g.g_N, -1.25);
  EXPECT_EQ(g.I_r_a, c - 0.5 * Vector3::UnitZ());
  EXPECT_EQ(g.I_r_b, c + 0.75 * Vector3::UnitZ());
}

// Reference: the pair swapped: n flips, g_N is the same, the points swap; and
// g_N = nᵀ(r_a − r_b). Seeded random spheres; tolerance 1e-14 (lengths ≤ ~5).
TEST(Exercise4_1, SwappingThePairFlipsTheNormalAndSwapsThePoints) {
  grbd::test::Random rng(4101);
  for (int k = 0; k < 1000; ++k) {
    const Vector3 c_a = rng.vector3(), c_b = rng.vector3();
    const double r_a = rng.uniform(0.1, 1.0), r_b = rng.uniform(0.1, 1.0);
    const ContactGeometry ab = grbd::collision::sphere_sphere(c_a, r_a, c_b, r_b);
    const ContactGeometry ba = grbd::collision::sphere_sphere(c_b, r_b, c_a, r_a);
    EXPECT_LE(max_diff(ab.I_n, -ba.I_n), 1e-14);
    EXPECT_NEAR(ab.g_N, ba.g_N, 1e-14);
    EXPECT_LE(max_diff(ab.I_r_a, ba.I_r_b), 1e-14);
    EXPECT_LE(max_diff(ab.I_r_b, ba.I_r_a), 1e-14);
    EXPECT_NEAR(ab.g_N, ab.I_n.dot(ab.I_r_a - ab.I_r_b), 1e-14);
    EXPECT_NEAR(ab.I_n.norm(), 1.0, 1e-15);
  }
}

// ----------------------------------------------------------------------------------------------
// Exercise 4.2: the contact of a sphere and a half-space
// ----------------------------------------------------------------------------------------------

// Reference: by hand, exact: the plane z = 0.5, centre (1, 2, 3), radius 1.
TEST(Exercise4_2, SphereAboveAHorizontalPlaneIsExact) {
  const ContactGeometry g = grbd::collision::sphere_half_space(Vector3(1.0, 2.0, 3.0), 1.0,
                                                               HalfSpace{Vector3::UnitZ(), 0.5});
  EXPECT_EQ(g.I_n, Vector3::UnitZ());
  EXPECT_EQ(g.g_N, 1.5);
  EXPECT_EQ(g.I_r_a, Vector3(1.0, 2.0, 2.0));
  EXPECT_EQ(g.I_r_b, Vector3(1.0, 2.0, 0.5));
}

// Reference: Eigen::Hyperplane (signed distance, projection) on seeded random planes and
// spheres, penetrating ones included. Tolerance 1e-14.
TEST(Exercise4_2, MatchesEigenHyperplane) {
  grbd::test::Random rng(4201);
  int penetrating = 0;
  for (int k = 0; k < 1000; ++k) {
    const Vector3 n = rng.unit_vector3();
    const double offset = rng.uniform();
    const Vector3 c = rng.vector3(-2.0, 2.0);
    const double r = rng.uniform(0.1, 1.0);
    const Eigen::Hyperplane<double, 3> plane(n, -offset);
    const ContactGeometry g = grbd::collision::sphere_half_space(c, r, HalfSpace{n, offset});
    EXPECT_NEAR(g.g_N, plane.signedDistance(c) - r, 1e-14);
    EXPECT_LE(max_diff(g.I_r_b, plane.projection(c)), 1e-14);
    EXPECT_LE(max_diff(g.I_r_a, c - r * n), 1e-14);
    EXPECT_EQ(g.I_n, n);
    penetrating += g.g_N < 0.0;
  }
  EXPECT_GT(penetrating, 100);
}

// ----------------------------------------------------------------------------------------------
// Exercise 4.3: the closest point on a triangle
// ----------------------------------------------------------------------------------------------

// Reference: projection onto each feature (reference_closest) on seeded random triangles and
// points, tolerance 1e-12; and a dense barycentric sampling (60 × 60 grid): no sample is closer
// than the answer by more than 1e-12.
TEST(Exercise4_3, MatchesProjectionOntoEachFeatureAndDenseSampling) {
  grbd::test::Random rng(4301);
  WorstCase worst;
  for (int k = 0; k < 2000; ++k) {
    const Vector3 a = rng.vector3(), b = rng.vector3(), c = rng.vector3();
    const Vector3 x = rng.vector3(-2.0, 2.0);
    const Vector3 p = grbd::collision::closest_point_on_triangle(x, a, b, c).point;
    worst.update(max_diff(p, reference_closest(x, a, b, c)), k,
                 [&] { return describe("x", x, "a", a, "b", b, "c", c, "found", p); });
    if (k < 100) {
      const double d = (p - x).norm();
      constexpr int kSamples = 60;
      for (int i = 0; i <= kSamples; ++i) {
        for (int j = 0; i + j <= kSamples; ++j) {
          const Vector3 y = a + (double(i) / kSamples) * (b - a) + (double(j) / kSamples) * (c - a);
          EXPECT_GE((y - x).norm(), d - 1e-12);
        }
      }
    }
  }
  EXPECT_LE(worst.value(), 1e-12) << worst;
}

// Reference: by hand, for the triangle (0, 0, 0), (2, 0, 0), (0, 2, 0): points exactly on the
// corners and edges, above them, and in each region get the exact feature and point.
TEST(Exercise4_3, ClassifiesFeaturesExactlyOnEdgesAndVertices) {
  const Vector3 a(0.0, 0.0, 0.0), b(2.0, 0.0, 0.0), c(0.0, 2.0, 0.0);
  struct Case {
    Vector3 x;
    TriangleFeature feature;
    Vector3 point;
  };
  const std::vector<Case> cases{
      {a, TriangleFeature::vertex_a, a},
      {b, TriangleFeature::vertex_b, b},
      {c, TriangleFeature::vertex_c, c},
      {Vector3(-1.0, -1.0, 3.0), TriangleFeature::vertex_a, a},
      {Vector3(5.0, 0.0, 0.0), TriangleFeature::vertex_b, b},
      {Vector3(-1.0, 4.0, -1.0), TriangleFeature::vertex_c, c},
      {Vector3(1.0, 0.0, 0.0), TriangleFeature::edge_ab, Vector3(1.0, 0.0, 0.0)},
      {Vector3(1.0, 0.0, 5.0), TriangleFeature::edge_ab, Vector3(1.0, 0.0, 0.0)},
      {Vector3(1.0, -3.0, 0.0), TriangleFeature::edge_ab, Vector3(1.0, 0.0, 0.0)},
      {Vector3(1.0, 1.0, 0.0), TriangleFeature::edge_bc, Vector3(1.0, 1.0, 0.0)},
      {Vector3(2.0, 2.0, -3.0), TriangleFeature::edge_bc, Vector3(1.0, 1.0, 0.0)},
      {Vector3(0.0, 1.0, 0.0), TriangleFeature::edge_ca, Vector3(0.0, 1.0, 0.0)},
      {Vector3(-4.0, 1.0, 2.0), TriangleFeature::edge_ca, Vector3(0.0, 1.0, 0.0)},
      {Vector3(0.5, 0.5, 1.0), TriangleFeature::face, Vector3(0.5, 0.5, 0.0)},
      {Vector3(0.5, 0.25, 0.0), TriangleFeature::face, Vector3(0.5, 0.25, 0.0)},
  };
  for (const Case& test : cases) {
    const auto result = grbd::collision::closest_point_on_triangle(test.x, a, b, c);
    EXPECT_EQ(result.feature, test.feature) << "x = " << test.x.transpose();
    EXPECT_EQ(result.point, test.point) << "x = " << test.x.transpose();
  }
}

// ----------------------------------------------------------------------------------------------
// Sphere–box and sphere–capsule
// ----------------------------------------------------------------------------------------------

// Reference: by hand for the box [−1, 1] × [−2, 2] × [−3, 3]: a face, an edge, a vertex and a
// centre inside the box. Tolerance 4 ε.
TEST(SphereBox, FaceEdgeVertexAndInsideAreExact) {
  using grbd::collision::edge_feature;
  using grbd::collision::face_feature;
  using grbd::collision::vertex_feature;
  const Box box{Vector3(1.0, 2.0, 3.0)};
  const Placement at_origin;
  ContactGeometry g = grbd::collision::sphere_box(Vector3(3.0, 0.5, 0.5), 1.0, box, at_origin);
  EXPECT_EQ(g.I_n, Vector3::UnitX());
  EXPECT_EQ(g.g_N, 1.0);
  EXPECT_EQ(g.I_r_b, Vector3(1.0, 0.5, 0.5));
  EXPECT_EQ(g.I_r_a, Vector3(2.0, 0.5, 0.5));
  EXPECT_EQ(g.feature_b, face_feature(1));

  g = grbd::collision::sphere_box(Vector3(2.0, 3.0, 0.0), 1.0, box, at_origin);
  EXPECT_LE(max_diff(g.I_n, Vector3(1.0, 1.0, 0.0) / std::sqrt(2.0)), 4 * kEps);
  EXPECT_NEAR(g.g_N, std::sqrt(2.0) - 1.0, 4 * kEps);
  EXPECT_EQ(g.I_r_b, Vector3(1.0, 2.0, 0.0));
  EXPECT_EQ(g.feature_b, edge_feature(4 * 2 + 1 + 2));  // parallel to z, at x > 0, y > 0

  g = grbd::collision::sphere_box(Vector3(-2.0, -3.0, 4.0), 0.5, box, at_origin);
  EXPECT_LE(max_diff(g.I_n, Vector3(-1.0, -1.0, 1.0) / std::sqrt(3.0)), 4 * kEps);
  EXPECT_NEAR(g.g_N, std::sqrt(3.0) - 0.5, 4 * kEps);
  EXPECT_EQ(g.I_r_b, Vector3(-1.0, -2.0, 3.0));
  EXPECT_EQ(g.feature_b, vertex_feature(4));

  // Centre inside, nearest face −y (depth 0.5): pushed out through it.
  g = grbd::collision::sphere_box(Vector3(0.25, -1.5, 1.0), 0.5, box, at_origin);
  EXPECT_EQ(g.I_n, -Vector3::UnitY());
  EXPECT_EQ(g.g_N, -1.0);
  EXPECT_EQ(g.I_r_b, Vector3(0.25, -2.0, 1.0));
  EXPECT_EQ(g.I_r_a, Vector3(0.25, -1.0, 1.0));
  EXPECT_EQ(g.feature_b, face_feature(2));

  // Centre exactly on the face +z: gap −r, normal +z.
  g = grbd::collision::sphere_box(Vector3(0.5, 0.5, 3.0), 0.5, box, at_origin);
  EXPECT_EQ(g.I_n, Vector3::UnitZ());
  EXPECT_EQ(g.g_N, -0.5);
  EXPECT_EQ(g.feature_b, face_feature(5));
}

// Reference: the same configuration in the box frame, moved rigidly (seeded random rotations
// and translations): n and points move with it, g_N and the feature do not. Tolerance 1e-13.
TEST(SphereBox, IsInvariantUnderRigidMotions) {
  grbd::test::Random rng(4401);
  const Box box{Vector3(0.5, 1.0, 1.5)};
  for (int k = 0; k < 500; ++k) {
    const Vector3 x_C = rng.vector3(-3.0, 3.0);
    const double r = rng.uniform(0.1, 1.0);
    const Matrix3 R = rng.rotation();
    const Vector3 t = rng.vector3();
    const ContactGeometry local = grbd::collision::sphere_box(x_C, r, box, Placement{});
    const ContactGeometry moved = grbd::collision::sphere_box(R * x_C + t, r, box, Placement{t, R});
    EXPECT_LE(max_diff(moved.I_n, R * local.I_n), 1e-13);
    EXPECT_NEAR(moved.g_N, local.g_N, 1e-13);
    EXPECT_LE(max_diff(moved.I_r_b, R * local.I_r_b + t), 1e-13);
    EXPECT_LE(max_diff(moved.I_r_a, R * local.I_r_a + t), 1e-13);
    EXPECT_EQ(moved.feature_b, local.feature_b);
  }
}

// Reference: by hand for the capsule along z (half length 1, radius 0.5): beside the segment,
// beyond an end. Exact.
TEST(SphereCapsule, SideAndEndAreExact) {
  const Capsule capsule{0.5, 1.0};
  ContactGeometry g =
      grbd::collision::sphere_capsule(Vector3(2.0, 0.0, 0.25), 0.5, capsule, Placement{});
  EXPECT_EQ(g.I_n, Vector3::UnitX());
  EXPECT_EQ(g.g_N, 1.0);
  EXPECT_EQ(g.I_r_b, Vector3(0.5, 0.0, 0.25));
  g = grbd::collision::sphere_capsule(Vector3(0.0, 0.0, -3.0), 0.5, capsule, Placement{});
  EXPECT_EQ(g.I_n, -Vector3::UnitZ());
  EXPECT_EQ(g.g_N, 1.0);
  EXPECT_EQ(g.I_r_b, Vector3(0.0, 0.0, -1.5));
}

// ----------------------------------------------------------------------------------------------
// Box–half-space and capsule–half-space
// ----------------------------------------------------------------------------------------------

// Reference: by hand: the cube [−1, 1]³ resting on z = 0 touches with its 4 lower vertices
// (0–3), g = 0 exactly; raised by 0.25, the margin decides; standing on an edge (rotated 45°
// about x), 2 contacts with g = 0 to 4 ε.
TEST(BoxHalfSpace, RestingFaceGivesFourContactsAndEdgeTwo) {
  const Box cube{Vector3::Ones()};
  const HalfSpace floor{Vector3::UnitZ(), 0.0};
  std::vector<ContactGeometry> out;
  grbd::collision::box_half_space(cube, Placement{Vector3(0.0, 0.0, 1.0), Matrix3::Identity()},
                                  floor, 0.0, out);
  ASSERT_EQ(out.size(), 4U);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(out[k].feature_a, k);
    EXPECT_EQ(out[k].g_N, 0.0);
    EXPECT_EQ(out[k].I_n, Vector3::UnitZ());
    EXPECT_EQ(out[k].I_r_a, out[k].I_r_b);
    EXPECT_EQ(out[k].I_r_a.z(), 0.0);
    EXPECT_EQ(std::abs(out[k].I_r_a.x()), 1.0);
  }
  out.clear();
  const Placement raised{Vector3(0.0, 0.0, 1.25), Matrix3::Identity()};
  grbd::collision::box_half_space(cube, raised, floor, 0.125, out);
  EXPECT_TRUE(out.empty());
  grbd::collision::box_half_space(cube, raised, floor, 0.25, out);
  ASSERT_EQ(out.size(), 4U);
  EXPECT_EQ(out[0].g_N, 0.25);

  out.clear();
  const Matrix3 R = Eigen::AngleAxisd(M_PI / 4, Vector3::UnitX()).toRotationMatrix();
  grbd::collision::box_half_space(cube, Placement{Vector3(0.0, 0.0, std::sqrt(2.0)), R}, floor,
                                  1e-12, out);
  ASSERT_EQ(out.size(), 2U);
  for (const ContactGeometry& g : out) EXPECT_NEAR(g.g_N, 0.0, 4 * kEps);
  EXPECT_NEAR(out[0].I_r_a.x(), -1.0, 4 * kEps);
  EXPECT_NEAR(out[1].I_r_a.x(), 1.0, 4 * kEps);
}

// Reference: by hand: a capsule (radius 0.5, half length 1) lying parallel to the plane z = 0
// with its axis at height 0.5 touches with both ends (2 contacts, g = 0, at x = ±1); tilted, only
// the lower end is within the margin.
TEST(CapsuleHalfSpace, ParallelCapsuleGivesTwoContacts) {
  const Capsule capsule{0.5, 1.0};
  const HalfSpace floor{Vector3::UnitZ(), 0.0};
  Matrix3 lying;  // the capsule axis e_z of C along e_x of I
  lying << 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0;
  std::vector<ContactGeometry> out;
  grbd::collision::capsule_half_space(capsule, Placement{Vector3(0.0, 0.0, 0.5), lying}, floor, 0.0,
                                      out);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(out[0].feature_a, 0U);
  EXPECT_EQ(out[1].feature_a, 1U);
  EXPECT_EQ(out[0].I_r_b, Vector3(-1.0, 0.0, 0.0));
  EXPECT_EQ(out[1].I_r_b, Vector3(1.0, 0.0, 0.0));
  for (const ContactGeometry& g : out) {
    EXPECT_EQ(g.g_N, 0.0);
    EXPECT_EQ(g.I_n, Vector3::UnitZ());
  }
  out.clear();
  const Matrix3 tilted = Eigen::AngleAxisd(0.3, Vector3::UnitX()).toRotationMatrix();
  grbd::collision::capsule_half_space(capsule, Placement{Vector3(0.0, 0.0, 2.0), tilted}, floor,
                                      1.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].feature_a, 0U);
  EXPECT_NEAR(out[0].g_N, 2.0 - std::cos(0.3) - 0.5, 4 * kEps);
}
