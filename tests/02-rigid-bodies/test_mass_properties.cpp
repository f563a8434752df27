// Chapter 2: mass properties of closed triangle meshes (Exercises 2.1 and 2.2, and the core
// functions of mass_properties.hpp).
//
// Independent references, written out in this file (the box table in grbd_test/bodies.hpp):
// - the affine image of the unit corner tetrahedron T0 = {ξ ≥ 0, Σξ ≤ 1}, whose moments are
//   Dirichlet integrals, ∫_T0 ξ^a η^b ζ^c = a! b! c! / (a + b + c + 3)!: |T0| = 1/6,
//   ∫ ξ = 1/24, ∫ ξ² = 1/60, ∫ ξη = 1/120, so ∫ ξξᵀ = (I + 11ᵀ)/120;
// - Tonon (2004), "Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of its
//   vertex coordinates", J. Math. Stat. 1(1), for a general tetrahedron;
// - the tables of moments of inertia (box, sphere, cylinder, torus), the regular n-gon prism
//   (derived below), and the parallel-axis (Steiner) theorem for the capsule;
// - the convergence of inscribed meshes of sphere, torus and cylinder at second order in the
//   edge length h, and invariance under rigid motions (seeded random).
//
// Tolerances are relative to the size of the compared quantity unless a comment says otherwise:
// polyhedra (box, tetrahedra, prisms) are exact up to round-off, 1e-14…1e-12 depending on how
// many digits Steiner's shift cancels; meshes of curved solids are judged by their observed
// order of convergence, which must lie in [1.8, 2.2].

#include <gtest/gtest.h>

#include <Eigen/Geometry>  // cross()
#include <Eigen/LU>        // determinant()
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "grbd/body/mass_properties.hpp"
#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/bodies.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::Matrix3;
using grbd::Vector3;
using grbd::body::inertia_about_centre_of_mass;
using grbd::body::mass_properties;
using grbd::body::MassProperties;
using grbd::body::principal_axes;
using grbd::body::PrincipalAxes;
using grbd::body::tetrahedron_integrals;
using grbd::body::TriangleMesh;
using grbd::body::VolumeIntegrals;
using grbd::test::box_inertia;
using grbd::test::describe;
using grbd::test::max_abs;
using grbd::test::WorstCase;

constexpr double pi = std::numbers::pi;

/// Relative distance of two tensors, measured by the larger entry of the expected one.
double relative(const Matrix3& found, const Matrix3& expected) {
  return max_abs(found - expected) / max_abs(expected);
}

/// The message of the grbd::InvalidArgument that `call` throws, or a failure if it throws none.
template <class F>
std::string invalid_argument_message(F&& call) {
  try {
    call();
  } catch (const grbd::InvalidArgument& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a grbd::InvalidArgument, none was thrown";
  return {};
}

/// The parallel-axis term m (dᵀd I − d dᵀ) for a shift d.
Matrix3 steiner(double mass, const Vector3& d) {
  return mass * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose());
}

/// The volume integrals of the tetrahedron x = p0 + J ξ, ξ ∈ T0 (J = [p1 − p0, p2 − p0,
/// p3 − p0]), signed by det J, from the Dirichlet integrals of T0.
VolumeIntegrals affine_tetrahedron(const Vector3& p0, const Vector3& p1, const Vector3& p2,
                                   const Vector3& p3) {
  Matrix3 J;
  J << p1 - p0, p2 - p0, p3 - p0;
  const double det = J.determinant();
  const Vector3 m1 = J * Vector3::Constant(1.0 / 24.0);  // ∫ Jξ dξ
  const Matrix3 M2 = (Matrix3::Identity() + Matrix3::Ones()) / 120.0;
  VolumeIntegrals I;
  I.volume = det / 6.0;
  I.first = det * (p0 / 6.0 + m1);
  I.second = det * (p0 * p0.transpose() / 6.0 + p0 * m1.transpose() + m1 * p0.transpose() +
                    J * M2 * J.transpose());
  return I;
}

/// The analytic volume integrals of the box [lo.x, hi.x] × [lo.y, hi.y] × [lo.z, hi.z]:
/// products of the one-dimensional moments ∫ 1, ∫ u, ∫ u² over each interval.
VolumeIntegrals box_integrals(const Vector3& lo, const Vector3& hi) {
  const Vector3 m0 = hi - lo;
  const Vector3 m1 = (hi.cwiseAbs2() - lo.cwiseAbs2()) / 2.0;
  const Vector3 m2 =
      (hi.cwiseProduct(hi).cwiseProduct(hi) - lo.cwiseProduct(lo).cwiseProduct(lo)) / 3.0;
  VolumeIntegrals I;
  I.volume = m0.prod();
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const int k = (i + 2) % 3;
    I.first[i] = m1[i] * m0[j] * m0[k];
    I.second(i, i) = m2[i] * m0[j] * m0[k];
    I.second(i, j) = I.second(j, i) = m1[i] * m1[j] * m0[k];
  }
  return I;
}

/// Cylinder table: Θ_S = diag(m(3R² + h²)/12, m(3R² + h²)/12, mR²/2) about the axis z.
Matrix3 cylinder_inertia(double mass, double R, double h) {
  return Vector3(mass * (3 * R * R + h * h) / 12.0, mass * (3 * R * R + h * h) / 12.0,
                 0.5 * mass * R * R)
      .asDiagonal();
}

/// The unit corner tetrahedron's Θ_S for ρ = 1 (Tonon 2004): diagonal 1/80, off-diagonal 1/480.
Matrix3 corner_tetrahedron_inertia() {
  Matrix3 Theta = Matrix3::Constant(1.0 / 480.0);
  Theta.diagonal().setConstant(1.0 / 80.0);
  return Theta;
}

