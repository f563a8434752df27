// Chapter 7: scene files. Every error names the file, line and column, the key, what was expected
// and what was found; unknown keys suggest the closest known one; the parser survives thousands
// of seeded mutations of the example scenes with nothing but grbd::scene::SceneError.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"

namespace {

using grbd::scene::parse_scene;
using grbd::scene::Scene;
using grbd::scene::SceneError;

const std::string kMinimal = R"([simulation]
dt = 1e-3
end_time = 0.01

[[material]]
name = "glass"

[default_contact]
mu = 0.5

[[bodies]]
radius = 0.01
density = 2500
material = "glass"
positions = [[0.0, 0.0, 0.1], [0.0, 0.0, 0.2]]
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The message of the SceneError that parsing (and building) `text` throws, or "" if none.
std::string error_of(const std::string& text, bool build = false) {
  try {
    const Scene scene = parse_scene(text, "scene.toml");
    if (build) grbd::scene::Simulation simulation(scene);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(SceneFile, AMinimalSceneTakesTheDocumentedDefaults) {
  const Scene scene = parse_scene(kMinimal, "runs/minimal.toml");
  EXPECT_EQ(scene.name, "minimal");
  EXPECT_EQ(scene.settings.dt, 1e-3);
  EXPECT_EQ(scene.steps(), 10U);
  EXPECT_EQ(scene.settings.I_g, grbd::Vector3(0.0, 0.0, -9.81));
  EXPECT_EQ(scene.settings.method, grbd::contact::Method::sor);
  EXPECT_EQ(scene.settings.reorder_interval, 100);
  EXPECT_EQ(scene.output.every, 100U);
  EXPECT_EQ(scene.output.file, "minimal.h5");
  EXPECT_EQ(scene.checkpoint.file, "minimal.ckpt.h5");
  EXPECT_FALSE(scene.output.float32);
  ASSERT_EQ(scene.groups.size(), 1U);
  EXPECT_EQ(scene.groups[0].generator.positions.size(), 2U);
  EXPECT_EQ(scene.text, kMinimal);
  grbd::scene::Simulation simulation(scene);
  EXPECT_EQ(simulation.system().size(), 2U);
  // m = ρ (4/3) π r³.
  EXPECT_NEAR(simulation.system().inertia()[0].m, 2500.0 * 4.0 / 3.0 * M_PI * 1e-6, 1e-15);
}

TEST(SceneFile, TheActiveSetToleranceScalesTheSmallestRadiusAnyGroupCanProduce) {
  // chapter 7's test chute: beads of radius uniform in [4, 6] mm from a lattice and an inflow,
  // removed at an outlet; the tolerance must not follow the smallest bead present.
  const Scene chute =
      grbd::scene::load_scene(std::filesystem::path(GRBD_CH07_DATA_DIR) / "chute.toml");
  EXPECT_EQ(chute.settings.tolerance_radius, 0.004);
  // A box's bounding radius is |h|, a capsule's r + l; the smallest over the groups counts.
  std::string text = replace(kMinimal, "radius = 0.01", "radius = 2.0");
  EXPECT_EQ(parse_scene(text, "x.toml").settings.tolerance_radius, 2.0);
  text +=
      "[[bodies]]\nname = \"bricks\"\nshape = \"box\"\nhalf_extents = [0.3, 0.4, 1.2]\n"
      "density = 1000.0\nmaterial = \"glass\"\npositions = [[5.0, 0.0, 2.0]]\n"
      "[[bodies]]\nname = \"rods\"\nshape = \"capsule\"\nradius = 0.5\n"
      "half_length = 0.9\ndensity = 1000.0\nmaterial = \"glass\"\n"
      "positions = [[9.0, 0.0, 2.0]]\n";
  EXPECT_DOUBLE_EQ(parse_scene(text, "x.toml").settings.tolerance_radius, 1.3);
  text = replace(text, "half_length = 0.9", "half_length = 0.7");  // now the capsule: 1.2
  EXPECT_DOUBLE_EQ(parse_scene(text, "x.toml").settings.tolerance_radius, 1.2);
  grbd::scene::Simulation simulation(chute);
  const double tolerance = simulation.stepper().active_set_tolerance();
  // The scene's look-ahead (0.1 r) and its reach (1 r by default) reach further than Moreau's
  // contact tolerance.
  EXPECT_EQ(tolerance,
            std::max({chute.settings.contact_tolerance, chute.settings.look_ahead,
                      chute.settings.look_ahead_reach}) *
                0.004);
  for (int step = 0; step < 200; ++step) simulation.step();  // inflow and outlet at work
  EXPECT_EQ(simulation.stepper().active_set_tolerance(), tolerance);
}

TEST(SceneFile, ASimulationKeepsItsOwnCopyOfTheScene) {
  // Built from a temporary scene, it runs on: it does not refer to the scene it was given.
  const auto path = std::filesystem::path(GRBD_CH07_DATA_DIR) / "chute.toml";
  grbd::scene::Simulation simulation(grbd::scene::load_scene(path));
  for (int step = 0; step < 20; ++step) simulation.step();
  EXPECT_EQ(simulation.scene().text, read(path));
  EXPECT_EQ(simulation.stepper().steps(), 20U);
}

TEST(SceneFile, UnknownKeysAreErrorsWithTheClosestKnownKey) {
  EXPECT_EQ(error_of(replace(kMinimal, "end_time", "end_tme")),
            "scene.toml:3:1: simulation.end_tme: unknown key (did you mean \"end_time\"?)");
  EXPECT_EQ(error_of(replace(kMinimal, "density = 2500", "densty = 2500\ndensity = 2500")),
            "scene.toml:13:1: bodies[0].densty: unknown key (did you mean \"density\"?)");
  // Nothing close: the message lists the keys of the table.
  const std::string far = error_of(replace(kMinimal, "mu = 0.5", "mu = 0.5\nwobble = 1"));
  EXPECT_NE(far.find("scene.toml:10:1: default_contact.wobble: unknown key; the keys of "
                     "default_contact are: eps_N eps_T mu"),
            std::string::npos)
      << far;
  EXPECT_EQ(error_of(replace(kMinimal, "[simulation]", "[simulaton]\ndt=1\n[simulation]")),
            "scene.toml:1:2: simulaton: unknown key (did you mean \"simulation\"?)");
}

TEST(SceneFile, AMisspeltKeyOfAnEitherOrPairIsNamedAtItsLine) {
  // Exactly one of density and mass, of positions and [bodies.generator]: when neither is found
  // because one is misspelt, the message is the misspelling's, at its line, not "found neither".
  EXPECT_EQ(error_of(replace(kMinimal, "density = 2500", "densty = 2500")),
            "scene.toml:13:1: bodies[0].densty: unknown key (did you mean \"density\"?)");
  EXPECT_EQ(error_of(replace(kMinimal, "density = 2500", "mas = 0.01")),
            "scene.toml:13:1: bodies[0].mas: unknown key (did you mean \"mass\"?)");
  EXPECT_EQ(error_of(replace(kMinimal, "positions = ", "positons = ")),
            "scene.toml:15:1: bodies[0].positons: unknown key (did you mean \"positions\"?)");
  EXPECT_EQ(error_of(replace(kMinimal, "positions = [[0.0, 0.0, 0.1], [0.0, 0.0, 0.2]]",
                             "[bodies.generatr]\nkind = \"lattice\"")),
            "scene.toml:15:9: bodies[0].generatr: unknown key (did you mean \"generator\"?)");
  // Truly neither, or both: said as such.
  EXPECT_NE(error_of(replace(kMinimal, "density = 2500\n", ""))
                .find("expected exactly one of density [kg/m³] and mass [kg], found neither"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kMinimal, "density = 2500", "density = 2500\nmass = 1.0"))
                .find("found both"),
            std::string::npos);
}

TEST(SceneFile, OutOfRangeValuesNameTheKeyTheRangeAndTheValue) {
  EXPECT_EQ(error_of(replace(kMinimal, "radius = 0.01", "radius = -0.01")),
            "scene.toml:12:10: bodies[0].radius: expected a number > 0, found the number -0.01");
  EXPECT_EQ(error_of(replace(kMinimal, "dt = 1e-3", "dt = 0")),
            "scene.toml:2:6: simulation.dt: expected a number > 0, found the integer 0");
  EXPECT_EQ(error_of(replace(kMinimal, "dt = 1e-3", "dt = \"fast\"")),
            "scene.toml:2:6: simulation.dt: expected a number > 0, found the string \"fast\"");
  EXPECT_EQ(error_of(replace(kMinimal, "mu = 0.5", "mu = -0.1")),
            "scene.toml:9:6: default_contact.mu: expected a number ≥ 0, found the number -0.1");
  EXPECT_EQ(
      error_of(replace(kMinimal, "mu = 0.5", "mu = 0.5\neps_N = 1.5")),
      "scene.toml:10:9: default_contact.eps_N: expected a number in [0, 1], found the number 1.5");
  EXPECT_EQ(error_of(replace(kMinimal, "mu = 0.5", "mu = nan")),
            "scene.toml:9:6: default_contact.mu: expected a number ≥ 0, found the number nan");
  EXPECT_EQ(error_of(replace(kMinimal, "end_time = 0.01\n", "")),
            "scene.toml:1:1: simulation.end_time: expected a number > 0, found nothing (the key is "
            "required)");
  EXPECT_EQ(error_of(replace(kMinimal, "density = 2500", "density = 2500\nmass = 1")),
            "scene.toml:11:1: bodies[0].density: expected exactly one of density [kg/m³] and mass "
            "[kg], found both");
  const std::string region = error_of(replace(
      kMinimal, "positions = [[0.0, 0.0, 0.1], [0.0, 0.0, 0.2]]",
      "[bodies.generator]\nkind = \"lattice\"\nregion = { min = [0, 0, 1], max = [1, 1, 0] }"));
  EXPECT_EQ(region,
            "scene.toml:17:10: bodies[0].generator.region: expected a table { min = [x, "
            "y, z], max = [x, y, z] } with min < max, found a table");
  EXPECT_EQ(
      error_of(replace(kMinimal, "[simulation]", "[solver]\nmethod = \"sore\"\n[simulation]")),
      "scene.toml:2:10: solver.method: expected one of \"sor\", \"jor\", \"apgd\", \"newton\" "
      "(did you mean \"sor\"?), found the string \"sore\"");
}

// The gap-aware normal law's keys (chapter 6) reach the stepper's settings; bad values are
// refused by name.
TEST(SceneFile, TheGapAwareLawIsASceneKey) {
  const Scene scene = parse_scene(
      replace(kMinimal, "[simulation]",
              "[solver]\noverlap_recovery = 0.5\nmax_recovery_speed = 0.02\nlook_ahead = 0.1\n"
              "[simulation]"),
      "scene.toml");
  EXPECT_EQ(scene.settings.look_ahead, 0.1);
  EXPECT_EQ(scene.settings.overlap_recovery, 0.5);
  EXPECT_EQ(scene.settings.max_recovery_speed, 0.02);
  EXPECT_EQ(error_of(replace(kMinimal, "[simulation]", "[solver]\noverlap_recovery = 1.5\n[simulation]")),
            "scene.toml:2:20: solver.overlap_recovery: expected a number in [0, 1], found the "
            "number 1.5");
  EXPECT_NE(error_of(replace(kMinimal, "[simulation]", "[solver]\nmax_recovery_speed = 0\n[simulation]"))
                .find("solver.max_recovery_speed: expected a number > 0"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kMinimal, "[simulation]", "[solver]\nmax_recovery_speed = nan\n[simulation]"))
                .find("solver.max_recovery_speed: expected a number > 0"),
            std::string::npos);
  // The look-ahead's reach: named, or at least the look-ahead, or off with it.
  const auto reach = [](const std::string& keys) {
    return parse_scene(replace(kMinimal, "[simulation]", "[solver]\n" + keys + "[simulation]"),
                       "scene.toml")
        .settings.look_ahead_reach;
  };
  EXPECT_EQ(reach("look_ahead_reach = 0.5\n"), 0.5);
  EXPECT_EQ(reach("look_ahead_reach = 0\n"), 0.0);
  EXPECT_EQ(reach("look_ahead = 2.5\n"), 2.5);
  EXPECT_EQ(reach("look_ahead = 0\n"), 0.0);
  EXPECT_EQ(error_of(replace(kMinimal, "[simulation]", "[solver]\nlook_ahead_reach = 0.05\n[simulation]")),
            "scene.toml:2:20: solver.look_ahead_reach: expected 0 (none) or, with a look_ahead > 0, "
            "at least the look_ahead (0.1), found the number 0.05");
  EXPECT_NE(error_of(replace(kMinimal, "[simulation]",
                             "[solver]\nlook_ahead = 0\nlook_ahead_reach = 1\n[simulation]"))
                .find("solver.look_ahead_reach: expected 0 (none) or, with a look_ahead > 0"),
            std::string::npos);
}

// Newton's keys reach the stepper's settings, and bad values are refused by name.
TEST(SceneFile, NewtonsLinearSolverAndHybridAreSceneKeys) {
  const Scene scene = parse_scene(
      replace(kMinimal, "[simulation]",
              "[solver]\nmethod = \"newton\"\nlinear_solver = \"direct\"\nhybrid_sweeps = 300\n"
              "[simulation]"),
      "scene.toml");
  EXPECT_EQ(scene.settings.method, grbd::contact::Method::newton);
  EXPECT_EQ(scene.settings.solver.newton.linear_solver, grbd::contact::LinearSolver::direct);
  EXPECT_EQ(scene.settings.solver.newton.hybrid_sweeps, 300);
  grbd::scene::Simulation simulation(scene);
  EXPECT_EQ(error_of(replace(kMinimal, "[simulation]", "[solver]\nhybrid_sweeps = -1\n[simulation]")),
            "scene.toml:2:17: solver.hybrid_sweeps: expected an integer in [0, 100000000], found "
            "the integer -1");
  EXPECT_NE(error_of(replace(kMinimal, "[simulation]", "[solver]\nlinear_solver = \"lu\"\n[simulation]"))
                .find("solver.linear_solver: expected one of \"automatic\", \"direct\", \"gmres\""),
            std::string::npos);
}

TEST(SceneFile, MaterialsAndPairsMustBeDeclared) {
  EXPECT_EQ(error_of(replace(kMinimal, "material = \"glass\"", "material = \"glas\"")),
            "scene.toml:14:12: bodies[0].material: expected the name of a declared material "
            "([[material]]) (did you mean \"glass\"?), found the string \"glas\"");
  const std::string two = replace(
      replace(kMinimal, "[default_contact]\nmu = 0.5\n",
              "[[material]]\nname = \"steel\"\n\n[[contact]]\nmaterials = [\"glass\", \"glass\"]\n"
              "mu = 0.5\n"),
      "[[bodies]]",
      "[[static]]\nshape = \"half_space\"\nnormal = [0, 0, 1]\nmaterial = \"steel\"\n\n[[bodies]]");
  EXPECT_EQ(error_of(two),
            "scene.toml: contact: expected a [[contact]] with materials = [\"glass\", \"steel\"] "
            "(bodies of \"glass\" can touch \"steel\") or a [default_contact], found neither");
  EXPECT_EQ(error_of(replace(two, "mu = 0.5\n",
                             "mu = 0.5\n\n[[contact]]\nmaterials = [\"steel\", "
                             "\"glass\"]\nmu = 0.2\n")),
            "");
}

TEST(SceneFile, UnsupportedShapePairsAndUnreadableMeshesAreRefusedBeforeTheRun) {
  const std::string boxes =
      replace(kMinimal, "radius = 0.01", "shape = \"box\"\nhalf_extents = [0.01, 0.01, 0.01]");
  EXPECT_EQ(error_of(boxes, true),
            "scene.toml: bodies[0] (bodies[0]): a box of it can touch a box of bodies[0], a "
            "pair grbd cannot collide (supported pairs: sphere with any shape, box or capsule "
            "with a half-space)");
  const std::string mesh = replace(kMinimal, "[[bodies]]",
                                   "[[static]]\nshape = \"mesh\"\nfile = \"no/such.obj\"\n"
                                   "material = \"glass\"\n\n[[bodies]]");
  const std::string message = error_of(mesh);
  EXPECT_EQ(
      message.rfind("scene.toml:13:8: static[0].file: expected a readable OBJ mesh, found ", 0), 0U)
      << message;
  EXPECT_NE(message.find("no/such.obj"), std::string::npos) << message;
}

TEST(SceneFile, SyntaxErrorsNameLineAndColumn) {
  const std::string message = error_of(replace(kMinimal, "dt = 1e-3", "dt = 1e-3 x"));
  EXPECT_EQ(message.rfind("scene.toml:2:11: not valid TOML: ", 0), 0U) << message;
}

// Seeded mutations of every example scene: each parse (and, for small scenes, the build and two
// steps) ends normally or with a grbd error, never with another exception, a crash or a hang.
TEST(SceneFile, FuzzedScenesGiveOnlyGrbdErrors) {
  std::vector<std::string> seeds = {kMinimal,
                                    read(std::filesystem::path(GRBD_CH07_DATA_DIR) / "chute.toml")};
  for (const auto& entry : std::filesystem::directory_iterator(GRBD_CH07_SCENE_DIR)) {
    if (entry.path().extension() == ".toml") seeds.push_back(read(entry.path()));
  }
  const std::vector<std::string> tokens = {
      "-1",         "0",    "1e308",  "-1e-308", "nan", "inf",     "1e400", "99999999999999999999",
      "\"x\"",      "[",    "]",      "{",       "}",   "=",       "\n",    "\"",
      "[[bodies]]", "true", "[1, 2]", ".",       "#",   "\\u0000", "'''",   "1979-05-27"};
  grbd::scene::Random random(20261125);
  auto pick = [&](std::size_t n) { return static_cast<std::size_t>(random.bits() % n); };
  const int kMutations = 4000;
  int accepted = 0;
  int refused = 0;
  int built = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < kMutations; ++k) {
    std::string text = seeds[pick(seeds.size())];
    const int edits = 1 + static_cast<int>(pick(3));
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const std::size_t at = pick(text.size());
      switch (pick(6)) {
        case 0:
          text[at] = static_cast<char>(1 + pick(255));
          break;  // any byte
        case 1:
          text.insert(at, tokens[pick(tokens.size())]);
          break;  // a token
        case 2:
          text.erase(at, 1 + pick(20));
          break;  // a deletion
        case 3:
          text.resize(at);
          break;   // truncation
        case 4: {  // a number
          const std::size_t digit = text.find_first_of("0123456789", at);
          if (digit != std::string::npos) {
            const std::size_t end = text.find_first_not_of("0123456789.e-", digit);
            text.replace(digit, end - digit, tokens[pick(8)]);
          }
          break;
        }
        default: {  // a duplicated line
          const std::size_t begin = text.rfind('\n', at);
          const std::size_t end = text.find('\n', at);
          const std::size_t b = begin == std::string::npos ? 0 : begin + 1;
          text.insert(b, text.substr(b, (end == std::string::npos ? text.size() : end) - b) + "\n");
        }
      }
    }
    try {
      const Scene scene = parse_scene(text, "fuzz.toml");
      ++accepted;
      // Build and step the small ones only (a mutated count can ask for 10⁸ bodies, which is
      // valid but slow).
      bool small = true;
      for (const auto& g : scene.groups) {
        const auto& gen = g.generator;
        if (gen.kind == grbd::scene::GeneratorKind::lattice) {
          const double s =
              gen.spacing > 0 ? gen.spacing : 2.0 * grbd::scene::largest_bounding_radius(g);
          const double sites = ((gen.region.max - gen.region.min) / s).array().floor().prod();
          small = small && (gen.count > 0 ? gen.count <= 2000 : sites <= 2000);
        } else {
          small = small && gen.count <= 2000;
        }
      }
      if (small && scene.steps() >= 2) {
        try {
          grbd::scene::Simulation simulation(scene);
          simulation.step();
          simulation.step();
          ++built;
        } catch (const grbd::Error&) {
        }
      }
    } catch (const SceneError& e) {
      ++refused;
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("fuzz.toml", 0), 0U) << message;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(accepted + refused, kMutations);
  EXPECT_GT(refused, kMutations / 4);
  EXPECT_GT(accepted, kMutations / 40);
  std::printf(
      "fuzz: %d mutations of %zu scenes, %d accepted (%d built and stepped), %d refused "
      "with a SceneError, %.1f s\n",
      kMutations, seeds.size(), accepted, built, refused, seconds);
}

