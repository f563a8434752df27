// Chapter 8: the communicator under mpiexec (run with 1, 2 and 3 processes). References: what
// each rank contributes is a known function of its rank, so every collective result has a closed
// form; a sum of doubles must equal, bit for bit, the sum formed in rank order.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/core/hash.hpp"
#include "grbd/parallel/balance.hpp"
#include "grbd/parallel/bisection.hpp"
#include "grbd/parallel/exchange.hpp"
#include "grbd/parallel/mpi.hpp"
#include "grbd/parallel/stepper.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/materials.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::parallel {
namespace {

const Communicator* world = nullptr;

std::vector<std::byte> bytes_of(const std::string& text) {
  std::vector<std::byte> b(text.size());
  if (!text.empty()) std::memcpy(b.data(), text.data(), text.size());
  return b;
}

std::string text_of(const std::vector<std::byte>& b) {
  return std::string(reinterpret_cast<const char*>(b.data()), b.size());
}

// What rank r contributes at position k: values whose sum depends on the order of addition.
double contribution(int r, std::size_t k) { return std::pow(10.0, 8 * (r % 3)) / (3.0 + k + r); }

TEST(Communicator, SumsAreFormedInRankOrderAndAgreeToTheBit) {
  const int p = world->size();
  std::vector<double> values(5);
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = contribution(world->rank(), k);
  world->sum(values);
  for (std::size_t k = 0; k < values.size(); ++k) {
    double expected = 0.0;
    for (int r = 0; r < p; ++r) expected += contribution(r, k);
    EXPECT_EQ(values[k], expected) << "k = " << k;
  }
  std::vector<std::uint64_t> counts{static_cast<std::uint64_t>(world->rank()) + 1, 1};
  world->sum(counts);
  EXPECT_EQ(counts[0], static_cast<std::uint64_t>(p * (p + 1) / 2));
  EXPECT_EQ(counts[1], static_cast<std::uint64_t>(p));
}

TEST(Communicator, MaxMinAllAny) {
  const int p = world->size();
  std::vector<double> hi{double(world->rank()), -double(world->rank())};
  std::vector<double> lo = hi;
  world->max(hi);
  world->min(lo);
  EXPECT_EQ(hi[0], p - 1.0);
  EXPECT_EQ(hi[1], 0.0);
  EXPECT_EQ(lo[0], 0.0);
  EXPECT_EQ(lo[1], 1.0 - p);
  EXPECT_TRUE(world->all(true));
  EXPECT_EQ(world->all(world->rank() != 0), false);
  EXPECT_EQ(world->any(world->rank() == p - 1), true);
  EXPECT_FALSE(world->any(false));
  // The error agreement: true when every process is fine; false on every process when one failed
  // and the others arrive (well within the patience, since none waits elsewhere).
  EXPECT_TRUE(world->agree(true, "unused", kAgreementPatience));
  EXPECT_FALSE(world->agree(world->rank() != p - 1, "the last rank failed", kAgreementPatience));
}

TEST(Communicator, BroadcastAndAllGatherHandEveryoneTheSameBytes) {
  const int p = world->size();
  std::vector<std::byte> b = bytes_of(world->rank() == p - 1 ? "from the last rank" : "x");
  world->broadcast(b, p - 1);
  EXPECT_EQ(text_of(b), "from the last rank");
  std::vector<std::vector<std::byte>> all;
  const std::string mine(static_cast<std::size_t>(world->rank()), 'a');  // rank 0 sends nothing
  world->all_gather(bytes_of(mine), all);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(p));
  for (int r = 0; r < p; ++r) EXPECT_EQ(text_of(all[r]), std::string(r, 'a'));
  EXPECT_THROW(world->broadcast(b, p), InvalidArgument);
}

// The traffic counters count what this process sent: a size and a message to each neighbour that
// is not itself, their bytes, and one collective operation per reduction or gather.
TEST(Communicator, TrafficCountsMessagesBytesAndCollectives) {
  const int p = world->size();
  const int me = world->rank();
  std::vector<int> neighbours;
  for (int r = 0; r < p; ++r) {
    if (r != me) neighbours.push_back(r);
  }
  std::vector<std::vector<std::byte>> send(neighbours.size(), std::vector<std::byte>(100 + me));
  std::vector<std::vector<std::byte>> received;
  const Communicator::Traffic before = world->traffic();
  world->exchange(neighbours, send, received);
  std::vector<double> x{1.0};
  world->sum(x);
  world->max(x);
  world->all_gather(bytes_of("x"), received);
  const Communicator::Traffic after = world->traffic();
  const std::uint64_t others = neighbours.size();
  EXPECT_EQ(after.messages - before.messages, 2 * others);
  EXPECT_EQ(after.bytes - before.bytes, others * (8 + 100 + static_cast<std::uint64_t>(me)));
  EXPECT_EQ(after.collectives - before.collectives, 3u);
  EXPECT_EQ(self_communicator().traffic().messages, 0u);
}

TEST(Communicator, ExchangeWithNeighboursOnARing) {
  // Each rank's neighbours on a ring of p: itself at p = 1, the other at p = 2, both sides else.
  const int p = world->size();
  const int me = world->rank();
  std::vector<int> neighbours;
  for (const int n : {(me + p - 1) % p, (me + 1) % p}) {
    if (std::find(neighbours.begin(), neighbours.end(), n) == neighbours.end()) {
      neighbours.push_back(n);
    }
  }
  std::vector<std::vector<std::byte>> send;
  for (const int n : neighbours) {
    send.push_back(bytes_of(std::to_string(me) + "->" + std::to_string(n) +
                            std::string(1000 * static_cast<std::size_t>(me), '.')));
  }
  std::vector<std::vector<std::byte>> received;
  for (int round = 0; round < 3; ++round) {  // reused buffers, repeated rounds
    world->exchange(neighbours, send, received);
    ASSERT_EQ(received.size(), neighbours.size());
    for (std::size_t k = 0; k < neighbours.size(); ++k) {
      EXPECT_EQ(text_of(received[k]),
                std::to_string(neighbours[k]) + "->" + std::to_string(me) +
                    std::string(1000 * static_cast<std::size_t>(neighbours[k]), '.'));
    }
  }
  const int outside[] = {p};
  EXPECT_THROW(world->exchange(outside, std::span(send).first(1), received), InvalidArgument);
}

