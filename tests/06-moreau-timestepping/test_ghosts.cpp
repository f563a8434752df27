// Chapter 6: owned bodies and ghosts in one BodySystem, the seam of chapter 8's parallel engine,
// and the body record that enters and leaves it.
//
// The reference is the system without ghosts: a process that owns some of the bodies and holds
// exact copies of the others must find, for the contacts with an owned side, the same keys and
// the same geometry bit for bit, and — when its contacts are all of the full system's — the same
// percussions and the same end-of-step states of its bodies.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/contacts.hpp"
#include "grbd/timestep/stepper.hpp"
#include "grbd_test/messages.hpp"
#include "scenes.hpp"

namespace grbd::timestep {
namespace {

using demo::sphere_body;

using test::message_of;

// Every row's id, image and owned flag agree with both lookups.
void expect_consistent(const BodySystem& system) {
  for (std::size_t i = 0; i < system.size(); ++i) {
    const bool owned = i < system.owned_count();
    EXPECT_EQ(system.owned(i), owned);
    EXPECT_EQ((system.flags()[i] & kOwned) != 0, owned) << "row " << i;
    if (owned) {
      EXPECT_EQ(system.index_of(system.ids()[i]), i);
      EXPECT_EQ(system.images()[i], 0u);
    } else {
      EXPECT_EQ(system.ghost_index_of(system.ids()[i], system.images()[i]), i);
    }
  }
}

TEST(Ghosts, FollowTheOwnedBodiesAndHaveTheirOwnLookup) {
  BodySystem system;
  for (GlobalId id = 1; id <= 4; ++id) system.add(sphere_body(id, 0.01, Vector3(0.1 * id, 0, 0)));
  // A copy of body 7 (owned elsewhere) and a periodic image of body 2, shifted by one period.
  const std::size_t g7 = system.add_ghost(sphere_body(7, 0.02, Vector3(1, 2, 3)));
  const std::size_t g2 =
      system.add_ghost(system.record(system.index_of(2)), Vector3(0.5, 0, 0), 1);
  EXPECT_EQ(system.owned_count(), 4u);
  EXPECT_EQ(system.ghost_count(), 2u);
  EXPECT_EQ(g7, 4u);
  EXPECT_EQ(g2, 5u);
  EXPECT_EQ(system.index_of(7), BodySystem::npos);  // owned bodies only
  EXPECT_EQ(system.index_of(2), 1u);
  EXPECT_EQ(system.ghost_index_of(2, 1), 5u);
  EXPECT_EQ(system.ghost_index_of(2, 0), BodySystem::npos);
  EXPECT_EQ(system.states()[g2].q.x(), 0.2 + 0.5);
  EXPECT_EQ(system.images()[g2], 1u);
  expect_consistent(system);

  // An owned body added now takes the first ghost's row; that ghost moves to the end.
  const std::size_t five = system.add(sphere_body(5, 0.01, Vector3(0.5, 0, 0)));
  EXPECT_EQ(five, 4u);
  EXPECT_EQ(system.owned_count(), 5u);
  EXPECT_EQ(system.ghost_index_of(7), 6u);
  EXPECT_EQ(system.states()[6].q.z(), 3.0);
  EXPECT_EQ(std::get<collision::Sphere>(system.shapes()[6]).radius, 0.02);
  expect_consistent(system);

  // Removal and reordering concern owned bodies; ghosts keep their order after them.
  const std::size_t first[] = {0};
  system.remove(first);
  EXPECT_EQ(system.owned_count(), 4u);
  EXPECT_EQ(system.ghost_count(), 2u);
  expect_consistent(system);
  const std::int32_t reverse[] = {3, 2, 1, 0};
  system.permute(reverse);
  EXPECT_EQ(system.ids()[0], 5u);
  expect_consistent(system);
  system.reorder_morton(0.05);
  expect_consistent(system);

  const std::uint64_t before = system.layout_version();
  system.clear_ghosts();
  EXPECT_GT(system.layout_version(), before);
  EXPECT_EQ(system.size(), 4u);
  EXPECT_EQ(system.ghost_index_of(7), BodySystem::npos);
  EXPECT_EQ(system.ghost_index_of(2, 1), BodySystem::npos);
  // After clearing, the same ghosts can come back.
  system.add_ghost(sphere_body(7, 0.02, Vector3(1, 2, 3)));
  EXPECT_EQ(system.ghost_index_of(7), 4u);
  expect_consistent(system);
}

TEST(Ghosts, MisuseIsRefusedNamingTheBody) {
  BodySystem system;
  system.add(sphere_body(1, 0.01, Vector3::Zero()));
  system.add_ghost(sphere_body(2, 0.01, Vector3::UnitX()));
  EXPECT_NE(message_of([&] { system.add_ghost(sphere_body(1, 0.01, Vector3::Zero())); })
                .find("add_ghost (body 1): the global id 1 is already used by the owned body"),
            std::string::npos);
  EXPECT_NE(message_of([&] { system.add_ghost(sphere_body(2, 0.01, Vector3::UnitX())); })
                .find("add_ghost (body 2): its ghost with image 0 is present already"),
            std::string::npos);
  EXPECT_NE(message_of([&] { system.add(sphere_body(2, 0.01, Vector3::UnitX())); })
                .find("add (body 2): a ghost of it is present at local index 1"),
            std::string::npos);
  const std::size_t ghost[] = {1};
  EXPECT_NE(message_of([&] { system.remove(ghost); })
                .find("expected local indices of owned bodies, below 1, found 1"),
            std::string::npos);
  const std::int32_t two[] = {1, 0};
  EXPECT_NE(message_of([&] { system.permute(two); })
                .find("expected a permutation of the 1 owned bodies, found 2 entries"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              system.add_ghost(sphere_body(3, 0.01, Vector3::Zero()),
                               Vector3(std::nan(""), 0, 0), 4);
            }).find("add_ghost (body 3): expected a finite shift"),
            std::string::npos);
  BodyRecord bad = sphere_body(9, 0.01, Vector3::Zero());
  bad.shape = collision::Sphere{-0.01};
  EXPECT_NE(message_of([&] { system.add_ghost(bad); }).find("BodySystem::add_ghost (body 9): "),
            std::string::npos);
  EXPECT_EQ(system.size(), 2u);  // nothing refused was added
  expect_consistent(system);
}

TEST(Ghosts, RandomAddsRemovesAndClearsKeepBothLookupsRight) {
  // A model of the system (ids of owned bodies, (id, image) of ghosts) against the real one over
  // random operations, growing both tables several times.
  std::mt19937_64 rng(5);
  BodySystem system;
  std::set<GlobalId> owned;
  std::set<std::pair<GlobalId, std::uint32_t>> ghosts;
  GlobalId next = 1;
  for (int op = 0; op < 4000; ++op) {
    const int what = static_cast<int>(rng() % 10);
    if (what < 4) {
      system.add(sphere_body(next, 0.01, Vector3(0.01 * static_cast<double>(next % 97), 0, 0)));
      owned.insert(next++);
    } else if (what < 8) {
      const GlobalId id = 100000 + rng() % 500;
      const auto image = static_cast<std::uint32_t>(rng() % 3);
      if (ghosts.contains({id, image})) continue;
      system.add_ghost(sphere_body(id, 0.01, Vector3::Zero()), Vector3(0.1 * image, 0, 0), image);
      ghosts.insert({id, image});
    } else if (what == 8 && !owned.empty()) {
      std::vector<std::size_t> rows;
      for (std::size_t i = 0; i < system.owned_count(); ++i) {
        if (rng() % 4 == 0) rows.push_back(i);
      }
      for (const std::size_t i : rows) owned.erase(system.ids()[i]);
      std::shuffle(rows.begin(), rows.end(), rng);
      system.remove(rows);
    } else if (rng() % 8 == 0) {
      system.clear_ghosts();
      ghosts.clear();
    }
    ASSERT_EQ(system.owned_count(), owned.size());
    ASSERT_EQ(system.ghost_count(), ghosts.size());
  }
  expect_consistent(system);
  for (const GlobalId id : owned) EXPECT_NE(system.index_of(id), BodySystem::npos);
  for (const auto& [id, image] : ghosts) {
    EXPECT_NE(system.ghost_index_of(id, image), BodySystem::npos);
  }
  EXPECT_EQ(system.index_of(next), BodySystem::npos);
}

// A dense random pile in an open box, a box body on top, after `steps` steps of free settling.
struct Pile {
  BodySystem system;
  StaticGeometry statics;
  MaterialTable materials = demo::one_material(0.4);
};

void fill(Pile& pile) {
  demo::add_open_box(pile.statics, 0.1, 0.1);
  demo::add_sphere_lattice(pile.system, 4, 4, 5, 0.01, 3);
  pile.system.add(demo::box_body(1000, Vector3(0.03, 0.03, 0.01), Vector3(0.05, 0.05, 0.14)));
}

StepSettings settings() {
  StepSettings s;
  s.dt = 1e-3;
  s.solver.max_iterations = 200;
  s.solver.rel_tol = 1e-8;
  return s;
}

// The system with the bodies of `ghosts` (global ids) as ghosts, owned and ghost rows each in a
// shuffled order.
BodySystem split(const BodySystem& full, const std::set<GlobalId>& ghosts, std::uint64_t seed) {
  std::vector<std::size_t> rows(full.size());
  std::iota(rows.begin(), rows.end(), 0);
  std::mt19937_64 rng(seed);
  std::shuffle(rows.begin(), rows.end(), rng);
  BodySystem part;
  for (const std::size_t i : rows) {
    if (!ghosts.contains(full.ids()[i])) part.add(full.record(i));
  }
  for (const std::size_t i : rows) {
    if (ghosts.contains(full.ids()[i])) part.add_ghost(full.record(i));
  }
  return part;
}

TEST(Ghosts, DetectionFindsTheFullSystemsContactsWithAnOwnedSideBitForBit) {
  Pile pile;
  fill(pile);
  MoreauStepper stepper(pile.system, pile.statics, pile.materials, settings());
  for (int k = 0; k < 150; ++k) stepper.step();
  ContactDetector detector;
  std::vector<DetectedContact> all;
  std::vector<ContactKey> all_keys;
  const double margin = 1e-4;
  detector.detect(pile.system, pile.statics, margin, all, all_keys);
  ASSERT_GT(all.size(), 150u);

  std::mt19937_64 rng(17);
  for (int trial = 0; trial < 4; ++trial) {
    std::set<GlobalId> ghosts;
    for (const GlobalId id : pile.system.ids()) {
      if (rng() % 2 == 0) ghosts.insert(id);
    }
    const BodySystem part = split(pile.system, ghosts, rng());
    ASSERT_EQ(part.ghost_count(), ghosts.size());
    std::vector<DetectedContact> found;
    std::vector<ContactKey> keys;
    detector.detect(part, pile.statics, margin, found, keys);
    // The expected keys: the full system's contacts with an owned side (a static object is not).
    std::map<ContactKey, std::size_t> expected;
    for (std::size_t k = 0; k < all_keys.size(); ++k) {
      const ContactKey& key = all_keys[k];
      const bool a_owned = !(key.a & kStaticTag) && !ghosts.contains(key.a);
      const bool b_owned = !(key.b & kStaticTag) && !ghosts.contains(key.b);
      if (a_owned || b_owned) expected.emplace(key, k);
    }
    ASSERT_GT(expected.size(), 40u);
    ASSERT_LT(expected.size(), all.size());
    ASSERT_EQ(keys.size(), expected.size()) << "trial " << trial;
    for (std::size_t k = 0; k < keys.size(); ++k) {
      const auto it = expected.find(keys[k]);
      ASSERT_NE(it, expected.end());
      const DetectedContact& a = all[it->second];
      const DetectedContact& b = found[k];
      EXPECT_EQ(a.geometry.g_N, b.geometry.g_N);
      EXPECT_EQ(a.geometry.I_n, b.geometry.I_n);
      EXPECT_EQ(a.geometry.I_r_a, b.geometry.I_r_a);
      EXPECT_EQ(a.geometry.I_r_b, b.geometry.I_r_b);
      const auto id = [](const BodySystem& s, collision::BodyIndex i) {
        return i == collision::kStatic ? ~GlobalId{0} : s.ids()[static_cast<std::size_t>(i)];
      };
      EXPECT_EQ(id(pile.system, a.body_a), id(part, b.body_a));
      EXPECT_EQ(id(pile.system, a.body_b), id(part, b.body_b));
    }
  }
}

TEST(Ghosts, AStepWithGhostsGivesTheOwnedBodiesTheFullSystemsPercussionsAndStates) {
  Pile pile;
  fill(pile);
  MoreauStepper full(pile.system, pile.statics, pile.materials, settings());
  for (int k = 0; k < 150; ++k) full.step();
  const BodySystem start = pile.system;
  const std::vector<ContactKey> warm_keys(full.warm_starts().keys().begin(),
                                          full.warm_starts().keys().end());
  const std::vector<Vector3> warm_lambda(full.warm_starts().lambda().begin(),
                                         full.warm_starts().lambda().end());
  const StepReport reference = full.step();
  ASSERT_GT(reference.contacts, 100u);
  ASSERT_GT(reference.iterations, 2);

  // Ghosts: a random set of bodies no two of which share a contact of this step, none touching
  // the walls (a pair needs an owned side), so that the contacts with an owned side are all the
  // contacts, and the problem is the full one.
  std::mt19937_64 rng(23);
  std::vector<GlobalId> candidates(start.ids().begin(), start.ids().end());
  std::shuffle(candidates.begin(), candidates.end(), rng);
  std::set<GlobalId> ghosts;
  const auto touches_a_ghost_or_a_wall = [&](GlobalId id) {
    const auto other = [](GlobalId x) { return (x & kStaticTag) != 0; };
    for (const ContactKey& key : full.keys()) {
      if ((key.a == id && other(key.b)) || (key.b == id && other(key.a))) return true;
      if ((key.a == id && ghosts.contains(key.b)) || (key.b == id && ghosts.contains(key.a))) {
        return true;
      }
    }
    return false;
  };
  for (const GlobalId id : candidates) {
    if (!touches_a_ghost_or_a_wall(id)) ghosts.insert(id);
  }
  ASSERT_GT(ghosts.size(), start.size() / 5);

  BodySystem part = split(start, ghosts, 29);
  MoreauStepper stepper(part, pile.statics, pile.materials, settings());
  stepper.set_clock(full.time() - full.settings().dt, full.steps() - 1);
  stepper.warm_starts().store(warm_keys, warm_lambda);
  const StepReport report = stepper.step();

  ASSERT_EQ(std::vector<ContactKey>(stepper.keys().begin(), stepper.keys().end()),
            std::vector<ContactKey>(full.keys().begin(), full.keys().end()));
  EXPECT_EQ(report.iterations, reference.iterations);
  EXPECT_EQ(report.residual, reference.residual);
  for (std::size_t k = 0; k < full.keys().size(); ++k) {
    EXPECT_EQ(stepper.percussions()[k], full.percussions()[k]) << "contact " << k;
  }
  double kinetic = 0.0;
  for (std::size_t i = 0; i < part.owned_count(); ++i) {
    const std::size_t j = pile.system.index_of(part.ids()[i]);
    EXPECT_EQ(part.states()[i].q, pile.system.states()[j].q);
    EXPECT_EQ(part.states()[i].u, pile.system.states()[j].u);
    kinetic += body::kinetic_energy(part.inertia()[i], part.states()[i].u);
  }
  // The report's energies are the owned bodies'.
  EXPECT_NEAR(report.kinetic_energy, kinetic, 1e-12 * kinetic);
  EXPECT_LT(report.kinetic_energy, reference.kinetic_energy);
  // Ghosts are left at the midpoint: their owner advances them.
  for (std::size_t i = part.owned_count(); i < part.size(); ++i) {
    const std::size_t j = start.index_of(part.ids()[i]);
    EXPECT_EQ(part.states()[i].u, start.states()[j].u);
  }
}

// ---- The body record ----------------------------------------------------------------------

std::vector<BodyRecord> assorted_records() {
  std::vector<BodyRecord> records;
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> x(-1.0, 1.0);
  for (int k = 0; k < 30; ++k) {
    BodyRecord r;
    r.id = rng() >> 2;
    switch (k % 3) {
      case 0: r.shape = collision::Sphere{0.5 + x(rng) * 0.1}; break;
      case 1: r.shape = collision::Box{Vector3(1.0 + x(rng), 1.5, 0.25)}; break;
      default: r.shape = collision::Capsule{0.2, 0.7 + x(rng) * 0.1}; break;
    }
    r.inertia = {2.0 + x(rng), Vector3(1.0, 1.0 + 0.1 * x(rng), 1.5)};
    r.material = static_cast<MaterialId>(rng() % 7);
    r.flags = k % 4 == 0 ? 0 : kDynamic;
    r.state.q << x(rng), x(rng), -0.0, Vector4::Random().normalized();
    r.state.u << x(rng), 0.0, 1e-310, x(rng), x(rng), x(rng);  // a subnormal survives too
    records.push_back(r);
  }
  return records;
}

TEST(BodyRecord, PackAndUnpackAreExactInverses) {
  for (const BodyRecord& r : assorted_records()) {
    PackedBody bytes;
    pack(r, bytes);
    const BodyRecord back = unpack(bytes);
    EXPECT_EQ(back.id, r.id);
    EXPECT_EQ(back.shape.index(), r.shape.index());
    EXPECT_EQ(collision::bounding_radius(back.shape), collision::bounding_radius(r.shape));
    EXPECT_EQ(back.inertia.m, r.inertia.m);
    EXPECT_EQ(back.inertia.K_Theta, r.inertia.K_Theta);
    EXPECT_EQ(back.material, r.material);
    EXPECT_EQ(back.flags, r.flags);
    EXPECT_EQ(back.state.q, r.state.q);
    EXPECT_EQ(back.state.u, r.state.u);
    EXPECT_TRUE(std::signbit(back.state.q[2]));  // −0 stays −0: bits, not values
    PackedBody again;
    pack(back, again);
    EXPECT_EQ(again, bytes);  // every byte, the state's included
    EXPECT_TRUE(same_constants(back, r));
  }
}

TEST(BodyRecord, TheSystemGivesBackTheRecordsItWasGiven) {
  BodySystem system;
  const std::vector<BodyRecord> records = assorted_records();
  for (std::size_t k = 0; k < records.size(); ++k) {
    BodyRecord r = records[k];
    r.state.q.head<3>() = Vector3(double(k), 0.0, 0.0);  // (positions aside, any record will do)
    if (k % 2) {
      system.add(r);
    } else {
      system.add_ghost(r);
    }
  }
  for (std::size_t i = 0; i < system.size(); ++i) {
    const BodyRecord r = system.record(i);
    const auto k = static_cast<std::size_t>(r.state.q.x());
    EXPECT_TRUE(same_constants(r, records[k]));
    if (r.dynamic()) {
      EXPECT_EQ(r.state.u, records[k].state.u);
    } else {
      EXPECT_EQ(r.state.u, Vector6::Zero());  // a fixed body does not move
    }
  }
}

TEST(BodyRecord, BytesThatPackDidNotWriteAreRefused) {
  PackedBody bytes;
  pack(assorted_records()[1], bytes);
  PackedBody bad = bytes;
  bad[packed::shape] = std::byte{3};
  EXPECT_NE(message_of([&] { unpack(bad); }).find("expected a shape code 0–2"), std::string::npos);
  bad = bytes;
  bad[packed::fixed] = std::byte{2};
  EXPECT_NE(message_of([&] { unpack(bad); }).find("fixed byte 0 or 1, found"), std::string::npos);
  BodyRecord half_space = assorted_records()[0];
  half_space.shape = collision::HalfSpace{};
  EXPECT_NE(message_of([&] { pack(half_space, bytes); }).find("found a half-space"),
            std::string::npos);
  BodyRecord owned = assorted_records()[0];
  owned.flags = kDynamic | kOwned;
  EXPECT_NE(message_of([&] { pack(owned, bytes); }).find("expected the flags kDynamic or none"),
            std::string::npos);
  BodySystem system;
  EXPECT_NE(message_of([&] { system.add(owned); }).find("kOwned belongs to the row"),
            std::string::npos);
}

}  // namespace
}  // namespace grbd::timestep