TEST(SceneFile, ClosestKeyIsTheNearestWithinHalfTheLength) {
  EXPECT_EQ(grbd::scene::closest_key("jiter", {"jitter", "spacing", "count"}), "jitter");
  EXPECT_EQ(grbd::scene::closest_key("xyz", {"jitter", "spacing", "count"}), "");
  EXPECT_EQ(grbd::scene::closest_key("cout", {"jitter", "spacing", "count"}), "count");
}

// A half-space faces where its normal points: a rotation or orientation for it is refused with
// that explanation, not answered with the closest key.
TEST(SceneFile, AHalfSpaceIsOrientedByItsNormalAlone) {
  const std::string text = kMinimal +
                           "\n[[static]]\nshape = \"half_space\"\nnormal = [0, 0, 1]\n"
                           "rotation = [1, 0, 0, 30]\nmaterial = \"glass\"\n";
  const auto line = 1 + std::count(text.begin(), text.begin() + text.find("rotation"), '\n');
  try {
    parse_scene(text, "plane.toml");
    ADD_FAILURE() << "a rotated half-space was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("plane.toml:" + std::to_string(line) +
                                         ":12: static[0].rotation: expected no orientation: a "
                                         "half-space is oriented by its normal"),
              std::string::npos)
        << e.what();
  }
}