// ---- Body exchange: migration, borders, forward -------------------------------------------

// A number in [−1, 1) from a body's id and a round: the same on every process, whatever P.
double noise(std::uint64_t id, int round, int axis) {
  const std::uint64_t h =
      mix64(mix64(id * 0x9e3779b97f4a7c15ULL + static_cast<std::uint64_t>(round)) +
            static_cast<std::uint64_t>(axis));
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

timestep::BodyRecord bead(std::uint64_t id, const Box& domain) {
  timestep::BodyRecord r;
  r.id = id;
  const double radius = 0.01 + 0.01 * (noise(id, -1, 3) + 1.0);  // 0.01 … 0.03 m
  r.shape = collision::Sphere{radius};
  r.inertia = {1.0, Vector3::Constant(0.4 * radius * radius)};
  const Vector3 u(noise(id, -1, 0), noise(id, -1, 1), noise(id, -1, 2));
  const Vector3 c = domain.min() + (0.5 * (u.array() + 1.0)).matrix().cwiseProduct(domain.sizes());
  r.state.q << c, 1.0, 0.0, 0.0, 0.0;
  r.state.u << noise(id, -2, 0), noise(id, -2, 1), 0.0, 0.0, 0.0, noise(id, -2, 2);
  return r;
}

// Every owned body of every process: id, bounding radius, q, u.
struct Everyone {
  std::vector<std::uint64_t> ids;
  std::vector<double> radii;
  std::vector<body::State> states;
};

Everyone gather(const timestep::BodySystem& system) {
  std::vector<std::byte> mine;
  for (std::size_t i = 0; i < system.owned_count(); ++i) {
    const std::uint64_t id = system.ids()[i];
    const double r = system.bounding_radii()[i];
    const body::State& x = system.states()[i];
    const auto put = [&](const void* p, std::size_t n) {
      const auto* b = static_cast<const std::byte*>(p);
      mine.insert(mine.end(), b, b + n);
    };
    put(&id, 8);
    put(&r, 8);
    put(x.q.data(), 56);
    put(x.u.data(), 48);
  }
  std::vector<std::vector<std::byte>> all;
  world->all_gather(mine, all);
  Everyone e;
  for (const auto& bytes : all) {
    for (std::size_t at = 0; at + 120 <= bytes.size(); at += 120) {
      std::uint64_t id;
      double r;
      body::State x;
      std::memcpy(&id, bytes.data() + at, 8);
      std::memcpy(&r, bytes.data() + at + 8, 8);
      std::memcpy(x.q.data(), bytes.data() + at + 16, 56);
      std::memcpy(x.u.data(), bytes.data() + at + 72, 48);
      e.ids.push_back(id);
      e.radii.push_back(r);
      e.states.push_back(x);
    }
  }
  return e;
}

// Every ghost this process must hold, from everyone's bodies, without the exchange's shortcuts:
// each body, each periodic shift, tested against this subdomain.
void expect_exact_ghosts(const timestep::BodySystem& system, const Partition& grid,
                         double max_radius, double margin, const Everyone& all) {
  const int me = world->rank();
  const Box mine = grid.subdomain(me);
  const Vector3 L = grid.domain().sizes();
  std::size_t expected = 0;
  for (std::size_t b = 0; b < all.ids.size(); ++b) {
    const Vector3 c = all.states[b].q.head<3>();
    for (int sz = -1; sz <= 1; ++sz) {
      for (int sy = -1; sy <= 1; ++sy) {
        for (int sx = -1; sx <= 1; ++sx) {
          const std::array<int, 3> s{sx, sy, sz};
          bool allowed = true;
          for (int d = 0; d < 3; ++d) allowed = allowed && (s[d] == 0 || grid.periodic()[d]);
          if (!allowed) continue;
          const bool plain = sx == 0 && sy == 0 && sz == 0;
          if (plain && grid.owner_of(c) == me) continue;
          const Vector3 shift(sx * L.x(), sy * L.y(), sz * L.z());
          if (!overlaps(c + shift, all.radii[b] + max_radius + margin, mine)) continue;
          ++expected;
          const std::size_t row = system.ghost_index_of(all.ids[b], image_code(s));
          ASSERT_NE(row, timestep::BodySystem::npos)
              << "rank " << me << ": no ghost of body " << all.ids[b] << " image " << image_code(s);
          Vector3 p = c;
          p += shift;
          EXPECT_EQ(system.states()[row].q.head<3>(), p);
          EXPECT_EQ(system.states()[row].q.tail<4>(), all.states[b].q.tail<4>());
          EXPECT_EQ(system.states()[row].u, all.states[b].u);
        }
      }
    }
  }
  EXPECT_EQ(system.ghost_count(), expected) << "rank " << me;
}

// 400 beads in random motion through a box periodic along x and y, cut by `grid`.
void expect_every_body_once_and_every_ghost_exact(const Partition& grid) {
  const int p = world->size();
  const int me = world->rank();
  const Box& domain = grid.domain();
  const double margin = 0.02;
  const std::uint64_t n = 400;
  timestep::BodySystem system;
  for (std::uint64_t id = 1; id <= n; ++id) {
    const timestep::BodyRecord r = bead(id, domain);
    if (grid.owner_of(r.state.q.head<3>()) == me) system.add(r);
  }
  BodyExchange exchange(*world, grid, margin, 0.03);
  std::uint64_t migrated = 0;
  for (int round = 0; round < 25; ++round) {
    // Every body moves by up to 2 cm along x and y (periodic) and 1 cm along z (kept inside).
    for (std::size_t i = 0; i < system.owned_count(); ++i) {
      body::State& x = system.states()[i];
      const std::uint64_t id = system.ids()[i];
      x.q.x() += 0.02 * noise(id, round, 0);
      x.q.y() += 0.02 * noise(id, round, 1);
      x.q.z() = std::clamp(x.q.z() + 0.01 * noise(id, round, 2), 0.05, 0.35);
    }
    migrated += exchange.migrate(system);
    exchange.borders(system);
    const Everyone all = gather(system);
    // No body lost or duplicated: the ids are 1 … n, each once, each with its owner.
    std::vector<std::uint64_t> ids = all.ids;
    std::sort(ids.begin(), ids.end());
    ASSERT_EQ(ids.size(), n);
    for (std::uint64_t k = 0; k < n; ++k) ASSERT_EQ(ids[k], k + 1);
    for (std::size_t i = 0; i < system.owned_count(); ++i) {
      const Vector3 c = system.states()[i].q.head<3>();
      ASSERT_EQ(grid.owner_of(c), me);
      ASSERT_TRUE(c.x() >= 0.0 && c.x() < 1.0 && c.y() >= 0.0 && c.y() < 0.6);  // wrapped
    }
    expect_exact_ghosts(system, grid, 0.03, margin, all);
    if (::testing::Test::HasFatalFailure()) return;
    // Forward: the owners move a little (no migration) and change their velocities; the ghosts
    // follow, bit for bit.
    for (std::size_t i = 0; i < system.owned_count(); ++i) {
      system.states()[i].q.z() += 1e-4;
      system.states()[i].u[3] = static_cast<double>(round);
    }
    exchange.forward(system);
    expect_exact_ghosts(system, grid, 0.03, margin, gather(system));
  }
  std::vector<std::uint64_t> total{migrated};
  world->sum(total);
  if (p > 1) {
    EXPECT_GT(total[0], 100u);  // bodies did cross between processes
  }
  // forward() after a change of layout is refused.
  if (system.owned_count() > 0) {
    const std::size_t first[] = {0};
    system.remove(first);
    EXPECT_THROW(exchange.forward(system), InvalidArgument);
  }
}

TEST(BodyExchange, MigrationAndBordersKeepEveryBodyOnceAndEveryGhostExact) {
  const Box domain(Vector3(0.0, 0.0, 0.0), Vector3(1.0, 0.6, 0.4));
  expect_every_body_once_and_every_ghost_exact(
      CartesianGrid(domain, grid_dims(world->size(), domain.sizes()), {true, true, false}));
}

// The same through the leaves of a bisection tree, whose boxes do not line up in a grid.
TEST(BodyExchange, MigrationAndBordersThroughABisectionTreeKeepEveryBodyOnceAndEveryGhostExact) {
  const Box domain(Vector3(0.0, 0.0, 0.0), Vector3(1.0, 0.6, 0.4));
  expect_every_body_once_and_every_ghost_exact(
      BisectionTree(domain, world->size(), {true, true, false}));
}

TEST(BodyExchange, ImageCodesRoundTrip) {
  for (int sz = -1; sz <= 1; ++sz) {
    for (int sy = -1; sy <= 1; ++sy) {
      for (int sx = -1; sx <= 1; ++sx) {
        const std::array<int, 3> s{sx, sy, sz};
        EXPECT_EQ(image_shift(image_code(s)), s);
      }
    }
  }
  EXPECT_EQ(image_code({0, 0, 0}), 0u);
  EXPECT_THROW(image_shift(14), InvalidArgument);
  EXPECT_THROW(image_shift(28), InvalidArgument);
  EXPECT_THROW(image_code({2, 0, 0}), InvalidArgument);
}

// The image of one copy seen from another is the difference of their shifts: seen from the body
// itself, a ghost's own code; seen from an image, the body's code is the opposite shift's.
TEST(BodyExchange, RelativeImagesAreDifferencesOfShifts) {
  std::size_t pairs = 0;
  for (std::uint32_t a = 0; a <= 27; ++a) {
    if (a == 14) continue;
    EXPECT_EQ(timestep::relative_image(0, a), a);
    EXPECT_EQ(timestep::relative_image(a, a), 0u);
    const std::array<int, 3> sa = image_shift(a);
    EXPECT_EQ(timestep::relative_image(a, 0), image_code({-sa[0], -sa[1], -sa[2]}));
    for (std::uint32_t b = 0; b <= 27; ++b) {
      if (b == 14) continue;
      const std::array<int, 3> sb = image_shift(b);
      const std::array<int, 3> d{sb[0] - sa[0], sb[1] - sa[1], sb[2] - sa[2]};
      if (std::abs(d[0]) > 1 || std::abs(d[1]) > 1 || std::abs(d[2]) > 1) {
        EXPECT_THROW(timestep::relative_image(a, b), InvalidArgument);  // two periods apart
      } else {
        EXPECT_EQ(image_shift(timestep::relative_image(a, b)), d);
        ++pairs;
      }
    }
  }
  EXPECT_EQ(pairs, 343u);  // per axis 7 of the 9 pairs of shifts are at most one apart: 7³
}

// ---- The parallel step ----------------------------------------------------------------------

timestep::BodyRecord sphere(std::uint64_t id, double r, const Vector3& c, const Vector3& v) {
  timestep::BodyRecord b;
  b.id = id;
  b.shape = collision::Sphere{r};
  const double m = 2500.0 * 4.0 / 3.0 * M_PI * r * r * r;
  b.inertia = {m, Vector3::Constant(0.4 * m * r * r)};
  b.state.q << c, 1.0, 0.0, 0.0, 0.0;
  b.state.u << v, 0.0, 0.0, 0.0;
  return b;
}

timestep::MaterialTable glass() {
  timestep::MaterialTable table;
  table.set_pair(table.add("glass"), 0, {0.5, 0.0, 0.0});
  return table;
}

// A column of n spheres of radius r standing on the floor at (x, y), moving with v: the ones this
// process owns.
void add_column(timestep::BodySystem& mine, const Partition& grid, int n, double r,
                const Vector3& base, const Vector3& v) {
  for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(n); ++k) {
    const Vector3 c = base + Vector3(0.0, 0.0, r + 2.0 * r * static_cast<double>(k));
    if (grid.owner_of(c) == world->rank()) mine.add(sphere(k + 1, r, c, v));
  }
}

