/// \file
/// \brief Chapter 6's step on many processes: ghosts, one process per contact, mass splitting, a
/// global verdict and report.

#include "grbd/parallel/stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::parallel {

ParallelStepper::ParallelStepper(const Communicator& comm, const Partition& partition,
                                 timestep::BodySystem& system,
                                 const timestep::StaticGeometry& statics,
                                 const timestep::MaterialTable& materials,
                                 timestep::StepSettings settings, ParallelSettings parallel)
    : comm_(comm),
      system_(system),
      skin_(settings.skin),
      average_every_(parallel.average_every),
      max_iterations_(settings.solver.max_iterations),
      reorder_interval_(settings.reorder_interval),
      rebalance_every_(parallel.rebalance_every),
      imbalance_(parallel.imbalance),
      margin_(ghost_margin(settings)),
      max_radius_(parallel.max_radius),
      averages_(settings.method == contact::Method::sor),
      partition_(partition.clone()) {
  exchange_.emplace(comm, *partition_, margin_, max_radius_);
  if (parallel.rebalance_every < 0 || !(parallel.imbalance >= 1.0)) {
    throw InvalidArgument(
        "ParallelStepper: expected rebalance_every >= 0 and imbalance >= 1, "
        "found " +
        std::to_string(parallel.rebalance_every) + " and " + std::to_string(parallel.imbalance));
  }
  if (parallel.average_every < 1) {
    throw InvalidArgument("ParallelStepper: expected average_every >= 1, found " +
                          std::to_string(parallel.average_every));
  }
  if (!(settings.tolerance_radius > 0.0)) {
    throw InvalidArgument(
        "ParallelStepper: expected the tolerance radius of the scene "
        "(StepSettings::tolerance_radius > 0): the active set of a parallel run "
        "must not depend on the bodies a process holds");
  }
  timestep::StepHooks hooks;
  hooks.after_detection =
      [this](const timestep::BodySystem& s, std::vector<timestep::DetectedContact>& contacts,
             std::vector<timestep::ContactKey>& keys) { select_contacts(s, contacts, keys); };
  hooks.after_assembly = [this](contact::CompactProblem& problem, contact::ContactSolution&) {
    split_masses(problem);
  };
  // Split bodies need SOR (their copies' velocities are averaged between its sweeps). On one
  // process every ghost is a periodic image of a body owned here and is folded onto it, so any
  // method runs there.
  if (averages_) {
    hooks.solver.velocities_between_sweeps = [this](int k, std::span<Vector6> u) {
      sweep_ = k;
      if (k % average_every_ == 0 || k == max_iterations_) average_split_velocities(u);
    };
  } else if (comm.size() > 1) {
    throw InvalidArgument(
        "ParallelStepper: method " + std::string(contact::method_name(settings.method)) +
        " on " + std::to_string(comm.size()) +
        " processes: the bodies split between processes need method SOR, whose sweeps their "
        "copies' velocities are averaged between (one process runs any method)");
  }
  hooks.solver.global_status = [this](contact::IterationStatus local) {
    // The verdict is taken after the averaged sweeps only, where the copies of every split body
    // agree: one reduction every average_every sweeps (and at the last sweep the solver may do),
    // the same sweeps on every process. In between every process goes on.
    if (sweep_ % average_every_ != 0 && sweep_ != max_iterations_) {
      return contact::IterationStatus::running;
    }
    double status[1] = {static_cast<double>(local)};
    comm_.max(status);
    return static_cast<contact::IterationStatus>(static_cast<int>(status[0]));
  };
  hooks.solver.global_norm_c = [this](double norm_c) {
    double squares[1] = {norm_c * norm_c};
    comm_.sum(squares);
    return contact::GlobalNorm{std::sqrt(squares[0]), comm_.size()};
  };
  hooks.reduce_report = [this](timestep::StepReport& report) { reduce(report); };
  stepper_ = std::make_unique<timestep::MoreauStepper>(system, statics, materials, settings,
                                                       std::move(hooks));
}

