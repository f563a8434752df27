/// \file
/// \brief Chapter 6: after the first steps, a step of a settled pile performs no heap allocation:
/// collision detection, assembly, warm starts and the solver all reuse their buffers. Adding a
/// body (owned or ghost) to a system with room, and clearing the ghosts, allocate nothing either.
///
/// Reference: a counting replacement of the global operator new (grbd_demo/allocation_counter.hpp),
/// in this executable of its own so that it counts no other test; the counter is checked to work.

#include <gtest/gtest.h>

#include <vector>

#include "grbd/timestep/stepper.hpp"
#include "grbd_demo/allocation_counter.hpp"
#include "pile.hpp"

namespace grbd::timestep {
namespace {

TEST(StepAllocations, ASteadyStepOfASettledPileAllocatesNothing) {
  const long before = demo::allocations();
  std::vector<int> probe(100);
  ASSERT_GT(demo::allocations(), before) << "the counter counts";

  for (const contact::Method method :
       {contact::Method::sor, contact::Method::jor, contact::Method::apgd}) {
    BodySystem system;
    StaticGeometry statics;
    demo::fcc_pile(system, statics, 4, 4, 3);
    const MaterialTable materials = demo::glass_materials();
    StepSettings settings;
    settings.dt = 2e-4;
    settings.method = method;
    settings.reorder_interval = 5;  // reordering reuses its buffers too
    MoreauStepper stepper(system, statics, materials, settings);
    for (int step = 0; step < 60; ++step) {  // the buffers reach their size
      stepper.reorder_if_due();
      stepper.step();
    }
    const long start = demo::allocations();
    std::size_t contacts = 0;
    int reordered = 0;
    for (int step = 0; step < 20; ++step) {
      reordered += stepper.reorder_if_due() ? 1 : 0;
      contacts += stepper.step().contacts;
    }
    EXPECT_EQ(reordered, 4);
    EXPECT_GT(contacts, 20u * system.size());
    EXPECT_EQ(demo::allocations() - start, 0) << contact::method_name(method);
  }
}

TEST(StepAllocations, AddingBodiesAndGhostsToASystemWithRoomAllocatesNothing) {
  BodySystem source;
  StaticGeometry statics;
  demo::fcc_pile(source, statics, 3, 3, 2);  // 72 spheres
  std::vector<BodyRecord> records;
  for (std::size_t i = 0; i < source.size(); ++i) records.push_back(source.record(i));
  BodySystem system;
  system.reserve(2 * records.size());
  // The lookups grow once; after clear_ghosts() and removal the same adds find them grown.
  for (std::size_t i = 0; i < records.size(); i += 2) system.add(records[i]);
  for (std::size_t i = 1; i < records.size(); i += 2) system.add_ghost(records[i]);
  system.clear_ghosts();
  std::vector<std::size_t> all(system.owned_count());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  system.remove(all);
  const long start = demo::allocations();
  for (std::size_t i = 0; i < records.size(); i += 2) system.add(records[i]);
  for (std::size_t i = 1; i < records.size(); i += 2) system.add_ghost(records[i], Vector3::UnitX(), 7);
  system.clear_ghosts();
  EXPECT_EQ(demo::allocations() - start, 0);
  EXPECT_EQ(system.owned_count(), (records.size() + 1) / 2);
}

}  // namespace
}  // namespace grbd::timestep