// The floor z = 0, static object 0.
timestep::StaticGeometry floor_only() {
  timestep::StaticGeometry statics;
  timestep::StaticObject floor;
  floor.shape = collision::HalfSpace{Vector3::UnitZ(), 0.0};
  statics.add(floor);
  return statics;
}

// A resting column's step: Δt = 1 ms, solved to a relative 10⁻¹³.
timestep::StepSettings resting(double r) {
  timestep::StepSettings settings;
  settings.dt = 1e-3;
  settings.tolerance_radius = r;
  settings.solver.abs_tol = 0.0;
  settings.solver.rel_tol = 1e-13;
  settings.solver.max_iterations = 20000;
  return settings;
}

// A flight of spheres of radius 5 mm with centres on a lattice, first at `origin`, `spacing` apart,
// and velocities `drift` plus `spread` times a noise of their own: all of them in `serial`, those
// this process owns in `mine`.
void add_flight(timestep::BodySystem& serial, timestep::BodySystem& mine, const Partition& grid,
                const std::array<int, 3>& count, const Vector3& origin, const Vector3& spacing,
                const Vector3& drift, double spread, int round) {
  std::uint64_t id = 1;
  for (int i = 0; i < count[0]; ++i) {
    for (int j = 0; j < count[1]; ++j) {
      for (int k = 0; k < count[2]; ++k, ++id) {
        const Vector3 c = origin + Vector3(i, j, k).cwiseProduct(spacing);
        const Vector3 v =
            drift + spread * Vector3(noise(id, round, 0), noise(id, round, 1), noise(id, round, 2));
        serial.add(sphere(id, 0.005, c, v));
        if (grid.owner_of(c) == world->rank()) mine.add(sphere(id, 0.005, c, v));
      }
    }
  }
}

