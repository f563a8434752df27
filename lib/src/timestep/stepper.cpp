/// \file
/// \brief Moreau's midpoint scheme for a system of bodies.

#include "grbd/timestep/stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "grbd/collision/world.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/timestep/midpoint.hpp"

namespace grbd::timestep {

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

void require_settings(const StepSettings& s) {
  const std::string where = "MoreauStepper: ";
  require_positive_finite("MoreauStepper", "time step dt", s.dt);
  if (!s.I_g.allFinite()) throw InvalidArgument(where + "expected a finite gravity vector I_g");
  if (s.reorder_interval < 0) {
    throw InvalidArgument(where + "expected reorder_interval >= 0 (0: never), found " +
                          std::to_string(s.reorder_interval));
  }
  if (!(s.tolerance_radius >= 0.0) || !std::isfinite(s.tolerance_radius)) {
    throw InvalidArgument(where + "expected a finite tolerance_radius >= 0 (0: the smallest "
                          "bounding radius of the first bodies), found " +
                          format_number(s.tolerance_radius));
  }
  if (!(s.contact_tolerance >= 0.0) || !std::isfinite(s.contact_tolerance)) {
    throw InvalidArgument(where + "expected a finite contact_tolerance >= 0, found " +
                          format_number(s.contact_tolerance));
  }
  if (!(s.skin >= 0.0) || !std::isfinite(s.skin)) {
    throw InvalidArgument(where + "expected a finite skin >= 0 [m] (0: no candidate list), found " +
                          format_number(s.skin));
  }
  if (!(s.drift_correction >= 0.0 && s.drift_correction <= 1.0)) {
    throw InvalidArgument(where + "expected drift_correction in [0, 1] (0: off), found " +
                          format_number(s.drift_correction));
  }
  if (!(s.overlap_recovery >= 0.0 && s.overlap_recovery <= 1.0)) {
    throw InvalidArgument(where + "expected overlap_recovery in [0, 1] (0: off), found " +
                          format_number(s.overlap_recovery));
  }
  if (!(s.look_ahead >= 0.0) || !std::isfinite(s.look_ahead)) {
    throw InvalidArgument(where + "expected a finite look_ahead >= 0 (0: off), found " +
                          format_number(s.look_ahead));
  }
  if (!std::isfinite(s.look_ahead_reach) ||
      !(s.look_ahead_reach == 0.0 || (s.look_ahead > 0.0 && s.look_ahead_reach >= s.look_ahead))) {
    throw InvalidArgument(where + "expected a finite look_ahead_reach, 0 (none) or, with a " +
                          "look_ahead > 0, at least the look_ahead (" + format_number(s.look_ahead) +
                          "), found " + format_number(s.look_ahead_reach));
  }
  if (!(s.max_recovery_speed > 0.0)) {
    throw InvalidArgument(where + "expected max_recovery_speed > 0 [m/s] (may be infinite), found " +
                          format_number(s.max_recovery_speed));
  }
  switch (s.on_non_convergence) {
    case NonConvergence::count:
    case NonConvergence::warn:
    case NonConvergence::stop:
      break;
    default:
      throw InvalidArgument(where + "on_non_convergence is not one of count, warn, stop");
  }
  switch (s.orientation_update) {
    case OrientationUpdate::exponential_map:
    case OrientationUpdate::add_and_normalize:
      break;
    default:
      throw InvalidArgument(where +
                            "orientation_update is not one of exponential_map, add_and_normalize");
  }
}

std::string id_name(std::uint64_t id) {
  return (id & kStaticTag) ? "static object " + std::to_string(id & ~kStaticTag)
                           : "body " + std::to_string(id);
}

}  // namespace

MoreauStepper::MoreauStepper(BodySystem& system, const StaticGeometry& statics,
                             const MaterialTable& materials, StepSettings settings,
                             StepHooks hooks)
    : system_(system),
      statics_(statics),
      materials_(materials),
      settings_((require_settings(settings), settings)),
      hooks_(std::move(hooks)),
      solver_(settings.method, settings.solver, hooks_.solver) {
  detector_.set_skin(settings_.skin);
  check_layout();
}