/// Tonon (2004), the formulas for a, b, c, a', b', c': the inertia tensor about the centroid of
/// the tetrahedron with vertices p[0..3] and density ρ, coordinates taken from the centroid:
///   a = ρ|det J|/60 Σ_{i≤j} (y_i y_j + z_i z_j)  (= Θ_xx; b = Θ_yy, c = Θ_zz likewise),
///   a' = ρ|det J|/120 (Σ_i 2 y_i z_i + Σ_{i≠j} y_i z_j)  (= ∫ρyz; b' = ∫ρxz, c' = ∫ρxy),
/// and the products of inertia enter Θ with a minus sign: Θ_yz = −a', Θ_xz = −b', Θ_xy = −c'.
Matrix3 tonon_inertia(const std::array<Vector3, 4>& p, double density) {
  const Vector3 centroid = (p[0] + p[1] + p[2] + p[3]) / 4.0;
  std::array<Vector3, 4> x;
  for (int i = 0; i < 4; ++i) x[i] = p[i] - centroid;
  Matrix3 J;
  J << x[1] - x[0], x[2] - x[0], x[3] - x[0];
  const double det = std::abs(J.determinant());
  auto square_sum = [&](int u) {  // Σ_{i≤j} u_i u_j
    double s = 0.0;
    for (int i = 0; i < 4; ++i) {
      for (int j = i; j < 4; ++j) s += x[i][u] * x[j][u];
    }
    return s;
  };
  auto product_sum = [&](int u, int v) {  // Σ_i 2 u_i v_i + Σ_{i≠j} u_i v_j
    double s = 0.0;
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) s += (i == j ? 2.0 : 1.0) * x[i][u] * x[j][v];
    }
    return s;
  };
  const double a = density * det / 60.0 * (square_sum(1) + square_sum(2));
  const double b = density * det / 60.0 * (square_sum(0) + square_sum(2));
  const double c = density * det / 60.0 * (square_sum(0) + square_sum(1));
  const double a_p = density * det / 120.0 * product_sum(1, 2);
  const double b_p = density * det / 120.0 * product_sum(0, 2);
  const double c_p = density * det / 120.0 * product_sum(0, 1);
  Matrix3 Theta;
  Theta << a, -c_p, -b_p, -c_p, b, -a_p, -b_p, -a_p, c;
  return Theta;
}

/// Observed orders p_k = log(e_k / e_{k+1}) / log(h_k / h_{k+1}) of successive refinements.
std::vector<double> observed_orders(const std::vector<double>& errors,
                                    const std::vector<double>& h) {
  std::vector<double> orders;
  for (std::size_t k = 0; k + 1 < errors.size(); ++k) {
    orders.push_back(std::log(errors[k] / errors[k + 1]) / std::log(h[k] / h[k + 1]));
  }
  return orders;
}

/// The mean edge length of a mesh (each edge counted once per face side; all edges of a closed
/// mesh are counted twice, which does not change the mean).
double mean_edge_length(const TriangleMesh& mesh) {
  double sum = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      sum += (mesh.V.row(mesh.F(f, k)) - mesh.V.row(mesh.F(f, (k + 1) % 3))).norm();
    }
  }
  return sum / (3.0 * static_cast<double>(mesh.F.rows()));
}