// Free flight, 2 ms steps, contacts measured against radius 5 mm, the given skin.
timestep::StepSettings flight(double skin) {
  timestep::StepSettings settings;
  settings.dt = 2e-3;
  settings.tolerance_radius = 0.005;
  settings.skin = skin;
  return settings;
}

// Every body once over the processes, each in the state of the serial run, bit for bit.
void expect_the_serial_bodies(const timestep::BodySystem& mine,
                              const timestep::BodySystem& serial) {
  std::vector<std::uint64_t> owned{mine.owned_count()};
  world->sum(owned);
  EXPECT_EQ(owned[0], serial.size());
  for (std::size_t i = 0; i < mine.owned_count(); ++i) {
    const std::size_t j = serial.index_of(mine.ids()[i]);
    ASSERT_NE(j, timestep::BodySystem::npos);
    ASSERT_EQ(mine.states()[i].q, serial.states()[j].q) << "body " << mine.ids()[i];
    ASSERT_EQ(mine.states()[i].u, serial.states()[j].u);
  }
}

// Free flight across subdomains: without contacts each body's motion is its own, and the parallel
// step must reproduce the serial one bit for bit, wherever the body is owned.
TEST(ParallelStepper, FreeFlightAcrossSubdomainsIsTheSerialRunBitForBit) {
  const int p = world->size();
  const Box domain(Vector3(0, 0, 0), Vector3(1, 1, 1));
  const CartesianGrid grid(domain, grid_dims(p, domain.sizes()));
  timestep::BodySystem serial;
  timestep::BodySystem mine;
  // A common drift (0.45 m along x in the run) and differences too small to close a gap.
  add_flight(serial, mine, grid, {6, 6, 6}, Vector3(0.1, 0.1, 0.5), Vector3(0.16, 0.16, 0.07),
             Vector3(1.5, 1.0, 2.0), 0.05, 7);
  const timestep::StaticGeometry statics;
  const timestep::MaterialTable materials = glass();
  timestep::MoreauStepper reference(serial, statics, materials, flight(0.02));
  ParallelStepper parallel(*world, grid, mine, statics, materials, flight(0.02), {0.005});
  std::size_t contacts = 0;
  for (int step = 0; step < 150; ++step) {  // collective: no ASSERT inside, no early exit
    reference.step();
    contacts += parallel.step().contacts;
  }
  EXPECT_EQ(contacts, 0u);
  expect_the_serial_bodies(mine, serial);
  EXPECT_GT(parallel.rebuilds(), 5u);    // the bodies moved more than half the skin, often …
  EXPECT_LT(parallel.rebuilds(), 150u);  // … but not at every step
}

// The scene's Morton reordering (StepSettings::reorder_interval) on many processes: every 10 steps
// each process reorders its own bodies along the Morton curve, as the serial engine does. The
// bodies are at rest (no gravity, no drift), so that after the step that followed a reordering
// each process's bodies must be in the order BodySystem::reorder_morton gives them; free flight
// stays the serial run.
TEST(ParallelStepper, MortonReorderingIsDoneOnEveryProcessAndKeepsTheSerialRun) {
  const int p = world->size();
  const Box domain(Vector3(0, 0, 0), Vector3(1, 1, 1));
  const CartesianGrid grid(domain, grid_dims(p, domain.sizes()));
  timestep::BodySystem serial;
  timestep::BodySystem mine;
  // Ids along z first: the Morton order is another one.
  add_flight(serial, mine, grid, {6, 6, 6}, Vector3(0.1, 0.1, 0.1), Vector3(0.16, 0.16, 0.16),
             Vector3::Zero(), 0.0, 3);
  timestep::StepSettings settings = flight(0.02);
  settings.I_g = Vector3::Zero();
  settings.reorder_interval = 10;
  const timestep::StaticGeometry statics;
  const timestep::MaterialTable materials = glass();
  ParallelStepper parallel(*world, grid, mine, statics, materials, settings, {0.005});
  const auto ids = [](const timestep::BodySystem& system) {
    return std::vector<std::uint64_t>(system.ids().begin(),
                                      system.ids().begin() +
                                          static_cast<std::ptrdiff_t>(system.owned_count()));
  };
  std::vector<std::uint64_t> before;
  for (int step = 0; step < 11; ++step) {  // collective: no ASSERT inside, no early exit
    if (step == 10) before = ids(mine);
    parallel.step();
  }
  // Step 11 began with the reordering due after 10 steps.
  timestep::BodySystem expected;
  for (std::size_t i = 0; i < mine.owned_count(); ++i) expected.add(mine.record(i));
  expected.reorder_morton(2.0 * 0.005);
  EXPECT_EQ(ids(mine), ids(expected));
  EXPECT_NE(ids(mine), before) << "nothing was reordered: nothing was tested";
}