void MoreauStepper::set_clock(double t, std::uint64_t steps) {
  if (!std::isfinite(t) || !(t >= 0.0)) {
    throw InvalidArgument("MoreauStepper::set_clock: expected a finite time t >= 0, found " +
                          format_number(t));
  }
  t_ = t;
  steps_ = steps;
}

// Once per layout: every material in use is known and every pair of them has a law; every pair
// of shape kinds that can meet is supported. O(N + S), run again only when bodies were added or
// removed.
void MoreauStepper::check_layout() {
  if (checked_layout_ == system_.layout_version()) return;
  const std::size_t n = system_.size();
  // Bodies meet bodies and static objects; static objects never meet each other.
  std::vector<MaterialId> body_materials;
  std::vector<MaterialId> static_materials;
  std::vector<std::uint8_t> seen(2 * materials_.size(), 0);
  const auto use = [&](MaterialId m, const std::string& who, bool is_static) {
    if (m >= materials_.size()) {
      throw InvalidArgument("MoreauStepper: " + who + " has the material id " +
                            std::to_string(m) + ", but only " +
                            std::to_string(materials_.size()) + " materials are declared");
    }
    std::uint8_t& flag = seen[2 * m + (is_static ? 1 : 0)];
    if (!flag) {
      flag = 1;
      (is_static ? static_materials : body_materials).push_back(m);
    }
  };
  double smallest = std::numeric_limits<double>::infinity();
  // First body of each (kind, dynamic) and first static object of each kind, for the messages.
  constexpr int kKinds = 5;
  std::int64_t dynamic_kind[kKinds], fixed_kind[kKinds], static_kind[kKinds];
  std::fill(std::begin(dynamic_kind), std::end(dynamic_kind), -1);
  std::fill(std::begin(fixed_kind), std::end(fixed_kind), -1);
  std::fill(std::begin(static_kind), std::end(static_kind), -1);
  std::size_t dynamic_count[kKinds] = {0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    use(system_.materials()[i], id_name(system_.ids()[i]), false);
    smallest = std::min(smallest, system_.bounding_radii()[i]);
    auto& first = system_.dynamic(i) ? dynamic_kind : fixed_kind;
    const int k = static_cast<int>(collision::kind(system_.shapes()[i]));
    if (first[k] < 0) first[k] = static_cast<std::int64_t>(i);
    if (system_.dynamic(i)) ++dynamic_count[k];
  }
  const auto objects = statics_.objects();
  for (std::size_t s = 0; s < objects.size(); ++s) {
    use(objects[s].material, id_name(kStaticTag | objects[s].id), true);
    const int k = static_cast<int>(collision::kind(objects[s].shape));
    if (static_kind[k] < 0) static_kind[k] = static_cast<std::int64_t>(s);
  }
  materials_.require_pairs(body_materials, body_materials);
  materials_.require_pairs(body_materials, static_materials);
  // The length the tolerance scales is the settings', or fixed by the first bodies seen.
  if (settings_.tolerance_radius > 0.0) {
    unit_ = settings_.tolerance_radius;
  } else if (unit_ == 0.0 && n > 0) {
    unit_ = smallest;
  }
  near_tolerance_ = std::max(settings_.contact_tolerance, settings_.look_ahead) * unit_;
  tolerance_ = std::max(near_tolerance_, settings_.look_ahead_reach * unit_);
  moreau_tolerance_ = settings_.contact_tolerance * unit_;
  const auto body_name = [&](std::int64_t i) {
    return id_name(system_.ids()[static_cast<std::size_t>(i)]);
  };
  for (int a = 0; a < kKinds; ++a) {
    if (dynamic_kind[a] < 0) continue;
    const auto refuse = [&](int b, const std::string& other) {
      throw InvalidArgument(
          "MoreauStepper: " + body_name(dynamic_kind[a]) + " (a dynamic " +
          std::string(collision::kind_name(static_cast<collision::ShapeKind>(a))) +
          ") can meet " + other + " (a " +
          std::string(collision::kind_name(static_cast<collision::ShapeKind>(b))) +
          "), a pair the narrow phase does not support");
    };
    for (int b = 0; b < kKinds; ++b) {
      const auto ka = static_cast<collision::ShapeKind>(a);
      const auto kb = static_cast<collision::ShapeKind>(b);
      if (collision::supported(ka, kb)) continue;
      // Two dynamic bodies of kinds a and b (for a == b: two of that kind).
      if (dynamic_count[b] >= (b == a ? 2U : 1U)) refuse(b, "another dynamic body");
      if (fixed_kind[b] >= 0) refuse(b, body_name(fixed_kind[b]));
      if (static_kind[b] >= 0) {
        refuse(b, id_name(kStaticTag | objects[static_cast<std::size_t>(static_kind[b])].id));
      }
    }
  }
  checked_layout_ = system_.layout_version();
}

