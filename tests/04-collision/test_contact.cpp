// Chapter 4: the contact frame — a tangent basis of the contact plane (Exercise 4.4) and the
// contact Jacobian W of one body (Exercise 4.5); the hash of contact keys.
//
// Independent references: orthonormality and handedness written out with dot and cross
// products; perturbations of n for continuity; for W, central differences of the gap and of the
// positions of the material contact points along the exact motion with constant u,
// q(t) = (r0 + t v, p0 exp(t ω/2)) (grbd_test/references.hpp), with rotation matrices by
// Eigen::Quaterniond.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "grbd/collision/contact.hpp"
#include "grbd/collision/narrow_phase.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_test/bodies.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

using grbd::Matrix3;
using grbd::Vector3;
using grbd::Vector6;
using grbd::Vector7;
using grbd::body::State;
using grbd::collision::ContactGeometry;
using grbd::collision::ContactJacobian;
using grbd::test::describe;
using grbd::test::exact_motion;
using grbd::test::reference_A_IK;
using grbd::test::WorstCase;
using Basis = Eigen::Matrix<double, 3, 2>;

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Central differences with δ = 1e-5: truncation δ²/6 |g⃛| ≲ 1e-9 for the speeds (≤ 2√3) and
// distances (≥ 0.5) used here; round-off ~1e-11. Tolerance 1e-7.
constexpr double kDelta = 1e-5;
constexpr double kDifferenceTol = 1e-7;

// The largest deviation of (n, t1, t2) from an orthonormal right-handed frame (value()), and
// which property deviates most (input()); a NaN counts as the largest deviation.
WorstCase frame_error(const Vector3& n, const Basis& T) {
  const Vector3 t1(T.col(0));
  const Vector3 t2(T.col(1));
  WorstCase e;
  e.update(std::abs(t1.norm() - 1.0), [] { return "|t1| = 1"; });
  e.update(std::abs(t2.norm() - 1.0), [] { return "|t2| = 1"; });
  e.update(std::abs(t1.dot(n)), [] { return "t1·n = 0"; });
  e.update(std::abs(t2.dot(n)), [] { return "t2·n = 0"; });
  e.update(std::abs(t1.dot(t2)), [] { return "t1·t2 = 0"; });
  e.update((n.cross(t1) - t2).cwiseAbs().maxCoeff(), [] { return "n × t1 = t2"; });
  return e;
}

// Records the frame error of tangent_basis(n) in `worst`, for sample number `sample` (none if
// negative).
void update_frame_error(WorstCase& worst, const Vector3& n, int sample = -1) {
  const Basis T = grbd::collision::tangent_basis(n);
  const WorstCase frame = frame_error(n, T);
  worst.update(frame.value(), sample, [&] {
    return describe("n", n, "t1", T.col(0), "t2", T.col(1), "failing", frame.input());
  });
}

grbd::kinematics::Quaternion orientation(const Vector7& q) {
  return grbd::kinematics::Quaternion(grbd::Vector4(q.tail<4>()));
}

// The position of the material point K_rho at time t along the exact motion from x.
Vector3 material_point(const State& x, const Vector3& K_rho, double t) {
  const Vector7 q = exact_motion(x.q, x.u, t);
  return q.head<3>() + reference_A_IK(q) * K_rho;
}

// γ = W_aᵀ u_a − W_bᵀ u_b for the contact between a's point I_r_a and b's point I_r_b.
Vector3 contact_velocity(const State& a, const State& b, const ContactGeometry& g) {
  const Basis T = grbd::collision::tangent_basis(g.I_n);
  const Vector3 rho_a = reference_A_IK(a.q).transpose() * (g.I_r_a - a.q.head<3>());
  const Vector3 rho_b = reference_A_IK(b.q).transpose() * (g.I_r_b - b.q.head<3>());
  const ContactJacobian W_a =
      grbd::collision::contact_jacobian(orientation(a.q), rho_a, g.I_n, T.col(0), T.col(1));
  const ContactJacobian W_b =
      grbd::collision::contact_jacobian(orientation(b.q), rho_b, g.I_n, T.col(0), T.col(1));
  return W_a.transpose() * a.u - W_b.transpose() * b.u;
}