void expect_second_order(const std::vector<double>& errors, const std::vector<double>& h,
                         const std::string& what) {
  const std::vector<double> orders = observed_orders(errors, h);
  for (std::size_t k = 0; k < orders.size(); ++k) {
    EXPECT_GE(orders[k], 1.8) << what << ", refinement " << k << ": errors " << errors[k] << " → "
                              << errors[k + 1];
    EXPECT_LE(orders[k], 2.2) << what << ", refinement " << k << ": errors " << errors[k] << " → "
                              << errors[k + 1];
    ::testing::Test::RecordProperty(what + "_order_" + std::to_string(k),
                                    std::to_string(orders[k]));
  }
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 2.1: the volume integrals of one surface triangle
// ----------------------------------------------------------------------------------------------

// Reference: the Dirichlet integrals of the unit corner tetrahedron (0, e_x, e_y, e_z):
// V = 1/6, ∫x = (1/24)(1, 1, 1), ∫x² = 1/60, ∫xy = 1/120. Exact up to 1e-17 absolute (the
// results are of order 0.01: a few ulps).
TEST(Exercise2_1, UnitCornerTetrahedronHasTheDirichletIntegrals) {
  const VolumeIntegrals I =
      tetrahedron_integrals(Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ());
  Matrix3 second;
  second << 2, 1, 1, 1, 2, 1, 1, 1, 2;
  second /= 120.0;
  EXPECT_NEAR(I.volume, 1.0 / 6.0, 1e-17);
  EXPECT_LE((I.first - Vector3::Constant(1.0 / 24.0)).cwiseAbs().maxCoeff(), 1e-17);
  EXPECT_LE(max_abs(I.second - second), 1e-17);
}

// Reference: the affine image of T0 (see the top of the file) for random triangles (a, b, c)
// with the fourth vertex at the origin. Tolerance 1e-14 relative to |a||b||c|, the size of the
// triple product before its cancellation (measured 5e-17); relative to V itself the error of a
// nearly flat tetrahedron may be much larger, in both computations alike.
TEST(Exercise2_1, RandomTrianglesMatchTheAffineImageOfTheCornerTetrahedron) {
  grbd::test::Random rng(2101);
  WorstCase worst;
  for (int n = 0; n < 1000; ++n) {
    const Vector3 a = rng.vector3(), b = rng.vector3(), c = rng.vector3();
    const VolumeIntegrals I = tetrahedron_integrals(a, b, c);
    const VolumeIntegrals ref = affine_tetrahedron(Vector3::Zero(), a, b, c);
    const double scale = a.norm() * b.norm() * c.norm();  // |x| ≤ √3: all moments ≲ 3 scale
    const auto inputs = [&] { return describe("a", a, "b", b, "c", c); };
    worst.update(std::abs(I.volume - ref.volume) / scale, n,
                 [&] { return "volume, " + inputs(); });
    worst.update((I.first - ref.first).cwiseAbs().maxCoeff() / scale, n,
                 [&] { return "first moments, " + inputs(); });
    worst.update(max_abs(I.second - ref.second) / scale, n,
                 [&] { return "second moments, " + inputs(); });
  }
  EXPECT_LE(worst.value(), 1e-14) << worst;
}

// Reference: the orientation rule: (a, c, b) is (a, b, c) seen from the other side, so every
// integral changes sign. Tolerance 1e-15 relative to |a||b||c| (the formula may be evaluated in
// another order, e.g. (a × b)·c, so the negation need not be exact).
TEST(Exercise2_1, ReversingTheTriangleNegatesEveryIntegral) {
  grbd::test::Random rng(2102);
  WorstCase worst;
  for (int n = 0; n < 100; ++n) {
    const Vector3 a = rng.vector3(), b = rng.vector3(), c = rng.vector3();
    const VolumeIntegrals I = tetrahedron_integrals(a, b, c);
    const VolumeIntegrals J = tetrahedron_integrals(a, c, b);
    const double scale = a.norm() * b.norm() * c.norm();
    const auto inputs = [&] { return describe("a", a, "b", b, "c", c); };
    worst.update(std::abs(J.volume + I.volume) / scale, n, [&] { return "volume, " + inputs(); });
    worst.update((J.first + I.first).cwiseAbs().maxCoeff() / scale, n,
                 [&] { return "first moments, " + inputs(); });
    worst.update(max_abs(J.second + I.second) / scale, n,
                 [&] { return "second moments, " + inputs(); });
  }
  EXPECT_LE(worst.value(), 1e-15) << worst;
}

// Reference: the divergence theorem: over the four outward faces of any tetrahedron the
// contributions sum to the tetrahedron's own integrals (the affine image of T0), whatever the
// position of the origin. Tolerance 1e-12 relative: vertices up to 3 from the origin make the
// single contributions up to ~100 times larger than their sum.
TEST(Exercise2_1, ContributionsOfTheFacesOfATetrahedronSumToItsIntegrals) {
  grbd::test::Random rng(2103);
  WorstCase worst;
  for (int n = 0; n < 300; ++n) {
    const Vector3 offset = rng.vector3(-2, 2);
    std::array<Vector3, 4> p = {offset + rng.vector3(), offset + rng.vector3(),
                                offset + rng.vector3(), offset + rng.vector3()};
    if ((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) < 0.0) std::swap(p[1], p[2]);
    const VolumeIntegrals ref = affine_tetrahedron(p[0], p[1], p[2], p[3]);
    if (ref.volume < 1e-3) continue;  // nearly flat: the relative error means little
    VolumeIntegrals sum = tetrahedron_integrals(p[0], p[2], p[1]);
    sum += tetrahedron_integrals(p[0], p[1], p[3]);
    sum += tetrahedron_integrals(p[0], p[3], p[2]);
    sum += tetrahedron_integrals(p[1], p[2], p[3]);
    const auto inputs = [&] { return describe("vertices", p); };
    worst.update(std::abs(sum.volume - ref.volume) / ref.volume, n,
                 [&] { return "volume, " + inputs(); });
    worst.update((sum.first - ref.first).cwiseAbs().maxCoeff() / ref.first.cwiseAbs().maxCoeff(),
                 n, [&] { return "first moments, " + inputs(); });
    worst.update(relative(sum.second, ref.second), n,
                 [&] { return "second moments, " + inputs(); });
  }
  EXPECT_LE(worst.value(), 1e-12) << worst;
}

// ----------------------------------------------------------------------------------------------
// Exercise 2.2: the inertia tensor about the centre of mass
// ----------------------------------------------------------------------------------------------
//
// The integrals are built analytically here, not with Exercise 2.1, so that 2.2 is graded on
// its own.

// Reference: the box table Θ_S = m/3 diag(b² + c², a² + c², a² + b²), from the analytic moments
// of boxes placed anywhere in [−3, 3]³. Tolerance 1e-12 relative: moments about the origin up to
// ~40 times Θ_S lose about two digits in Steiner's shift.
TEST(Exercise2_2, OffsetBoxesHaveTheBoxTableInertia) {
  grbd::test::Random rng(2201);
  WorstCase worst;
  for (int n = 0; n < 300; ++n) {
    const Vector3 centre = rng.vector3(-2, 2);
    const Vector3 h = rng.vector3(0.2, 1.0);
    const double density = rng.uniform(500.0, 8000.0);
    const Matrix3 Theta =
        inertia_about_centre_of_mass(box_integrals(centre - h, centre + h), density);
    worst.update(relative(Theta, box_inertia(h, density * 8.0 * h.prod())), n,
                 [&] { return describe("centre", centre, "h", h, "density", density); });
  }
  EXPECT_LE(worst.value(), 1e-12) << worst;
}

// Reference: the unit corner tetrahedron's Dirichlet integrals give, with ρ = 1, Θ_S with
// diagonal 1/80 and off-diagonal 1/480 (Tonon 2004: a = b = c = 1/80 and a' = b' = c' = −1/480
// about the centroid, the products of inertia entering Θ with a minus sign). Tolerance 1e-14
// relative.
TEST(Exercise2_2, UnitCornerTetrahedronHasTononsInertia) {
  VolumeIntegrals I;
  I.volume = 1.0 / 6.0;
  I.first = Vector3::Constant(1.0 / 24.0);
  I.second = (Matrix3::Identity() + Matrix3::Ones()) / 120.0;
  const Matrix3 expected = corner_tetrahedron_inertia();
  EXPECT_LE(relative(inertia_about_centre_of_mass(I, 1.0), expected), 1e-14);
  EXPECT_LE(relative(inertia_about_centre_of_mass(I, 2700.0), 2700.0 * expected), 1e-14);
}

// Reference: a rigid motion x = A y + r of a box centred at the origin: V, ∫x = V r and
// ∫x xᵀ = A (∫y yᵀ) Aᵀ + V r rᵀ, with ∫y yᵀ = V/3 diag(a², b², c²); the inertia about S must be
// A Θ_box Aᵀ. Seeded random motions; tolerance 1e-12 relative (as for the offset boxes).
TEST(Exercise2_2, RotatedTranslatedSolidsHaveTheRotatedInertia) {
  grbd::test::Random rng(2202);
  WorstCase worst;
  for (int n = 0; n < 300; ++n) {
    const Matrix3 A = rng.rotation();
    const Vector3 r = rng.vector3(-2, 2);
    const Vector3 h = rng.vector3(0.2, 1.0);
    const double density = rng.uniform(500.0, 8000.0);
    VolumeIntegrals I;
    I.volume = 8.0 * h.prod();
    I.first = I.volume * r;
    const Matrix3 C = (I.volume / 3.0 * h.cwiseAbs2()).asDiagonal();
    I.second = A * C * A.transpose() + I.volume * r * r.transpose();
    const Matrix3 Theta = inertia_about_centre_of_mass(I, density);
    const Matrix3 expected = A * box_inertia(h, density * I.volume) * A.transpose();
    worst.update(relative(Theta, expected), n,
                 [&] { return describe("A", A, "r", r, "h", h, "density", density); });
  }
  EXPECT_LE(worst.value(), 1e-12) << worst;
}

// ----------------------------------------------------------------------------------------------
// mass_properties of meshes
// ----------------------------------------------------------------------------------------------

// Reference: the box table (m = 8ρabc, Θ_S = m/3 diag(b² + c², a² + c², a² + b²), r_S = centre),
// for box meshes at the origin and shifted. The mesh is the polyhedron itself, so the result is
// exact up to round-off: 1e-14 relative (measured ≤ 2e-15).
TEST(MassProperties, BoxMeshIsExact) {
  grbd::test::Random rng(2301);
  for (int n = 0; n < 50; ++n) {
    const Vector3 h = rng.vector3(0.1, 2.0);
    const Vector3 r = n == 0 ? Vector3::Zero() : rng.vector3(-5, 5);
    const double density = rng.uniform(500.0, 8000.0);
    const TriangleMesh mesh =
        grbd::body::transformed(grbd::body::box_mesh(h), Matrix3::Identity(), r);
    const MassProperties props = mass_properties(mesh, density, "box");
    const double volume = 8.0 * h.prod();
    EXPECT_NEAR(props.volume, volume, 1e-14 * volume);
    EXPECT_NEAR(props.mass, density * volume, 1e-14 * density * volume);
    EXPECT_LE((props.M_r_S - r).cwiseAbs().maxCoeff(), 1e-14 * (r.norm() + h.norm()));
    EXPECT_LE(relative(props.M_Theta_S, box_inertia(h, density * volume)), 1e-14);
  }
}

// Reference: the unit corner tetrahedron: V = 1/6, r_S = (1/4)(1, 1, 1), and with ρ = 1 the
// inertia of Exercise2_2.UnitCornerTetrahedronHasTononsInertia. Exact: 1e-14 relative (measured
// 8e-16, a few ulps).
TEST(MassProperties, UnitCornerTetrahedronMeshIsExact) {
  const TriangleMesh mesh = grbd::body::tetrahedron_mesh(Vector3::Zero(), Vector3::UnitX(),
                                                         Vector3::UnitY(), Vector3::UnitZ());
  const MassProperties props = mass_properties(mesh, 1.0, "corner tetrahedron");
  EXPECT_NEAR(props.volume, 1.0 / 6.0, 1e-16);
  EXPECT_NEAR(props.mass, 1.0 / 6.0, 1e-16);
  EXPECT_LE((props.M_r_S - Vector3::Constant(0.25)).cwiseAbs().maxCoeff(), 1e-16);
  EXPECT_LE(relative(props.M_Theta_S, corner_tetrahedron_inertia()), 1e-14);
}

// Reference: Tonon's (2004) formulas for general tetrahedra (random, seeded). Tolerance 1e-12
// relative: thin random tetrahedra lose a few digits in both computations.
TEST(MassProperties, GeneralTetrahedronMatchesTonon) {
  grbd::test::Random rng(2302);
  WorstCase worst;
  for (int n = 0; n < 200; ++n) {
    const Vector3 offset = rng.vector3(-3, 3);
    const std::array<Vector3, 4> p = {offset + rng.vector3(), offset + rng.vector3(),
                                      offset + rng.vector3(), offset + rng.vector3()};
    const double volume = std::abs((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))) / 6.0;
    if (volume < 1e-2) continue;
    const double density = rng.uniform(500.0, 8000.0);
    const MassProperties props =
        mass_properties(grbd::body::tetrahedron_mesh(p[0], p[1], p[2], p[3]), density);
    EXPECT_NEAR(props.volume, volume, 1e-13 * volume);
    const Vector3 centroid = (p[0] + p[1] + p[2] + p[3]) / 4.0;
    EXPECT_LE((props.M_r_S - centroid).cwiseAbs().maxCoeff(), 1e-13 * (1.0 + centroid.norm()));
    worst.update(relative(props.M_Theta_S, tonon_inertia(p, density)), n,
                 [&] { return describe("vertices", p, "density", density); });
  }
  EXPECT_LE(worst.value(), 1e-12) << worst;
}