// [step]
StepReport MoreauStepper::step() {
  const auto t0 = Clock::now();
  check_layout();
  StepReport report;
  report.step = steps_ + 1;
  report.t = t_ + settings_.dt;
  midpoint(report);  // q_M, the loads there, u_free
  const auto t1 = Clock::now();
  detect(report);  // the active set at q_M; hook after_detection
  const auto t2 = Clock::now();
  assemble(report);  // the contact problem, warm-started; hook after_assembly
  const auto t3 = Clock::now();
  solve(report);  // Λ and u_E; the solver's hooks
  const auto t4 = Clock::now();
  finish(report);  // q_E, warm starts kept, energies, blow-up checks; the clock advances
  const auto t5 = Clock::now();
  report.seconds = {seconds(t0, t1), seconds(t1, t2), seconds(t2, t3),
                    seconds(t3, t4), seconds(t4, t5), seconds(t0, t5)};
  if (hooks_.reduce_report) hooks_.reduce_report(report);
  report.p99_penetration = report.overlaps.quantile(0.99) * unit_;
  return report;
}
// [step]

Vector7 MoreauStepper::half(const Vector7& q, const Vector6& u) const {
  return settings_.orientation_update == OrientationUpdate::exponential_map
             ? half_step(q, u, settings_.dt)
             : half_step_add_normalize(q, u, settings_.dt);
}

bool MoreauStepper::reorder_if_due() {
  check_layout();
  const auto interval = static_cast<std::uint64_t>(settings_.reorder_interval);
  const std::size_t owned = system_.owned_count();
  if (interval == 0 || steps_ == 0 || steps_ % interval != 0 || owned == 0) return false;
  const auto radii = system_.bounding_radii().first(owned);
  system_.reorder_morton(2.0 * *std::max_element(radii.begin(), radii.end()));
  checked_layout_ = system_.layout_version();  // the same bodies, reordered
  return true;
}

// [stage midpoint]
// 1. The midpoint q_M = q_S + Δt/2 F(q_S) u_S, the loads there, and the problem's world-frame
// inverse masses, u_free = u_S + Δt M⁻¹ h and u_S (in solution_.u until the solver overwrites it).
// Ghosts too: they hold their owner's q_S and u_S, and the same arithmetic gives the owner's q_M.
void MoreauStepper::midpoint(const StepReport& report) {
  const double dt = settings_.dt;
  const std::size_t n = system_.size();
  const auto states = system_.states();
  const auto inertia = system_.inertia();
  bool finite = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (!system_.dynamic(i)) continue;
    states[i].q = half(states[i].q, states[i].u);
    finite = finite && states[i].q.allFinite();
  }
  if (!finite) require_finite(report, " at the midpoint");
  loads_.assign(n, body::Loads{});
  if (external_loads) {
    external_loads(t_ + 0.5 * dt, system_, loads_);
    for (std::size_t i = 0; i < n; ++i) {
      body::require_finite(loads_[i], "MoreauStepper: the external loads of " +
                                          id_name(system_.ids()[i]));
    }
  }
  problem_.M_inv.resize(n);
  problem_.u_free.resize(n);
  solution_.u.resize(n);
  const auto M_inv = system_.M_inv();
  problem_.isotropic = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (!system_.dynamic(i)) {
      problem_.M_inv[i] = {};
      problem_.u_free[i].setZero();
      solution_.u[i].setZero();
      continue;
    }
    loads_[i].I_F += inertia[i].m * settings_.I_g;
    const Vector6 u_free = free_velocity(inertia[i], states[i].u, loads_[i], dt);
    const Matrix3 A_IK = kinematics::rotation_matrix(kinematics::orientation(states[i].q));
    problem_.M_inv[i] = contact::world_inverse_mass(M_inv[i], A_IK);
    const Matrix3& T = problem_.M_inv[i].I_Theta_inv;
    problem_.isotropic = problem_.isotropic && T == T(0, 0) * Matrix3::Identity();
    problem_.u_free[i] << u_free.head<3>(), A_IK * u_free.tail<3>();
    solution_.u[i] << states[i].u.head<3>(), A_IK * states[i].u.tail<3>();
  }
}
// [stage midpoint]