ParallelStepper::~ParallelStepper() = default;

void ParallelStepper::rebuild() {
  exchange_->migrate(system_, stepper_->warm_starts());
  // Between migration and borders the system holds only its own bodies: the place where the
  // serial engine's Morton reordering (StepSettings::reorder_interval) fits, when it is due.
  stepper_->reorder_if_due();
  exchange_->borders(system_);
  reference_.resize(system_.owned_count());
  for (std::size_t i = 0; i < reference_.size(); ++i) {
    reference_[i] = system_.states()[i].q.head<3>();
  }
  ++rebuilds_;
  changed_ = false;
}

void ParallelStepper::settle() { rebuild(); }

// [parallel step]
timestep::StepReport ParallelStepper::step() {
  // A reordering moves rows under the ghosts' bookkeeping: it comes with a rebuild.
  if (reorder_due() || rebuild_due()) {
    rebuild();
  } else {
    exchange_->forward(system_);
  }
  const timestep::StepReport report = stepper_->step();
  rebalance_if_due();
  return report;
}
// [parallel step]

// [rebalance]
// After every rebalance_every-th step (counted from the start of the run, so that a restart looks
// at the same steps), with the weights of that step's contacts: when the most loaded process
// carries more than imbalance times the mean weight (1 per body, 1 per contact it took part in),
// the partition is rebalanced (Partition::rebalanced: the balanced grid, or the balanced bisection
// tree, of the bodies), and every body moves to its new owner (an exchange among all processes,
// which a rebalance may send a body to), with its warm starts; the next step rebuilds the ghosts.
// A checkpoint written after this step keeps the new cuts.
void ParallelStepper::rebalance_if_due() {
  const std::uint64_t step = stepper_->steps();
  if (rebalance_every_ == 0 || step % static_cast<std::uint64_t>(rebalance_every_) != 0) return;
  const std::size_t n = system_.owned_count();
  std::vector<double> weights(n, 1.0);
  for (const timestep::DetectedContact& c : stepper_->contacts()) {
    for (const int row : {c.row_a, c.row_b}) {
      if (row >= 0 && static_cast<std::size_t>(row) < n)
        weights[static_cast<std::size_t>(row)] += 1.0;
    }
  }
  // Each process's load as the partition assigns the bodies, not as they happen to lie now (a
  // body that crossed a cut since the last rebuild still lives with its old owner): the same
  // verdict whenever the ghosts were last rebuilt, so that a restart, which rebuilds at once,
  // balances as the run it continues. The weights are whole numbers: their sums are exact.
  std::vector<double> loads(static_cast<std::size_t>(comm_.size()), 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    loads[static_cast<std::size_t>(partition_->owner_of(system_.states()[i].q.head<3>()))] +=
        weights[i];
  }
  comm_.sum(loads);
  double total = 0.0, largest = 0.0;
  for (const double load : loads) {
    total += load;
    largest = std::max(largest, load);
  }
  if (!(largest > imbalance_ * total / comm_.size())) return;
  std::vector<Vector3> centres(n);
  for (std::size_t i = 0; i < n; ++i) centres[i] = system_.states()[i].q.head<3>();
  exchange_.reset();  // it refers to the partition replaced here
  partition_ = partition_->rebalanced(comm_, centres, weights);
  // Every process is a neighbour of every other for this one migration: a reach beyond the domain.
  const double everywhere = 2.0 * partition_->domain().diagonal().norm() + margin_;
  BodyExchange all(comm_, *partition_, margin_, everywhere);
  all.migrate(system_, stepper_->warm_starts());
  exchange_.emplace(comm_, *partition_, margin_, max_radius_);
  changed_ = true;  // the ghosts went with the migration: rebuild them before the next step
  ++rebalances_;
}
// [rebalance]