// Reference: the regular n-gon prism inscribed in the cylinder (circumradius R, height h), made
// of n triangles (0, p_i, p_{i+1}) with apex angle α = 2π/n: area A = (n/2) R² sin α; polar
// moment J = Σ (A_t/6)(|p|² + |q|² + p·q) = n R⁴ sin α (2 + cos α)/12; a regular polygon (n ≥ 3)
// has isotropic in-plane second moments J/2. So m = ρAh, Θ_zz = ρhJ, Θ_xx = Θ_yy =
// ρ(hJ/2 + Ah³/12). cylinder_mesh is that prism: exact, 1e-13 relative.
TEST(MassProperties, CylinderMeshIsTheExactRegularPrism) {
  const double R = 0.35;
  const double h = 1.7;
  const double density = 7850.0;
  for (const int n : {3, 5, 12, 64}) {
    const MassProperties props = mass_properties(grbd::body::cylinder_mesh(R, h, n), density);
    const double alpha = 2.0 * pi / n;
    const double area = 0.5 * n * R * R * std::sin(alpha);
    const double J = n * std::pow(R, 4) * std::sin(alpha) * (2.0 + std::cos(alpha)) / 12.0;
    const double transverse = density * (h * J / 2.0 + area * h * h * h / 12.0);
    const Matrix3 expected = Vector3(transverse, transverse, density * h * J).asDiagonal();
    EXPECT_NEAR(props.mass, density * area * h, 1e-13 * density * area * h) << "n = " << n;
    EXPECT_LE(props.M_r_S.norm(), 1e-15) << "n = " << n;
    EXPECT_LE(relative(props.M_Theta_S, expected), 1e-13) << "n = " << n;
  }
}

// Reference: the sphere, V = 4/3 π R³ and Θ = (2/5) m R² I with m = ρV (exact mass). The
// inscribed icospheres of levels 2…6 converge at second order in the mean edge length: the
// observed orders of the errors of V and of Θ must lie in [1.8, 2.2]; the mesh lies inside the
// sphere, so both errors are negative.
TEST(MassProperties, IcospheresConvergeAtSecondOrder) {
  const double R = 0.9;
  const double density = 2500.0;
  const double volume = 4.0 / 3.0 * pi * R * R * R;
  const double moment = 0.4 * density * volume * R * R;
  std::vector<double> volume_errors, inertia_errors, h;
  for (int k = 2; k <= 6; ++k) {
    const TriangleMesh mesh = grbd::body::icosphere_mesh(R, k);
    const MassProperties props = mass_properties(mesh, density, "icosphere");
    EXPECT_LT(props.volume, volume);
    EXPECT_LT(props.M_Theta_S.diagonal().maxCoeff(), moment);
    EXPECT_LE(props.M_r_S.norm(), 1e-14 * R);  // measured ≈ 1e-15: cancelling contributions
    volume_errors.push_back((volume - props.volume) / volume);
    inertia_errors.push_back(relative(props.M_Theta_S, moment * Matrix3::Identity()));
    h.push_back(mean_edge_length(mesh));
  }
  expect_second_order(volume_errors, h, "icosphere_volume");
  expect_second_order(inertia_errors, h, "icosphere_inertia");
  EXPECT_LT(inertia_errors.back(), 1e-3);
}