// [stage detect]
// 2. Contacts at the midpoint; Moreau's active set g_N(q_M) ≤ 0 (to the tolerance).
void MoreauStepper::detect(const StepReport& report) {
  try {
    detector_.detect(system_, statics_, tolerance_, contacts_, keys_);
  } catch (const InvalidArgument& e) {  // a state set from outside that is not finite
    throw Error("MoreauStepper: step " + std::to_string(report.step) + " (t = " +
                format_number(report.t) + " s): " + e.what());
  }
  // Active: Moreau's set, and, within the look-ahead, the contacts of inelastic pairs (ε_N = 0);
  // a restituted pair must hit to rebound, so it keeps Moreau's law (chapter 6). Beyond the
  // look-ahead, within its reach, an inelastic pair whose free velocities close it to the
  // look-ahead by the next midpoint, g_N + Δt γ_N,free ≤ look-ahead.
  // [reach]
  const auto states = system_.states();
  const auto free_approach = [&](const DetectedContact& c) {
    const auto velocity = [&](collision::BodyIndex body, const Vector3& I_r) -> Vector3 {
      if (body == collision::kStatic) return Vector3::Zero();
      const auto i = static_cast<std::size_t>(body);
      const Vector6& u = problem_.u_free[i];
      return u.head<3>() + u.tail<3>().cross(I_r - states[i].q.head<3>());
    };
    return c.geometry.I_n.dot(velocity(c.body_a, c.geometry.I_r_a) -
                              velocity(c.body_b, c.geometry.I_r_b));
  };
  keep_contacts_if(contacts_, keys_, [&](const DetectedContact& c) {
    if (!is_active(c.geometry, tolerance_)) return false;
    if (tolerance_ == moreau_tolerance_ || is_active(c.geometry, moreau_tolerance_)) return true;
    if (materials_.pair_unchecked(c.material_a, c.material_b).eps_N != 0.0) return false;
    return is_active(c.geometry, near_tolerance_) ||
           c.geometry.g_N + settings_.dt * free_approach(c) <= near_tolerance_;
  });
  // [reach]
  if (hooks_.after_detection) {
    hooks_.after_detection(system_, contacts_, keys_);
    if (keys_.size() != contacts_.size()) {
      throw InvalidArgument("StepHooks::after_detection left " + std::to_string(contacts_.size()) +
                            " contacts and " + std::to_string(keys_.size()) +
                            " keys: expected one key per contact");
    }
  }
}
// [stage detect]

