#pragma once
/// \file
/// \brief Scene files (chapter 7): a TOML description of a granular experiment (time step,
/// solver, gravity, materials and their contact laws, static geometry, body groups with their
/// generators, output and checkpoints), read with toml++ into a Scene and checked completely
/// before a run starts.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/shapes.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd/scene/radius.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::scene {

/// A scene that cannot be run: the message reads "<file>:<line>:<column>: <key>: expected …,
/// found …" (line and column where the file has them), so that an editor jumps to the place.
class SceneError : public InvalidArgument {
 public:
  using InvalidArgument::InvalidArgument;
};

/// An axis-aligned box of frame I, [min, max].
struct Region {
  Vector3 min = Vector3::Zero();  ///< lower corner [m]
  Vector3 max = Vector3::Zero();  ///< upper corner [m], ≥ min in every coordinate
};

/// How the bodies of a group are placed.
enum class GeneratorKind {
  list,     ///< the positions given in the file
  lattice,  ///< a simple cubic lattice filling a region, each centre jittered
  packing,  ///< random sequential addition in a region: uniform positions, no overlaps
  inflow,   ///< bodies created over time in a region at a given rate, without overlaps
};

/// "list", "lattice", "packing" or "inflow".
std::string_view generator_name(GeneratorKind kind);

/// The generator of a body group.
struct GeneratorSpec {
  GeneratorKind kind = GeneratorKind::list;  ///< which generator
  std::vector<Vector3> positions;            ///< list: the centres [m]
  Region region;                             ///< lattice, packing, inflow: where the centres go
  /// lattice: exactly this many, the first sites in x, y, z order (0: every site of the region);
  /// packing: exactly this many; inflow: in all (0: no limit until `stop`)
  std::uint64_t count = 0;
  double spacing = 0.0;  ///< lattice: distance of neighbours [m] (0: 2 × the largest radius)
  double jitter = 0.0;   ///< lattice: random shift, a fraction in [0, 1] of the free gap
  double rate = 0.0;     ///< inflow: bodies per second > 0
  double start = 0.0;    ///< inflow: first time [s]
  double stop = 0.0;     ///< inflow: last time [s] (0: the end of the run)
  bool random_orientation = false;  ///< uniformly random orientations (else the identity)
  std::uint64_t seed = 0;           ///< of this group's random numbers
  /// tries per body before giving up: packing (default 1000) refuses the scene, inflow (default
  /// 20) owes the body to the next step
  int max_attempts = 1000;
};

/// A group of bodies of one shape and material.
struct BodyGroup {
  std::string name;                                           ///< for messages and the summary
  collision::ShapeKind shape = collision::ShapeKind::sphere;  ///< sphere, box or capsule
  /// sphere: its radius; capsule: the radius of its segment [m]
  RadiusDistribution radius = RadiusDistribution::fixed(1.0);
  Vector3 half_extents = Vector3::Ones();  ///< box [m]
  double half_length = 0.0;                ///< capsule [m]
  std::optional<double> density;           ///< [kg/m³]; exactly one of density and mass
  std::optional<double> mass;              ///< [kg] per body
  std::string material;                    ///< the name of a material
  Vector3 I_v_S = Vector3::Zero();         ///< initial velocity [m/s]
  Vector3 K_omega = Vector3::Zero();       ///< initial angular velocity, body frame [rad/s]
  bool fixed = false;                      ///< fixed bodies never move
  GeneratorSpec generator;                 ///< where the bodies go
};

/// A static object: a half-space, box, capsule, sphere or triangle mesh fixed in frame I.
struct StaticSpec {
  std::string name;                 ///< for messages and the summary
  collision::Shape shape;           ///< the geometry (a mesh is read when the scene is)
  collision::Placement pose;        ///< where its frame sits in I
  std::string material;             ///< the name of a material
  std::filesystem::path mesh_file;  ///< mesh: the OBJ file, resolved against the scene's folder
  /// The time from which the object is gone [s] (key `until`): a gate that holds the bodies while
  /// they settle and is then taken away. The step that starts at t ≥ until no longer sees it.
  std::optional<double> until;
};

/// The contact law of a pair of materials.
struct ContactSpec {
  std::string a;                 ///< first material
  std::string b;                 ///< second material (may equal a)
  contact::ContactMaterial law;  ///< μ, ε_N, ε_T
};

/// Output of the run (chapter 7's HDF5 + XDMF files).
struct OutputSpec {
  std::filesystem::path
      file;  ///< the HDF5 file (empty: NAME.h5 in the working folder, NAME the scene file's stem)
  std::uint64_t every = 100;  ///< a record every this many steps (0: none but the first and last)
  bool float32 = false;       ///< q and u of the records in single precision
  /// Each record also holds the contacts of the step that led to it (group `contacts`: the two
  /// ids, point, normal, gap and percussions, sorted by key), drawn as lines in the XDMF.
  bool contacts = false;
};

