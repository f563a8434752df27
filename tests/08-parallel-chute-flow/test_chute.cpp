// Chapter 8: the chute study's measurements — the run-out frame against the reference chute's
// trees, the flow count (Exercise 8.4), the front, and the flow times against closed forms.

#include <gtest/gtest.h>

#include <array>
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

// A bead placed in the run-out's frame at the centre of pixel (i, j), at any height above the
// floor, is seen in that pixel; the image's edges are half-open; beyond them there is no pixel.
TEST(Exercise8_5, ABeadIsSeenInThePixelUnderIt) {
  const CameraGrid camera;  // 800 × 600 at 967.59 px/m from the kink, rows centred on the axis
  const double a = 10.0 * std::numbers::pi / 180.0;
  const Vector3 along(std::cos(a), 0.0, -std::sin(a)), normal(std::sin(a), 0.0, std::cos(a));
  const auto at = [&](double x, double y, double z) -> Vector3 {  // run-out frame → frame I
    return Vector3(-0.296, 0.0, 0.0) + x * along + Vector3(0.0, y, 0.0) + z * normal;
  };
  const double s = camera.pixels_per_metre;
  for (const auto& [i, j] : std::vector<std::array<int, 2>>{{0, 0}, {17, 300}, {799, 599}}) {
    for (const double z : {0.0007, 0.02}) {
      const auto pixel =
          pixel_of(camera, kReference, at(camera.x0 - (i + 0.5) / s, camera.y0 + (j + 0.5) / s, z));
      ASSERT_TRUE(pixel.has_value());
      EXPECT_EQ((*pixel)[0], i);
      EXPECT_EQ((*pixel)[1], j);
    }
  }
  EXPECT_FALSE(pixel_of(camera, kReference, at(0.001, 0.0, 0.001)));       // upstream of x0
  EXPECT_FALSE(pixel_of(camera, kReference, at(-800.5 / s, 0.0, 0.001)));  // past the image
  EXPECT_FALSE(pixel_of(camera, kReference, at(-0.1, camera.y0 - 1e-6, 0.001)));
  EXPECT_FALSE(pixel_of(camera, kReference, at(-0.1, camera.y0 + 600.5 / s, 0.001)));
  // The tree the reference places at x' = −0.1254 m on the axis is 121 pixels downstream.
  EXPECT_EQ((*pixel_of(camera, kReference, at(-0.1254, 0.004, 0.04)))[0], 121);
}

// Beads moving alike in the run-out's plane give that velocity in every pixel they are in and
// nothing elsewhere; two beads in one pixel give their mean.
TEST(VelocityField, IsTheMeanPlanViewVelocityOfTheBeadsInEachPixel) {
  const CameraGrid camera{40, 30, 100.0, 0.0, -0.15};  // 1 cm pixels
  const double a = 10.0 * std::numbers::pi / 180.0;
  const Vector3 along(std::cos(a), 0.0, -std::sin(a)), normal(std::sin(a), 0.0, std::cos(a));
  const Vector3 kink(-0.296, 0.0, 0.0);
  std::vector<Vector3> centres, velocities;
  for (int k = 0; k < 20; ++k) {  // downstream at 1.5 m/s, across at 0.2 m/s, sinking a little
    centres.push_back(kink - (0.015 + 0.02 * k) * along + 0.001 * normal);
    velocities.push_back(-1.5 * along + Vector3(0.0, 0.2, 0.0) - 0.05 * normal);
  }
  centres.push_back(centres[0] + Vector3(0.0, 0.002, 0.0));  // a second bead in pixel (1, 15)
  velocities.push_back(-0.5 * along);
  centres.push_back(kink + 0.5 * along);  // upstream of the image: not seen
  velocities.push_back(Vector3(9.0, 9.0, 9.0));
  const VelocityField field = velocity_field(camera, kReference, centres, velocities);
  ASSERT_EQ(field.count.size(), 1200u);
  std::size_t seen = 0;
  for (int j = 0; j < 30; ++j) {
    for (int i = 0; i < 40; ++i) {
      const std::size_t k = static_cast<std::size_t>(j * 40 + i);
      if (field.count[k] == 0) {
        EXPECT_EQ(field.along[k], 0.0);
        continue;
      }
      seen += field.count[k];
      EXPECT_EQ(j, 15);
      if (i == 1) {
        EXPECT_EQ(field.count[k], 2u);
        EXPECT_NEAR(field.along[k], 1.0, 1e-12);
        EXPECT_NEAR(field.across[k], 0.1, 1e-12);
      } else {
        EXPECT_NEAR(field.along[k], 1.5, 1e-12);
        EXPECT_NEAR(field.across[k], 0.2, 1e-12);
      }
    }
  }
  EXPECT_EQ(seen, 21u);
  EXPECT_THROW(velocity_field(camera, kReference, centres, std::vector<Vector3>(3)),
               InvalidArgument);
  EXPECT_THROW(velocity_field(CameraGrid{0, 30, 100.0, 0.0, 0.0}, kReference, centres, velocities),
               InvalidArgument);
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