// The serial engine's Morton reordering is due before this step (the same on every process).
bool ParallelStepper::reorder_due() const {
  const auto interval = static_cast<std::uint64_t>(std::max(0, reorder_interval_));
  const std::uint64_t step = stepper_->steps();
  return interval > 0 && step > 0 && step % interval == 0;
}

// Some body of some process has moved more than half the skin since the last rebuild (the rule of
// the candidate list).
bool ParallelStepper::rebuild_due() const {
  if (rebuilds_ == 0) return true;
  // Bodies added or removed here: the rows moved, and every process must rebuild with this one.
  double largest = changed_ ? std::numeric_limits<double>::infinity() : 0.0;
  for (std::size_t i = 0; !changed_ && i < reference_.size(); ++i) {
    largest = std::max(largest, (system_.states()[i].q.head<3>() - reference_[i]).squaredNorm());
  }
  std::vector<double> global{largest};
  comm_.max(global);
  return global[0] > timestep::rebuild_distance_squared(skin_);
}

// [select contacts]
void ParallelStepper::select_contacts(const timestep::BodySystem& system,
                                      std::vector<timestep::DetectedContact>& contacts,
                                      std::vector<timestep::ContactKey>& keys) {
  // Each contact on one process: the owner of its side a (of side b when a is a static object).
  timestep::keep_contacts_if(contacts, keys, [&](const timestep::DetectedContact& c) {
    return solves_contact(system, c);
  });
  // A ghost that is a periodic image of a body owned here is that body, moved by a period: its
  // side of the contact is folded onto the owner (split_masses), and the body is not split. The
  // copies of each body: its owner's, and each ghost of another process's body that takes part
  // in a kept contact.
  const std::size_t n = system.size();
  copies_.assign(n, 0.0);
  folds_.clear();
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const timestep::DetectedContact& c = contacts[k];
    for (const int side : {0, 1}) {
      const int row = side == 0 ? c.row_a : c.row_b;
      if (row < 0 || system.owned(static_cast<std::size_t>(row)) ||
          !system.dynamic(static_cast<std::size_t>(row))) {
        continue;
      }
      const std::size_t owner = system.index_of(system.ids()[static_cast<std::size_t>(row)]);
      const int other = side == 0 ? c.row_b : c.row_a;
      if (owner == timestep::BodySystem::npos) {
        copies_[static_cast<std::size_t>(row)] = 1.0;  // another process's body
      } else if (static_cast<int>(owner) != other) {
        folds_.push_back({k, side, static_cast<collision::BodyIndex>(owner)});
      } else if (averages_) {
        copies_[static_cast<std::size_t>(row)] = 1.0;  // a body touching its own image: split
      } else {
        throw Error("ParallelStepper: step " + std::to_string(stepper_->steps() + 1) + ": body " +
                    std::to_string(system.ids()[static_cast<std::size_t>(row)]) +
                    " touches its own periodic image, which only SOR's mass splitting solves: "
                    "make the periods longer than a body, or use method = \"sor\"");
      }
    }
  }
  active_.assign(copies_.begin(), copies_.end());
  exchange_->reverse_add(system, copies_, 1);
  split_owned_ = 0;
  for (std::size_t i = 0; i < system.owned_count(); ++i) {
    copies_[i] += 1.0;
    if (copies_[i] > 1.0) ++split_owned_;
  }
  exchange_->forward_values(system, copies_, 1);
  // The rows the averaging exchanges: split bodies' owners and copies, flagged alike on both sides.
  split_.assign(n, 0);
  split_rows_.clear();
  for (std::size_t r = 0; r < n; ++r) {
    if (copies_[r] > 1.0) {
      split_[r] = 1;
      split_rows_.push_back(r);
    }
  }
  if (velocities_.size() < 6 * n) velocities_.resize(6 * n);
  any_split_ = comm_.any(split_owned_ > 0);
}
// [select contacts]