// Bodies crowded into one corner of the domain, all owned by one process at the start: every 5
// steps the stepper looks at the balance and moves the grid's boundaries to the bodies' weighted
// quantiles, and the bodies to their new owners — far beyond the neighbours. Free flight stays the
// serial run bit for bit, no body is lost or duplicated, and the load ends balanced.
void expect_rebalancing_keeps_the_serial_run(const Partition& partition) {
  const int p = world->size();
  timestep::BodySystem serial;
  timestep::BodySystem mine;
  add_flight(serial, mine, partition, {8, 6, 6}, Vector3(0.02, 0.1, 0.1), Vector3(0.03, 0.03, 0.03),
             Vector3(0.5, 0.2, 0.1), 0.02, 9);
  const timestep::StaticGeometry statics;
  const timestep::MaterialTable materials = glass();
  timestep::MoreauStepper reference(serial, statics, materials, flight(0.004));
  ParallelSettings balanced{0.005};
  balanced.rebalance_every = 5;
  ParallelStepper parallel(*world, partition, mine, statics, materials, flight(0.004), balanced);
  for (int step = 0; step < 60; ++step) {  // collective: no ASSERT inside, no early exit
    reference.step();
    parallel.step();
  }
  std::vector<double> most{static_cast<double>(mine.owned_count())};
  world->max(most);
  expect_the_serial_bodies(mine, serial);
  if (p > 1) {
    EXPECT_GE(parallel.rebalances(), 1u);
    // the bodies drift by less than a subdomain between two looks at the balance
    EXPECT_LE(most[0], 1.25 * static_cast<double>(serial.size()) / p);
    // the first cut along x, between the crowd's start near 0.02 m and the middle
    const double cut = parallel.partition().subdomain(0).max().x();
    EXPECT_GT(cut, 0.0);
    EXPECT_LT(cut, 0.5);  // moved towards the crowd
  } else {
    EXPECT_EQ(parallel.rebalances(), 0u);
  }
}

TEST(ParallelStepper, RebalancingMovesTheBoundariesToTheBodiesAndKeepsTheSerialRun) {
  const Box domain(Vector3(0, 0, 0), Vector3(1, 1, 1));
  expect_rebalancing_keeps_the_serial_run(
      CartesianGrid(domain, grid_dims(world->size(), domain.sizes())));
}

// The same with recursive coordinate bisection: the tree's cuts follow the crowd.
TEST(ParallelStepper, RebalancingMovesTheBisectionCutsToTheBodiesAndKeepsTheSerialRun) {
  const Box domain(Vector3(0, 0, 0), Vector3(1, 1, 1));
  expect_rebalancing_keeps_the_serial_run(BisectionTree(domain, world->size()));
}

// The balanced grid does not depend on how the bodies are spread over the processes: each process
// passes a share of the same 5000 centres (weights 1 to 4) and gets the grid that one process
// computes from all of them, bit for bit; each slab holds a quarter of the weight, to one body.
TEST(BalancedGrid, IsTheSameForEveryDistributionOfTheBodies) {
  const Box domain(Vector3(0, 0, 0), Vector3(2, 1, 1));
  std::vector<Vector3> all, part;
  std::vector<double> weights, part_weights;
  for (std::uint64_t i = 0; i < 5000; ++i) {
    // crowded towards x = 0: x = 2 u³
    const double u = 0.5 * (noise(i, 11, 0) + 1.0);
    all.emplace_back(2.0 * u * u * u, 0.5 * (noise(i, 11, 1) + 1.0), 0.5 * (noise(i, 11, 2) + 1.0));
    weights.push_back(1.0 + static_cast<double>(i % 4));
    if (static_cast<int>(mix64(i) % static_cast<std::uint64_t>(world->size())) == world->rank()) {
      part.push_back(all.back());
      part_weights.push_back(weights.back());
    }
  }
  const std::array<int, 3> dims{4, 1, 1};
  const CartesianGrid one =
      balanced_grid(self_communicator(), domain, dims, {false, false, false}, all, weights);
  const CartesianGrid shared =
      balanced_grid(*world, domain, dims, {false, false, false}, part, part_weights);
  EXPECT_EQ(one.boundaries(0), shared.boundaries(0));
  std::array<double, 4> slab{};
  for (std::size_t i = 0; i < all.size(); ++i)
    slab[static_cast<std::size_t>(one.owner_of(all[i]))] += weights[i];
  for (const double w : slab) EXPECT_NEAR(w, 12500.0 / 4.0, 4.0);
  EXPECT_LT(one.boundaries(0)[1], 0.5);  // the crowd near x = 0 gets narrow slabs
}

// The bisection tree from bodies spread over the processes is the tree of all of them on one:
// every cut (and so every owner) the same.
TEST(BisectionTree, IsTheSameForEveryDistributionOfTheBodies) {
  const Box domain(Vector3(0, 0, 0), Vector3(2, 1, 1));
  std::vector<Vector3> all, part;
  std::vector<double> weights, part_weights;
  for (std::uint64_t i = 0; i < 5000; ++i) {
    // crowded towards the corner x = y = 0: x = 2 u³, y = v²
    const double u = 0.5 * (noise(i, 12, 0) + 1.0), v = 0.5 * (noise(i, 12, 1) + 1.0);
    all.emplace_back(2.0 * u * u * u, v * v, 0.5 * (noise(i, 12, 2) + 1.0));
    weights.push_back(1.0 + static_cast<double>(i % 3));
    if (static_cast<int>(mix64(i) % static_cast<std::uint64_t>(world->size())) == world->rank()) {
      part.push_back(all.back());
      part_weights.push_back(weights.back());
    }
  }
  const int leaves = 6;
  const BisectionTree one = BisectionTree::balanced(self_communicator(), domain, leaves,
                                                    {false, false, false}, all, weights);
  const BisectionTree shared =
      BisectionTree::balanced(*world, domain, leaves, {false, false, false}, part, part_weights);
  std::vector<double> load(leaves);
  for (int r = 0; r < leaves; ++r) {
    EXPECT_TRUE(one.subdomain(r).min() == shared.subdomain(r).min()) << r;
    EXPECT_TRUE(one.subdomain(r).max() == shared.subdomain(r).max()) << r;
  }
  for (std::size_t i = 0; i < all.size(); ++i) {
    load[static_cast<std::size_t>(one.owner_of(all[i]))] += weights[i];
  }
  for (const double w : load) EXPECT_NEAR(w, 9999.0 / leaves, 6.0);
}

