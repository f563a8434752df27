#pragma once
/// \file
/// \brief A scene made runnable (chapter 7): the materials, the static geometry, the bodies from
/// the generators (lattice, packing, inflow) and chapter 6's stepper, with the state a checkpoint
/// must keep to continue a run bit for bit.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/materials.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::scene {

/// What a generator has done so far: enough to continue it exactly.
struct GeneratorState {
  std::uint64_t random = 0;   ///< state of its Random
  std::uint64_t created = 0;  ///< bodies it created so far
};

/// Everything the next step depends on (what a checkpoint holds, chapter 7).
struct SimulationState {
  double t = 0.0;                               ///< time [s]
  std::uint64_t steps = 0;                      ///< steps done
  std::uint64_t next_id = 0;                    ///< the global id of the next body created
  std::uint64_t removed = 0;                    ///< bodies removed by the outlet so far
  double removed_mass = 0.0;                    ///< their mass [kg]
  std::vector<timestep::BodyRecord> bodies;     ///< with their states, in the system's order
  std::vector<timestep::ContactKey> warm_keys;  ///< the stepper's warm starts
  std::vector<Vector3> warm_lambda;             ///< their percussions
  std::vector<GeneratorState> generators;       ///< one per body group
  /// The state of the run's Distribution (chapter 8: the processes and the partition's cuts,
  /// which a balance moves), the same on every process; empty for a run without one.
  std::vector<double> distribution;
};

/// A saved state (a checkpoint's) that does not fit the scene it is restored into, or holds a
/// body the scene cannot make. The message names what, not the file: the caller knows the file.
class StateError : public Error {
 public:
  using Error::Error;
};

/// The memory a body takes in a running granular scene [bytes]: the system, the stepper and its
/// contacts (about six per body in a dense packing), as chapter 6's step benchmark measures it
/// (3.4–4.2 KiB per sphere after a step). What a scene asks for is compared with what the process
/// can still take before anything is allocated.
inline constexpr double kBytesPerBody = 4096.0;

/// The step a Simulation takes: chapter 6's MoreauStepper on its own (the serial run), or chapter
/// 8's parallel step around one.
class StepEngine {
 public:
  virtual ~StepEngine() = default;
  /// One step of the bodies (collective in a parallel run).
  virtual timestep::StepReport step() = 0;
  /// The stepper that does the work (its contacts, percussions, warm starts, clock).
  virtual timestep::MoreauStepper& stepper() = 0;
  /// Told when bodies were added or removed between steps (inflow, outlet).
  virtual void bodies_changed() {}
  /// Before a checkpoint (collective): brings the engine into the state that a restart from the
  /// checkpoint starts in, so that the run goes on as the restart will (chapter 8: every body
  /// with the process that owns it, the ghosts rebuilt). The serial engine has nothing to do.
  virtual void settle() {}
};

/// How the processes of a parallel run share a scene (chapter 8), handed to a Simulation by the
/// parallel module; a serial run has none. Every process makes every body a generator makes, in
/// the same order and with the same ids, and keeps those it owns; the inflow sees the bodies of
/// every process near its region; the outlet's counts are summed over the processes.
class Distribution {
 public:
  virtual ~Distribution() = default;
  /// The processes of the run.
  virtual const Communicator& communicator() const = 0;
  /// Whether this process owns a body whose centre is at `centre`.
  virtual bool owns(const Vector3& centre) const = 0;
  /// The engine that steps this process's bodies.
  virtual std::unique_ptr<StepEngine> engine(timestep::BodySystem& system,
                                             const timestep::StaticGeometry& statics,
                                             const timestep::MaterialTable& materials,
                                             const timestep::StepSettings& settings) const = 0;
  /// Gives every body of a restart's `state`, read by each process in slabs, to the process that
  /// owns it, and every warm start to the process that solves its contact (collective).
  virtual void redistribute(SimulationState& state) const = 0;
  /// How often the engine re-cut the domain to even the load so far.
  virtual std::uint64_t rebalances() const = 0;
  /// What a checkpoint keeps of the distribution (SimulationState::distribution), the same on
  /// every process.
  virtual std::vector<double> state() const = 0;
  /// Continues from a checkpoint's state() before the simulation is built: the same cuts when it
  /// was written by as many processes (a restart then steps as the run it continues), else the
  /// scene's own partition. Throws InvalidArgument for a state that does not fit the scene.
  virtual void restore(std::span<const double> state) = 0;
};