// What a scene gets where it names nothing (chapter 6, "What a scene gets"): SOR held to the
// natural residual 1e-4 with α = 1.3 and the gap-aware look-ahead of 0.1 r, no overlap recovery;
// a StepSettings built in C++ stays Moreau's scheme as chapter 6 derives it.
TEST(SceneFile, AScenesDefaultsAreTheNaturalResidualAndTheLookAhead) {
  const Scene scene = parse_scene(kMinimal, "minimal.toml");
  const auto& s = scene.settings;
  EXPECT_EQ(s.method, grbd::contact::Method::sor);
  EXPECT_EQ(s.solver.criterion, grbd::contact::Criterion::natural_residual);
  EXPECT_EQ(s.solver.rel_tol, 1e-4);
  EXPECT_EQ(s.solver.alpha, 1.3);
  EXPECT_EQ(s.solver.max_iterations, 1000);
  EXPECT_EQ(s.look_ahead, 0.1);
  EXPECT_EQ(s.look_ahead_reach, 1.0);
  EXPECT_EQ(s.overlap_recovery, 0.0);
  EXPECT_EQ(s.reorder_interval, 100);
  // A [solver] table that names other keys keeps the defaults of those it does not name, and
  // every default can be named away.
  const Scene named = parse_scene(kMinimal + "[solver]\nmax_iterations = 50\n", "named.toml");
  EXPECT_EQ(named.settings.solver.criterion, grbd::contact::Criterion::natural_residual);
  EXPECT_EQ(named.settings.look_ahead, 0.1);
  EXPECT_EQ(named.settings.solver.max_iterations, 50);
  const Scene moreau = parse_scene(kMinimal +
                                       "[solver]\ncriterion = \"percussion_change\"\n"
                                       "tolerance = 1e-6\nalpha = 1.0\nlook_ahead = 0.0\n"
                                       "reorder_interval = 0\n",
                                   "moreau.toml");
  const grbd::timestep::StepSettings library;
  EXPECT_EQ(moreau.settings.solver.criterion, library.solver.criterion);
  EXPECT_EQ(moreau.settings.solver.rel_tol, library.solver.rel_tol);
  EXPECT_EQ(moreau.settings.solver.alpha, library.solver.alpha);
  EXPECT_EQ(moreau.settings.look_ahead, library.look_ahead);
  EXPECT_EQ(moreau.settings.look_ahead_reach, library.look_ahead_reach);
  EXPECT_EQ(moreau.settings.overlap_recovery, library.overlap_recovery);
  EXPECT_EQ(moreau.settings.reorder_interval, library.reorder_interval);
  // grbd validate says what the solve and the normal law are.
  const std::string text = grbd::scene::summary(scene);
  EXPECT_NE(text.find("solver: SOR, natural residual tolerance 0.0001, alpha 1.3, at most 1000"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("normal law: gap-aware, look_ahead 0.1 r, reach 1 r for approaching pairs, "
                      "overlap_recovery 0"),
            std::string::npos)
      << text;
  EXPECT_NE(grbd::scene::summary(moreau).find("normal law: Moreau's"), std::string::npos);
}

// The issue that made the defaults: a user who writes a dense scene and names no [solver] must
// get overlaps of at most 1 % of a grain. 300 glass beads (r = 1 mm) poured from a loose lattice
// into a box 12 mm wide, 0.15 s, Δt = 0.2 ms: with the defaults the largest overlap of any step
// stays below 0.01 d (about 1 µm); Moreau's law (look_ahead = 0) on the same scene lets the
// landings overlap by more than 0.01 d (about 50 µm). The share of steps whose solve met the
// tolerance within 1000 sweeps is recorded, not held: it is the beads' landings on a pile, where
// Gauss–Seidel converges slowly (chapter 6, "What a scene gets").
TEST(SceneFile, AScenesDefaultsKeepASettlingPilesOverlapsBelowAPercentOfAGrain) {
  const std::string pile = R"([simulation]
dt = 2e-4
end_time = 0.15
seed = 3

[[material]]
name = "glass"

[default_contact]
mu = 0.5

[[static]]
shape = "half_space"
normal = [0.0, 0.0, 1.0]
material = "glass"
[[static]]
shape = "half_space"
normal = [1.0, 0.0, 0.0]
point = [-0.006, 0.0, 0.0]
material = "glass"
[[static]]
shape = "half_space"
normal = [-1.0, 0.0, 0.0]
point = [0.006, 0.0, 0.0]
material = "glass"
[[static]]
shape = "half_space"
normal = [0.0, 1.0, 0.0]
point = [0.0, -0.006, 0.0]
material = "glass"
[[static]]
shape = "half_space"
normal = [0.0, -1.0, 0.0]
point = [0.0, 0.006, 0.0]
material = "glass"

[[bodies]]
radius = 0.001
density = 2500.0
material = "glass"
[bodies.generator]
kind = "lattice"
region = { min = [-0.006, -0.006, 0.0], max = [0.006, 0.006, 0.04] }
spacing = 0.0024
count = 300
jitter = 0.4
)";
  const auto largest_overlap = [](const std::string& text, double& converged) {
    grbd::scene::Simulation simulation(parse_scene(text, "pile.toml"));
    double largest = 0.0;
    int steps = 0, met = 0;
    while (!simulation.finished()) {
      const grbd::timestep::StepReport report = simulation.step();
      largest = std::max(largest, report.max_penetration);
      ++steps;
      met += report.converged ? 1 : 0;
    }
    EXPECT_EQ(simulation.system().size(), 300u);
    converged = static_cast<double>(met) / steps;
    return largest;
  };
  double converged_defaults = 0.0, converged_moreau = 0.0;
  const double d = 0.002;
  const double defaults = largest_overlap(pile, converged_defaults);
  const double moreau =
      largest_overlap(pile + "[solver]\nlook_ahead = 0.0\n", converged_moreau);
  EXPECT_LE(defaults, 0.01 * d);
  EXPECT_GT(moreau, 0.01 * d);
  RecordProperty("converged_defaults", std::to_string(converged_defaults));
  RecordProperty("converged_moreau", std::to_string(converged_moreau));
  RecordProperty("largest_overlap_defaults_um", std::to_string(defaults * 1e6));
  RecordProperty("largest_overlap_moreau_um", std::to_string(moreau * 1e6));
}