// The tangential velocity of a's material contact point relative to b's, by central
// differences, in the basis (t1, t2).
Eigen::Vector2d slip_by_differences(const State& a, const State& b, const ContactGeometry& g) {
  const Basis T = grbd::collision::tangent_basis(g.I_n);
  const Vector3 rho_a = reference_A_IK(a.q).transpose() * (g.I_r_a - a.q.head<3>());
  const Vector3 rho_b = reference_A_IK(b.q).transpose() * (g.I_r_b - b.q.head<3>());
  const auto relative = [&](double t) -> Vector3 {
    return material_point(a, rho_a, t) - material_point(b, rho_b, t);
  };
  return T.transpose() * (relative(kDelta) - relative(-kDelta)) / (2.0 * kDelta);
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// Exercise 4.4: a tangent basis of the contact plane
// ----------------------------------------------------------------------------------------------

// Reference: dot and cross products. Seeded random unit normals and the six axis directions;
// tolerance 4 ε.
TEST(Exercise4_4, IsOrthonormalAndRightHanded) {
  grbd::test::Random rng(4401);
  WorstCase worst;
  for (int k = 0; k < 10000; ++k) {
    const Vector3 n = rng.unit_vector3();
    update_frame_error(worst, n, k);
  }
  for (int i = 0; i < 3; ++i) {
    for (const double s : {1.0, -1.0}) {
      const Vector3 n = s * Vector3::Unit(i);
      update_frame_error(worst, n);
    }
  }
  EXPECT_LE(worst.value(), 4 * kEps) << worst;
}

// Reference: n close to the singular point −e_z, at angles 1e-3 … 1e-15 and 0 from it: still
// orthonormal to 4 ε (Frisvad's 1/(1 + n_z) would lose every digit here).
TEST(Exercise4_4, IsAccurateNearTheSingularPoint) {
  grbd::test::Random rng(4402);
  WorstCase worst;
  for (double angle = 1e-3; angle > 1e-16; angle /= 10.0) {
    for (int k = 0; k < 20; ++k) {
      const double phi = rng.uniform(0.0, 2.0 * M_PI);
      const Vector3 n(std::sin(angle) * std::cos(phi), std::sin(angle) * std::sin(phi),
                      -std::cos(angle));
      update_frame_error(worst, n);
    }
  }
  update_frame_error(worst, -Vector3::UnitZ());
  EXPECT_LE(worst.value(), 4 * kEps) << worst;
}

// Reference: a perturbation of n by δ = 1e-7 (renormalised) changes t1, t2 by at most 100 |Δn|
// for every n with n_z ≥ −0.9, the equator n_z = 0 (where the formula switches) included:
// Frisvad's basis has derivatives of order 4/(1 + n_z) ≤ 40 there.
TEST(Exercise4_4, IsContinuousAwayFromTheSingularPoint) {
  grbd::test::Random rng(4403);
  constexpr double kStep = 1e-7;
  WorstCase worst;
  for (int k = 0; k < 20000; ++k) {
    Vector3 n = rng.unit_vector3();
    if (k % 4 == 0) n = Vector3(n.x(), n.y(), 1e-9 * n.z()).normalized();  // at the equator
    if (n.z() < -0.9) continue;
    const Vector3 m = (n + kStep * rng.unit_vector3()).normalized();
    const Basis change = grbd::collision::tangent_basis(m) - grbd::collision::tangent_basis(n);
    worst.update(change.cwiseAbs().maxCoeff() / (m - n).norm(), k,
                 [&] { return describe("n", n, "m", m); });
  }
  EXPECT_LE(worst.value(), 100.0) << worst;
}

// ----------------------------------------------------------------------------------------------
// Exercise 4.5: the contact Jacobian of one body
// ----------------------------------------------------------------------------------------------

// Reference: the formula of the declaration with A_IK by Eigen::Quaterniond: each column is
// (d, K_rho × A_IKᵀ d). Tolerance 1e-14.
TEST(Exercise4_5, ColumnsAreDirectionAndMomentArm) {
  grbd::test::Random rng(4501);
  for (int k = 0; k < 200; ++k) {
    const State x = grbd::test::random_state(rng);
    const Vector3 rho = rng.vector3();
    const Vector3 n = rng.unit_vector3();
    const Basis T = grbd::collision::tangent_basis(n);
    const ContactJacobian W =
        grbd::collision::contact_jacobian(orientation(x.q), rho, n, T.col(0), T.col(1));
    const Matrix3 A = reference_A_IK(x.q);
    Eigen::Matrix3d d;  // the directions n, t1, t2 as columns
    d << n, T;
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE((W.col(c).head<3>() - d.col(c)).cwiseAbs().maxCoeff(), 1e-14);
      EXPECT_LE((W.col(c).tail<3>() - rho.cross(A.transpose() * d.col(c))).cwiseAbs().maxCoeff(),
                1e-14);
    }
  }
}