// A column of four spheres on the floor, standing across the boundaries between processes (one
// subdomain per process along z): the percussion of the k-th contact from the top is k m g Δt, as
// in the serial step, to the solver's tolerance; the spheres whose contacts another process solves
// are split, and their copies end with one velocity.
// Averaging every sweep, and every third sweep (the copies then disagree in between, and the solver
// stops only after an averaged sweep).
class ColumnAcrossBoundaries : public ::testing::TestWithParam<int> {};

TEST_P(ColumnAcrossBoundaries, CarriesItsWeight) {
  const int p = world->size();
  const int average_every = GetParam();
  const double r = 0.01;
  const Box domain(Vector3(-0.05, -0.05, 0.0), Vector3(0.05, 0.05, 0.08));
  const CartesianGrid grid(domain, {1, 1, p});
  timestep::BodySystem mine;
  add_column(mine, grid, 4, r, Vector3::Zero(), Vector3::Zero());
  const timestep::StaticGeometry statics = floor_only();
  const timestep::MaterialTable materials = glass();
  ParallelStepper parallel(*world, grid, mine, statics, materials, resting(r), {r, average_every});
  timestep::StepReport report;
  for (int step = 0; step < 5; ++step) report = parallel.step();
  EXPECT_EQ(report.contacts, 4u);
  EXPECT_TRUE(report.converged);
  if (world->rank() == 0) {
    std::printf(
        "column of 4 spheres on %d process(es), averaged every %d sweeps: %d iterations "
        "in the last step\n",
        p, average_every, report.iterations);
  }
  // Every process's kept contacts and percussions, gathered.
  std::vector<std::byte> bytes;
  const auto keys = parallel.stepper().keys();
  const auto lambda = parallel.stepper().percussions();
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const auto put = [&](const void* q, std::size_t n) {
      const auto* b = static_cast<const std::byte*>(q);
      bytes.insert(bytes.end(), b, b + n);
    };
    put(&keys[k].a, 8);
    put(&keys[k].b, 8);
    put(lambda[k].data(), 24);
  }
  std::vector<std::vector<std::byte>> all;
  world->all_gather(bytes, all);
  const double m = 2500.0 * 4.0 / 3.0 * M_PI * r * r * r;
  int found = 0;
  for (const auto& from : all) {
    for (std::size_t at = 0; at + 40 <= from.size(); at += 40) {
      std::uint64_t a, b;
      Vector3 l;
      std::memcpy(&a, from.data() + at, 8);
      std::memcpy(&b, from.data() + at + 8, 8);
      std::memcpy(l.data(), from.data() + at + 16, 24);
      // Spheres 1 … 4 from the bottom; the floor is side b of sphere 1's contact.
      const double below = (b & timestep::kStaticTag) ? 4.0 : 4.0 - static_cast<double>(a);
      EXPECT_NEAR(l[0], below * m * 9.81 * 1e-3, 1e-9 * m * 9.81 * 1e-3)
          << "contact " << a << "–" << (b & ~timestep::kStaticTag);
      EXPECT_LT(std::abs(l[1]) + std::abs(l[2]), 1e-15);
      ++found;
    }
  }
  EXPECT_EQ(found, 4);
  for (std::size_t i = 0; i < mine.owned_count(); ++i) {
    EXPECT_LT(mine.states()[i].u.norm(), 1e-12) << "sphere " << mine.ids()[i];
  }
  std::vector<std::uint64_t> split{parallel.split_bodies()};
  world->sum(split);
  if (p == 1) {
    EXPECT_EQ(split[0], 0u);
  } else {
    EXPECT_GT(split[0], 0u);  // a sphere whose contact below is solved by another process
  }
}

INSTANTIATE_TEST_SUITE_P(ParallelStepper, ColumnAcrossBoundaries, ::testing::Values(1, 3));

// A column of four frictionless spheres sliding across the boundaries between processes (one
// subdomain per process along x): when its spheres migrate, the warm starts of the contacts they
// decide go with them, and every contact of every step after the first stays warm-started, as in
// the serial run.
TEST(ParallelStepper, WarmStartsTravelWithMigratingBodies) {
  const int p = world->size();
  const double r = 0.01;
  const Box domain(Vector3(-0.1, -0.05, 0.0), Vector3(0.1, 0.05, 0.1));
  const CartesianGrid grid(domain, {p, 1, 1});
  timestep::BodySystem mine;
  add_column(mine, grid, 4, r, Vector3(-0.09, 0.0, 0.0), Vector3(1.0, 0.0, 0.0));
  const timestep::StaticGeometry statics = floor_only();
  timestep::MaterialTable materials;
  materials.set_pair(materials.add("ice"), 0, {0.0, 0.0, 0.0});
  timestep::StepSettings settings;
  settings.dt = 1e-3;
  settings.tolerance_radius = r;
  settings.skin = 0.004;
  ParallelStepper parallel(*world, grid, mine, statics, materials, settings, {r});
  std::size_t cold = 0;
  for (int step = 0; step < 150; ++step) {
    const timestep::StepReport report = parallel.step();
    if (step > 0) cold += report.contacts - report.warm_started;
  }
  EXPECT_EQ(cold, 0u);
  EXPECT_GT(parallel.rebuilds(), 30u);
  // The column ended up on the last process, 0.15 m further.
  std::vector<double> x{mine.owned_count() > 0 ? mine.states()[0].q.x() : -1.0};
  world->max(x);
  EXPECT_NEAR(x[0], 0.06, 1e-9);
}

