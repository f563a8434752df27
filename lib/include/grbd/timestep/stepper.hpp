#pragma once
/// \file
/// \brief Moreau's midpoint time-stepping scheme for a system of bodies (chapter 6; Moreau 1988,
/// Jean 1999): half step to the midpoint, collision detection there, the contact problem in
/// percussions with Newton's impact law and a warm start, the end-of-step velocities and the
/// second half step.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "grbd/collision/contact.hpp"
#include "grbd/contact/compact.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/contacts.hpp"
#include "grbd/timestep/materials.hpp"
#include "grbd/timestep/overlaps.hpp"

namespace grbd::timestep {

/// What a step does when the contact solver stops at max_iterations without meeting its
/// tolerance. Divergence (a non-finite iterate) always throws: a NaN is never carried on.
enum class NonConvergence {
  count,  ///< count it in the report and the stepper's total, and go on
  warn,   ///< as count, and print one line to stderr
  stop,   ///< throw grbd::Error naming the step, time, iterations and residual
};

/// The farthest a dynamic body's centre may be from the origin after a step, in its bounding
/// radii: beyond it the spacing of the doubles exceeds 2·10⁻⁴ of its radius, contact geometry is
/// noise, and MoreauStepper::step() reports a blow-up.
inline constexpr double kFarthest = 1e12;

/// How the two half steps move the orientation.
enum class OrientationUpdate {
  exponential_map,    ///< p ← p exp_S3(Δt/4 ω): stays on |p| = 1 (half_step())
  add_and_normalize,  ///< p ← (p + Δt/4 p∘(0, ω))/|…| (the lecture's and GRSFramework's variant)
};

/// Settings of the stepper; MoreauStepper refuses (InvalidArgument) values outside their ranges.
struct StepSettings {
  double dt = 1e-4;                          ///< time step Δt [s] > 0
  Vector3 I_g = Vector3(0.0, 0.0, -9.81);    ///< gravity in frame I [m/s²], any direction
  contact::Method method = contact::Method::sor;  ///< the contact solver
  contact::SolverOptions solver;             ///< its options
  bool warm_start = true;                    ///< start each solve from the last step's percussions
  /// Reorder the bodies along the Morton curve every this many steps (0: never): the driver
  /// does it between steps with MoreauStepper::reorder_if_due().
  int reorder_interval = 0;
  NonConvergence on_non_convergence = NonConvergence::count;  ///< see NonConvergence
  OrientationUpdate orientation_update = OrientationUpdate::exponential_map;  ///< half steps
  /// A contact is active when g_N(q_M) ≤ contact_tolerance × tolerance_radius: Moreau's
  /// g_N ≤ 0 made robust against round-off, which otherwise opens the corners of a box resting
  /// on a face by 10⁻¹⁷ m and lets it rock. ≥ 0 and finite.
  double contact_tolerance = 1e-9;
  /// The length that contact_tolerance scales [m], ≥ 0 and finite. A scene sets the smallest
  /// bounding radius that any of its body groups can produce, so that the active set does not
  /// depend on which bodies are present (an inflow, an outlet) or on which of them a process
  /// holds. 0: the smallest bounding radius among the bodies when the stepper first sees any,
  /// kept from then on.
  double tolerance_radius = 0.0;
  /// Skin of detection's candidate list of sphere pairs [m], ≥ 0 and finite (0: none, the cell
  /// grid at every step): the list is rebuilt only when a sphere has moved more than half of it
  /// (ContactDetector::set_skin), with exactly the contacts of detection from scratch.
  double skin = 0.0;
  /// Penetration drift correction β ∈ [0, 1] (0: off, the default): after the step, each active
  /// contact with g_N(q_M) < 0 pushes its bodies apart by β|g_N| along the normal (positions
  /// only, velocities untouched), shared by inverse mass and divided among the contacts of a body.
  double drift_correction = 0.0;
  /// The gap-aware normal law (chapter 6, \ref ch06_gap_law): the fraction β_g ∈ [0, 1] of a
  /// midpoint overlap that the step removes through the contact's velocity (0: off, Moreau's law).
  /// A contact with g_N(q_M) < 0 must leave the step separating at least at the recovery speed
  /// v_R = min(β_g · 2|g_N(q_M)|/Δt, max_recovery_speed): γ_N,E ≥ max(−ε_N γ_N,S, v_R). With
  /// β_g = 1 and no cap, a lone overlap is gone at the end of the step, q_E = q_M + Δt/2 u_E.
  double overlap_recovery = 0.0;
  /// The largest recovery speed v_R [m/s], > 0 (may be +∞): it bounds the kinetic energy the law
  /// can give a contact, ½ m v_R², and the height a resting body hops, v_R²/(2|g|).
  double max_recovery_speed = std::numeric_limits<double>::infinity();
  /// The look-ahead of the gap-aware law (chapter 6, \ref ch06_gap_law), a length in units of
  /// tolerance_radius, ≥ 0 and finite (0: off): contacts whose gap at the midpoint is at most
  /// look_ahead × tolerance_radius are active, and one with a positive gap g_N(q_M) may approach
  /// by that gap until the next step's midpoint and no further, γ_N,E ≥ −g_N(q_M)/Δt (Stewart and
  /// Trinkle 1996), without restitution: an impact then starts at the next midpoint with the
  /// bodies touching instead of overlapping by up to |γ_N| Δt. Inelastic pairs only (ε_N = 0): a
  /// pair with restitution must hit to rebound, so it keeps Moreau's law and its active set.
  double look_ahead = 0.0;
  /// The reach of the look-ahead for approaching pairs, in units of tolerance_radius, finite and
  /// 0 (none: look_ahead alone) or ≥ look_ahead (chapter 6, \ref ch06_gap_law): a contact of an
  /// inelastic pair whose gap at the midpoint lies beyond look_ahead but within this reach is
  /// active when the free velocities would close it to the look-ahead by the next midpoint,
  /// g_N(q_M) + Δt γ_N,free ≤ look_ahead × tolerance_radius, and then obeys the same law. A pair
  /// closing by more than the look-ahead in a step is caught before it lands, up to approach
  /// speeds of (look_ahead_reach − look_ahead) × tolerance_radius / Δt.
  double look_ahead_reach = 0.0;
};

/// Wall time of the stages of one step [s].
struct StepTimes {
  double midpoint = 0.0;   ///< first half step, free velocities
  double detection = 0.0;  ///< collision detection at q_M
  double assembly = 0.0;   ///< world-frame M⁻¹ and velocities, contact frames, γ_S, materials, warm start
  double solve = 0.0;      ///< the contact solver
  double update = 0.0;     ///< end velocities, second half step, warm-start store, energies
  double total = 0.0;      ///< the whole step
};

/// What one step did.
struct StepReport {
  std::uint64_t step = 0;         ///< number of this step (1 for the first)
  double t = 0.0;                 ///< time at the end of the step [s]
  std::size_t contacts = 0;       ///< active contacts
  std::size_t warm_started = 0;   ///< contacts that found a percussion of the previous step
  int iterations = 0;             ///< solver iterations
  double residual = 0.0;          ///< natural-map residual of the returned percussions
  bool converged = true;          ///< the solver met its tolerance (true without contacts)
  double kinetic_energy = 0.0;    ///< of the owned bodies at the end of the step [J]
  double potential_energy = 0.0;  ///< −Σ m I_gᵀ I_r_S over the owned bodies, end of step [J]
  double max_penetration = 0.0;   ///< max(0, −g_N) over the contacts at the midpoint [m]
  /// the mean of max(0, −g_N) over the contacts at the midpoint [m] (0 without contacts)
  double mean_penetration = 0.0;
  /// The 99th percentile of max(0, −g_N) over the contacts at the midpoint [m], read from
  /// `overlaps` (the upper edge of its bin: at most 12 % above the true percentile)
  double p99_penetration = 0.0;
  /// The distribution of max(0, −g_N) over the contacts at the midpoint, in units of
  /// MoreauStepper::overlap_unit()
  OverlapHistogram overlaps;
  StepTimes seconds;              ///< stage timings
};

/// Loads on the bodies besides gravity, evaluated at the midpoint: called once per step with the
/// time t_M, the system at q_M (velocities u_S) and one Loads per body, zeroed, to add to.
using ExternalLoads =
    std::function<void(double t_M, const BodySystem& system, std::span<body::Loads> loads)>;

/// Where a driver takes part in a step (chapter 8's parallel engine: the contacts a process
/// solves, split bodies, reductions over processes), in the idiom of contact::SolverHooks and
/// ExternalLoads: plain functions, an empty one is not called. What each may change is part of
/// its contract; with no hook set, a step is exactly the serial step.
// [step hooks]
struct StepHooks {
  /// After detection and the active set, before assembly: the active contacts at q_M and their
  /// keys, one per contact, in canonical order. May remove contacts (keeping the two vectors
  /// aligned and in order), e.g. keep only those this process solves; must not add contacts or
  /// change their geometry.
  std::function<void(const BodySystem& system, std::vector<DetectedContact>& contacts,
                     std::vector<ContactKey>& keys)>
      after_detection;
  /// After assembly, before the solve: the contact problem in the compact form (world-frame M⁻¹
  /// at q_M, u_free, the contacts with their frames, lever arms, μ and ξ_A) and the initial guess
  /// (solution.lambda, warm-started; solution.u holds u_S in frame I). May change the inverse
  /// masses and free velocities of bodies (a split body's copy carries M⁻¹ scaled by its
  /// multiplicity) and the guess, and fold a contact's side from a body onto another that moves
  /// with it (a periodic image onto its owner, the lever arm kept); must not change the number or
  /// the order of bodies or contacts.
  std::function<void(contact::CompactProblem& problem, contact::ContactSolution& solution)>
      after_assembly;
  /// The contact solver's own hooks, given to its ContactSolver: between iterations
  /// (velocities_between_sweeps keeps SOR on its fast path) and the global stopping decision.
  contact::SolverHooks solver;
  /// Last thing in a step: turns this process's report into the global one (contacts and
  /// energies summed, residual, iterations and penetration maximised, converged only if
  /// everywhere). Called after the step has succeeded.
  std::function<void(StepReport& report)> reduce_report;
};
// [step hooks]

/// Moreau's midpoint scheme for a BodySystem among a StaticGeometry, with per-pair materials.
///
/// A step runs five named stages — midpoint(), detect(), assemble(), solve(), finish() — with the
/// hooks of StepHooks between them (see step()).
///
/// Owned bodies and ghosts (BodySystem): the midpoint moves every dynamic row, ghosts included —
/// a ghost holds its owner's q_S and u_S, so the same arithmetic gives the owner's q_M bit for
/// bit; detection keeps the contacts with an owned side; the solve sees ghosts as bodies; the end
/// of the step, the energies and the blow-up checks concern owned bodies only. A ghost is left at
/// q_M: its owner advances it, and the driver refreshes it before the next step.
///
/// The stepper keeps references to the three (they must outlive it) and owns every buffer of a
/// step; after the first steps, a step of a settled system allocates nothing. Bodies may be
/// added or removed between steps; the stepper notices (BodySystem::layout_version) and checks
/// the materials and shapes of the new layout once.
class MoreauStepper {
 public:
  /// Checks the settings, that every pair of materials in use has a law (naming both
  /// materials), and that every pair of shapes that can meet is supported.
  MoreauStepper(BodySystem& system, const StaticGeometry& statics, const MaterialTable& materials,
                StepSettings settings = {}, StepHooks hooks = {});

