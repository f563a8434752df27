// Chapter 4: the collision world — supported pairs, validation of colliders, and contact
// detection in small scenes.
//
// Independent references: contacts computed by hand for spheres in a box of half-spaces, a
// sphere on a mesh floor, a box resting on the ground, a sphere against a moving box; lever arms
// K_rho = A_IKᵀ(I_r − I_r_S) with A_IK by Eigen::Quaterniond.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd/collision/world.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/references.hpp"

namespace {

using grbd::Vector3;
using grbd::Vector6;
using grbd::body::State;
using grbd::collision::Box;
using grbd::collision::Capsule;
using grbd::collision::Collider;
using grbd::collision::CollisionWorld;
using grbd::collision::Contact;
using grbd::collision::HalfSpace;
using grbd::collision::kStatic;
using grbd::collision::ShapeKind;
using grbd::collision::Sphere;
using grbd::collision::StaticMesh;

constexpr double kEps = std::numeric_limits<double>::epsilon();

State at(const Vector3& r, const grbd::kinematics::Quaternion& p = {}) {
  return {grbd::kinematics::make_q(r, p), Vector6::Zero()};
}

// The message of the grbd::InvalidArgument that `add` throws, or "" when it does not throw.
std::string refusal(CollisionWorld& world, Collider collider) {
  try {
    world.add(std::move(collider));
  } catch (const grbd::InvalidArgument& error) {
    return error.what();
  }
  return "";
}

const Contact* find(const std::vector<Contact>& contacts, int a, int b) {
  for (const Contact& c : contacts) {
    if (c.collider_a == a && c.collider_b == b) return &c;
  }
  return nullptr;
}

}  // namespace

// Reference: the list of the declaration, in both orders.
TEST(CollisionWorld, SupportedPairsAreTheDocumentedOnes) {
  const ShapeKind kinds[] = {ShapeKind::sphere, ShapeKind::box, ShapeKind::capsule,
                             ShapeKind::half_space, ShapeKind::mesh};
  int count = 0;
  for (const ShapeKind a : kinds) {
    for (const ShapeKind b : kinds) {
      EXPECT_EQ(grbd::collision::supported(a, b), grbd::collision::supported(b, a));
      count += grbd::collision::supported(a, b) && a <= b;
    }
  }
  EXPECT_EQ(count, 7);
  EXPECT_TRUE(grbd::collision::supported(ShapeKind::half_space, ShapeKind::box));
  EXPECT_TRUE(grbd::collision::supported(ShapeKind::capsule, ShapeKind::half_space));
  EXPECT_FALSE(grbd::collision::supported(ShapeKind::box, ShapeKind::capsule));
  EXPECT_EQ(grbd::collision::kind_name(ShapeKind::half_space), "half-space");
}

// Reference: the declaration: box–box, capsule–capsule and box–mesh are refused when added, with
// a message naming both colliders and their kinds.
TEST(CollisionWorld, RefusesUnsupportedPairsNamingBothColliders) {
  CollisionWorld world;
  world.add({Box{}, 0});
  std::string message = refusal(world, {Box{}, 1});
  EXPECT_NE(message.find("collider 1 (box, body 1)"), std::string::npos) << message;
  EXPECT_NE(message.find("collider 0 (box, body 0)"), std::string::npos) << message;
  EXPECT_NE(message.find("box–box"), std::string::npos) << message;

  CollisionWorld capsules;
  capsules.add({Capsule{}, 0});
  message = refusal(capsules, {Capsule{}, 3});
  EXPECT_NE(message.find("collider 1 (capsule, body 3)"), std::string::npos) << message;
  EXPECT_NE(message.find("collider 0 (capsule, body 0)"), std::string::npos) << message;

  CollisionWorld with_mesh;
  with_mesh.add({std::make_shared<const StaticMesh>(grbd::body::box_mesh(Vector3::Ones()))});
  message = refusal(with_mesh, {Box{}, 0});
  EXPECT_NE(message.find("collider 1 (box, body 0)"), std::string::npos) << message;
  EXPECT_NE(message.find("collider 0 (mesh, static)"), std::string::npos) << message;

  // Two static colliders never meet, nor two colliders of one body; a static box cannot meet a
  // moving capsule.
  CollisionWorld statics;
  statics.add({Box{}});
  EXPECT_EQ(refusal(statics, {Box{}}), "");
  EXPECT_EQ(refusal(statics, {Sphere{}, 2}), "");
  message = refusal(statics, {Capsule{}, 2});
  EXPECT_NE(message.find("collider 3 (capsule, body 2)"), std::string::npos) << message;
  EXPECT_NE(message.find("collider 0 (box, static)"), std::string::npos) << message;
  EXPECT_EQ(statics.colliders().size(), 3U);
  CollisionWorld one_body;
  one_body.add({Box{}, 0});
  EXPECT_EQ(refusal(one_body, {Capsule{}, 0}), "");
}

