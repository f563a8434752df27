#pragma once
/// \file
/// \brief Chapter 6's step on many processes (chapter 8): every process steps its own bodies with
/// a MoreauStepper whose hooks do the parallel work — ghosts refreshed before the step, each
/// contact kept by one process, split bodies by mass splitting, the solver's verdict and the
/// report made global.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/parallel/decomposition.hpp"
#include "grbd/parallel/exchange.hpp"
#include "grbd/scene/simulation.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::parallel {

/// What the parallel step adds to StepSettings.
struct ParallelSettings {
  /// The largest bounding radius a body of the run can have [m] > 0 (from the scene): ghosts reach
  /// r + r_max + margin.
  double max_radius = 0.0;
  /// Average the split bodies' velocities after every this many sweeps (≥ 1). Averaging less often
  /// saves messages and lets each process's sweeps go further on their own, at the price of copies
  /// that disagree in between; the solver stops only after a sweep that was averaged, and the last
  /// sweep it may do (max_iterations) is always averaged.
  int average_every = 1;
  /// Look at the balance of the processes' work after every step whose number is a multiple of
  /// this (0: never); when the most loaded process has more than `imbalance` times the mean
  /// weight (a body weighs 1 plus its contacts of that step), the partition is replaced by its
  /// Partition::rebalanced() for the bodies (a balanced_grid(), or a BisectionTree::balanced()
  /// tree), every body moves to its new owner and the next step rebuilds the ghosts. The steps
  /// are counted from the start of the run, so that a restart from a checkpoint that kept the cuts
  /// (scene::Distribution::state) balances at the same steps.
  int rebalance_every = 0;
  double imbalance = 1.1;  ///< the largest load over the mean that needs no rebalancing, ≥ 1
};

/// Moreau's step for the bodies of this process, in lock step with the other processes of the
/// communicator. Construction and step() are collective.
///
/// Before each step the ghosts are refreshed (BodyExchange::forward), or rebuilt (migrate, then
/// borders) when some body of any process has moved more than half the skin
/// (StepSettings::skin; 0 rebuilds at every step). In the step:
/// - after detection, a contact is kept only by the process that owns its side a (a static side a:
///   side b), so that each contact is solved exactly once;
/// - a ghost that is a periodic image of a body owned by the same process is that body, translated
///   by a period: its side of a kept contact is folded onto the owner (the contact's body index
///   becomes the owner's, the lever arm stays the one from the image's centre), so that one
///   process, periodic or not, solves the serial problem — with any method — and P processes
///   split only the bodies that other processes touch;
/// - a body whose ghost copies take part in kept contacts on other processes is split: each of its
///   m copies (the owner's and the active ghosts) carries the mass M/m, and after every sweep the
///   copies' velocities are replaced by their mean, the velocity all copies share at the solution
///   (Tonge, Benevolenski, Voroshilov 2012);
/// - the solver stops when every process has converged, a verdict taken together (one reduction)
///   after each averaged sweep only, and the report sums contacts and
///   energies over the processes (in rank order) and takes the largest residual, penetration and
///   iteration count.
/// Every reorder_interval steps (StepSettings) the ghosts are rebuilt and, between migration and
/// borders, each process reorders its own bodies along the Morton curve, as the serial engine does.
/// With one process and no periodic axis there are no ghosts, and the step is the serial step.
class ParallelStepper final : public scene::StepEngine {
 public:
  /// Throws InvalidArgument when settings.tolerance_radius is 0 (the active set of a parallel run
  /// must not depend on the bodies a process holds: take it from the scene), when max_radius is not
  /// positive, or when the partition does not fit the communicator. The stepper keeps its own copy
  /// of the partition.
  ParallelStepper(const Communicator& comm, const Partition& partition,
                  timestep::BodySystem& system, const timestep::StaticGeometry& statics,
                  const timestep::MaterialTable& materials, timestep::StepSettings settings,
                  ParallelSettings parallel);
  ~ParallelStepper() override;
  ParallelStepper(const ParallelStepper&) = delete;
  ParallelStepper& operator=(const ParallelStepper&) = delete;