// A gate (a static object with `until`) holds a sphere against gravity along −x until t = 0.05 s
// and is then gone: the sphere rests at the gate, then falls freely, x = x₀ − g (t − 0.05)² / 2
// (Moreau's midpoint step is exact for a constant acceleration).
TEST(SceneFile, AGateHoldsTheBodiesUntilItsTimeAndIsThenGone) {
  const std::string text =
      replace(replace(kMinimal, "end_time = 0.01",
                      "end_time = 0.1\n"
                      "gravity = [-9.81, 0.0, 0.0]"),
              "positions = [[0.0, 0.0, 0.1], [0.0, 0.0, 0.2]]", "positions = [[0.01, 0.0, 0.0]]") +
      "\n[[static]]\nname = \"gate\"\nshape = \"half_space\"\n"
      "normal = [1, 0, 0]\nmaterial = \"glass\"\nuntil = 0.05\n"
      // The closed form to 1e-9 m needs each step's solve to 1e-12 relative (the scene's
      // default, 1e-4, lets a resting sphere drift by ~1e-9 m in 30 steps).
      "[solver]\ntolerance = 1e-12\n";
  const Scene scene = parse_scene(text, "gate.toml");
  ASSERT_EQ(scene.statics.size(), 1u);
  EXPECT_EQ(scene.statics[0].until, 0.05);
  grbd::scene::Simulation simulation(scene);
  while (!simulation.finished()) {
    const double t = simulation.stepper().time();
    simulation.step();
    const double x = simulation.system().states()[0].q.x();
    if (t < 0.05 - 1e-9) {
      EXPECT_NEAR(x, 0.01, 1e-9) << "held by the gate at t = " << t;
      EXPECT_EQ(simulation.statics().size(), 1u);
    } else {
      const double fall = simulation.stepper().time() - 0.05;
      EXPECT_NEAR(x, 0.01 - 0.5 * 9.81 * fall * fall, 1e-9) << "falling at t = " << t;
      EXPECT_EQ(simulation.statics().size(), 0u);
    }
  }
  EXPECT_LT(simulation.system().states()[0].q.x(), 0.0);  // past where the gate stood
  const std::string bad = error_of(replace(text, "until = 0.05", "until = 0"));
  EXPECT_NE(bad.find("static[0].until: expected a number > 0, found the integer 0"),
            std::string::npos)
      << bad;
}

