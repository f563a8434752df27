// Chapter 7: output records and checkpoints. A record gives back the states it was written from
// (bit for bit in double precision, to float rounding in single); a checkpoint gives back every
// part of the simulation state, so that 2N steps equal N steps, a restart and N steps, bit for
// bit; checkpoints replace each other atomically; damaged files are refused with their name.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/io/checkpoint.hpp"
#include "grbd/io/output.hpp"
#include "grbd/io/run.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"
#include "grbd_test/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using grbd::io::IoError;
using grbd::scene::Simulation;

// A folder of its own for each test (unique per process too: the student build's test program,
// run by the honesty check, runs the same tests at the same time).
class Folder : public ::testing::Test {
 protected:
  fs::path path(const std::string& name) const { return dir_ / name; }
  grbd::test::TempDir dir_;
};

grbd::scene::Scene chute() {
  return grbd::scene::load_scene(fs::path(GRBD_CH07_DATA_DIR) / "chute.toml");
}

void expect_same_state(const grbd::scene::SimulationState& a,
                       const grbd::scene::SimulationState& b) {
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.next_id, b.next_id);
  EXPECT_EQ(a.removed, b.removed);
  EXPECT_EQ(a.removed_mass, b.removed_mass);
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    EXPECT_EQ(a.bodies[i].id, b.bodies[i].id);
    EXPECT_TRUE(grbd::timestep::same_constants(a.bodies[i], b.bodies[i])) << "body " << i;
    EXPECT_EQ(a.bodies[i].state.q, b.bodies[i].state.q) << "body " << i;
    EXPECT_EQ(a.bodies[i].state.u, b.bodies[i].state.u) << "body " << i;
  }
  ASSERT_EQ(a.warm_keys.size(), b.warm_keys.size());
  for (std::size_t k = 0; k < a.warm_keys.size(); ++k) {
    EXPECT_TRUE(a.warm_keys[k] == b.warm_keys[k]);
    EXPECT_EQ(a.warm_lambda[k], b.warm_lambda[k]);
  }
  ASSERT_EQ(a.generators.size(), b.generators.size());
  for (std::size_t g = 0; g < a.generators.size(); ++g) {
    EXPECT_EQ(a.generators[g].random, b.generators[g].random);
    EXPECT_EQ(a.generators[g].created, b.generators[g].created);
  }
}

TEST_F(Folder, ACheckpointRestoresEveryPartOfTheState) {
  const auto scene = chute();
  Simulation sim(scene);
  for (int k = 0; k < 150; ++k) sim.step();
  const auto state = sim.save();
  ASSERT_GT(state.warm_keys.size(), 10U);
  ASSERT_GT(state.generators[1].created, 0U);
  ASSERT_GE(state.next_id, 120U);
  grbd::io::write_checkpoint(path("c.h5"), {state, {3, 150, 120}, scene.text});
  const grbd::io::Checkpoint back = grbd::io::read_checkpoint(path("c.h5"));
  expect_same_state(state, back.state);
  EXPECT_EQ(back.output.records, 3U);
  EXPECT_EQ(back.output.steps, 150U);
  EXPECT_EQ(back.output.bodies, 120U);
  EXPECT_EQ(back.scene_text, scene.text);
  // Rebuilt from it, the simulation saves the same state again.
  Simulation restored(scene, back.state);
  expect_same_state(state, restored.save());
}

TEST_F(Folder, TwoNStepsEqualNStepsARestartAndNSteps) {
  const auto scene = chute();
  Simulation straight(scene);
  for (int k = 0; k < 600; ++k) straight.step();
  Simulation first(scene);
  for (int k = 0; k < 300; ++k) first.step();
  grbd::io::write_checkpoint(path("c.h5"), {first.save(), {}, scene.text});
  Simulation second(scene, grbd::io::read_checkpoint(path("c.h5")).state);
  for (int k = 0; k < 300; ++k) second.step();
  expect_same_state(straight.save(), second.save());
  EXPECT_GT(straight.bodies_removed(), 0U);  // the outlet took part
}