// Reference: the declaration: non-positive or non-finite sizes, a zero normal, a half-space or
// mesh attached to a body, a null mesh are refused with grbd::InvalidArgument.
TEST(CollisionWorld, RefusesBadShapes) {
  CollisionWorld world;
  EXPECT_NE(refusal(world, {Sphere{0.0}, 0}).find("radius"), std::string::npos);
  EXPECT_NE(refusal(world, {Sphere{-1.0}, 0}), "");
  EXPECT_NE(refusal(world, {Sphere{std::nan("")}, 0}), "");
  EXPECT_NE(refusal(world, {Box{Vector3(1.0, 0.0, 1.0)}, 0}), "");
  EXPECT_NE(refusal(world, {Capsule{0.5, -1.0}, 0}), "");
  EXPECT_NE(refusal(world, {HalfSpace{Vector3::Zero(), 0.0}}).find("normal"), std::string::npos);
  EXPECT_NE(refusal(world, {HalfSpace{Vector3::UnitZ(), 0.0}, 0}).find("static"),
            std::string::npos);
  EXPECT_NE(refusal(world, {std::shared_ptr<const StaticMesh>()}), "");
  EXPECT_NE(refusal(world,
                    {std::make_shared<const StaticMesh>(grbd::body::box_mesh(Vector3::Ones())), 1}),
            "");
  EXPECT_TRUE(world.colliders().empty());
  // A non-unit normal is accepted and normalised, the plane unchanged.
  world.add({HalfSpace{Vector3(0.0, 0.0, 2.0), 1.0}});
  const auto& h = std::get<HalfSpace>(world.colliders()[0].shape);
  EXPECT_EQ(h.I_n, Vector3::UnitZ());
  EXPECT_EQ(h.offset, 0.5);
}