// Costs that grow linearly: 10⁵ static objects (each id checked against the others by a hash,
// not by a scan: a quadratic check took 45 s here) and 1024 materials (the pair table grows by
// doubling). The test's time limit is what fails when they become quadratic again.
TEST(SceneFile, ManyStaticObjectsAndMaterialsCostLinearTime) {
  std::ostringstream text;
  text << "[simulation]\ndt = 1e-3\nend_time = 0.01\n\n[[material]]\nname = \"glass\"\n\n"
          "[default_contact]\nmu = 0.5\n";
  constexpr int kStatics = 100000;
  for (int k = 0; k < kStatics; ++k) {
    text << "[[static]]\nshape = \"sphere\"\nradius = 0.001\nposition = [" << k * 0.01
         << ", 5.0, 5.0]\nmaterial = \"glass\"\n";
  }
  for (int k = 1; k < 1024; ++k) text << "[[material]]\nname = \"m" << k << "\"\n";
  text << "[[bodies]]\nradius = 0.01\ndensity = 2500.0\nmaterial = \"glass\"\n"
          "positions = [[0.0, 0.0, 0.05]]\n";
  const Scene scene = parse_scene(text.str(), "many.toml");
  grbd::scene::Simulation sim(scene);
  EXPECT_EQ(sim.statics().size(), static_cast<std::size_t>(kStatics));
  EXPECT_EQ(sim.materials().size(), 1024U);
  EXPECT_EQ(*sim.materials().find("m1023"), 1023U);
  // The hash still refuses an id used twice, and the table a 1025th material, naming the file.
  grbd::timestep::StaticGeometry statics = sim.statics();
  grbd::timestep::StaticObject again = sim.statics().objects()[54321];
  EXPECT_THROW(statics.add(again), grbd::InvalidArgument);
  try {
    parse_scene(text.str() + "[[material]]\nname = \"one too many\"\n", "many.toml");
    ADD_FAILURE() << "a 1025th material was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("many.toml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at most 1024 materials"), std::string::npos);
  }
}

}  // namespace
