/// \file
/// \brief The system of bodies (chapter 6, part A): stable ids through append, remove and
/// permute; static geometry; per-pair materials; contact keys by identity and the flat warm-start
/// table; the O(1) pair check of CollisionWorld::add.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "grbd/collision/world.hpp"
#include "grbd/core/error.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/contacts.hpp"
#include "grbd/timestep/materials.hpp"
#include "grbd_test/messages.hpp"
#include "scenes.hpp"

namespace grbd::timestep {
namespace {

using demo::sphere_body;

using test::message_of;

BodySystem ten_spheres() {
  BodySystem system;
  for (GlobalId id = 0; id < 10; ++id) {
    system.add(sphere_body(100 + id, 0.01 * (1 + id), Vector3(double(id), 0.0, 1.0)));
  }
  return system;
}

TEST(BodySystem, AppendKeepsEveryArrayInStepAndFindsIdsInConstantTime) {
  BodySystem system = ten_spheres();
  ASSERT_EQ(system.size(), 10u);
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_EQ(system.ids()[i], 100 + i);
    EXPECT_EQ(system.index_of(100 + i), i);
    EXPECT_DOUBLE_EQ(system.states()[i].q.x(), double(i));
    EXPECT_DOUBLE_EQ(std::get<collision::Sphere>(system.shapes()[i]).radius, 0.01 * (1 + i));
    EXPECT_DOUBLE_EQ(system.bounding_radii()[i], 0.01 * (1 + i));
    EXPECT_DOUBLE_EQ(system.M_inv()[i].inv_m, 1.0 / system.inertia()[i].m);
    EXPECT_TRUE(system.dynamic(i));
  }
  EXPECT_EQ(system.index_of(99), BodySystem::npos);
}

TEST(BodySystem, PermuteMovesAllArraysTogether) {
  BodySystem system = ten_spheres();
  std::vector<std::int32_t> order(10);
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 rng(7);
  std::shuffle(order.begin(), order.end(), rng);
  const std::uint64_t version = system.layout_version();
  system.permute(order);
  EXPECT_GT(system.layout_version(), version);
  for (std::size_t i = 0; i < 10; ++i) {
    const auto old = static_cast<std::size_t>(order[i]);
    EXPECT_EQ(system.ids()[i], 100 + old);
    EXPECT_EQ(system.index_of(100 + old), i);
    EXPECT_DOUBLE_EQ(system.states()[i].q.x(), double(old));
    EXPECT_DOUBLE_EQ(std::get<collision::Sphere>(system.shapes()[i]).radius, 0.01 * (1 + old));
    EXPECT_DOUBLE_EQ(system.M_inv()[i].inv_m, 1.0 / system.inertia()[i].m);
    EXPECT_DOUBLE_EQ(system.bounding_radii()[i], 0.01 * (1 + old));
  }
}

TEST(BodySystem, RemoveKeepsTheOrderOfTheOthersAndTheirIds) {
  BodySystem system = ten_spheres();
  const std::vector<std::size_t> gone = {7, 0, 3};
  system.remove(gone);
  ASSERT_EQ(system.size(), 7u);
  const std::vector<GlobalId> expected = {101, 102, 104, 105, 106, 108, 109};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(system.ids()[i], expected[i]);
    EXPECT_EQ(system.index_of(expected[i]), i);
    EXPECT_DOUBLE_EQ(system.states()[i].q.x(), double(expected[i] - 100));
  }
  EXPECT_EQ(system.index_of(100), BodySystem::npos);
  EXPECT_EQ(system.index_of(107), BodySystem::npos);
}

TEST(BodySystem, MortonReorderDoesNotDependOnTheCurrentOrder) {
  BodySystem a;
  BodySystem b;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> x(0.0, 1.0);
  std::vector<BodyRecord> specs;
  for (GlobalId id = 0; id < 500; ++id) {
    specs.push_back(sphere_body(id, 0.01, Vector3(x(rng), x(rng), x(rng))));
  }
  for (const BodyRecord& s : specs) a.add(s);
  std::shuffle(specs.begin(), specs.end(), rng);
  for (const BodyRecord& s : specs) b.add(s);
  a.reorder_morton(0.02);
  b.reorder_morton(0.02);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.ids()[i], b.ids()[i]);
  // Along the curve, neighbours in memory are close in space: the mean distance of consecutive
  // bodies is far below that of the lattice order of random points (≈ 0.66 for the unit cube).
  double sum = 0.0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    sum += (a.states()[i].q.head<3>() - a.states()[i - 1].q.head<3>()).norm();
  }
  EXPECT_LT(sum / double(a.size() - 1), 0.25);
}