// Reference: by hand. Spheres in the box [−1, 1]³ of six half-spaces (solid outside), margin
// 0.15: s0 (r 0.5) rests on the floor (g 0); s1 (r 0.5) is 0.1 above s0 and 0.1 into the
// ceiling; s2 (r 0.2) is 0.1 into the wall x = 1 and 0.2055 from s1 (no contact). Bodies turned
// by random rotations: the lever arms K_rho are checked against Eigen's rotation. Tolerance 1e-15.
TEST(CollisionWorld, DetectsSpheresInABoxOfHalfSpaces) {
  CollisionWorld world;
  for (int i = 0; i < 3; ++i) {
    for (const double s : {1.0, -1.0}) world.add({HalfSpace{-s * Vector3::Unit(i), -1.0}});
  }
  world.add({Sphere{0.5}, 0});  // collider 6
  world.add({Sphere{0.5}, 1});  // collider 7
  world.add({Sphere{0.2}, 2});  // collider 8
  grbd::test::Random rng(4701);
  const std::vector<State> states{at(Vector3(0.0, 0.0, -0.5), rng.unit_quaternion()),
                                  at(Vector3(0.0, 0.0, 0.6), rng.unit_quaternion()),
                                  at(Vector3(0.9, 0.0, 0.5), rng.unit_quaternion())};
  std::vector<Contact> contacts;
  world.detect(states, 0.15, contacts);
  ASSERT_EQ(contacts.size(), 4U);

  const Contact* floor = find(contacts, 6, 5);  // half-space 5: −z side, the floor
  ASSERT_NE(floor, nullptr);
  EXPECT_EQ(floor->geometry.I_n, Vector3::UnitZ());
  EXPECT_EQ(floor->geometry.g_N, 0.0);
  EXPECT_EQ(floor->body_a, 0);
  EXPECT_EQ(floor->body_b, kStatic);

  const Contact* pair = find(contacts, 6, 7);
  ASSERT_NE(pair, nullptr);
  EXPECT_EQ(pair->geometry.I_n, -Vector3::UnitZ());
  EXPECT_NEAR(pair->geometry.g_N, 0.1, 2 * kEps);
  EXPECT_EQ(pair->body_b, 1);

  const Contact* ceiling = find(contacts, 7, 4);
  ASSERT_NE(ceiling, nullptr);
  EXPECT_EQ(ceiling->geometry.I_n, -Vector3::UnitZ());
  EXPECT_NEAR(ceiling->geometry.g_N, -0.1, 2 * kEps);

  const Contact* wall = find(contacts, 8, 0);
  ASSERT_NE(wall, nullptr);
  EXPECT_EQ(wall->geometry.I_n, -Vector3::UnitX());
  EXPECT_NEAR(wall->geometry.g_N, -0.1, 2 * kEps);

  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.I_t1.dot(c.geometry.I_n), 0.0, 4 * kEps);
    EXPECT_LE((c.geometry.I_n.cross(c.I_t1) - c.I_t2).cwiseAbs().maxCoeff(), 4 * kEps);
    const State& a = states[static_cast<std::size_t>(c.body_a)];
    const Vector3 K_rho_a =
        grbd::test::reference_A_IK(a.q).transpose() * (c.geometry.I_r_a - a.q.head<3>());
    EXPECT_LE((c.K_rho_a - K_rho_a).cwiseAbs().maxCoeff(), 1e-15);
    if (c.body_b != kStatic) {
      const State& b = states[static_cast<std::size_t>(c.body_b)];
      const Vector3 K_rho_b =
          grbd::test::reference_A_IK(b.q).transpose() * (c.geometry.I_r_b - b.q.head<3>());
      EXPECT_LE((c.K_rho_b - K_rho_b).cwiseAbs().maxCoeff(), 1e-15);
    }
  }
}

// Reference: by hand: a sphere (r 0.5) 0.25 above a flat mesh floor has one contact, g = 0.25,
// n = e_z, at the foot of the centre. Tolerance 0 (exact numbers).
TEST(CollisionWorld, DetectsASphereOnAMesh) {
  grbd::body::TriangleMesh floor_mesh;
  floor_mesh.V.resize(4, 3);
  floor_mesh.V << -4, -4, 0, 4, -4, 0, 4, 4, 0, -4, 4, 0;
  floor_mesh.F.resize(2, 3);
  floor_mesh.F << 0, 1, 2, 0, 2, 3;
  CollisionWorld world;
  world.add({std::make_shared<const StaticMesh>(floor_mesh)});  // 0
  world.add({Sphere{0.5}, 0});                                  // 1
  world.add({Sphere{0.5}, 1});                                  // 2, far above
  const std::vector<State> states{at(Vector3(1.0, 2.0, 0.75)), at(Vector3(1.0, 2.0, 3.0))};
  std::vector<Contact> contacts;
  world.detect(states, 0.3, contacts);
  ASSERT_EQ(contacts.size(), 1U);
  const Contact& c = contacts[0];
  EXPECT_EQ(c.collider_a, 1);
  EXPECT_EQ(c.collider_b, 0);
  EXPECT_EQ(c.geometry.I_n, Vector3::UnitZ());
  EXPECT_EQ(c.geometry.g_N, 0.25);
  EXPECT_EQ(c.geometry.I_r_b, Vector3(1.0, 2.0, 0.0));
  EXPECT_EQ(c.geometry.feature_b, 1U);  // the foot (1, 2) has y > x: face 1, (0, 2, 3)
}