/// A runnable scene. Construction generates the initial bodies (list, lattice and packing
/// groups) and checks everything the stepper checks (materials of every pair, supported shape
/// pairs); a scene that cannot run throws SceneError before the first step.
class Simulation {
 public:
  /// Builds the scene and its initial bodies. The simulation keeps its own copy of the scene
  /// (meshes are shared, not copied), so `Simulation sim(load_scene(path));` is safe.
  explicit Simulation(Scene scene);
  /// Builds the scene and continues from `state` instead (restart); throws StateError when the
  /// state does not fit the scene: another number of groups, t and steps that do not agree with
  /// Δt, a material it does not have, a body that no group makes (shape, material, size, mass and
  /// inertia from its density or mass), or a body the system refuses.
  Simulation(Scene scene, const SimulationState& state);
  /// The same on one process of a parallel run: the system holds the bodies `distribution` says
  /// this process owns (and, while stepping, ghosts of its neighbours' bodies), and step() is
  /// collective. `distribution` must outlive the simulation; `state` may be null (a fresh run).
  /// A scene with periodic axes needs one, also on one process (the other constructors throw
  /// SceneError for it).
  Simulation(Scene scene, const SimulationState* state, const Distribution& distribution);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// One step: inflow generators add their bodies, the stepper steps, the outlet removes the
  /// bodies that left the domain.
  timestep::StepReport step();
  /// True when the scene's number of steps is done.
  bool finished() const { return stepper_->steps() >= scene_.steps(); }
  /// Whether this is one process of a parallel run (its system holds only its own bodies).
  bool distributed() const { return distribution_ != nullptr; }

  /// Everything the next step depends on (in a parallel run: this process's bodies and warm
  /// starts, and the counts of the whole run).
  SimulationState save() const;
  /// Before a checkpoint: StepEngine::settle() (collective in a parallel run).
  void settle() { engine_->settle(); }

  /// \name Parts
  ///@{
  const Scene& scene() const { return scene_; }                            ///< the scene
  const timestep::BodySystem& system() const { return system_; }           ///< the bodies
  const timestep::StaticGeometry& statics() const { return statics_; }     ///< static geometry
  const timestep::MaterialTable& materials() const { return materials_; }  ///< materials
  timestep::MoreauStepper& stepper() { return *stepper_; }                 ///< the stepper
  const timestep::MoreauStepper& stepper() const { return *stepper_; }     ///< the stepper
  const Distribution* distribution() const { return distribution_; }       ///< null: serial
  ///@}
  /// Bodies created since the caller last emptied this list (their records, in the state they
  /// were created with), for the output.
  std::vector<timestep::BodyRecord>& created() { return created_; }
  /// Bodies created so far (all groups) and removed by the outlet.
  std::uint64_t bodies_created() const { return next_id_; }
  std::uint64_t bodies_removed() const { return removed_; }  ///< by the outlet
  /// The mass the outlet removed so far [kg]: its rate is a discharge's mass flow.
  double mass_removed() const { return removed_mass_; }
  /// Bodies an inflow generator owed but could not place (the region was full) at the last step.
  std::uint64_t inflow_backlog() const { return backlog_; }

 private:
  Simulation(Scene scene, const SimulationState* state, const Distribution* distribution);
  void restore(const SimulationState& state);
  void build_static();
  void generate_initial();
  void add_body(timestep::BodyRecord record, const body::State& state);
  void inflow();
  void outlet();
  void remove_expired_statics();
  void gather_near(std::vector<Vector4>& near);
  void check_shapes() const;
  timestep::BodyRecord make_body(std::size_t group, Random& random);
  timestep::BodyRecord body_for(const BodyGroup& group, double radius) const;
  void require_invertible_constants() const;
  void require_memory(std::uint64_t bodies, std::size_t group) const;
  void require_from_scene(const timestep::BodyRecord& body) const;
  // The deepest overlap of a body (its constants and a state) with the static geometry: the gap
  // (< 0 when they overlap, +∞ without static objects) and the static object's index.
  std::pair<double, std::size_t> static_gap(const collision::Shape& shape, const body::State& x);
  struct Scratch;

  const Scene scene_;
  timestep::MaterialTable materials_;
  timestep::StaticGeometry statics_;
  timestep::BodySystem system_;
  const Distribution* distribution_ = nullptr;
  std::unique_ptr<StepEngine> engine_;
  timestep::MoreauStepper* stepper_ = nullptr;
  std::vector<timestep::BodyRecord> created_;
  std::vector<GeneratorState> generators_;
  std::uint64_t next_id_ = 0;
  std::uint64_t removed_ = 0;
  double removed_mass_ = 0.0;
  std::uint64_t backlog_ = 0;
  std::vector<std::size_t> leaving_;
  std::vector<Vector3> image_shifts_;  // of a body's periodic images, the body itself first
  std::size_t pending_removals_ = 0;   // static objects with an `until` still present
  std::unique_ptr<Scratch> scratch_;
};

/// The radius of the sphere about S that holds a body of a group, at its largest [m].
double largest_bounding_radius(const BodyGroup& group);

}  // namespace grbd::scene