// [stage assemble]
// 3. The contact problem at q_M: the frame and the lever arms of each contact, γ_S from the
// velocities at the start, the materials of the pair; the warm start.
void MoreauStepper::assemble(StepReport& report) {
  const auto states = system_.states();
  const std::size_t m = contacts_.size();
  problem_.contacts.resize(m);
  const double recovery = 2.0 * settings_.overlap_recovery / settings_.dt;  // v_R per metre
  const bool look_ahead = tolerance_ > moreau_tolerance_;
  double reference = 0.0;  // Σ ‖γ_free + xi_A‖² without the look-ahead's gap rates
  for (std::size_t k = 0; k < m; ++k) {
    const DetectedContact& c = contacts_[k];
    contact::CompactContact& cc = problem_.contacts[k];
    cc.body_a = c.body_a;
    cc.body_b = c.body_b;
    cc.n = c.geometry.I_n;
    cc.t1 = collision::tangent_basis(cc.n).col(0);
    const auto lever = [&](collision::BodyIndex body, const Vector3& I_r) -> Vector3 {
      if (body == collision::kStatic) return Vector3::Zero();
      return I_r - states[static_cast<std::size_t>(body)].q.head<3>();
    };
    cc.r_a = lever(c.body_a, c.geometry.I_r_a);
    cc.r_b = lever(c.body_b, c.geometry.I_r_b);
    cc.xi_A.setZero();
    const Vector3 gamma_S = contact::contact_velocity(cc, solution_.u);
    const contact::ContactMaterial& law = materials_.pair_unchecked(c.material_a, c.material_b);
    cc.mu = law.mu;
    // Newton's law restitutes a closing contact, γ_N,S ≤ 0. A contact closed at the midpoint but
    // already opening at the start (γ_N,S > 0, a resting contact's round-off or the rebound of a
    // penetrating one) takes ε_N = 1: then λ_N > 0 gives γ_N,E = −γ_N,S, and the percussion, which
    // works on the mean velocity (γ_N,S + γ_N,E)/2 of the step, does no work. With its own ε_N < 1
    // it would do positive work and the energy of a ball at rest would creep up.
    const double eps_N = gamma_S(0) > 0.0 ? 1.0 : law.eps_N;
    cc.xi_A = {eps_N * gamma_S(0), law.eps_T * gamma_S(1), law.eps_T * gamma_S(2)};
    // [gap law]
    // The gap-aware law: an overlapping contact leaves the step at least at the recovery speed
    // v_R, or at its restituted speed where that is larger, γ_N,E ≥ max(−ε_N γ_N,S, v_R).
    if (recovery > 0.0 && c.geometry.g_N < 0.0) {
      const double v_R = std::min(recovery * -c.geometry.g_N, settings_.max_recovery_speed);
      cc.xi_A(0) = std::min(cc.xi_A(0), -v_R);
    }
    // The look-ahead: a contact of an inelastic pair still apart at the midpoint may close its
    // gap by the next midpoint, γ_N,E ≥ −g_N(q_M)/Δt, and is not restituted (it has not hit).
    const bool gap_rate = look_ahead && c.geometry.g_N > 0.0 && law.eps_N == 0.0;
    if (gap_rate) cc.xi_A(0) = c.geometry.g_N / settings_.dt;
    // [gap law]
    if (look_ahead) {
      Vector3 c_free = contact::contact_velocity(cc, problem_.u_free) + cc.xi_A;
      if (gap_rate) c_free(0) -= cc.xi_A(0);
      reference += c_free.squaredNorm();
    }
    if (!cc.xi_A.allFinite() || !cc.r_a.allFinite() || !cc.r_b.allFinite()) {
      throw Error("MoreauStepper: step " + std::to_string(report.step) + ": the contact of " +
                  id_name(keys_[k].a) + " and " + id_name(keys_[k].b) +
                  " has a non-finite lever arm or velocity");
    }
  }
  // The criterion's reference leaves out the look-ahead's gap rates: a gap over a step is a
  // length, not a velocity of the motion, and would loosen the tolerance with every contact
  // about to close (0: the solver's own ‖c‖).
  problem_.reference_norm = look_ahead ? std::sqrt(reference) : 0.0;
  solution_.lambda.resize(m);
  if (settings_.warm_start) {
    report.warm_started = warm_.initialize(keys_, solution_.lambda);
  } else {
    std::fill(solution_.lambda.begin(), solution_.lambda.end(), Vector3::Zero());
  }
  if (hooks_.after_assembly) {
    const std::size_t bodies = problem_.M_inv.size();
    hooks_.after_assembly(problem_, solution_);
    if (problem_.contacts.size() != m || problem_.M_inv.size() != bodies ||
        problem_.u_free.size() != bodies || solution_.lambda.size() != m ||
        solution_.u.size() != bodies) {
      throw InvalidArgument("StepHooks::after_assembly changed the number of bodies or contacts "
                            "of the problem; it may change their values only");
    }
  }
}
// [stage assemble]