// Reference: central differences of g_N = |c_a − c_b| − r_a − r_b along the exact motion of two
// rotating, translating spheres (γ_N = ġ_N), and of the relative position of the material contact
// points (γ_T). Tolerance kDifferenceTol.
TEST(Exercise4_5, NormalVelocityIsTheGapRateOfTwoMovingSpheres) {
  grbd::test::Random rng(4502);
  WorstCase worst_normal, worst_slip;
  for (int k = 0; k < 500; ++k) {
    const State a = grbd::test::random_state(rng);
    State b = grbd::test::random_state(rng);
    b.q.head<3>() = a.q.head<3>() + rng.uniform(1.0, 2.0) * rng.unit_vector3();
    const double r_a = rng.uniform(0.2, 0.6), r_b = rng.uniform(0.2, 0.6);
    const auto gap = [&](double t) {
      return grbd::collision::sphere_sphere(exact_motion(a.q, a.u, t).head<3>(), r_a,
                                            exact_motion(b.q, b.u, t).head<3>(), r_b)
          .g_N;
    };
    const ContactGeometry g =
        grbd::collision::sphere_sphere(a.q.head<3>(), r_a, b.q.head<3>(), r_b);
    const Vector3 gamma = contact_velocity(a, b, g);
    const auto inputs = [&] { return describe("a", a, "b", b, "r_a", r_a, "r_b", r_b); };
    worst_normal.update(std::abs(gamma[0] - (gap(kDelta) - gap(-kDelta)) / (2 * kDelta)), k,
                        inputs);
    worst_slip.update((gamma.tail<2>() - slip_by_differences(a, b, g)).cwiseAbs().maxCoeff(), k,
                      inputs);
  }
  EXPECT_LE(worst_normal.value(), kDifferenceTol) << worst_normal;
  EXPECT_LE(worst_slip.value(), kDifferenceTol) << worst_slip;
}

// Reference: a rotating sphere above the plane z = 0.25: γ_N = ġ_N by central differences, and
// γ_T by central differences of the material point against the (static) plane point.
TEST(Exercise4_5, NormalVelocityIsTheGapRateAboveAHalfSpace) {
  grbd::test::Random rng(4503);
  const grbd::collision::HalfSpace plane{Vector3(0.0, 0.6, 0.8), 0.25};
  const State ground{grbd::kinematics::make_q(Vector3::Zero(), {}), Vector6::Zero()};
  WorstCase worst_normal, worst_slip;
  for (int k = 0; k < 500; ++k) {
    const State a = grbd::test::random_state(rng);
    const double r = rng.uniform(0.1, 0.5);
    const auto gap = [&](double t) {
      return grbd::collision::sphere_half_space(exact_motion(a.q, a.u, t).head<3>(), r, plane).g_N;
    };
    const ContactGeometry g = grbd::collision::sphere_half_space(a.q.head<3>(), r, plane);
    const Vector3 gamma = contact_velocity(a, ground, g);
    const auto inputs = [&] { return describe("a", a, "r", r); };
    worst_normal.update(std::abs(gamma[0] - (gap(kDelta) - gap(-kDelta)) / (2 * kDelta)), k,
                        inputs);
    worst_slip.update((gamma.tail<2>() - slip_by_differences(a, ground, g)).cwiseAbs().maxCoeff(),
                      k, inputs);
  }
  EXPECT_LE(worst_normal.value(), kDifferenceTol) << worst_normal;
  EXPECT_LE(worst_slip.value(), kDifferenceTol) << worst_slip;
}

