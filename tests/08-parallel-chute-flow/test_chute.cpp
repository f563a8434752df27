// Chapter 8: the chute study's measurements — the run-out frame against the reference chute's
// trees, the flow count (Exercise 8.4), the front, and the flow times against closed forms.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/parallel/chute.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"

namespace grbd::parallel {
namespace {

const ChuteGeometry kReference;  // kink at x = −0.296 m, run-out 10° flatter

// GRSFramework's reference chute gives its trees in the run-out's frame: (x', y') =
// (−0.1254, 0.004) m, standing 40 mm above the run-out's floor; the scene places them in frame I.
TEST(ChuteGeometry, TheRunoutFrameGivesBackTheTreesOfTheReferenceChute) {
  const double a = 10.0 * std::numbers::pi / 180.0;
  const Vector3 tree(-0.296 - 0.1254 * std::cos(a) + 0.04 * std::sin(a), 0.004,
                     0.1254 * std::sin(a) + 0.04 * std::cos(a));
  const Vector3 local = kReference.runout(tree);
  EXPECT_NEAR(local.x(), -0.1254, 1e-12);
  EXPECT_NEAR(local.y(), 0.004, 1e-15);
  EXPECT_NEAR(local.z(), 0.04, 1e-12);
  // On the upper chute the path is −x; past the kink it goes on along the run-out's floor.
  EXPECT_DOUBLE_EQ(kReference.path(Vector3(-0.1, 0.0, 0.01)), 0.1);
  EXPECT_NEAR(kReference.path(tree), 0.296 + 0.1254, 1e-12);
  EXPECT_NEAR(kReference.path(Vector3(-0.296, 0.0, 0.0)), 0.296, 1e-15);
}

TEST(Exercise8_4, TheFlowCountIsTheNumberOfBeadsPastTheKink) {
  std::vector<Vector3> beads;
  std::mt19937_64 random(4);
  std::uniform_real_distribution<double> x(-0.8, 0.1);
  std::size_t past = 0;
  for (int i = 0; i < 1000; ++i) {
    beads.emplace_back(x(random), 0.0, 0.002);
    if (beads.back().x() < -0.296) ++past;
  }
  EXPECT_EQ(flow_count(beads, kReference), past);
  EXPECT_EQ(flow_count({}, kReference), 0u);
  // A bead exactly at the kink has not passed it.
  const std::vector<Vector3> at{Vector3(-0.296, 0.0, 0.001),
                                Vector3(std::nextafter(-0.296, -1.0), 0.0, 0.001)};
  EXPECT_EQ(flow_count(at, kReference), 1u);
  const ChuteGeometry other{-0.5, 10.0};
  EXPECT_EQ(flow_count(at, other), 0u);
}

// The front ignores the thousandth of the beads that runs ahead: of 2000 beads, two.
TEST(ChuteGeometry, TheFrontIsWhereTheLeadingBeadsAre) {
  std::vector<Vector3> beads;
  for (int i = 0; i < 2000; ++i) beads.emplace_back(-0.1 + 1e-5 * i, 0.0, 0.001);
  EXPECT_NEAR(front(beads, kReference), 0.1 - 2e-5, 1e-12);  // the third bead from the front
  beads.emplace_back(-0.25, 0.0, 0.001);                     // two beads thrown ahead
  beads.emplace_back(-0.26, 0.0, 0.001);
  EXPECT_NEAR(front(beads, kReference), 0.1, 1e-12);
  beads.emplace_back(-0.27, 0.0, 0.001);  // a third: the front is the slowest of the three
  EXPECT_NEAR(front(beads, kReference), 0.25, 1e-12);
  EXPECT_EQ(front({}, kReference), 0.0);
}

// F(t) rising linearly from 0 at t = 0.2 s to all N = 10 000 beads at t = 1.2 s: F reaches 150
// at 0.215 s, 1 % at 0.21 s and 95 % at 1.15 s, whatever the sampling that holds those points.
TEST(FlowTimes, ALinearRiseGivesTheTimesOfItsClosedForm) {
  const double n = 10000.0;
  for (const double dt : {0.001, 0.02, 0.1}) {
    std::vector<double> t, count;
    for (double s = 0.0; s <= 1.5 + 1e-12; s += dt) {
      t.push_back(s);
      count.push_back(std::clamp((s - 0.2) / 1.0, 0.0, 1.0) * n);
    }
    const FlowTimes times = flow_times(t, count, n);
    ASSERT_TRUE(times.entry && times.first && times.last && times.duration());
    EXPECT_NEAR(*times.entry, 0.215, 1e-9) << "dt = " << dt;
    EXPECT_NEAR(*times.first, 0.21, 1e-9);
    EXPECT_NEAR(*times.last, 1.15, 1e-9);
    EXPECT_NEAR(*times.duration(), 0.94, 1e-9);
  }
  // A flow that never gets to 95 % has no duration; one that never starts has no entry.
  const std::vector<double> t{0.0, 1.0, 2.0};
  const FlowTimes stuck = flow_times(t, std::vector<double>{0.0, 200.0, 500.0}, 1000.0);
  EXPECT_TRUE(stuck.entry && stuck.first);
  EXPECT_FALSE(stuck.last);
  EXPECT_FALSE(stuck.duration());
  EXPECT_FALSE(flow_times(t, std::vector<double>{0.0, 0.0, 0.0}, 1000.0).entry);
  // Bad series are refused.
  EXPECT_THROW(flow_times(t, std::vector<double>{0.0, 1.0}, 10.0), InvalidArgument);
  EXPECT_THROW(flow_times(std::vector<double>{0.0, 0.0, 1.0}, std::vector<double>{0, 1, 2}, 10.0),
               InvalidArgument);
  EXPECT_THROW(flow_times(t, std::vector<double>{0.0, 11.0, 2.0}, 10.0), InvalidArgument);
  EXPECT_THROW(flow_times(t, std::vector<double>{0.0, NAN, 2.0}, 10.0), InvalidArgument);
  EXPECT_THROW(flow_times(t, std::vector<double>{0.0, 1.0, 2.0}, 0.0), InvalidArgument);
  EXPECT_THROW(flow_times(t, std::vector<double>{0.0, 1.0, 2.0}, 10.0, NAN), InvalidArgument);
}

// The tests' tiny chute run in this process with this build's solver — in the exercise build, the
// student's prox solver and flow count: nothing passes the kink while the gate holds (it opens at
// 0.05 s), the front arrives there between the frictionless-slide and rolling times after the
// release (0.347 s and 0.411 s for 0.296 m at 30°, with room for the column's collapse), and by
// 0.7 s every bead has passed it, those the outlet removed included.
TEST(Chute, TheTinyChuteFlowsPastTheKinkWithThisBuildsSolver) {
  const scene::Scene scene =
      scene::load_scene(std::string(GRBD_CH08_DATA_DIR) + "/tiny_chute.toml");
  scene::Simulation simulation(scene);
  const std::size_t beads = simulation.system().owned_count();
  ASSERT_EQ(beads, 400u);
  std::vector<Vector3> centres;
  std::optional<double> arrived;
  while (!simulation.finished()) {
    simulation.step();
    centres.clear();
    for (std::size_t i = 0; i < simulation.system().owned_count(); ++i) {
      centres.push_back(simulation.system().states()[i].q.head<3>());
    }
    const double t = simulation.stepper().time();
    const std::size_t past = flow_count(centres, kReference) + beads - centres.size();
    if (t <= 0.05) {
      EXPECT_EQ(past, 0u) << "t = " << t;
    }
    if (!arrived && front(centres, kReference) >= 0.296) arrived = t - 0.05;
  }
  ASSERT_TRUE(arrived.has_value());
  EXPECT_GT(*arrived, 0.30);
  EXPECT_LT(*arrived, 0.46);
  EXPECT_EQ(flow_count(centres, kReference) + beads - centres.size(), beads);
}

}  // namespace
}  // namespace grbd::parallel