// Two equal spheres collide head on through the periodic boundary along x, with Newton's law and
// ε_N = 1: their velocities swap (the closed form of a central elastic impact of equal masses), and
// the momentum stays zero. On one process the contact is between a sphere and the periodic image
// of the other, on several it also crosses processes.
TEST(ParallelStepper, AnElasticImpactThroughThePeriodicBoundarySwapsTheVelocities) {
  const int p = world->size();
  const double r = 0.01;
  const double L = 0.3;
  const Box domain(Vector3(0.0, -0.05, -0.05), Vector3(L, 0.05, 0.05));
  const CartesianGrid grid(domain, {p, 1, 1}, {true, false, false});
  timestep::BodySystem mine;
  const timestep::BodyRecord a = sphere(1, r, Vector3(0.02, 0.0, 0.0), Vector3(-1.0, 0.0, 0.0));
  const timestep::BodyRecord b =
      sphere(2, r, Vector3(L - 0.0205, 0.0, 0.0), Vector3(1.0, 0.0, 0.0));
  for (const timestep::BodyRecord& body : {a, b}) {
    if (grid.owner_of(body.state.q.head<3>()) == world->rank()) mine.add(body);
  }
  const timestep::StaticGeometry statics;
  timestep::MaterialTable materials;
  materials.set_pair(materials.add("steel"), 0, {0.0, 1.0, 0.0});
  timestep::StepSettings settings;
  settings.dt = 1e-4;
  settings.I_g.setZero();
  settings.tolerance_radius = r;
  settings.skin = 0.002;
  settings.solver.abs_tol = 0.0;
  settings.solver.rel_tol = 1e-12;
  settings.solver.max_iterations = 5000;
  ParallelStepper parallel(*world, grid, mine, statics, materials, settings, {r});
  std::size_t contacts = 0;
  for (int step = 0; step < 200; ++step) contacts += parallel.step().contacts;  // 20 ms
  EXPECT_GT(contacts, 0u);
  std::vector<double> v(2, 0.0);  // v_x of spheres 1 and 2, summed over the processes
  for (std::size_t i = 0; i < mine.owned_count(); ++i) v[mine.ids()[i] - 1] = mine.states()[i].u[0];
  world->sum(v);
  EXPECT_NEAR(v[0], 1.0, 1e-9);
  EXPECT_NEAR(v[1], -1.0, 1e-9);
  EXPECT_NEAR(v[0] + v[1], 0.0, 1e-12);
}

// A ring of five touching spheres, frictionless and without restitution, in a box periodic along x
// exactly five diameters long: the first is struck at v, every contact closes at once, and the
// converged step leaves every contact at rest, γ_N = 0, so that all move at v/5 (momentum). The
// fifth contact is between the last sphere and the periodic image of the first. On one process
// every image is folded onto its owner: nothing is split, and APGD and Newton solve the step as SOR
// does; on several, the methods other than SOR are refused (split bodies need SOR's averaging).
TEST(ParallelStepper, ARingThroughThePeriodicBoundaryMovesAsOneOnAnyMethod) {
  const int p = world->size();
  const double r = 0.01;
  const int n = 5;
  const double L = 2.0 * r * n;
  const Box domain(Vector3(0.0, -0.05, -0.05), Vector3(L, 0.05, 0.05));
  const CartesianGrid grid(domain, {p, 1, 1}, {true, false, false});
  timestep::MaterialTable materials;
  materials.set_pair(materials.add("ice"), 0, {0.0, 0.0, 0.0});
  for (const contact::Method method :
       {contact::Method::sor, contact::Method::apgd, contact::Method::newton}) {
    timestep::BodySystem mine;
    for (int i = 0; i < n; ++i) {
      const timestep::BodyRecord body =
          sphere(static_cast<std::uint64_t>(i + 1), r, Vector3(r + 2.0 * r * i, 0.0, 0.0),
                 Vector3(i == 0 ? 1.0 : 0.0, 0.0, 0.0));
      if (grid.owner_of(body.state.q.head<3>()) == world->rank()) mine.add(body);
    }
    const timestep::StaticGeometry statics;
    timestep::StepSettings settings;
    settings.dt = 1e-4;
    settings.I_g.setZero();
    settings.tolerance_radius = r;
    settings.contact_tolerance = 0.01;  // the contact the first half step opens stays active
    settings.method = method;
    settings.solver.abs_tol = 0.0;
    settings.solver.rel_tol = 1e-10;
    settings.solver.criterion = contact::Criterion::natural_residual;
    settings.solver.max_iterations = 20000;
    if (p > 1 && method != contact::Method::sor) {
      EXPECT_THROW(ParallelStepper(*world, grid, mine, statics, materials, settings, {r}),
                   InvalidArgument);
      continue;
    }
    ParallelStepper parallel(*world, grid, mine, statics, materials, settings, {r});
    const timestep::StepReport report = parallel.step();
    EXPECT_EQ(report.contacts, static_cast<std::size_t>(n)) << contact::method_name(method);
    EXPECT_TRUE(report.converged) << contact::method_name(method) << ", residual " << report.residual << " after " << report.iterations;
    if (p == 1) {
      EXPECT_EQ(parallel.split_bodies(), 0u) << "images folded onto their owners";
    }
    std::vector<double> v(n, 0.0);
    for (std::size_t i = 0; i < mine.owned_count(); ++i) {
      v[mine.ids()[i] - 1] = mine.states()[i].u[0];
    }
    world->sum(v);
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(v[static_cast<std::size_t>(i)], 1.0 / n, 1e-8)
          << contact::method_name(method) << ", sphere " << i + 1;
    }
  }
}