// Reference: a sphere (a) in front of the +z face of a rotating, translating box (b) [−1, 1]³:
// γ_N = ġ_N of sphere_box by central differences, γ_T from the material contact points.
TEST(Exercise4_5, NormalVelocityIsTheGapRateAgainstARotatingBox) {
  grbd::test::Random rng(4504);
  const grbd::collision::Box box{Vector3::Ones()};
  WorstCase worst_normal, worst_slip;
  for (int k = 0; k < 500; ++k) {
    const State b = grbd::test::random_state(rng);
    State a = grbd::test::random_state(rng);
    const double r = rng.uniform(0.2, 0.5);
    const Vector3 K_x(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5),
                      1.0 + r + rng.uniform(0.0, 1.0));
    a.q.head<3>() = b.q.head<3>() + reference_A_IK(b.q) * K_x;
    const auto geometry = [&](double t) {
      const Vector7 q_b = exact_motion(b.q, b.u, t);
      return grbd::collision::sphere_box(exact_motion(a.q, a.u, t).head<3>(), r, box,
                                         {q_b.head<3>(), reference_A_IK(q_b)});
    };
    const ContactGeometry g = geometry(0.0);
    ASSERT_EQ(g.feature_b, grbd::collision::face_feature(5));
    const Vector3 gamma = contact_velocity(a, b, g);
    const auto inputs = [&] { return describe("a", a, "b", b, "r", r, "K_x", K_x); };
    worst_normal.update(
        std::abs(gamma[0] - (geometry(kDelta).g_N - geometry(-kDelta).g_N) / (2 * kDelta)), k,
        inputs);
    worst_slip.update((gamma.tail<2>() - slip_by_differences(a, b, g)).cwiseAbs().maxCoeff(), k,
                      inputs);
  }
  EXPECT_LE(worst_normal.value(), kDifferenceTol) << worst_normal;
  EXPECT_LE(worst_slip.value(), kDifferenceTol) << worst_slip;
}

// ----------------------------------------------------------------------------------------------
// Contact keys
// ----------------------------------------------------------------------------------------------

// Reference: equal keys hash equally; 10 000 distinct keys of a grid of colliders and features
// (box and mesh feature ids) give (almost) distinct hashes.
TEST(ContactKey, EqualKeysHashEquallyAndDistinctKeysSpread) {
  using grbd::collision::ContactKey;
  const grbd::collision::ContactKeyHash hash;
  const ContactKey key{3, 7, 0,
                       grbd::collision::edge_feature(grbd::collision::mesh_edge_index(9, 4))};
  ContactKey same = key;
  EXPECT_EQ(hash(key), hash(same));
  EXPECT_EQ(grbd::collision::mesh_edge_index(9, 4), grbd::collision::mesh_edge_index(4, 9));
  std::unordered_set<std::size_t> hashes;
  for (int a = 0; a < 10; ++a) {
    for (int b = 0; b < 10; ++b) {
      for (std::uint64_t f = 0; f < 100; ++f) {
        const std::uint64_t feature = f % 3 == 0   ? grbd::collision::face_feature(f)
                                      : f % 3 == 1 ? grbd::collision::edge_feature(f)
                                                   : grbd::collision::vertex_feature(f);
        hashes.insert(hash(ContactKey{a, b, f % 8, feature}));
      }
    }
  }
  EXPECT_GE(hashes.size(), 9990U);
}