// [split masses]
void ParallelStepper::split_masses(contact::CompactProblem& problem) {
  // A folded side: the owner's index, the lever arm from the image's centre as assembled (the
  // image is the owner translated, with its orientation and velocity).
  for (const Fold& f : folds_) {
    contact::CompactContact& cc = problem.contacts[f.contact];
    (f.side == 0 ? cc.body_a : cc.body_b) = f.owner;
  }
  // A copy of a body with m copies carries the mass M/m: its inverse mass is m M⁻¹. Its load is
  // scaled alike, so its free velocity u + Δt M⁻¹ h does not change.
  for (std::size_t i = 0; i < copies_.size(); ++i) {
    if (copies_[i] > 1.0) {
      problem.M_inv[i].inv_m *= copies_[i];
      problem.M_inv[i].I_Theta_inv *= copies_[i];
    }
  }
}
// [split masses]

// [average]
void ParallelStepper::average_split_velocities(std::span<Vector6> u) {
  if (!any_split_) return;  // the same decision on every process: no exchange at all
  const auto start = std::chrono::steady_clock::now();
  // Only the split rows: the owners' sums start at zero, each copy sends its velocity if it took
  // part in a kept contact (zero if not), the owner forms the mean and sends it back.
  const std::size_t owned = system_.owned_count();
  for (const std::size_t r : split_rows_) {
    auto v = Eigen::Map<Vector6>(velocities_.data() + 6 * r);
    if (r < owned || active_[r] == 0.0) {
      v.setZero();
    } else {
      v = u[r];
    }
  }
  exchange_->reverse_add(system_, velocities_, 6, split_);
  // The copies share one mass M/m each: the mass-weighted mean is the plain mean, for the
  // angular velocity too (the same orientation, so the same world-frame inertia).
  for (const std::size_t r : split_rows_) {
    if (r >= owned) break;  // owned rows come first
    const Vector6 mean =
        (u[r] + Eigen::Map<const Vector6>(velocities_.data() + 6 * r)) / copies_[r];
    u[r] = mean;
    Eigen::Map<Vector6>(velocities_.data() + 6 * r) = mean;
  }
  exchange_->forward_values(system_, velocities_, 6, split_);
  for (const std::size_t r : split_rows_) {
    if (r >= owned) u[r] = Eigen::Map<const Vector6>(velocities_.data() + 6 * r);
  }
  averaging_seconds_ +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
// [average]

void ParallelStepper::reduce(timestep::StepReport& report) const {
  // The mean penetration as a sum over this process's contacts, each contact on one process.
  std::vector<double> sums{static_cast<double>(report.contacts),
                           static_cast<double>(report.warm_started), report.kinetic_energy,
                           report.potential_energy,
                           report.mean_penetration * static_cast<double>(report.contacts)};
  // The overlaps' histogram: counts, exact in doubles below 2⁵³.
  const auto counts = report.overlaps.counts();
  sums.insert(sums.end(), counts.begin(), counts.end());
  comm_.sum(sums);
  for (std::size_t b = 0; b < counts.size(); ++b) {
    report.overlaps.counts()[b] = static_cast<std::uint64_t>(sums[5 + b]);
  }
  std::vector<double> maxima{static_cast<double>(report.iterations), report.residual,
                             report.max_penetration, report.converged ? 0.0 : 1.0};
  comm_.max(maxima);
  report.contacts = static_cast<std::size_t>(sums[0]);
  report.warm_started = static_cast<std::size_t>(sums[1]);
  report.kinetic_energy = sums[2];
  report.potential_energy = sums[3];
  report.mean_penetration = report.contacts > 0 ? sums[4] / static_cast<double>(report.contacts) : 0.0;
  // Without a contact on any process the solve had nothing to do; the processes still swept once
  // together (each must learn that the others have no contacts): the serial count is 0.
  report.iterations = report.contacts == 0 ? 0 : static_cast<int>(maxima[0]);
  report.residual = maxima[1];
  report.max_penetration = maxima[2];
  report.converged = maxima[3] == 0.0;
}

}  // namespace grbd::parallel