/// Checkpoints of the run.
struct CheckpointSpec {
  std::filesystem::path file;  ///< (empty: NAME.ckpt.h5 in the working folder)
  std::uint64_t every = 0;     ///< a checkpoint every this many steps (0: only at the end)
};

/// Bodies whose centre leaves this box are removed (an outlet): chapter 7's silo discharge.
struct DomainSpec {
  bool enabled = false;  ///< without a domain no body is ever removed
  Region box;            ///< the domain [m]
  /// Axes along which the domain is periodic (key `periodic`, chapter 8): a body leaving through
  /// one side enters through the other, and bodies touch across the boundary; the outlet removes
  /// bodies along the other axes only. A periodic scene runs on chapter 8's parallel engine, also
  /// on one process.
  std::array<bool, 3> periodic{false, false, false};
  /// Whether some axis is periodic.
  bool any_periodic() const { return periodic[0] || periodic[1] || periodic[2]; }
};

/// The radius of the sphere about S that holds a body of a group, at its smallest [m]: the
/// smallest radius its distribution can give (sphere, capsule), or the box's. The scene's
/// active-set tolerance scales the smallest over its groups (StepSettings::tolerance_radius).
double smallest_bounding_radius(const BodyGroup& group);

/// How a run on many processes shares the work (table `[parallel]`, chapter 8); a serial run
/// ignores it.
struct ParallelSpec {
  /// How the domain is cut among the processes: a Cartesian grid (`"grid"`, the default) or a
  /// recursive coordinate bisection (`"bisection"`), each rebalanced by the bodies' weight.
  enum class Partition { grid, bisection };
  Partition partition = Partition::grid;  ///< key `partition`
  int average_every = 1;     ///< average the split bodies' velocities every this many sweeps, ≥ 1
  int rebalance_every = 50;  ///< look at the balance every this many steps (0: never)
  double imbalance = 1.1;    ///< the largest load over the mean that needs no rebalancing, ≥ 1
};

/// Everything a scene file says, checked: every value in range, every material named exists,
/// every pair of materials that can meet has a law.
struct Scene {
  std::filesystem::path file;          ///< where it was read from (for messages and relative paths)
  std::string text;                    ///< the file's text (the output keeps it)
  std::string name;                    ///< the file's stem, e.g. "silo"
  double end_time = 1.0;               ///< [s] > 0
  timestep::StepSettings settings;     ///< Δt, gravity, solver
  std::uint64_t seed = 1;              ///< default seed of the generators
  std::vector<std::string> materials;  ///< names; a material's id is its index
  std::vector<ContactSpec> contacts;   ///< laws per pair
  std::optional<contact::ContactMaterial> default_contact;  ///< the law of every other pair
  std::vector<StaticSpec> statics;                          ///< static geometry
  std::vector<BodyGroup> groups;                            ///< body groups
  DomainSpec domain;                                        ///< outlet
  OutputSpec output;                                        ///< HDF5 output
  CheckpointSpec checkpoint;                                ///< checkpoints
  ParallelSpec parallel;                                    ///< many processes (chapter 8)
  /// The number of steps of the run: round(end_time / Δt).
  std::uint64_t steps() const;
};

/// The most steps a run may have (end_time / Δt): the key end_time and `grbd run --end-time`
/// obey it, and a checkpoint may not count more.
inline constexpr std::uint64_t kMaxSteps = 1'000'000'000'000;

/// Sets `scene.end_time` under the rules of the key [simulation] end_time: a finite time > 0 of
/// at most kMaxSteps steps of Δt. Throws SceneError naming `source` (e.g. "--end-time") and the
/// value otherwise.
void set_end_time(Scene& scene, double end_time, std::string_view source);

/// A time or other real number given as text (a command-line option): a decimal number as in a
/// scene file ("0.5", "2e-3"); throws SceneError naming `source` for anything else (empty text,
/// hexadecimal, "inf", "nan", trailing characters).
double parse_real(std::string_view text, std::string_view source);

/// Reads a scene from TOML text. `file` names it in messages and is the folder that relative
/// mesh paths are resolved against. Throws SceneError for a syntax error, an unknown key (with
/// the closest known key suggested), a value of the wrong type or out of range, a material that
/// is not declared, a pair of materials without a law, and a mesh that cannot be read.
Scene parse_scene(std::string_view text, const std::filesystem::path& file);

/// The largest scene file read (a scene of 10⁵ static objects takes a few MiB).
inline constexpr std::size_t kMaxSceneBytes = std::size_t{64} << 20;

/// Reads the scene file `file` (SceneError also when it cannot be read, is not a regular file or
/// is larger than kMaxSceneBytes).
Scene load_scene(const std::filesystem::path& file);

/// A few lines that say what a scene holds (for `grbd validate`).
std::string summary(const Scene& scene);

/// The known key of a table closest to an unknown one (Levenshtein distance, at most 1/2 of the
/// key's length), or "" when none is close.
std::string closest_key(std::string_view key, const std::vector<std::string_view>& known);

}  // namespace grbd::scene