// [stage solve]
// 4. The contact problem: Λ and u_E (world frame).
void MoreauStepper::solve(StepReport& report) {
  const std::size_t m = contacts_.size();
  report.contacts = m;
  // Without contacts there is nothing to solve, unless the processes of a parallel run decide
  // together (a global verdict, chapter 8): then this process's solver takes part in the others'
  // iterations with its empty problem, in the same loop — offering its velocities to the hook
  // (a split body's copies elsewhere may change them) and the verdict "converged" once
  // min_iterations are done, until every process agrees to stop.
  if (m == 0 && !hooks_.solver.global_status) {
    solution_.u.assign(problem_.u_free.begin(), problem_.u_free.end());
    return;
  }
  const contact::SolverResult result = solver_.solve_prepared(problem_, solution_);
  report.iterations = result.iterations;
  report.residual = result.residual;
  report.converged = result.converged;
  if (result.diverged) {
    throw Error("MoreauStepper: step " + std::to_string(report.step) + " (t = " +
                format_number(report.t) + " s): the contact solver diverged: " +
                contact::describe(result));
  }
  if (!result.converged) {
    ++non_converged_;
    if (settings_.on_non_convergence == NonConvergence::stop) {
      throw Error("MoreauStepper: step " + std::to_string(report.step) + " (t = " +
                  format_number(report.t) + " s): " + contact::describe(result));
    }
    if (settings_.on_non_convergence == NonConvergence::warn) {
      std::fprintf(stderr, "grbd: step %llu (t = %s s): %s\n",
                   static_cast<unsigned long long>(report.step), format_number(report.t).c_str(),
                   contact::describe(result).c_str());
    }
  }
}
// [stage solve]

// [stage finish]
// 5. u_E back in the body frames, q_E = q_M + Δt/2 F(q_M) u_E, the warm starts kept, the
// energies and the checks for a blow-up; the clock advances.
void MoreauStepper::finish(StepReport& report) {
  const std::size_t n = system_.owned_count();  // ghosts stay at q_M: their owners advance them
  const auto states = system_.states();
  const auto inertia = system_.inertia();
  for (std::size_t i = 0; i < n; ++i) {
    if (!system_.dynamic(i)) continue;
    // Only the change of ω goes back to frame K: ω_K,E = ω_K,S + A_IKᵀ(ω_I,E − A_IK ω_K,S),
    // with A_IK ω_K,S formed exactly as in the assembly. A body the contacts leave alone keeps
    // its ω_K to the bit, and the rounding of A_IK (‖p‖ drifts from 1 by 10⁻¹⁴ over thousands of
    // exp-map steps, so A_IKᵀ A_IK ≠ I) touches the change only, never the whole ω: a rolling ball
    // does not pick up slip of 10⁻¹³ m/s per step.
    const Matrix3 A_IK = kinematics::rotation_matrix(kinematics::orientation(states[i].q));
    const Vector6& u_E = solution_.u[i];
    const Vector3 I_omega_S = A_IK * states[i].u.tail<3>();
    states[i].u.head<3>() = u_E.head<3>();
    states[i].u.tail<3>() += A_IK.transpose() * (u_E.tail<3>() - I_omega_S);
    states[i].q = half(states[i].q, states[i].u);
  }
  if (settings_.drift_correction > 0.0) correct_drift();
  if (settings_.warm_start) warm_.store(keys_, solution_.lambda);
  const auto radii = system_.bounding_radii();
  bool finite = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (!system_.dynamic(i)) continue;
    report.kinetic_energy += body::kinetic_energy(inertia[i], states[i].u);
    report.potential_energy -= inertia[i].m * settings_.I_g.dot(states[i].q.head<3>());
    finite = finite && states[i].q.head<3>().cwiseAbs().maxCoeff() <= kFarthest * radii[i] &&
             states[i].q.tail<4>().allFinite();
  }
  // A blow-up is an error, not data: a state or an energy that left the doubles (a NaN or an
  // infinity in q or u makes one of the energies non-finite, 0 · ∞ included), or a body so far
  // out that the doubles no longer resolve its size (the comparison is false for NaN, too).
  if (!finite || !std::isfinite(report.kinetic_energy) || !std::isfinite(report.potential_energy)) {
    require_finite(report, "");
  }
  double penetration = 0.0;
  for (const DetectedContact& c : contacts_) {
    const double overlap = std::max(0.0, -c.geometry.g_N);
    report.max_penetration = std::max(report.max_penetration, overlap);
    penetration += overlap;
    report.overlaps.add(overlap, unit_);
  }
  if (!contacts_.empty()) {
    report.mean_penetration = penetration / static_cast<double>(contacts_.size());
  }
  t_ += settings_.dt;
  ++steps_;
}
// [stage finish]