TEST_F(Folder, RecordsGiveBackTheirStates) {
  auto scene = chute();
  for (const bool float32 : {false, true}) {
    scene.output.float32 = float32;
    const fs::path file = path(float32 ? "f.h5" : "d.h5");
    Simulation sim(scene);
    grbd::io::OutputFile out(file, scene);
    for (int k = 0; k < 40; ++k) out.add_step(sim.step(), sim.system().size());
    out.write_record(sim);
    out.close(sim);
    const grbd::io::Record record = grbd::io::read_record(file, 0);
    EXPECT_EQ(record.step, 40U);
    EXPECT_EQ(record.t, sim.stepper().time());
    ASSERT_EQ(record.id.size(), sim.system().size());
    for (std::size_t k = 0; k < record.id.size(); ++k) {
      const std::size_t i = sim.system().index_of(record.id[k]);
      const auto& x = sim.system().states()[i];
      if (float32) {
        for (int d = 0; d < 7; ++d)
          EXPECT_EQ(record.states[k].q[d], static_cast<double>(static_cast<float>(x.q[d])));
      } else {
        EXPECT_EQ(record.states[k].q, x.q);
        EXPECT_EQ(record.states[k].u, x.u);
      }
      if (k > 0) {
        EXPECT_LT(record.id[k - 1], record.id[k]);
      }
    }
    const grbd::io::OutputSummary s = grbd::io::read_summary(file);
    EXPECT_EQ(s.records, 1U);
    EXPECT_EQ(s.steps, 40U);
    EXPECT_EQ(s.bodies, sim.bodies_created());
    EXPECT_EQ(s.precision, float32 ? "float" : "double");
  }
}

// What the chapters' analyses read back (chapter 8's ch08_chute, the steady-flow study): every step
// of /steps as the stepper reported it, and a record's contacts as the simulation held them.
TEST_F(Folder, StepsAndContactsReadBackAsTheRunHadThem) {
  auto scene = chute();
  scene.output.contacts = true;
  const fs::path file = path("c.h5");
  Simulation sim(scene);
  grbd::io::OutputFile out(file, scene);
  std::vector<grbd::timestep::StepReport> reports;
  for (int k = 0; k < 120; ++k) {
    reports.push_back(sim.step());
    out.add_step(reports.back(), sim.system().size());
  }
  out.write_record(sim);
  grbd::io::RecordPart part;
  grbd::io::collect_record(sim, true, part);
  out.close(sim);
  const std::vector<grbd::io::StepInfo> steps = grbd::io::read_steps(file);
  ASSERT_EQ(steps.size(), reports.size());
  for (std::size_t k = 0; k < steps.size(); ++k) {
    EXPECT_EQ(steps[k].step, reports[k].step);
    EXPECT_EQ(steps[k].t, reports[k].t);
    EXPECT_EQ(steps[k].contacts, reports[k].contacts);
    EXPECT_EQ(steps[k].iterations, reports[k].iterations);
    EXPECT_EQ(steps[k].converged, reports[k].converged);
    EXPECT_EQ(steps[k].residual, reports[k].residual);
    EXPECT_EQ(steps[k].max_penetration, reports[k].max_penetration);
    EXPECT_EQ(steps[k].mean_penetration, reports[k].mean_penetration);
    EXPECT_EQ(steps[k].kinetic_energy, reports[k].kinetic_energy);
  }
  auto expected = part.contacts;
  ASSERT_GT(expected.size(), 10U);
  std::sort(expected.begin(), expected.end(),
            [](const auto& a, const auto& b) { return a.key < b.key; });
  const std::vector<grbd::io::RecordContact> contacts = grbd::io::read_contacts(file, 0);
  ASSERT_EQ(contacts.size(), expected.size());
  for (std::size_t j = 0; j < contacts.size(); ++j) {
    EXPECT_EQ(contacts[j].key.a, expected[j].key.a);
    EXPECT_EQ(contacts[j].key.b, expected[j].key.b);
    EXPECT_EQ(contacts[j].point, expected[j].point);
    EXPECT_EQ(contacts[j].normal, expected[j].normal);
    EXPECT_EQ(contacts[j].gap, expected[j].gap);
    EXPECT_EQ(contacts[j].lambda_N, expected[j].lambda_N);
    EXPECT_EQ(contacts[j].lambda_T, expected[j].lambda_T);
    EXPECT_EQ(contacts[j].line, expected[j].line);
  }
  // A record that is not there, and a file written without contacts, are refused by name.
  try {
    grbd::io::read_contacts(file, 1);
    ADD_FAILURE() << "record 1 read";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("record 1 asked for"), std::string::npos) << e.what();
  }
  scene.output.contacts = false;
  Simulation plain(scene);
  grbd::io::OutputFile without(path("p.h5"), scene);
  without.write_record(plain);
  without.close(plain);
  try {
    grbd::io::read_contacts(path("p.h5"), 0);
    ADD_FAILURE() << "contacts read from a file without them";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("p.h5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("holds no contacts"), std::string::npos) << e.what();
  }
}