// Reference: the solid torus (Pappus: V = 2π² R r²; I_axis = m (R² + ¾ r²),
// I_diam = m (½ R² + ⅝ r²)). Refining both directions together (n_minor = 8 … 64, n_major = 3
// n_minor), the observed orders of the errors of V, I_axis and I_diam must lie in [1.8, 2.2].
TEST(MassProperties, ToriConvergeAtSecondOrder) {
  const double R = 1.0;
  const double r = 0.4;
  const double density = 1000.0;
  const double volume = 2.0 * pi * pi * R * r * r;
  const double mass = density * volume;
  const double axial = mass * (R * R + 0.75 * r * r);
  const double diametral = mass * (0.5 * R * R + 0.625 * r * r);
  std::vector<double> volume_errors, axial_errors, diametral_errors, h;
  for (const int n : {8, 16, 32, 64}) {
    const MassProperties props =
        mass_properties(grbd::body::torus_mesh(R, r, 3 * n, n), density, "torus");
    EXPECT_LE(props.M_r_S.norm(), 1e-14);
    EXPECT_LE(std::abs(props.M_Theta_S(0, 1)) + std::abs(props.M_Theta_S(0, 2)) +
                  std::abs(props.M_Theta_S(1, 2)),
              1e-12 * axial);
    volume_errors.push_back(std::abs(volume - props.volume) / volume);
    axial_errors.push_back(std::abs(axial - props.M_Theta_S(2, 2)) / axial);
    diametral_errors.push_back(std::abs(diametral - props.M_Theta_S(0, 0)) / diametral);
    h.push_back(1.0 / n);
  }
  expect_second_order(volume_errors, h, "torus_volume");
  expect_second_order(axial_errors, h, "torus_axial");
  expect_second_order(diametral_errors, h, "torus_diametral");
}

// Reference: the cylinder table (m = ρπR²h, Θ_zz = mR²/2, Θ_xx = Θ_yy = m(3R² + h²)/12); the
// inscribed prisms of cylinder_mesh (n = 16 … 256) converge at second order in 1/n.
TEST(MassProperties, CylinderMeshesConvergeAtSecondOrder) {
  const double R = 0.5;
  const double height = 1.2;
  const double density = 7850.0;
  const double mass = density * pi * R * R * height;
  const Matrix3 expected = cylinder_inertia(mass, R, height);
  std::vector<double> mass_errors, inertia_errors, h;
  for (const int n : {16, 32, 64, 128, 256}) {
    const MassProperties props =
        mass_properties(grbd::body::cylinder_mesh(R, height, n), density, "cylinder");
    mass_errors.push_back((mass - props.mass) / mass);
    inertia_errors.push_back(relative(props.M_Theta_S, expected));
    h.push_back(1.0 / n);
  }
  expect_second_order(mass_errors, h, "cylinder_mass");
  expect_second_order(inertia_errors, h, "cylinder_inertia");
}

// Reference: a rigid motion x ↦ A x + r of the body leaves m and the principal moments unchanged
// and maps r_S ↦ A r_S + r, Θ_S ↦ A Θ_S Aᵀ. The body is a torus stretched to three distinct
// principal moments and moved off-centre; 50 seeded random motions with |r| ≤ 2√3. Tolerances:
// mass 1e-13, r_S 1e-13 absolute (the body has size ~1), Θ_S and principal moments 1e-12
// relative.
TEST(MassProperties, InvariantUnderRigidMotions) {
  const Matrix3 stretch = Vector3(1.0, 0.8, 0.5).asDiagonal();
  const TriangleMesh body = grbd::body::transformed(grbd::body::torus_mesh(1.0, 0.35, 24, 12),
                                                    stretch, Vector3(0.3, -0.2, 0.1));
  const double density = 1200.0;
  const MassProperties props = mass_properties(body, density, "stretched torus");
  const PrincipalAxes axes = principal_axes(props.M_Theta_S);
  ASSERT_GT(axes.K_Theta[1] - axes.K_Theta[0], 1e-2 * axes.K_Theta[2]);
  ASSERT_GT(axes.K_Theta[2] - axes.K_Theta[1], 1e-2 * axes.K_Theta[2]);
  grbd::test::Random rng(2303);
  WorstCase mass_error, position_error, inertia_error, moment_error;
  for (int n = 0; n < 50; ++n) {
    const Matrix3 A = rng.rotation();
    const Vector3 r = rng.vector3(-2, 2);
    const MassProperties moved =
        mass_properties(grbd::body::transformed(body, A, r), density, "moved torus");
    const auto inputs = [&] { return describe("A", A, "r", r); };
    mass_error.update(std::abs(moved.mass - props.mass) / props.mass, n, inputs);
    position_error.update((moved.M_r_S - (A * props.M_r_S + r)).cwiseAbs().maxCoeff(), n, inputs);
    inertia_error.update(relative(moved.M_Theta_S, A * props.M_Theta_S * A.transpose()), n,
                         inputs);
    moment_error.update(
        (principal_axes(moved.M_Theta_S).K_Theta - axes.K_Theta).cwiseAbs().maxCoeff() /
            axes.K_Theta[2],
        n, inputs);
  }
  EXPECT_LE(mass_error.value(), 1e-13) << mass_error;
  EXPECT_LE(position_error.value(), 1e-13) << position_error;
  EXPECT_LE(inertia_error.value(), 1e-12) << inertia_error;
  EXPECT_LE(moment_error.value(), 1e-12) << moment_error;
}

// Reference: the contract: the mesh is checked first (MeshError whose message starts with the
// source), then the density (InvalidArgument for ρ ≤ 0 or not finite).
TEST(MassProperties, RejectsBadMeshesAndDensities) {
  const std::string file = std::string(GRBD_TEST_DATA_DIR) + "/open_box.obj";
  const TriangleMesh open_box = grbd::body::read_obj(file);
  try {
    mass_properties(open_box, 1000.0, file);
    ADD_FAILURE() << "an open box has no mass properties";
  } catch (const grbd::body::MeshError& error) {
    EXPECT_EQ(std::string(error.what()).rfind(file + ": ", 0), 0U) << error.what();
    EXPECT_NE(std::string(error.what()).find("4 boundary edges"), std::string::npos);
  }
  TriangleMesh inward = grbd::body::box_mesh(Vector3(1, 1, 1));
  inward.F.col(1).swap(inward.F.col(2));
  try {
    mass_properties(inward, 1000.0);
    ADD_FAILURE() << "an inward-oriented box has no mass properties";
  } catch (const grbd::body::MeshError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("mesh: ", 0), 0U) << error.what();  // default
    EXPECT_NE(std::string(error.what()).find("inward"), std::string::npos) << error.what();
  }
  const TriangleMesh box = grbd::body::box_mesh(Vector3(1, 1, 1));
  for (const double density : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(mass_properties(box, density), grbd::InvalidArgument) << "ρ = " << density;
  }
}

