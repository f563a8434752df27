/// \file
/// \brief Chapter 6: after the first steps, a step of a settled pile performs no heap allocation:
/// collision detection, assembly, warm starts and the solver all reuse their buffers.
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

}  // namespace
}  // namespace grbd::timestep