  /// One step of length Δt; returns its report. Throws grbd::Error when the solver diverges or
  /// (NonConvergence::stop) does not converge, the system then left at the midpoint state; and
  /// when the step leaves a body's q or u, or the kinetic or potential energy, not finite, or a
  /// dynamic body farther than kFarthest bounding radii from the origin (a blow-up), naming the
  /// step, the time and the body's id: the system then holds that state, which must not be
  /// continued.
  StepReport step();

  /// Between steps, the driver's call: reorders the bodies along the Morton curve
  /// (BodySystem::reorder_morton, cells of twice the largest bounding radius) when
  /// settings().reorder_interval asks for it before the next step — steps() > 0 and a multiple of
  /// the interval — and returns whether it did. The stepper keeps what it checked of the layout
  /// (the same bodies, reordered). A parallel driver migrates bodies at the same point.
  bool reorder_if_due();

  /// Time [s] at the end of the last step.
  double time() const { return t_; }
  /// Number of steps done.
  std::uint64_t steps() const { return steps_; }
  /// Sets the clock (restart); throws InvalidArgument unless t is finite and ≥ 0.
  void set_clock(double t, std::uint64_t steps);
  /// Steps that did not converge so far.
  std::uint64_t non_converged_steps() const { return non_converged_; }

  /// Loads besides gravity (empty: none).
  ExternalLoads external_loads;
  /// The settings.
  const StepSettings& settings() const { return settings_; }
  /// The hooks.
  const StepHooks& hooks() const { return hooks_; }
  /// The largest gap at which detection finds a contact [m]: the largest of contact_tolerance,
  /// look_ahead and look_ahead_reach, times tolerance_radius (0 before any body).
  double active_set_tolerance() const { return tolerance_; }
  /// The length r that StepReport::overlaps counts in [m]: tolerance_radius, or the smallest
  /// bounding radius of the first bodies (0 before any body).
  double overlap_unit() const { return unit_; }