  /// One step of every process; the report is the global one (the same on every process).
  timestep::StepReport step() override;

  /// The serial stepper underneath (its contacts, percussions and warm starts are this process's).
  const timestep::MoreauStepper& stepper() const { return *stepper_; }
  timestep::MoreauStepper& stepper() override { return *stepper_; }  ///< the same
  /// Bodies were added or removed since the last step: the next step rebuilds the ghosts.
  void bodies_changed() override { changed_ = true; }
  /// Before a checkpoint: every body moves to the process that owns it and the ghosts are rebuilt
  /// (migrate, borders), as a restart from the checkpoint starts — so that the run goes on as the
  /// restart will, bit for bit, on as many processes.
  void settle() override;
  /// How often the ghosts were rebuilt.
  std::uint64_t rebuilds() const { return rebuilds_; }
  /// Wall time spent so far averaging the split bodies' velocities (with its exchanges) [s].
  double averaging_seconds() const { return averaging_seconds_; }
  /// How often the partition was rebalanced.
  std::uint64_t rebalances() const { return rebalances_; }
  /// The partition in use (the one given, or the last balanced one).
  const Partition& partition() const { return *partition_; }
  /// Bodies owned here that were split in the last step (their copies elsewhere had contacts).
  std::size_t split_bodies() const { return split_owned_; }

 private:
  bool rebuild_due() const;
  bool reorder_due() const;
  void rebuild();  // migrate, borders, and the reference positions of the skin's rule
  void rebalance_if_due();
  void select_contacts(const timestep::BodySystem& system,
                       std::vector<timestep::DetectedContact>& contacts,
                       std::vector<timestep::ContactKey>& keys);
  void split_masses(contact::CompactProblem& problem);
  void average_split_velocities(std::span<Vector6> u);
  void reduce(timestep::StepReport& report) const;

  const Communicator& comm_;
  timestep::BodySystem& system_;
  double skin_;
  int average_every_;
  int max_iterations_;
  int reorder_interval_;  // StepSettings::reorder_interval: Morton reordering at rebuilds
  int sweep_ = 0;  // sweeps of the current solve (velocities_between_sweeps' k)
  int rebalance_every_;
  double imbalance_;
  double margin_;      // of the ghosts: contact margin + skin [m]
  double max_radius_;  // the largest bounding radius of the run [m]
  bool averages_;      // SOR: split bodies' velocities are averaged between sweeps
  std::unique_ptr<Partition> partition_;
  std::optional<BodyExchange> exchange_;  // over *partition_
  std::unique_ptr<timestep::MoreauStepper> stepper_;
  std::vector<Vector3> reference_;       // owned centres at the last rebuild
  std::vector<double> copies_;           // per row: the number of copies of its body (1: not split)
  std::vector<double> active_;           // per row: 1 for a ghost in a kept contact
  std::vector<double> velocities_;       // per row: 6 doubles for the averaging
  std::vector<std::uint8_t> split_;      // per row: 1 for a split body's row (owner or copy)
  std::vector<std::size_t> split_rows_;  // those rows, ascending
  /// A side of a kept contact that is a periodic image of a body owned here, folded onto it.
  struct Fold {
    std::size_t contact;           // index among the kept contacts
    int side;                      // 0: a, 1: b
    collision::BodyIndex owner;    // the owner's row
  };
  std::vector<Fold> folds_;
  std::uint64_t rebuilds_ = 0;
  std::uint64_t rebalances_ = 0;
  double averaging_seconds_ = 0.0;
  std::size_t split_owned_ = 0;
  bool any_split_ = false;
  bool changed_ = false;  // bodies added or removed here since the last rebuild
};

}  // namespace grbd::parallel