// ----------------------------------------------------------------------------------------------
// principal_axes
// ----------------------------------------------------------------------------------------------

// Reference: Θ = A diag(d) Aᵀ built from a known rotation A and known moments d (sorted):
// principal_axes must give back d (1e-13 relative), an orthonormal right-handed A_MK (1e-14)
// whose columns are ±the columns of A (1e-10: the moments are separated by ≥ 5 %), and
// A_MK diag(K_Theta) A_MKᵀ = Θ (1e-14 relative).
TEST(PrincipalAxes, RecoversKnownAxesAndMoments) {
  grbd::test::Random rng(2401);
  for (int n = 0; n < 1000; ++n) {
    const Matrix3 A = rng.rotation();
    Vector3 d(rng.uniform(1.0, 2.0), rng.uniform(1.0, 2.0), rng.uniform(1.0, 2.0));
    std::sort(d.data(), d.data() + 3);
    if (d[1] - d[0] < 0.05 || d[2] - d[1] < 0.05) continue;
    const Matrix3 Theta = A * d.asDiagonal() * A.transpose();
    const PrincipalAxes axes = principal_axes(Theta);
    EXPECT_LE((axes.K_Theta - d).cwiseAbs().maxCoeff(), 1e-13 * d[2]);
    EXPECT_LE(max_abs(axes.A_MK.transpose() * axes.A_MK - Matrix3::Identity()), 1e-14);
    EXPECT_NEAR(axes.A_MK.determinant(), 1.0, 1e-14);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(std::abs(axes.A_MK.col(k).dot(A.col(k))), 1.0, 1e-10) << "axis " << k;
    }
    EXPECT_LE(relative(axes.A_MK * axes.K_Theta.asDiagonal() * axes.A_MK.transpose(), Theta),
              1e-14);
  }
}

// Reference: the definition of a right-handed frame, det A_MK = +1, on tensors with repeated
// moments (sphere: Θ = cI; symmetric tops Θ1 = Θ2 or Θ2 = Θ3), where any orthonormal basis of an
// eigenspace is correct but must still be right-handed and reproduce Θ.
TEST(PrincipalAxes, RepeatedMomentsGiveARightHandedFrame) {
  grbd::test::Random rng(2402);
  for (int n = 0; n < 300; ++n) {
    const Matrix3 A = rng.rotation();
    const double a = rng.uniform(1.0, 2.0);
    const double b = a + rng.uniform(0.1, 1.0);
    const std::array<Vector3, 3> moments = {Vector3(a, a, a), Vector3(a, a, b), Vector3(a, b, b)};
    for (const Vector3& d : moments) {
      const Matrix3 Theta = A * d.asDiagonal() * A.transpose();
      const PrincipalAxes axes = principal_axes(Theta);
      EXPECT_LE((axes.K_Theta - d).cwiseAbs().maxCoeff(), 1e-13 * d[2]);
      EXPECT_LE(max_abs(axes.A_MK.transpose() * axes.A_MK - Matrix3::Identity()), 1e-14);
      EXPECT_NEAR(axes.A_MK.determinant(), 1.0, 1e-14);
      EXPECT_LE(relative(axes.A_MK * axes.K_Theta.asDiagonal() * axes.A_MK.transpose(), Theta),
                1e-14);
    }
  }
}

// Reference: the box table for a rotated box mesh: the principal moments are the sorted box
// moments, and each principal axis is ± the rotated box axis of that moment (1e-12).
TEST(PrincipalAxes, PrincipalFrameOfARotatedBoxMeshIsTheBoxFrame) {
  grbd::test::Random rng(2403);
  const Vector3 h(0.3, 0.7, 0.5);  // moments ∝ 0.74, 0.34, 0.58: ascending about y, z, x
  const Matrix3 Theta_box = box_inertia(h, 1000.0 * 8.0 * h.prod());
  for (int n = 0; n < 50; ++n) {
    const Matrix3 A = rng.rotation();
    const MassProperties props = mass_properties(
        grbd::body::transformed(grbd::body::box_mesh(h), A, rng.vector3(-1, 1)), 1000.0);
    const PrincipalAxes axes = principal_axes(props.M_Theta_S);
    std::array<int, 3> order = {0, 1, 2};
    std::sort(order.begin(), order.end(),
              [&](int i, int j) { return Theta_box(i, i) < Theta_box(j, j); });
    for (int k = 0; k < 3; ++k) {
      const int i = order[static_cast<std::size_t>(k)];
      EXPECT_NEAR(axes.K_Theta[k], Theta_box(i, i), 1e-12 * Theta_box.maxCoeff());
      EXPECT_NEAR(std::abs(axes.A_MK.col(k).dot(A.col(i))), 1.0, 1e-12) << "axis " << k;
    }
    EXPECT_NEAR(axes.A_MK.determinant(), 1.0, 1e-14);
  }
}

// Reference: the contract: non-finite or clearly non-symmetric tensors are InvalidArgument.
TEST(PrincipalAxes, RejectsNonFiniteAndNonSymmetricTensors) {
  Matrix3 Theta = Matrix3::Identity();
  Theta(0, 1) = 0.5;  // Θ(1, 0) = 0
  EXPECT_THROW(principal_axes(Theta), grbd::InvalidArgument);
  Theta = Matrix3::Identity();
  Theta(2, 2) = std::nan("");
  EXPECT_THROW(principal_axes(Theta), grbd::InvalidArgument);
}

// Reference: issue 11 (fuzzing): a NaN in Θ was reported as an asymmetry ("max |Θ − Θᵀ| =
// nan"); it must be called not finite, with the entry.
TEST(PrincipalAxes, CallsANaNEntryNotFinite) {
  for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    Matrix3 Theta = Matrix3::Identity();
    Theta(1, 2) = Theta(2, 1) = bad;
    const std::string message = invalid_argument_message([&] { principal_axes(Theta); });
    EXPECT_NE(message.find("not finite"), std::string::npos) << message;
    EXPECT_NE(message.find("(1, 2)"), std::string::npos) << message;
    EXPECT_EQ(message.find("symmetric"), std::string::npos) << message;
  }
}