// Reference: by hand: a box body [−0.5, 0.5]³, offset by K_r_KC = (0, 0, 1) from its centre of
// mass, resting on the ground half-space z = −2: 4 contacts with g = 0 and lever arms
// K_rho_a = (±0.5, ±0.5, 0.5); a sphere body (r 0.25) 0.1 from the box's +x face: one sphere–box
// contact, the sphere as a, n = e_x, g = 0.1. Tolerance 4 ε.
TEST(CollisionWorld, DetectsBoxOnGroundAndSphereAgainstBox) {
  CollisionWorld world;
  world.add({HalfSpace{Vector3::UnitZ(), -2.0}});                       // 0
  world.add({Box{Vector3::Constant(0.5)}, 1, Vector3(0.0, 0.0, 1.0)});  // 1
  world.add({Sphere{0.25}, 0});                                         // 2
  const std::vector<State> states{at(Vector3(-2.0 + 0.5 + 0.1 + 0.25, 0.0, -1.5)),
                                  at(Vector3(-2.0, 0.0, -2.5))};
  std::vector<Contact> contacts;
  world.detect(states, 0.15, contacts);
  ASSERT_EQ(contacts.size(), 5U);
  int on_ground = 0;
  for (const Contact& c : contacts) {
    if (c.collider_a == 1 && c.collider_b == 0) {
      ++on_ground;
      EXPECT_EQ(c.geometry.g_N, 0.0);
      EXPECT_EQ(c.K_rho_a.z(), 0.5);
      EXPECT_EQ(c.K_rho_a.head<2>().cwiseAbs(), Eigen::Vector2d(0.5, 0.5));
      EXPECT_EQ(c.body_b, kStatic);
    }
  }
  EXPECT_EQ(on_ground, 4);
  const Contact* sphere_box = find(contacts, 2, 1);
  ASSERT_NE(sphere_box, nullptr);
  EXPECT_EQ(sphere_box->geometry.I_n, Vector3::UnitX());
  EXPECT_NEAR(sphere_box->geometry.g_N, 0.1, 4 * kEps);
  EXPECT_EQ(sphere_box->body_a, 0);
  EXPECT_EQ(sphere_box->body_b, 1);
}

// Regression (issue 11): detect used the quaternion of a state as given. A sphere 0.5 above the
// ground with p = (2, 0, 0, 0) got a contact (its lever arms scale by |p|²), and zero or NaN
// orientations went through. Reference: body::State requires |p| = 1 (rigid_body.hpp); the
// refusal names the body and |p|.
TEST(CollisionWorld, RefusesStatesWithoutAUnitQuaternionNamingTheBody) {
  CollisionWorld world;
  world.add({HalfSpace{Vector3::UnitZ(), 0.0}});
  world.add({Sphere{0.5}, 0});
  world.add({Sphere{0.5}, 1});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const State good = at(Vector3(3.0, 0.0, 1.0));
  struct Bad {
    const char* what;
    grbd::Vector4 p;
    const char* named;
  };
  const std::vector<Bad> cases{{"|p| = 2", {2.0, 0.0, 0.0, 0.0}, "|p| = 2"},
                               {"zero", {0.0, 0.0, 0.0, 0.0}, "|p| = 0"},
                               {"NaN", {nan, 0.0, 0.0, 0.0}, "nan"},
                               {"|p| = 1 + 1e-5", {1.0 + 1e-5, 0.0, 0.0, 0.0}, "unit"}};
  for (const Bad& bad : cases) {
    SCOPED_TRACE(bad.what);
    State spoilt = at(Vector3(0.0, 0.0, 0.5));
    spoilt.q.tail<4>() = bad.p;
    std::vector<Contact> contacts;
    std::string message;
    try {
      world.detect(std::vector<State>{good, spoilt}, 0.1, contacts);
    } catch (const grbd::InvalidArgument& error) {
      message = error.what();
    }
    EXPECT_NE(message.find("body 1"), std::string::npos) << "message: '" << message << "'";
    EXPECT_NE(message.find(bad.named), std::string::npos) << "message: '" << message << "'";
  }
  // Within the documented tolerance 1e-6 (round-off of the exponential map is 1e-15 per step).
  State nearly = at(Vector3(0.0, 0.0, 0.5));
  nearly.q.tail<4>() *= 1.0 + 1e-9;
  std::vector<Contact> contacts;
  EXPECT_NO_THROW(world.detect(std::vector<State>{good, nearly}, 0.1, contacts));
  EXPECT_EQ(contacts.size(), 1U);
  // A non-finite position or velocity is named too.
  State moving = at(Vector3(0.0, 0.0, 0.5));
  moving.u[4] = nan;
  try {
    world.detect(std::vector<State>{moving, good}, 0.1, contacts);
    ADD_FAILURE() << "a NaN velocity was accepted";
  } catch (const grbd::InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("body 0"), std::string::npos) << error.what();
  }
}