// A pile settling from a jittered lattice in an open box, on 1, 2 and 3 processes (slices along x)
// and serially: the same physics, so the same statistics at the end — contacts, the height of the
// heap (potential energy), nearly at rest — though not the same bits, since splitting changes the
// iterates within the solver's tolerance.
TEST(ParallelStepper, ASettlingPileEndsAsTheSerialPileDoes) {
  const int p = world->size();
  if (p > 2) {
    // Three processes on two cores take the step's many split-body sweeps (see the chapter's
    // table) half a minute here; the agreement was checked by hand (126 contacts against 127,
    // potential energy within 6.4e-4).
    GTEST_SKIP() << "more processes than this test's time allows on two cores";
  }
  const double r = 0.01;
  const double L = 0.1;
  timestep::BodySystem serial;
  std::uint64_t id = 1;
  for (int k = 0; k < 4; ++k) {
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i, ++id) {
        const Vector3 c(0.012 + 0.025 * i + 0.001 * noise(id, 9, 0),
                        0.012 + 0.025 * j + 0.001 * noise(id, 9, 1), 0.011 + 0.024 * k);
        serial.add(sphere(id, r, c, Vector3::Zero()));
      }
    }
  }
  timestep::StaticGeometry statics;
  const auto wall = [&](timestep::GlobalId sid, const Vector3& n, double offset) {
    timestep::StaticObject o;
    o.id = sid;
    o.shape = collision::HalfSpace{n, offset};
    statics.add(o);
  };
  wall(0, Vector3::UnitZ(), 0.0);
  wall(1, Vector3::UnitX(), 0.0);
  wall(2, -Vector3::UnitX(), -L);
  wall(3, Vector3::UnitY(), 0.0);
  wall(4, -Vector3::UnitY(), -L);
  const timestep::MaterialTable materials = glass();
  timestep::StepSettings settings;
  settings.dt = 1e-3;
  settings.tolerance_radius = r;
  settings.skin = 0.002;
  settings.solver.max_iterations = 3000;
  const Box domain(Vector3(0, 0, 0), Vector3(L, L, 0.12));
  const CartesianGrid grid(domain, {p, 1, 1});
  timestep::BodySystem mine;
  for (std::size_t i = 0; i < serial.size(); ++i) {
    if (grid.owner_of(serial.states()[i].q.head<3>()) == world->rank()) mine.add(serial.record(i));
  }
  timestep::MoreauStepper reference(serial, statics, materials, settings);
  ParallelStepper parallel(*world, grid, mine, statics, materials, settings, {r});
  timestep::StepReport a, b;
  for (int step = 0; step < 400; ++step) {
    a = reference.step();
    b = parallel.step();
  }
  // Both nearly at rest after 0.4 s (the last ripples hold less than 1 % of the energy).
  EXPECT_LT(b.kinetic_energy, 1e-2 * std::abs(b.potential_energy));
  EXPECT_LT(a.kinetic_energy, 1e-2 * std::abs(a.potential_energy));
  // The same height of the heap (potential energy) to a tenth of a per cent, about as many
  // contacts.
  EXPECT_NEAR(b.potential_energy, a.potential_energy, 1e-3 * std::abs(a.potential_energy));
  EXPECT_NEAR(static_cast<double>(b.contacts), static_cast<double>(a.contacts),
              0.05 * static_cast<double>(a.contacts));
  std::vector<std::uint64_t> owned{mine.owned_count()};
  world->sum(owned);
  EXPECT_EQ(owned[0], serial.size());
  if (world->rank() == 0) {
    std::printf(
        "settled pile on %d process(es): %zu contacts (serial %zu), potential energy "
        "%.9g J (serial %.9g J)\n",
        p, b.contacts, a.contacts, b.potential_energy, a.potential_energy);
  }
}

// A partition finer than the bodies: two stacked spheres of radius 1 cm in a domain 4 cm high, cut
// into slices of 4/P cm (on three processes thinner than a sphere's radius and a half), so that a
// sphere reaches into subdomains beyond the next one. The neighbours are found by distance, not
// adjacency, and the percussions are still those of the serial step: m g Δt between the spheres,
// 2 m g Δt on the floor.
TEST(ParallelStepper, APartitionFinerThanTheBodiesStillGivesTheSerialPercussions) {
  const int p = world->size();
  const double r = 0.01;
  const Box domain(Vector3(-0.02, -0.02, 0.0), Vector3(0.02, 0.02, 0.04));
  const CartesianGrid grid(domain, {1, 1, p});
  timestep::BodySystem mine;
  add_column(mine, grid, 2, r, Vector3::Zero(), Vector3::Zero());
  const timestep::StaticGeometry statics = floor_only();
  const timestep::MaterialTable materials = glass();
  ParallelStepper parallel(*world, grid, mine, statics, materials, resting(r), {r});
  timestep::StepReport report;
  for (int step = 0; step < 3; ++step) report = parallel.step();
  EXPECT_EQ(report.contacts, 2u);
  EXPECT_TRUE(report.converged);
  const double m = 2500.0 * 4.0 / 3.0 * M_PI * r * r * r;
  double total = 0.0;  // Λ_N summed over the processes' kept contacts: 3 m g Δt
  for (const Vector3& l : parallel.stepper().percussions()) total += l[0];
  std::vector<double> sum{total};
  world->sum(sum);
  EXPECT_NEAR(sum[0], 3.0 * m * 9.81 * 1e-3, 1e-9 * m * 9.81 * 1e-3);
  for (std::size_t i = 0; i < mine.owned_count(); ++i) {
    EXPECT_LT(mine.states()[i].u.norm(), 1e-12) << "sphere " << mine.ids()[i];
  }
}

}  // namespace
}  // namespace grbd::parallel

// gtest under mpiexec: every rank runs every test; rank 0 prints the report, the others their
// failures only; the program fails on every rank when a test failed on any.
int main(int argc, char** argv) {
  grbd::parallel::MpiEnvironment mpi(true);
  grbd::parallel::world = &mpi.world();
  // --fail-on-last-rank: the last rank fails alone while the others wait in a collective call;
  // abort_run must end them all with one message (the test ch08.mpi.abort checks it, with a
  // timeout, so that a hang fails).
  if (argc > 1 && std::string(argv[1]) == "--fail-on-last-rank") {
    if (mpi.world().rank() == mpi.world().size() - 1) {
      grbd::parallel::abort_run("a scene that fails on this rank only", 3);
    }
    mpi.world().barrier();
    return 0;
  }
  ::testing::InitGoogleTest(&argc, argv);
  if (mpi.world().rank() != 0) {
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  const int failed = RUN_ALL_TESTS();
  const bool everywhere = mpi.world().all(failed == 0);
  if (!everywhere && mpi.world().rank() == 0) {
    std::fprintf(stderr, "a test failed on some rank (its failures are printed above)\n");
  }
  return everywhere ? 0 : 1;
}