// Reference: issue 11 (fuzzing) and the definition Θ = ∫ (|x|² I − x xᵀ) dm: for any unit axis
// e, eᵀΘe = ∫ |x − (eᵀx) e|² dm ≥ 0, so no principal moment is negative, and
// Θ1 + Θ2 − Θ3 = 2 ∫ x3² dm ≥ 0 in the principal frame (the triangle inequality, Θ3 the
// largest). A negative moment and (1, 1, 5) were accepted.
TEST(PrincipalAxes, RejectsNegativeMomentsAndTheBrokenTriangleInequality) {
  grbd::test::Random rng(2404);
  const Matrix3 A = rng.rotation();
  const std::array<Vector3, 3> impossible = {Vector3(-1.0, 2.0, 3.0), Vector3(1.0, 1.0, 5.0),
                                             Vector3(1.0, 2.0, 3.0 + 1e-6)};
  for (const Vector3& d : impossible) {
    const Matrix3 Theta = A * d.asDiagonal() * A.transpose();
    const std::string message = invalid_argument_message([&] { principal_axes(Theta); });
    EXPECT_EQ(message.rfind("principal_axes: ", 0), 0U) << message;
    EXPECT_NE(message.find(d[0] < 0.0 ? "Θ1 ≥ 0" : "Θ1 + Θ2 ≥ Θ3"), std::string::npos) << message;
    EXPECT_NE(message.find("found"), std::string::npos) << message;
  }
  const std::string message =
      invalid_argument_message([&] { principal_axes(Matrix3(Vector3(1, 1, 5).asDiagonal())); });
  EXPECT_NE(message.find("(1, 1, 5)"), std::string::npos) << message;
}

// Reference: the equality cases of the inequalities above: a thin rod (0, m, m)·L²/12 has a zero
// moment and Θ1 + Θ2 = Θ3 up to the vanishing one; a flat plate has Θ1 + Θ2 = Θ3 exactly. Both
// are physical limits and must pass, rotated (round-off of 1e-16 relative in Θ), and so must a
// box mesh 10⁻⁷ thick, whose mesh-integrated moments meet the plate's equality to round-off.
TEST(PrincipalAxes, AcceptsTheEqualityCasesOfRodsAndPlates) {
  grbd::test::Random rng(2405);
  for (int n = 0; n < 200; ++n) {
    const Matrix3 A = rng.rotation();
    const double a = rng.uniform(0.1, 2.0);
    const double b = rng.uniform(0.1, 2.0);
    for (const Vector3& d : {Vector3(0.0, a, a), Vector3(a, b, a + b), Vector3(a, a, 2.0 * a)}) {
      const Matrix3 Theta = A * d.asDiagonal() * A.transpose();
      EXPECT_NO_THROW(principal_axes(Theta)) << describe("moments", d, "rotation", A);
    }
  }
  for (int n = 0; n < 20; ++n) {
    const TriangleMesh plate = grbd::body::transformed(
        grbd::body::box_mesh(Vector3(0.5, 0.3, 1e-7)), rng.rotation(), rng.vector3(-1, 1));
    const MassProperties props = mass_properties(plate, 1000.0);
    EXPECT_NO_THROW(principal_axes(props.M_Theta_S));
  }
}

// Reference: issue 11 (fuzzing): a box of half-extent 1e100 has a finite volume (8e300) but
// second moments ∫ x xᵀ dV ≈ 1e500 that overflow; the mass properties came out inf/NaN. They must
// be refused as coordinates too large, naming the source and the size of the mesh. A finite mesh
// with a density so large that m = ρV overflows names the density instead.
TEST(MassProperties, NamesOverflowingIntegralsAndMass) {
  const TriangleMesh huge = grbd::body::box_mesh(Vector3::Constant(1e100));
  std::string message;
  try {
    mass_properties(huge, 1.0, "huge.obj");
    ADD_FAILURE() << "the inertia of a box of 1e100 overflows";
  } catch (const grbd::body::MeshError& error) {
    message = error.what();
  }
  EXPECT_EQ(message.rfind("huge.obj: ", 0), 0U) << message;
  EXPECT_NE(message.find("coordinates too large"), std::string::npos) << message;
  EXPECT_NE(message.find("1e+100"), std::string::npos) << message;

  const TriangleMesh box = grbd::body::box_mesh(Vector3::Ones());
  message = invalid_argument_message([&] { mass_properties(box, 1e308, "box.obj"); });
  EXPECT_EQ(message.rfind("mass_properties (box.obj): ", 0), 0U) << message;
  EXPECT_NE(message.find("density"), std::string::npos) << message;
  EXPECT_NE(message.find("overflow"), std::string::npos) << message;
}

// ----------------------------------------------------------------------------------------------
// Closed forms of primitive solids
// ----------------------------------------------------------------------------------------------

// Reference: the box mesh, which is the box itself (exact, 1e-14 relative), and the mass and
// volume 8ρabc.
TEST(PrimitiveClosedForms, BoxEqualsItsMesh) {
  const Vector3 h(0.4, 1.3, 0.25);
  const double density = 2700.0;
  const MassProperties closed = grbd::body::box_mass_properties(h, density);
  const MassProperties mesh = mass_properties(grbd::body::box_mesh(h), density);
  EXPECT_NEAR(closed.volume, 8.0 * h.prod(), 1e-15 * closed.volume);
  EXPECT_NEAR(closed.mass, mesh.mass, 1e-14 * closed.mass);
  EXPECT_EQ(closed.M_r_S, Vector3::Zero());
  EXPECT_LE(relative(mesh.M_Theta_S, closed.M_Theta_S), 1e-14);
}

// Reference: the sphere closed form is the limit of the icospheres: the errors of levels 5 and 6
// fall as h², so Richardson's extrapolation (4 X_6 − X_5)/3 (h halves) must be much closer to
// the closed form than X_6: 1e-5 relative (measured 1.3e-7), against 2.3e-4 for X_6 itself.
TEST(PrimitiveClosedForms, SphereIsTheLimitOfIcospheres) {
  const double R = 1.1;
  const double density = 1000.0;
  const MassProperties closed = grbd::body::sphere_mass_properties(R, density);
  EXPECT_NEAR(closed.volume, 4.0 / 3.0 * pi * R * R * R, 1e-15 * closed.volume);
  EXPECT_NEAR(closed.mass, density * closed.volume, 1e-15 * closed.mass);
  EXPECT_EQ(closed.M_r_S, Vector3::Zero());
  const MassProperties coarse = mass_properties(grbd::body::icosphere_mesh(R, 5), density);
  const MassProperties fine = mass_properties(grbd::body::icosphere_mesh(R, 6), density);
  const double mass = (4.0 * fine.mass - coarse.mass) / 3.0;
  const Matrix3 Theta = (4.0 * fine.M_Theta_S - coarse.M_Theta_S) / 3.0;
  EXPECT_NEAR(mass, closed.mass, 1e-5 * closed.mass);
  EXPECT_LE(relative(Theta, closed.M_Theta_S), 1e-5);
  EXPECT_LE(relative(closed.M_Theta_S, 0.4 * closed.mass * R * R * Matrix3::Identity()), 1e-15);
}

