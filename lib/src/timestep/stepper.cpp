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
  if (!(s.contact_tolerance >= 0.0) || !std::isfinite(s.contact_tolerance)) {
    throw InvalidArgument(where + "expected a finite contact_tolerance >= 0, found " +
                          format_number(s.contact_tolerance));
  }
  if (!(s.drift_correction >= 0.0 && s.drift_correction <= 1.0)) {
    throw InvalidArgument(where + "expected drift_correction in [0, 1] (0: off), found " +
                          format_number(s.drift_correction));
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
                             const MaterialTable& materials, StepSettings settings)
    : system_(system),
      statics_(statics),
      materials_(materials),
      settings_((require_settings(settings), settings)),
      solver_(settings.method, settings.solver) {
  check_layout();
}

void MoreauStepper::set_clock(double t, std::uint64_t steps) {
  if (!std::isfinite(t)) {
    throw InvalidArgument("MoreauStepper::set_clock: expected a finite time, found " +
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
  tolerance_ = n > 0 ? settings_.contact_tolerance * smallest : 0.0;
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
  if (settings_.reorder_interval > 0 && steps_ > 0 &&
      steps_ % static_cast<std::uint64_t>(settings_.reorder_interval) == 0 && system_.size() > 0) {
    const auto radii = system_.bounding_radii();
    system_.reorder_morton(2.0 * *std::max_element(radii.begin(), radii.end()));
    checked_layout_ = system_.layout_version();  // the same bodies, reordered
  }
  const double dt = settings_.dt;
  const std::size_t n = system_.size();
  const auto states = system_.states();
  const auto inertia = system_.inertia();
  const bool exp_map = settings_.orientation_update == OrientationUpdate::exponential_map;
  const auto half = [&](const Vector7& q, const Vector6& u) {
    return exp_map ? half_step(q, u, dt) : half_step_add_normalize(q, u, dt);
  };
  StepReport report;
  report.step = steps_ + 1;
  report.t = t_ + dt;

  // 1. The midpoint q_M = q_S + Δt/2 F(q_S) u_S, the loads there, u_free = u_S + Δt M⁻¹ h.
  for (std::size_t i = 0; i < n; ++i) {
    if (system_.dynamic(i)) states[i].q = half(states[i].q, states[i].u);
  }
  loads_.assign(n, body::Loads{});
  if (external_loads) {
    external_loads(t_ + 0.5 * dt, system_, loads_);
    for (std::size_t i = 0; i < n; ++i) {
      body::require_finite(loads_[i], "MoreauStepper: the external loads of " +
                                          id_name(system_.ids()[i]));
    }
  }
  problem_.u_free.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!system_.dynamic(i)) {
      problem_.u_free[i].setZero();
      continue;
    }
    loads_[i].I_F += inertia[i].m * settings_.I_g;
    problem_.u_free[i] = free_velocity(inertia[i], states[i].u, loads_[i], dt);
  }
  // M⁻¹ is constant for a layout: copied when bodies were added, removed or reordered.
  if (M_inv_layout_ != system_.layout_version()) {
    problem_.M_inv.assign(system_.M_inv().begin(), system_.M_inv().end());
    M_inv_layout_ = system_.layout_version();
  }
  const auto t1 = Clock::now();

  // 2. Contacts at the midpoint; Moreau's active set g_N(q_M) ≤ 0 (to the tolerance).
  detector_.detect(system_, statics_, tolerance_, contacts_, keys_);
  std::size_t active = 0;
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    if (!is_active(contacts_[k].geometry, tolerance_)) continue;
    if (active != k) {
      contacts_[active] = contacts_[k];
      keys_[active] = keys_[k];
    }
    ++active;
  }
  contacts_.resize(active);
  keys_.resize(active);
  const auto t2 = Clock::now();

  // 3. The contact problem at q_M: W, γ_S with the velocities at the start, the materials of the
  // pair, the Delassus blocks once (the solver takes them as they are).
  const std::size_t m = contacts_.size();
  problem_.contacts.resize(m);
  problem_.keys.clear();
  G_.resize(m);
  // The material of a side: a dynamic body by its local index; a static object by its index; a
  // fixed body, which enters as kStatic, by its id.
  const auto material_of = [&](collision::BodyIndex body, std::uint64_t id,
                               std::int32_t collider) {
    if (body != collision::kStatic) return system_.materials()[static_cast<std::size_t>(body)];
    if (id & kStaticTag) return statics_.objects()[static_cast<std::size_t>(collider)].material;
    return system_.materials()[system_.index_of(id)];
  };
  for (std::size_t k = 0; k < m; ++k) {
    const collision::Contact& c = contacts_[k];
    contact::ContactConstraint& cc = problem_.contacts[k];
    cc.body_a = c.body_a;
    cc.body_b = c.body_b;
    const Vector3& n_ = c.geometry.I_n;
    const Vector6* u_a = nullptr;
    const Vector6* u_b = nullptr;
    if (c.body_a != collision::kStatic) {
      const body::State& s = states[static_cast<std::size_t>(c.body_a)];
      cc.W_a = collision::contact_jacobian(kinematics::orientation(s.q), c.K_rho_a, n_, c.I_t1,
                                           c.I_t2);
      u_a = &s.u;
    } else {
      cc.W_a.setZero();
    }
    if (c.body_b != collision::kStatic) {
      const body::State& s = states[static_cast<std::size_t>(c.body_b)];
      cc.W_b = collision::contact_jacobian(kinematics::orientation(s.q), c.K_rho_b, n_, c.I_t1,
                                           c.I_t2);
      u_b = &s.u;
    } else {
      cc.W_b.setZero();
    }
    cc.gamma_A = start_contact_velocity(u_a ? &cc.W_a : nullptr, u_a, u_b ? &cc.W_b : nullptr, u_b);
    const contact::ContactMaterial& law = materials_.pair_unchecked(
        material_of(c.body_a, keys_[k].a, c.collider_a),
        material_of(c.body_b, keys_[k].b, c.collider_b));
    cc.mu = law.mu;
    // Newton's law restitutes a closing contact, γ_N,S ≤ 0. A contact closed at the midpoint but
    // already opening at the start (γ_N,S > 0, a resting contact's round-off or the rebound of a
    // penetrating one) takes ε_N = 1: then λ_N > 0 gives γ_N,E = −γ_N,S, and the percussion, which
    // works on the mean velocity (γ_N,S + γ_N,E)/2 of the step, does no work. With its own ε_N < 1
    // it would do positive work and the energy of a ball at rest would creep up.
    cc.eps_N = cc.gamma_A(0) > 0.0 ? 1.0 : law.eps_N;
    cc.eps_T = law.eps_T;
    G_[k] = contact::delassus_block(cc, problem_.M_inv);
    if (!(G_[k](0, 0) > 0.0 && G_[k](1, 1) > 0.0 && G_[k](2, 2) > 0.0) || !G_[k].allFinite() ||
        !cc.gamma_A.allFinite()) {
      throw Error("MoreauStepper: step " + std::to_string(report.step) + ": the contact of " +
                  id_name(keys_[k].a) + " and " + id_name(keys_[k].b) +
                  " has a Delassus block without a positive finite diagonal or a non-finite "
                  "velocity");
    }
  }
  solution_.lambda.resize(m);
  if (settings_.warm_start) {
    report.warm_started = warm_.initialize(keys_, solution_.lambda);
  } else {
    std::fill(solution_.lambda.begin(), solution_.lambda.end(), Vector3::Zero());
  }
  const auto t3 = Clock::now();

  // 4. The contact problem.
  report.contacts = m;
  if (m > 0) {
    const contact::SolverResult result = solver_.solve_prepared(problem_, G_, solution_);
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
  } else {
    solution_.u.assign(problem_.u_free.begin(), problem_.u_free.end());
  }
  const auto t4 = Clock::now();

  // 5. u_E, q_E = q_M + Δt/2 F(q_M) u_E.
  for (std::size_t i = 0; i < n; ++i) {
    if (!system_.dynamic(i)) continue;
    states[i].u = solution_.u[i];
    states[i].q = half(states[i].q, states[i].u);
  }
  if (settings_.drift_correction > 0.0) correct_drift();
  if (settings_.warm_start) warm_.store(keys_, solution_.lambda);
  for (std::size_t i = 0; i < n; ++i) {
    if (!system_.dynamic(i)) continue;
    report.kinetic_energy += body::kinetic_energy(inertia[i], states[i].u);
    report.potential_energy -= inertia[i].m * settings_.I_g.dot(states[i].q.head<3>());
  }
  for (const collision::Contact& c : contacts_) {
    report.max_penetration = std::max(report.max_penetration, -c.geometry.g_N);
  }
  t_ += dt;
  ++steps_;
  const auto t5 = Clock::now();
  report.seconds = {seconds(t0, t1), seconds(t1, t2), seconds(t2, t3),
                    seconds(t3, t4), seconds(t4, t5), seconds(t0, t5)};
  return report;
}
// [step]

// [drift correction]
void MoreauStepper::correct_drift() {
  const std::size_t n = system_.size();
  shift_.assign(n, Vector3::Zero());
  share_.assign(n, 0);
  const auto M_inv = system_.M_inv();
  for (const collision::Contact& c : contacts_) {
    if (!(c.geometry.g_N < 0.0)) continue;
    if (c.body_a != collision::kStatic) ++share_[static_cast<std::size_t>(c.body_a)];
    if (c.body_b != collision::kStatic) ++share_[static_cast<std::size_t>(c.body_b)];
  }
  for (const collision::Contact& c : contacts_) {
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
  for (std::size_t i = 0; i < n; ++i) states[i].q.head<3>() += shift_[i];
}
// [drift correction]

}  // namespace grbd::timestep