TEST_F(Folder, CheckpointsReplaceEachOtherAtomically) {
  const auto scene = chute();
  Simulation sim(scene);
  grbd::io::write_checkpoint(path("c.h5"), {sim.save(), {}, scene.text});
  for (int k = 0; k < 20; ++k) sim.step();
  // A crash while writing the next one leaves its temporary file: the previous one is intact.
  dir_.write("c.h5.tmp", "\x89HDF\r\n\x1a\n half a checkpoint");
  EXPECT_EQ(grbd::io::read_checkpoint(path("c.h5")).state.steps, 0U);
  // The next write replaces both.
  grbd::io::write_checkpoint(path("c.h5"), {sim.save(), {}, scene.text});
  EXPECT_EQ(grbd::io::read_checkpoint(path("c.h5")).state.steps, 20U);
  EXPECT_FALSE(fs::exists(path("c.h5.tmp")));
  // A folder that cannot be written: an IoError, and the old checkpoint is untouched.
  EXPECT_THROW(
      grbd::io::write_checkpoint(path("no/such/folder/c.h5"), {sim.save(), {}, scene.text}),
      IoError);
  EXPECT_EQ(grbd::io::read_checkpoint(path("c.h5")).state.steps, 20U);
}

TEST_F(Folder, DamagedCheckpointsAreRefusedWithTheirName) {
  const auto scene = chute();
  Simulation sim(scene);
  for (int k = 0; k < 10; ++k) sim.step();
  grbd::io::write_checkpoint(path("c.h5"), {sim.save(), {}, scene.text});
  auto message = [](const fs::path& file) {
    try {
      grbd::io::read_checkpoint(file);
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(path("missing.h5")), path("missing.h5").string() + ": no such checkpoint file");
  dir_.write("text.h5", "not HDF5\n");
  EXPECT_EQ(message(path("text.h5")), path("text.h5").string() + ": is not an HDF5 file");
  // Cut short: every prefix of the file is refused with an IoError.
  std::ifstream in(path("c.h5"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const double fraction : {0.1, 0.5, 0.9, 0.99}) {
    const auto n = static_cast<std::size_t>(fraction * static_cast<double>(bytes.size()));
    dir_.write("cut.h5", bytes.substr(0, n));
    const std::string m = message(path("cut.h5"));
    EXPECT_EQ(m.rfind(path("cut.h5").string() + ": ", 0), 0U) << fraction << ": " << m;
  }
  // An output file is not a checkpoint.
  grbd::io::OutputFile out(path("out.h5"), scene);
  out.close(sim);
  EXPECT_EQ(message(path("out.h5")),
            path("out.h5").string() +
                ": is not a grbd checkpoint (attribute format is not \"grbd checkpoint\")");
}

// What a checkpoint holds is checked before the first step: its own values on reading (with
// the checksum written over them: here the values are written consistently, so the checks behind
// it are what refuses them), and what the scene fixes when a Simulation is built from it.
TEST_F(Folder, CheckpointsThatContradictThemselvesOrTheSceneAreRefused) {
  const auto scene = chute();
  Simulation sim(scene);
  for (int k = 0; k < 150; ++k) sim.step();
  const grbd::scene::SimulationState good = sim.save();
  ASSERT_FALSE(good.warm_lambda.empty());
  auto read_message = [&](const grbd::scene::SimulationState& state, const std::string& name) {
    grbd::io::write_checkpoint(path(name), {state, {}, scene.text});
    try {
      grbd::io::read_checkpoint(path(name));
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  auto state_message = [&](const grbd::scene::SimulationState& state) {
    try {
      Simulation restored(scene, state);
    } catch (const grbd::scene::StateError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  auto state = good;
  state.warm_lambda[0][0] = -1e300;
  EXPECT_NE(read_message(state, "a.h5").find("lambda_N ≥ 0"), std::string::npos);
  state = good;
  state.removed_mass = std::nan("");
  EXPECT_NE(read_message(state, "b.h5").find("attribute removed_mass"), std::string::npos);
  state = good;
  state.next_id = ~std::uint64_t{0};
  EXPECT_NE(read_message(state, "c.h5").find("attribute next_id"), std::string::npos);
  state = good;
  state.removed = state.next_id + 1;
  EXPECT_NE(read_message(state, "d.h5").find("attribute removed"), std::string::npos);
  EXPECT_EQ(read_message(good, "e.h5"), "");
  // Against the scene: the clock and Δt, each body's mass and inertia.
  EXPECT_EQ(state_message(good), "");
  state = good;
  state.steps = 0;
  EXPECT_NE(state_message(state).find("do not fit the scene's dt"), std::string::npos);
  state = good;
  state.bodies[3].inertia.K_Theta[0] = 3.5e-47;
  EXPECT_NE(state_message(state).find("is not a body that a group of the scene makes"),
            std::string::npos);
  state = good;
  state.bodies[2].inertia.m *= 1.0 + 1e-9;
  EXPECT_NE(state_message(state).find("body " + std::to_string(state.bodies[2].id)),
            std::string::npos);
  state = good;
  std::get<grbd::collision::Sphere>(state.bodies[1].shape).radius =
      0.0065;  // beyond the group's largest
  EXPECT_NE(state_message(state), "");
  // A value damaged in the file is named as damage by the checksum.
  grbd::io::write_checkpoint(path("f.h5"), {good, {}, scene.text});
  std::string bytes;
  {
    std::ifstream in(path("f.h5"), std::ios::binary);
    bytes.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  const double t = good.t;
  std::string pattern(sizeof(double), '\0');
  std::memcpy(pattern.data(), &t, sizeof(double));
  const std::size_t at = bytes.find(pattern);
  ASSERT_NE(at, std::string::npos);
  bytes[at] ^= 1;  // the last bit of the attribute t
  dir_.write("g.h5", bytes);
  try {
    grbd::io::read_checkpoint(path("g.h5"));
    ADD_FAILURE() << "a damaged checkpoint was read";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("is damaged"), std::string::npos) << e.what();
  }
}

// A restart reopens an output only when it is the output of the run it continues.
TEST_F(Folder, ARestartRefusesTheOutputOfAnotherRunWithoutChangingIt) {
  auto scene = chute();
  Simulation sim(scene);
  grbd::io::OutputFile out(path("o.h5"), scene);
  for (int k = 0; k < 30; ++k) out.add_step(sim.step(), sim.system().size());
  out.write_record(sim);
  const grbd::io::OutputPosition at = out.position();
  const auto state = sim.save();
  // While it is open, the file is locked: a second OutputFile is refused.
  EXPECT_THROW(grbd::io::OutputFile(path("o.h5"), scene), IoError);
  out.close(sim);
  const auto before = fs::file_size(path("o.h5"));
  auto other = state;
  other.bodies[0].inertia.m *= 2.0;
  try {
    grbd::io::OutputFile(path("o.h5"), scene, at, {scene.text + "# another\n", state.bodies});
    ADD_FAILURE() << "another scene's output was reopened";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("belongs to another run"), std::string::npos);
  }
  EXPECT_THROW(grbd::io::OutputFile(path("o.h5"), scene, at, {scene.text, other.bodies}), IoError);
  EXPECT_EQ(fs::file_size(path("o.h5")), before);
  grbd::io::OutputFile again(path("o.h5"), scene, at, {scene.text, state.bodies});
  again.close(sim);
}

TEST_F(Folder, OutputCostsLittleOfARun) {
  // The run's own measure of the time in records and checkpoints, at one record every 25 steps of
  // a small scene (the 10⁵-sphere figure is measured by the benchmark, not asserted here).
  const auto scene = chute();
  grbd::io::RunOptions options;
  options.output = path("o.h5");
  options.checkpoint = path("o.ckpt.h5");
  const grbd::io::RunResult result = grbd::io::run(scene, options);
  EXPECT_EQ(result.steps, 600U);
  EXPECT_EQ(result.records, 25U);
  EXPECT_EQ(result.checkpoints, 6U);
  EXPECT_FALSE(result.interrupted);
  EXPECT_GT(result.step_seconds, 0.0);
  EXPECT_LE(result.step_seconds + result.output_seconds, result.seconds);
}

}  // namespace

// The static geometry that the output keeps for ParaView (group /static): independent references
// are the exact areas and volumes of the shapes, the plane equations, and the rule that every face
// points into the free space.
namespace static_surface_tests {

using grbd::Vector3;
using grbd::io::StaticSurface;

grbd::scene::Scene scene_of(const std::string& statics, const std::string& region) {
  const std::string text =
      "[simulation]\ndt = 1e-3\nend_time = 0.01\n"
      "[[material]]\nname = \"glass\"\n[default_contact]\nmu = 0.5\n" +
      statics +
      "[[bodies]]\nname = \"beads\"\nradius = 0.002\ndensity = 2500.0\nmaterial = \"glass\"\n"
      "[bodies.generator]\nkind = \"lattice\"\nregion = " +
      region + "\n";
  return grbd::scene::parse_scene(text, "surface.toml");
}

std::string half_space(const std::string& normal, const std::string& point) {
  return "[[static]]\nname = \"plane\"\nshape = \"half_space\"\nnormal = " + normal +
         "\npoint = " + point + "\nmaterial = \"glass\"\n";
}

// Area vector Σ ½ (b − a) × (c − a) and signed volume Σ a·(b × c)/6 of the triangles of object k.
struct Measure {
  Vector3 area_vector = Vector3::Zero();
  double area = 0.0;
  double volume = 0.0;
  std::size_t triangles = 0;
};
Measure measure(const StaticSurface& s, std::uint32_t k) {
  Measure m;
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    if (s.object[t] != k) continue;
    const Vector3& a = s.points[s.triangles[t][0]];
    const Vector3& b = s.points[s.triangles[t][1]];
    const Vector3& c = s.points[s.triangles[t][2]];
    const Vector3 n = 0.5 * (b - a).cross(c - a);
    m.area_vector += n;
    m.area += n.norm();
    m.volume += a.dot(b.cross(c)) / 6.0;
    ++m.triangles;
  }
  return m;
}

TEST(StaticSurface, HalfSpacesDrawTheBoundaryOfTheFreeSpaceFacingIntoIt) {
  // A square silo of side 30 mm: its floor is drawn between the walls, its walls above the
  // floor, up to the top of the fill region plus the margin of 5 % of its height.
  const std::string walls = half_space("[0.0, 0.0, 1.0]", "[0.0, 0.0, 0.0]") +
                            half_space("[1.0, 0.0, 0.0]", "[-0.015, 0.0, 0.0]") +
                            half_space("[-1.0, 0.0, 0.0]", "[0.015, 0.0, 0.0]") +
                            half_space("[0.0, 1.0, 0.0]", "[0.0, -0.015, 0.0]") +
                            half_space("[0.0, -1.0, 0.0]", "[0.0, 0.015, 0.0]");
  const auto scene = scene_of(walls, "{ min = [-0.015, -0.015, 0.0], max = [0.015, 0.015, 0.25] }");
  const StaticSurface s = grbd::io::static_surface(scene);
  const double top = 0.25 + 0.05 * 0.25;
  EXPECT_DOUBLE_EQ(s.bounds.max.z(), top);
  const Vector3 normals[5] = {Vector3::UnitZ(), Vector3::UnitX(), -Vector3::UnitX(),
                              Vector3::UnitY(), -Vector3::UnitY()};
  for (std::uint32_t k = 0; k < 5; ++k) {
    const Measure m = measure(s, k);
    const double expected = k == 0 ? 0.03 * 0.03 : 0.03 * top;
    EXPECT_EQ(m.triangles, 2u) << "plane " << k;
    EXPECT_NEAR(m.area, expected, 1e-15) << "plane " << k;
    // Every face points out of its solid, into the free space: the area vector is +area n.
    EXPECT_NEAR((m.area_vector - expected * normals[k]).norm(), 0.0, 1e-15) << "plane " << k;
  }
  for (const Vector3& p : s.points) {  // nothing outside the silo's box
    EXPECT_LE(std::abs(p.x()), 0.015 + 1e-15);
    EXPECT_LE(std::abs(p.y()), 0.015 + 1e-15);
    EXPECT_GE(p.z(), -1e-15);
  }
}

TEST(StaticSurface, AnInclinedPlaneIsCutAtTheOutletsBox) {
  // A 20° slope between two walls, cut at the outlet's box: the polygon lies in the plane, inside
  // the box and between the walls, and its area is that of the strip of the slope over the box's
  // x range, 0.18 m / cos 20° × 0.06 m (the slope stays inside the box's z range there).
  auto scene = grbd::scene::load_scene(fs::path(GRBD_CH07_DATA_DIR) / "chute.toml");
  const StaticSurface s = grbd::io::static_surface(scene);
  const Vector3 n(0.3420201433256687, 0.0, 0.9396926207859084);
  const Measure m = measure(s, 0);
  const double expected = 0.18 / n.z() * 0.06;
  EXPECT_NEAR(m.area, expected, 1e-14);
  EXPECT_NEAR((m.area_vector - expected * n).norm(), 0.0, 1e-14);
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    if (s.object[t] != 0) continue;
    for (const std::uint64_t i : s.triangles[t]) {
      const Vector3& p = s.points[i];
      EXPECT_NEAR(n.dot(p), 0.0, 1e-15);
      EXPECT_LE(std::abs(p.y()), 0.03 + 1e-15);
      EXPECT_GE(p.x(), -0.1 - 1e-15);
      EXPECT_LE(p.x(), 0.08 + 1e-15);
    }
  }
}

TEST(StaticSurface, FiniteObjectsAreClosedOutwardSurfacesOnTheirShapes) {
  // A sphere, a box and a capsule, turned and moved: every vertex lies on the exact surface, the
  // surfaces are closed (area vector 0) and outward (volume > 0); the box's volume is exact, the
  // inscribed sphere (320 faces) falls short of the exact one by less than 4 %, the capsule (24
  // segments around) by less than 3 %.
  const std::string objects =
      "[[static]]\nname = \"ball\"\nshape = \"sphere\"\nradius = 0.006\n"
      "position = [0.1, -0.01, 0.02]\nmaterial = \"glass\"\n"
      "[[static]]\nname = \"block\"\nshape = \"box\"\nhalf_extents = [0.01, 0.005, 0.004]\n"
      "position = [0.08, 0.01, 0.005]\nrotation = [1, 2, 3, 30]\nmaterial = \"glass\"\n"
      "[[static]]\nname = \"tree\"\nshape = \"capsule\"\nradius = 0.004\nhalf_length = 0.02\n"
      "position = [0.15, 0.0, 0.0]\nrotation = [1, 0, 0, 70]\nmaterial = \"glass\"\n";
  const auto scene = scene_of(objects, "{ min = [0.0, -0.02, 0.0], max = [0.04, 0.02, 0.03] }");
  const StaticSurface s = grbd::io::static_surface(scene);
  const double pi = std::numbers::pi;
  const double exact[3] = {4.0 / 3.0 * pi * std::pow(0.006, 3), 8 * 0.01 * 0.005 * 0.004,
                           pi * 0.004 * 0.004 * (4.0 / 3.0 * 0.004 + 0.04)};
  const double shortfall[3] = {0.96, 1 - 1e-12, 0.97};
  for (std::uint32_t k = 0; k < 3; ++k) {
    const Measure m = measure(s, k);
    EXPECT_GT(m.triangles, 0u);
    EXPECT_LT(m.area_vector.norm(), 1e-15) << "object " << k;
    EXPECT_LE(m.volume, exact[k] * (1 + 1e-12)) << "object " << k;
    EXPECT_GT(m.volume, exact[k] * shortfall[k]) << "object " << k;
  }
  const auto& capsule = scene.statics[2].pose;
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    for (const std::uint64_t i : s.triangles[t]) {
      const Vector3& p = s.points[i];
      if (s.object[t] == 0) {
        EXPECT_NEAR((p - Vector3(0.1, -0.01, 0.02)).norm(), 0.006, 1e-15);
      }
      if (s.object[t] == 2) {  // distance from the segment ±0.02 along the turned z axis
        const Vector3 axis = capsule.A_IC.col(2);
        const Vector3 d = p - capsule.I_r;
        const double along = std::clamp(axis.dot(d), -0.02, 0.02);
        EXPECT_NEAR((d - along * axis).norm(), 0.004, 1e-15);
      }
    }
  }
}

}  // namespace static_surface_tests