// Reference: the cylinder closed form is the limit of the regular prisms of cylinder_mesh:
// Richardson's extrapolation of n = 256 and 512 within 1e-7 relative.
TEST(PrimitiveClosedForms, CylinderIsTheLimitOfPrisms) {
  const double R = 0.3;
  const double height = 0.9;
  const double density = 7850.0;
  const MassProperties closed = grbd::body::cylinder_mass_properties(R, height, density);
  EXPECT_NEAR(closed.mass, density * pi * R * R * height, 1e-15 * closed.mass);
  const MassProperties coarse = mass_properties(grbd::body::cylinder_mesh(R, height, 256), density);
  const MassProperties fine = mass_properties(grbd::body::cylinder_mesh(R, height, 512), density);
  EXPECT_NEAR((4.0 * fine.mass - coarse.mass) / 3.0, closed.mass, 1e-7 * closed.mass);
  EXPECT_LE(relative((4.0 * fine.M_Theta_S - coarse.M_Theta_S) / 3.0, closed.M_Theta_S), 1e-7);
}

// Reference: the torus closed form is the limit of the torus meshes (Richardson's extrapolation
// of n_minor = 64 and 128, n_major = 3 n_minor, within 1e-5 relative, measured 4.6e-7; the
// meshes themselves are off by ≈ 5e-4), and Pappus's volume.
TEST(PrimitiveClosedForms, TorusIsTheLimitOfTorusMeshes) {
  const double R = 0.8;
  const double r = 0.3;
  const double density = 1000.0;
  const MassProperties closed = grbd::body::torus_mass_properties(R, r, density);
  EXPECT_NEAR(closed.volume, 2.0 * pi * R * pi * r * r, 1e-15 * closed.volume);
  const MassProperties coarse = mass_properties(grbd::body::torus_mesh(R, r, 192, 64), density);
  const MassProperties fine = mass_properties(grbd::body::torus_mesh(R, r, 384, 128), density);
  EXPECT_NEAR((4.0 * fine.mass - coarse.mass) / 3.0, closed.mass, 1e-5 * closed.mass);
  EXPECT_LE(relative((4.0 * fine.M_Theta_S - coarse.M_Theta_S) / 3.0, closed.M_Theta_S), 1e-5);
}

// Reference: composition. A capsule is a cylinder (table: m_c R²/2, m_c (3R² + h²)/12) plus the
// two halves of a sphere of radius R. By symmetry each half has half the sphere's mass and half
// its inertia about the sphere's centre, (1/5) m_s R² I; its centroid lies 3R/8 from the flat
// face. Two Steiner shifts move each half from the sphere centre O' to its centroid G and on to
// the capsule's centre S. Exact: 1e-14 relative.
TEST(PrimitiveClosedForms, CapsuleIsACylinderPlusTwoHemispheres) {
  grbd::test::Random rng(2501);
  for (int n = 0; n < 100; ++n) {
    const double R = rng.uniform(0.1, 1.0);
    const double h = n == 0 ? 0.0 : rng.uniform(0.0, 3.0);
    const double density = rng.uniform(500.0, 8000.0);
    const double m_c = density * pi * R * R * h;
    const double m_s = density * 4.0 / 3.0 * pi * R * R * R;
    const double m_half = 0.5 * m_s;
    Matrix3 Theta = cylinder_inertia(m_c, R, h);
    for (const double side : {1.0, -1.0}) {
      const Vector3 O_prime(0.0, 0.0, side * h / 2.0);  // centre of the flat face
      const Vector3 G = O_prime + Vector3(0.0, 0.0, side * 3.0 * R / 8.0);
      const Matrix3 Theta_O_prime = 0.2 * m_s * R * R * Matrix3::Identity();
      const Matrix3 Theta_G = Theta_O_prime - steiner(m_half, G - O_prime);
      Theta += Theta_G + steiner(m_half, G);
    }
    const MassProperties capsule = grbd::body::capsule_mass_properties(R, h, density);
    EXPECT_NEAR(capsule.mass, m_c + m_s, 1e-14 * capsule.mass);
    EXPECT_NEAR(capsule.volume, pi * R * R * h + 4.0 / 3.0 * pi * R * R * R,
                1e-14 * capsule.volume);
    EXPECT_EQ(capsule.M_r_S, Vector3::Zero());
    EXPECT_LE(relative(capsule.M_Theta_S, Theta), 1e-14) << "R = " << R << ", h = " << h;
  }
  // A capsule without a straight part is a sphere.
  const MassProperties ball = grbd::body::capsule_mass_properties(0.5, 0.0, 1000.0);
  const MassProperties sphere = grbd::body::sphere_mass_properties(0.5, 1000.0);
  EXPECT_NEAR(ball.mass, sphere.mass, 1e-15 * sphere.mass);
  EXPECT_LE(relative(ball.M_Theta_S, sphere.M_Theta_S), 1e-15);
}

// Reference: the preconditions of the closed forms (positive finite sizes and density; r ≤ R
// for the torus; a capsule's straight part may have zero height).
TEST(PrimitiveClosedForms, RejectInvalidArguments) {
  namespace b = grbd::body;
  using grbd::InvalidArgument;
  const double nan = std::nan("");
  EXPECT_THROW(b::sphere_mass_properties(0.0, 1.0), InvalidArgument);
  EXPECT_THROW(b::sphere_mass_properties(1.0, -1.0), InvalidArgument);
  EXPECT_THROW(b::box_mass_properties(Vector3(1, nan, 1), 1.0), InvalidArgument);
  EXPECT_THROW(b::cylinder_mass_properties(1.0, 0.0, 1.0), InvalidArgument);
  EXPECT_THROW(b::capsule_mass_properties(1.0, -0.1, 1.0), InvalidArgument);
  EXPECT_NO_THROW(b::capsule_mass_properties(1.0, 0.0, 1.0));
  EXPECT_THROW(b::torus_mass_properties(1.0, 1.5, 1.0), InvalidArgument);
  EXPECT_THROW(b::torus_mass_properties(1.0, 0.5, 0.0), InvalidArgument);
}