// Names the first body whose state or energy is not finite in the step of `report` (`where`: ""
// after the step, " at the midpoint" after its first half).
void MoreauStepper::require_finite(const StepReport& report, const char* where) const {
  const auto states = system_.states();
  const auto inertia = system_.inertia();
  const std::string when = "MoreauStepper: step " + std::to_string(report.step) + " (t = " +
                           format_number(report.t) + " s): ";
  const std::string energies = "kinetic energy " + format_number(report.kinetic_energy) +
                               " J, potential energy " + format_number(report.potential_energy) +
                               " J";
  const auto radii = system_.bounding_radii();
  for (std::size_t i = 0; i < system_.owned_count(); ++i) {
    const body::State& x = states[i];
    const double e = body::kinetic_energy(inertia[i], x.u) -
                     inertia[i].m * settings_.I_g.dot(x.q.head<3>());
    const bool far = !(x.q.head<3>().cwiseAbs().maxCoeff() <= kFarthest * radii[i]);
    if (!system_.dynamic(i) || (x.q.allFinite() && std::isfinite(e) && !far)) continue;
    std::string text = when + id_name(system_.ids()[i]) + " blew up" + where +
                       (x.q.allFinite() && std::isfinite(e)
                            ? ": it is more than 10¹² bounding radii from the origin, where "
                              "doubles no longer resolve its size"
                            : ": its state or its energy is no longer finite") +
                       " (check the time step, the loads and the initial velocities): q = (";
    for (int d = 0; d < 7; ++d) text += (d ? ", " : "") + format_number(x.q[d]);
    text += "), u = (";
    for (int d = 0; d < 6; ++d) text += (d ? ", " : "") + format_number(x.u[d]);
    throw Error(text + "); " + energies);
  }
  throw Error(when + "the energy of the system overflows (" + energies +
              "), though every body's state is finite: the velocities or positions are too "
              "large for doubles");
}

// [drift correction]
void MoreauStepper::correct_drift() {
  const std::size_t n = system_.size();
  shift_.assign(n, Vector3::Zero());
  share_.assign(n, 0);
  const auto M_inv = system_.M_inv();
  for (const DetectedContact& c : contacts_) {
    if (!(c.geometry.g_N < 0.0)) continue;
    if (c.body_a != collision::kStatic) ++share_[static_cast<std::size_t>(c.body_a)];
    if (c.body_b != collision::kStatic) ++share_[static_cast<std::size_t>(c.body_b)];
  }
  for (const DetectedContact& c : contacts_) {
    if (!(c.geometry.g_N < 0.0)) continue;
    const double w_a = c.body_a != collision::kStatic
                           ? M_inv[static_cast<std::size_t>(c.body_a)].inv_m : 0.0;
    const double w_b = c.body_b != collision::kStatic
                           ? M_inv[static_cast<std::size_t>(c.body_b)].inv_m : 0.0;
    const Vector3 d = settings_.drift_correction * (-c.geometry.g_N) * c.geometry.I_n / (w_a + w_b);
    if (c.body_a != collision::kStatic) {
      const auto a = static_cast<std::size_t>(c.body_a);
      shift_[a] += w_a * d / share_[a];
    }
    if (c.body_b != collision::kStatic) {
      const auto b = static_cast<std::size_t>(c.body_b);
      shift_[b] -= w_b * d / share_[b];
    }
  }
  const auto states = system_.states();
  for (std::size_t i = 0; i < system_.owned_count(); ++i) states[i].q.head<3>() += shift_[i];
}
// [drift correction]

}  // namespace grbd::timestep