  /// \name The last step
  /// Contacts (at the midpoint, canonical order), their keys and percussions, and the contact
  /// problem that was solved, in the compact form (world-frame velocities).
  ///@{
  std::span<const DetectedContact> contacts() const { return contacts_; }  ///< at q_M
  std::span<const ContactKey> keys() const { return keys_; }  ///< one per contact
  std::span<const Vector3> percussions() const { return solution_.lambda; }  ///< λ per contact
  const contact::CompactProblem& problem() const { return problem_; }  ///< the problem solved
  ///@}
  /// The warm starts (chapter 7 saves and restores them).
  WarmStartTable& warm_starts() { return warm_; }
  /// The warm starts, read only.
  const WarmStartTable& warm_starts() const { return warm_; }

 private:
  // The stages of step(), in order.
  void midpoint(const StepReport& report);
  void detect(const StepReport& report);
  void assemble(StepReport& report);
  void solve(StepReport& report);
  void finish(StepReport& report);

  // Half a step of the positions with the settings' orientation update.
  Vector7 half(const Vector7& q, const Vector6& u) const;
  void check_layout();
  void correct_drift();
  [[noreturn]] void require_finite(const StepReport& report, const char* where) const;

  BodySystem& system_;
  const StaticGeometry& statics_;
  const MaterialTable& materials_;
  StepSettings settings_;
  StepHooks hooks_;
  contact::ContactSolver solver_;
  ContactDetector detector_;
  WarmStartTable warm_;
  double t_ = 0.0;
  std::uint64_t steps_ = 0;
  std::uint64_t non_converged_ = 0;
  std::uint64_t checked_layout_ = ~std::uint64_t{0};
  double tolerance_ = 0.0;  // max(contact_tolerance, look_ahead, reach) × tolerance_radius [m]
  double near_tolerance_ = 0.0;    // max(contact_tolerance, look_ahead) × tolerance_radius [m]
  double moreau_tolerance_ = 0.0;  // contact_tolerance × tolerance_radius [m]
  double unit_ = 0.0;       // tolerance_radius, or the smallest first radius [m]

  std::vector<body::Loads> loads_;
  std::vector<DetectedContact> contacts_;
  std::vector<ContactKey> keys_;
  contact::CompactProblem problem_;
  contact::ContactSolution solution_;  // world-frame u; before the solve, u_S (for γ_S)
  std::vector<Vector3> shift_;      // drift correction: displacement per body
  std::vector<std::uint32_t> share_;  // drift correction: contacts per body
};

}  // namespace grbd::timestep