TEST(BodySystem, RefusesBadBodiesNamingTheId) {
  BodySystem system = ten_spheres();
  EXPECT_NE(message_of([&] { system.add(sphere_body(103, 0.1, Vector3::Zero())); })
                .find("global id 103 is already used by the owned body at local index 3"),
            std::string::npos);
  EXPECT_NE(message_of([&] { system.add(sphere_body(kStaticTag, 0.1, Vector3::Zero())); })
                .find("below 2^63"),
            std::string::npos);
  BodyRecord bad = sphere_body(500, 0.1, Vector3::Zero());
  bad.state.q(3) = 2.0;  // |p| = 2
  EXPECT_NE(message_of([&] { system.add(bad); }).find("body 500"), std::string::npos);
  BodyRecord negative = sphere_body(501, 0.1, Vector3::Zero());
  negative.shape = collision::Sphere{-1.0};
  EXPECT_NE(message_of([&] { system.add(negative); }).find("sphere radius"), std::string::npos);
  BodyRecord plane = sphere_body(502, 0.1, Vector3::Zero());
  plane.shape = collision::HalfSpace{};
  EXPECT_NE(message_of([&] { system.add(plane); }).find("static objects"), std::string::npos);
  EXPECT_EQ(system.size(), 10u);  // nothing half-added
  const std::vector<std::int32_t> twice = {0, 0, 1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_NE(message_of([&] { system.permute(twice); }).find("appears twice"), std::string::npos);
  const std::vector<std::size_t> out = {10};
  EXPECT_NE(message_of([&] { system.remove(out); }).find("below 10"), std::string::npos);
}

TEST(BodySystem, AFixedBodyHasNoVelocityAndNoInverseMass) {
  BodySystem system;
  BodyRecord spec = sphere_body(1, 0.1, Vector3::Zero(), Vector6::Ones());
  spec.flags = 0;  // fixed
  system.add(spec);
  EXPECT_FALSE(system.dynamic(0));
  EXPECT_EQ(system.states()[0].u, Vector6::Zero());
  EXPECT_EQ(system.M_inv()[0].inv_m, 0.0);
}

TEST(StaticGeometry, RefusesDuplicateIdsAndBadPoses) {
  StaticGeometry statics;
  statics.add(demo::floor_object(4));
  EXPECT_NE(message_of([&] { statics.add(demo::floor_object(4)); }).find("used twice"),
            std::string::npos);
  StaticObject tilted = demo::floor_object(5);
  tilted.pose.A_IC = 2.0 * Matrix3::Identity();
  EXPECT_NE(message_of([&] { statics.add(tilted); }).find("rotation matrix"), std::string::npos);
  StaticObject scaled = demo::floor_object(6);
  scaled.shape = collision::HalfSpace{Vector3(0.0, 0.0, 2.0), 1.0};
  statics.add(scaled);
  const auto& h = std::get<collision::HalfSpace>(statics.objects().back().shape);
  EXPECT_EQ(h.I_n, Vector3::UnitZ());
  EXPECT_EQ(h.offset, 0.5);
}

TEST(MaterialTable, PairsAreSymmetricAndAMissingPairNamesBothMaterials) {
  MaterialTable table;
  const MaterialId glass = table.add("glass");
  const MaterialId steel = table.add("steel");
  const MaterialId wood = table.add("wood");
  table.set_pair(glass, steel, {0.3, 0.6, 0.0});
  EXPECT_EQ(table.pair(steel, glass).mu, 0.3);
  EXPECT_EQ(table.pair(glass, steel).eps_N, 0.6);
  const std::string missing = message_of([&] { (void)table.pair(glass, wood); });
  EXPECT_NE(missing.find("\"glass\" and \"wood\""), std::string::npos) << missing;
  const std::vector<MaterialId> used = {glass, steel};
  const std::string self = message_of([&] { table.require_pairs(used, used); });
  EXPECT_NE(self.find("\"glass\" and \"glass\""), std::string::npos) << self;
  table.set_default({0.5, 0.0, 0.0});
  EXPECT_EQ(table.pair(glass, wood).mu, 0.5);
  EXPECT_EQ(table.pair(glass, steel).mu, 0.3);  // an entry wins over the default
  table.set_pair(glass, steel, {0.4, 0.6, 0.0});
  EXPECT_EQ(table.pair_unchecked(steel, glass).mu, 0.4);
}

TEST(MaterialTable, RefusesLawsOutOfRange) {
  MaterialTable table;
  const MaterialId a = table.add("a");
  EXPECT_NE(message_of([&] { table.add("a"); }).find("declared twice"), std::string::npos);
  EXPECT_NE(message_of([&] { table.set_pair(a, a, {-0.1, 0.0, 0.0}); }).find("mu >= 0"),
            std::string::npos);
  EXPECT_NE(message_of([&] { table.set_pair(a, a, {0.1, 1.5, 0.0}); }).find("eps_N in [0, 1]"),
            std::string::npos);
  EXPECT_NE(message_of([&] { table.set_pair(a, a, {0.1, 0.5, -2.0}); }).find("eps_T"),
            std::string::npos);
  EXPECT_NE(message_of([&] { table.set_pair(a, 3, {0.1, 0.5, 0.0}); }).find("unknown material"),
            std::string::npos);
}

TEST(WarmStartTable, FindsEveryStoredKeyAndZeroesNewOnes) {
  WarmStartTable table;
  std::vector<ContactKey> keys;
  std::vector<Vector3> lambda;
  for (std::uint64_t i = 0; i < 1000; ++i) {
    keys.push_back({i, i + 1, i % 3, kStaticTag | i});
    lambda.emplace_back(double(i), -double(i), 0.5);
  }
  table.store(keys, lambda);
  std::vector<ContactKey> query(keys.rbegin(), keys.rend());
  query.push_back({5000, 5001, 0, 0});
  std::vector<Vector3> out(query.size(), Vector3::Constant(9.0));
  EXPECT_EQ(table.initialize(query, out), 1000u);
  for (std::size_t k = 0; k < 1000; ++k) EXPECT_EQ(out[k], lambda[999 - k]);
  EXPECT_EQ(out.back(), Vector3::Zero());
  std::vector<Vector3> wrong(3);
  EXPECT_THROW(table.initialize(query, wrong), InvalidArgument);
}

TEST(ContactDetector, KeysAndOrderDoNotDependOnTheStorageOrder) {
  BodySystem a;
  StaticGeometry statics;
  demo::add_open_box(statics, 0.1, 0.1);
  demo::add_sphere_lattice(a, 4, 4, 3, 0.01);
  // Squeeze the lattice so that neighbours overlap.
  for (body::State& s : a.states()) s.q.head<3>() *= 0.8;
  BodySystem b = a;
  std::vector<std::int32_t> order(b.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 rng(11);
  std::shuffle(order.begin(), order.end(), rng);
  b.permute(order);
  ContactDetector da;
  ContactDetector db;
  std::vector<DetectedContact> ca;
  std::vector<DetectedContact> cb;
  std::vector<ContactKey> ka;
  std::vector<ContactKey> kb;
  da.detect(a, statics, 0.0, ca, ka);
  db.detect(b, statics, 0.0, cb, kb);
  ASSERT_GT(ka.size(), 50u);
  ASSERT_EQ(ka, kb);
  for (std::size_t k = 0; k < ka.size(); ++k) {
    // The same geometry, bit for bit, and side a the body with the smaller id.
    EXPECT_EQ(ca[k].geometry.g_N, cb[k].geometry.g_N);
    EXPECT_EQ(ca[k].geometry.I_n, cb[k].geometry.I_n);
    EXPECT_EQ(ca[k].geometry.I_r_a, cb[k].geometry.I_r_a);
    EXPECT_EQ(ca[k].geometry.I_r_b, cb[k].geometry.I_r_b);
    EXPECT_EQ(ca[k].material_a, cb[k].material_a);
    if (!(ka[k].b & kStaticTag)) {
      EXPECT_LT(ka[k].a, ka[k].b);
    }
    EXPECT_EQ(a.ids()[static_cast<std::size_t>(ca[k].body_a)],
              b.ids()[static_cast<std::size_t>(cb[k].body_a)]);
  }
}

// The candidate list with a skin (a Verlet list): over random motion, the contacts are those of
// detection from scratch, bit for bit, while the list is built far less often.
TEST(ContactDetector, ACandidateListWithASkinFindsExactlyTheContactsOfDetectionFromScratch) {
  BodySystem system;
  StaticGeometry statics;
  demo::add_open_box(statics, 0.2, 0.2);
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  GlobalId id = 1;
  for (int k = 0; k < 400; ++k) {
    const double r = 0.004 + 0.004 * u(rng);
    system.add(sphere_body(id++, r, Vector3(0.01 + 0.18 * u(rng), 0.01 + 0.18 * u(rng),
                                            0.005 + 0.1 * u(rng))));
  }
  const double skin = 0.002;
  ContactDetector scratch;
  ContactDetector listed;
  listed.set_skin(skin);
  std::vector<DetectedContact> a, b;
  std::vector<ContactKey> ka, kb;
  std::size_t total = 0;
  for (int step = 0; step < 300; ++step) {
    // Random steps of at most skin/20 per axis: the list lasts a few steps, then is rebuilt.
    for (body::State& x : system.states()) {
      for (int d = 0; d < 3; ++d) x.q[d] += (u(rng) - 0.5) * 0.1 * skin;
    }
    if (step == 150) {  // a layout change forces a new list
      const std::size_t gone[] = {7, 99};
      system.remove(gone);
    }
    const double margin = 1e-4;
    scratch.detect(system, statics, margin, a, ka);
    listed.detect(system, statics, margin, b, kb);
    ASSERT_EQ(ka, kb) << "step " << step;
    for (std::size_t k = 0; k < ka.size(); ++k) {
      ASSERT_EQ(a[k].geometry.g_N, b[k].geometry.g_N);
      ASSERT_EQ(a[k].geometry.I_n, b[k].geometry.I_n);
      ASSERT_EQ(a[k].geometry.I_r_a, b[k].geometry.I_r_a);
      ASSERT_EQ(a[k].body_a, b[k].body_a);
      ASSERT_EQ(a[k].body_b, b[k].body_b);
    }
    total += ka.size();
  }
  EXPECT_GT(total, 300u * 100u);  // the spheres are dense enough to touch
  EXPECT_EQ(scratch.list_builds(), 300u);
  EXPECT_GT(listed.list_builds(), 5u);    // rebuilt as the spheres wander …
  EXPECT_LT(listed.list_builds(), 100u);  // … but kept for several steps each time
  EXPECT_THROW(listed.set_skin(-1.0), InvalidArgument);
  EXPECT_THROW(listed.set_skin(std::nan("")), InvalidArgument);
}

TEST(CollisionWorldAdd, TheConstantTimePairCheckNamesTheFirstConflictingCollider) {
  const auto at = [](collision::Shape shape, collision::BodyIndex body) {
    return collision::Collider{std::move(shape), body, Vector3::Zero(), Matrix3::Identity()};
  };
  collision::CollisionWorld world;
  world.add(at(collision::Box{}, 0));                  // 0: a box of body 0
  world.add(at(collision::Capsule{}, 0));              // 1: same body, exempt
  world.add(at(collision::Sphere{}, 1));               // 2
  world.add(at(collision::HalfSpace{}, collision::kStatic));  // 3
  // A capsule of another body meets the box of body 0 first.
  std::string m = message_of([&] { world.add(at(collision::Capsule{}, 7)); });
  EXPECT_NE(m.find("cannot meet collider 0 (box, body 0)"), std::string::npos) << m;
  // Static boxes and capsules meet the moving box first.
  m = message_of([&] { world.add(at(collision::Box{}, collision::kStatic)); });
  EXPECT_NE(m.find("cannot meet collider 0 (box, body 0)"), std::string::npos) << m;
  // Parts of body 0 are exempt from each other.
  world.add(at(collision::Box{}, 0));  // 4
  EXPECT_EQ(world.colliders().size(), 5u);
  // Spheres meet everything: a hundred thousand of them is a matter of memory, not of the check.
  for (int i = 0; i < 100000; ++i) world.add(at(collision::Sphere{0.1}, 3 + i));
  EXPECT_EQ(world.colliders().size(), 100005u);
  // The second representative: the first box on a body other than the first box's.
  collision::CollisionWorld boxes;
  boxes.add(at(collision::Box{}, 5));
  boxes.add(at(collision::Box{}, 5));
  m = message_of([&] { boxes.add(at(collision::Box{}, 6)); });
  EXPECT_NE(m.find("cannot meet collider 0 (box, body 5)"), std::string::npos) << m;
  boxes.add(at(collision::HalfSpace{}, collision::kStatic));  // 2
  boxes.add(at(collision::Capsule{}, 5));                      // 3
  collision::CollisionWorld two;
  two.add(at(collision::Capsule{}, 5));  // 0
  two.add(at(collision::Sphere{}, 6));   // 1
  two.add(at(collision::Box{}, 5));      // 2: same body as the capsule
  // A capsule of body 5 is exempt from both; one of body 8 meets collider 0; a static box meets
  // collider 0 too; a box of body 6 meets collider 0.
  two.add(at(collision::Capsule{}, 5));
  m = message_of([&] { two.add(at(collision::Box{}, 6)); });
  EXPECT_NE(m.find("cannot meet collider 0 (capsule, body 5)"), std::string::npos) << m;
}

}  // namespace
}  // namespace grbd::timestep
