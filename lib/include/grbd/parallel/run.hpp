#pragma once
/// \file
/// \brief `mpirun -np P grbd run scene.toml` (chapter 8): a scene's run on the processes of a
/// communicator — the same generators, output, checkpoints and restart as chapter 7's serial run,
/// the bodies shared by a partition of the domain (a Cartesian grid or a bisection tree) and
/// stepped by the ParallelStepper.

#include <memory>

#include "grbd/core/communicator.hpp"
#include "grbd/io/run.hpp"
#include "grbd/parallel/partition.hpp"
#include "grbd/parallel/stepper.hpp"
#include "grbd/scene/simulation.hpp"

namespace grbd::parallel {

/// The box a scene's run is cut into subdomains over: the outlet's box when the scene has one,
/// else the box in which the output draws the static half-spaces (the regions and positions of
/// the body groups and the finite static objects, enlarged by 5 %, io::StaticSurface::bounds).
/// Bodies outside it belong to the nearest subdomain.
Box decomposition_box(const scene::Scene& scene);

/// A scene shared by the processes of a communicator: a partition of decomposition_box() into one
/// subdomain per process — by the scene's `[parallel] partition`, a CartesianGrid with grid_dims()
/// subdomains or the even BisectionTree — each process owning the bodies whose centre lies in
/// its own, and
/// a ParallelStepper for each, with the averaging and balance of the scene's `[parallel]` table
/// (by default: average every sweep, look at the balance every 50 steps and rebalance when a
/// process carries more than 1.1 times the mean load). Its step settings are the scene's,
/// with a skin of half the scene's tolerance radius when the scene gives none (the ghosts and the
/// candidate pairs are rebuilt when a body has moved a quarter of the smallest radius).
class SceneDecomposition final : public scene::Distribution {
 public:
  /// The partition for `comm.size()` processes over decomposition_box(scene); throws
  /// InvalidArgument when that box is empty or not finite.
  SceneDecomposition(const Communicator& comm, const scene::Scene& scene);
  /// The processes of the run.
  const Communicator& communicator() const override { return comm_; }
  /// Whether the partition gives a body centred at `centre` to this process (the engine's
  /// partition once there is one: it may have been rebalanced since).
  bool owns(const Vector3& centre) const override { return owner(centre) == comm_.rank(); }
  /// The process that owns a body with this centre (the engine's partition once there is one).
  int owner(const Vector3& centre) const {
    return (engine_ != nullptr ? engine_->partition() : *partition_).owner_of(centre);
  }
  /// A ParallelStepper over the partition (the scene's settings, with a skin of half the tolerance
  /// radius when they give none).
  std::unique_ptr<scene::StepEngine> engine(timestep::BodySystem& system,
                                            const timestep::StaticGeometry& statics,
                                            const timestep::MaterialTable& materials,
                                            const timestep::StepSettings& settings) const override;
  /// How often the last engine made rebalanced its partition (0 before there is one).
  std::uint64_t rebalances() const override {
    return engine_ != nullptr ? engine_->rebalances() : 0;
  }
  /// After a restart read in slabs (io::read_checkpoint): every body goes to the process that
  /// owns its centre, every warm start to the one that solves its contact (solves_contact()), in
  /// three exchanges among all processes, each of O(N/P) rows (collective).
  void redistribute(scene::SimulationState& state) const override;
  /// The number of processes, the partition's kind (0: grid, 1: bisection tree) and its cuts
  /// (Partition::cuts: the engine's, which a balance may have moved).
  std::vector<double> state() const override;
  /// Takes the cuts of a state() written by as many processes over a partition of the same kind;
  /// any other state leaves the scene's partition (a restart on another number of processes
  /// balances anew).
  void restore(std::span<const double> state) override;
  /// The partition the run starts from.
  const Partition& partition() const { return *partition_; }
  /// The parallel step's settings (largest bounding radius of the scene's groups).
  const ParallelSettings& settings() const { return parallel_; }

 private:
  // decomposition_box() once: it tessellates the static geometry when the scene has no outlet.
  SceneDecomposition(const Communicator& comm, const scene::Scene& scene, const Box& box);
  const Communicator& comm_;
  std::unique_ptr<Partition> partition_;
  ParallelSettings parallel_;
  mutable const ParallelStepper* engine_ = nullptr;  // the last engine made
};

/// Whether a run of `scene` on `comm` needs a SceneDecomposition: on more than one process, or
/// with a periodic axis (its images are ghosts, also on one process). Otherwise the run steps with
/// chapter 6's stepper alone.
bool needs_decomposition(const scene::Scene& scene, const Communicator& comm);

/// `grbd run` on every process of `comm` (collective): io::run(), the one run loop, with a
/// SceneDecomposition when needs_decomposition() — the same checks, records, checkpoints and
/// restart, the records with their bodies in ascending id and contacts by key, checkpoints with
/// the bodies in ascending id and the warm starts by key, so that any number of processes can
/// continue from them. Every error is agreed: one process's is thrown on every process.
io::RunResult run(const scene::Scene& scene, const io::RunOptions& options,
                  const Communicator& comm);

}  // namespace grbd::parallel
