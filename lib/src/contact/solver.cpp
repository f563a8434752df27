/// \file
/// \brief JOR, SOR and APGD for the body form and the local form of the contact problem.
///
/// The three methods are written once, over a small "model" that knows how to evaluate the
/// contact velocities ξ(Λ) of one form and how to do a Gauss–Seidel sweep in it: BodyModel keeps
/// the body velocities u in step with Λ (u = u_free + M⁻¹ W Λ), LocalModel reads block rows of W.

#include "grbd/contact/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "grbd/contact/prox.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/norms.hpp"

namespace grbd::contact {

namespace {

std::span<const double> flat(std::span<const Vector3> v) {
  return {v.empty() ? nullptr : v.data()->data(), 3 * v.size()};
}
std::span<const double> flat(std::span<const Vector6> v) {
  return {v.empty() ? nullptr : v.data()->data(), 6 * v.size()};
}

/// ‖v‖₂ without spurious overflow: a problem with q ≈ 10²⁰⁰ has finite norms.
double norm(std::span<const Vector3> v) { return euclidean_norm(flat(v)); }

bool all_finite(std::span<const Vector3> v) {
  for (const Vector3& x : v) {
    if (!x.allFinite()) return false;
  }
  return true;
}

void validate_options(const SolverOptions& o, const char* solver) {
  const std::string where = std::string(solver) + ": ";
  if (o.min_iterations < 0 || o.max_iterations < 1 || o.max_iterations < o.min_iterations) {
    throw InvalidArgument(where +
                          "expected 0 <= min_iterations <= max_iterations and "
                          "max_iterations >= 1; found min_iterations = " +
                          std::to_string(o.min_iterations) +
                          ", max_iterations = " + std::to_string(o.max_iterations));
  }
  if (!(o.abs_tol >= 0.0) || !(o.rel_tol >= 0.0) || !std::isfinite(o.abs_tol) ||
      !std::isfinite(o.rel_tol)) {
    throw InvalidArgument(where + "expected finite tolerances >= 0; found abs_tol = " +
                          format_number(o.abs_tol) + ", rel_tol = " + format_number(o.rel_tol));
  }
  if (!(o.alpha > 0.0 && o.alpha < 2.0)) {
    throw InvalidArgument(where + "expected the relaxation alpha in (0, 2); found " +
                          format_number(o.alpha));
  }
  // An enum holds any value of its underlying type: a cast or a corrupted options struct would
  // otherwise fall through every switch.
  const auto refuse_enum = [&](const char* name, int value, const char* expected) {
    throw InvalidArgument(where + "expected " + name + " to be one of " + expected + "; found " +
                          "the value " + std::to_string(value));
  };
  switch (o.criterion) {
    case Criterion::percussion_change:
    case Criterion::velocity_change:
    case Criterion::natural_residual:
      break;
    default:
      refuse_enum("criterion", static_cast<int>(o.criterion),
                  "percussion_change, velocity_change, natural_residual");
  }
  switch (o.r_strategy) {
    case RFactorStrategy::per_contact:
    case RFactorStrategy::global:
      break;
    default:
      refuse_enum("r_strategy", static_cast<int>(o.r_strategy), "per_contact, global");
  }
  switch (o.form) {
    case ProxForm::alart_curnier:
    case ProxForm::de_saxce:
      break;
    default:
      refuse_enum("form", static_cast<int>(o.form), "alart_curnier, de_saxce");
  }
}

void prepare_guess(std::vector<Vector3>& lambda, std::size_t n, const char* solver) {
  if (lambda.empty()) {
    lambda.assign(n, Vector3::Zero());
    return;
  }
  if (lambda.size() != n) {
    throw InvalidArgument(std::string(solver) + ": the initial guess has " +
                          std::to_string(lambda.size()) + " percussions for " + std::to_string(n) +
                          " contacts (leave it empty to start from zero)");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!lambda[i].allFinite()) {
      throw InvalidArgument(std::string(solver) + ": the initial guess of contact " +
                            std::to_string(i) + " is not finite");
    }
  }
}

Vector3 prox_update(ProxForm form, const Vector3& lambda, const Vector3& xi, const RFactors& r,
                    double mu) {
  return form == ProxForm::alart_curnier ? alart_curnier_update(lambda, xi, r.r_N, r.r_T, mu)
                                         : de_saxce_update(lambda, xi, std::min(r.r_N, r.r_T), mu);
}

/// The body form: Λ and the body velocities that go with it.
class BodyModel {
 public:
  BodyModel(const ContactProblem& problem, std::vector<Vector3>& lambda)
      : problem_(problem), lambda_(lambda) {}

  std::size_t size() const { return problem_.contacts.size(); }
  double mu(std::size_t i) const { return problem_.contacts[i].mu; }
  Matrix3 delassus(std::size_t i) const {
    return delassus_block(problem_.contacts[i], problem_.M_inv);
  }
  /// ξ(Λ) for the given percussions (not necessarily the model's own).
  void velocities(std::span<const Vector3> lambda, std::vector<Vector3>& xi) const {
    xi = contact_velocities(problem_, velocities_from_percussions(problem_, lambda));
  }
  /// y = G x = Wᵀ M⁻¹ W x, the linear part of ξ(Λ), without u_free or restitution.
  void apply_G(std::span<const Vector3> x, std::vector<Vector3>& y) const {
    std::vector<Vector6> v(problem_.M_inv.size(), Vector6::Zero());
    for (std::size_t i = 0; i < size(); ++i) {
      const ContactConstraint& c = problem_.contacts[i];
      if (c.body_a != kStatic) v[c.body_a] += problem_.M_inv[c.body_a].apply(c.W_a * x[i]);
      if (c.body_b != kStatic) v[c.body_b] -= problem_.M_inv[c.body_b].apply(c.W_b * x[i]);
    }
    y.assign(size(), Vector3::Zero());
    for (std::size_t i = 0; i < size(); ++i) {
      const ContactConstraint& c = problem_.contacts[i];
      if (c.body_a != kStatic) y[i] += c.W_a.transpose() * v[c.body_a];
      if (c.body_b != kStatic) y[i] -= c.W_b.transpose() * v[c.body_b];
    }
  }
  /// Makes u consistent with Λ.
  void synchronize() { u = velocities_from_percussions(problem_, lambda_); }
  /// After JOR or APGD changed all of Λ at once: u follows Λ only when the velocity criterion
  /// reads it, and once more at the end (done()), instead of a full pass every iteration.
  void record(const std::vector<Vector3>& /*xi*/, bool velocity_watched) {
    if (velocity_watched) synchronize();
  }
  /// Brings u up to date with the returned Λ.
  void done() { synchronize(); }
  void sor_sweep(std::span<const RFactors> r, ProxForm form) {
    contact::sor_sweep(problem_, r, form, u, lambda_);
  }
  /// What the velocity criterion watches.
  std::span<const double> watched_velocity() const { return flat(std::span<const Vector6>(u)); }

  std::vector<Vector6> u;

 private:
  const ContactProblem& problem_;
  std::vector<Vector3>& lambda_;
};

/// The local form ξ = W Λ + q.
class LocalModel {
 public:
  LocalModel(const LocalProblem& problem, std::vector<Vector3>& lambda)
      : problem_(problem), lambda_(lambda) {}

  std::size_t size() const { return problem_.q.size(); }
  double mu(std::size_t i) const { return problem_.mu[i]; }
  Matrix3 delassus(std::size_t i) const {
    return problem_.W.blocks[static_cast<std::size_t>(problem_.W.diagonal[i])];
  }
  void velocities(std::span<const Vector3> lambda, std::vector<Vector3>& xi) const {
    xi.resize(size());
    multiply(problem_.W, lambda, xi);
    for (std::size_t i = 0; i < xi.size(); ++i) xi[i] += problem_.q[i];
  }
  /// y = W x, the linear part of ξ(Λ).
  void apply_G(std::span<const Vector3> x, std::vector<Vector3>& y) const {
    y.resize(size());
    multiply(problem_.W, x, y);
  }
  void synchronize() { seen_.assign(size(), Vector3::Zero()); }
  void sor_sweep(std::span<const RFactors> r, ProxForm form) {
    const BlockSparseMatrix& W = problem_.W;
    for (std::size_t i = 0; i < size(); ++i) {
      Vector3 xi = problem_.q[i];
      for (std::int64_t k = W.row_start[i]; k < W.row_start[i + 1]; ++k) {
        xi.noalias() += W.blocks[k] * lambda_[W.column[k]];
      }
      seen_[i] = xi;
      lambda_[i] = prox_update(form, lambda_[i], xi, r[i], problem_.mu[i]);
    }
  }
  std::span<const double> watched_velocity() const { return flat(std::span<const Vector3>(seen_)); }
  /// After JOR or APGD changed all of Λ at once: keeps the velocities ξ of the iteration for the
  /// velocity criterion.
  void record(const std::vector<Vector3>& xi, bool velocity_watched) {
    if (velocity_watched) seen_ = xi;
  }
  /// Nothing to bring up to date: the local form has no body velocities.
  void done() {}

 private:
  const LocalProblem& problem_;
  std::vector<Vector3>& lambda_;
  std::vector<Vector3> seen_;
};

template <class Model>
std::vector<RFactors> model_r_factors(const Model& model, RFactorStrategy strategy, double alpha) {
  std::vector<RFactors> r(model.size());
  if (strategy == RFactorStrategy::per_contact) {
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = r_factors(model.delassus(i), alpha);
    return r;
  }
  double largest = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    largest = std::max(largest, model.delassus(i).diagonal().maxCoeff());
  }
  std::fill(r.begin(), r.end(), RFactors{alpha / largest, alpha / largest});
  return r;
}

/// The stopping test and the bookkeeping shared by the three methods.
template <class Model>
class Monitor {
 public:
  Monitor(const Model& model, const SolverOptions& options, std::vector<Vector3>& lambda,
          SolverResult& result)
      : model_(model), options_(options), lambda_(lambda), result_(result) {
    std::vector<Vector3> zero(model.size(), Vector3::Zero());
    model.velocities(zero, xi_);
    result_.norm_c = norm(xi_);
    mu_.resize(model.size());
    for (std::size_t i = 0; i < mu_.size(); ++i) mu_[i] = model.mu(i);
  }

  /// Call before an iteration changes Λ.
  void before() {
    if (options_.criterion == Criterion::percussion_change) lambda_old_ = lambda_;
    if (options_.criterion == Criterion::velocity_change) {
      const auto v = model_.watched_velocity();
      velocity_old_.assign(v.begin(), v.end());
    }
  }

  /// Call after iteration k (1-based) with the model up to date; true to stop: the criterion
  /// is met (from min_iterations on), or an iterate is not finite (divergence: stop at once,
  /// whatever max_iterations says).
  bool after(int k) {
    result_.iterations = k;
    if (!all_finite(lambda_)) {
      result_.diverged = true;
      return true;
    }
    double residual = -1.0;
    if (options_.record_history || options_.criterion == Criterion::natural_residual) {
      residual = natural_residual();
      if (options_.record_history) result_.history.push_back(residual);
    }
    bool met = false;
    switch (options_.criterion) {
      case Criterion::percussion_change:
        met = has_converged(flat(std::span<const Vector3>(lambda_old_)),
                            flat(std::span<const Vector3>(lambda_)), options_.abs_tol,
                            options_.rel_tol);
        break;
      case Criterion::velocity_change: {
        const auto v = model_.watched_velocity();
        met = has_converged(velocity_old_, v, options_.abs_tol, options_.rel_tol);
        break;
      }
      case Criterion::natural_residual:
        met = residual <= options_.abs_tol + options_.rel_tol * result_.norm_c;
        break;
    }
    if (met && k >= options_.min_iterations) {
      result_.converged = true;
      return true;
    }
    return false;
  }

  /// ‖F(Λ)‖ of the current percussions.
  double natural_residual() {
    model_.velocities(lambda_, xi_);
    return natural_map_residual(lambda_, xi_, mu_);
  }

  /// Fills residual and norm_max for the returned Λ. A non-finite Λ or residual is divergence,
  /// never convergence.
  void finish() {
    result_.residual = natural_residual();
    result_.norm_max = std::max({result_.norm_c, norm(lambda_), norm(xi_)});
    if (!all_finite(lambda_) || !std::isfinite(result_.residual)) {
      result_.diverged = true;
      result_.converged = false;
    }
  }

  const std::vector<double>& mu() const { return mu_; }

 private:
  const Model& model_;
  const SolverOptions& options_;
  std::vector<Vector3>& lambda_;
  SolverResult& result_;
  std::vector<Vector3> lambda_old_;
  std::vector<double> velocity_old_;
  std::vector<Vector3> xi_;
  std::vector<double> mu_;
};

using Clock = std::chrono::steady_clock;

/// APGD doubles L at most this many times in one iteration (a factor 2⁶⁰ ≈ 10¹⁸): enough for any
/// underestimate of λ_max(G) by the power iteration, and a bound on the work of one iteration.
constexpr int kMaxBacktracking = 60;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

template <class Model>
SolverResult run_sor(Model& model, std::vector<Vector3>& lambda, const SolverOptions& options) {
  const auto start = Clock::now();
  SolverResult result;
  result.solver = "SOR";
  const std::vector<RFactors> r = model_r_factors(model, options.r_strategy, options.alpha);
  model.synchronize();
  Monitor<Model> monitor(model, options, lambda, result);
  // The test sits at the end of the body: with max_iterations = INT_MAX the loop must stop
  // before ++k overflows.
  for (int k = 1;; ++k) {
    monitor.before();
    model.sor_sweep(r, options.form);
    if (monitor.after(k) || k == options.max_iterations) break;
  }
  monitor.finish();
  result.seconds = seconds_since(start);
  return result;
}

template <class Model>
SolverResult run_jor(Model& model, std::vector<Vector3>& lambda, const SolverOptions& options) {
  const auto start = Clock::now();
  SolverResult result;
  result.solver = "JOR";
  const std::vector<RFactors> r = model_r_factors(model, options.r_strategy, options.alpha);
  model.synchronize();
  Monitor<Model> monitor(model, options, lambda, result);
  std::vector<Vector3> xi;
  for (int k = 1;; ++k) {  // stops at max_iterations at the end of the body, as run_sor
    monitor.before();
    model.velocities(lambda, xi);
    for (std::size_t i = 0; i < lambda.size(); ++i) {
      lambda[i] = prox_update(options.form, lambda[i], xi[i], r[i], model.mu(i));
    }
    model.record(xi, options.criterion == Criterion::velocity_change);
    if (monitor.after(k) || k == options.max_iterations) break;
  }
  model.done();
  monitor.finish();
  result.seconds = seconds_since(start);
  return result;
}

/// λ_max(G) by power iteration from a fixed start vector, with the linear part G of ξ(Λ) applied
/// directly (Model::apply_G), not as ξ(x) − ξ(0): that difference loses G x in the rounding
/// of ξ(0) = c when ‖G x‖ ≪ ‖c‖ (a problem with c ≈ 10²⁰⁰, or with G ≈ 10⁻³⁰⁰).
template <class Model>
double largest_eigenvalue(const Model& model, int iterations) {
  const std::size_t n = model.size();
  std::vector<Vector3> x(n, Vector3(1.0, 0.5, 0.25)), y;
  double estimate = 0.0;
  for (int k = 0; k < iterations; ++k) {
    const double scale = norm(x);
    if (!(scale > 0.0) || !std::isfinite(scale)) break;
    for (Vector3& v : x) v /= scale;
    model.apply_G(x, y);
    estimate = norm(y);
    x.swap(y);
  }
  return estimate;
}

template <class Model>
SolverResult run_apgd(Model& model, std::vector<Vector3>& lambda, const SolverOptions& options) {
  const auto start = Clock::now();
  SolverResult result;
  result.solver = "APGD";
  const std::size_t n = model.size();
  model.synchronize();
  Monitor<Model> monitor(model, options, lambda, result);
  // Step t = α/L. L starts from a power-iteration estimate of λ_max(G) and is doubled whenever
  // the step fails the sufficient-decrease test of the quadratic part,
  // (x − y)ᵀ G (x − y) ≤ L ‖x − y‖² (backtracking, as in Mazhar et al. 2015); it shrinks by 10 %
  // after each accepted step so that it follows the local curvature.
  double L = largest_eigenvalue(model, 20);
  if (!(L > 0.0)) L = 1.0;

  std::vector<Vector3> x_prev = lambda, y = lambda, xi_x, xi_prev, xi_y;
  model.velocities(x_prev, xi_prev);
  xi_y = xi_prev;
  double theta = 1.0;
  // The De Saxcé offset s_i = μ_i ‖ξ_T,i‖, frozen for a cycle of at most kCycle iterations.
  constexpr int kCycle = 25;
  const auto offset = [&](std::size_t i, const Vector3& xi) {
    return model.mu(i) * norm2d(xi(1), xi(2));
  };
  std::vector<double> s(n);
  for (std::size_t i = 0; i < n; ++i) s[i] = offset(i, xi_prev[i]);
  int last_update = 0;
  // Restart at iteration k: drop the momentum and take the offsets of the current iterate x.
  const auto restart = [&](int k) {
    theta = 1.0;
    for (std::size_t i = 0; i < n; ++i) s[i] = offset(i, xi_x[i]);
    last_update = k;
  };
  bool frictional = false;
  for (std::size_t i = 0; i < n; ++i) frictional = frictional || model.mu(i) > 0.0;
  for (int k = 1;; ++k) {  // stops at max_iterations at the end of the body, as run_sor
    monitor.before();
    for (int attempt = 0;; ++attempt) {
      // x = P_K(y − t (ξ(y) + μ ‖ξ_T(y)‖ e_N)): one De Saxcé prox step from the extrapolated
      // point.
      const double t = options.alpha / L;
      for (std::size_t i = 0; i < n; ++i) {
        Vector3 g = xi_y[i];
        g(0) += s[i];
        lambda[i] = prox_cone(y[i] - t * g, model.mu(i));
      }
      model.velocities(lambda, xi_x);
      // G (x − y) = ξ(x) − ξ(y): ξ is affine in Λ. Both sides of the test are divided by
      // d² = max |x − y|², so that neither overflows nor underflows for percussions of 10²⁰⁰
      // or 10⁻²⁰⁰ (a NaN from ∞ − ∞ would fail the test and drive L up for good).
      double d = 0.0;
      for (std::size_t i = 0; i < n; ++i) d = std::max(d, (lambda[i] - y[i]).cwiseAbs().maxCoeff());
      // No step; or a step to ∞ or NaN, which the monitor reports as divergence: backtracking
      // would only hide an iterate that overflows, as the solution of the problem does.
      if (!(d > 0.0) || !std::isfinite(d)) break;
      double curvature = 0.0;
      double step2 = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const Vector3 dx = (lambda[i] - y[i]) / d;
        curvature += dx.dot((xi_x[i] - xi_y[i]) / d);
        step2 += dx.squaredNorm();
      }
      if (curvature <= L * step2 * (1.0 + 1e-12) || attempt == kMaxBacktracking) break;
      L *= 2.0;
    }
    // Adaptive restart (O'Donoghue and Candès 2015): drop the momentum when the step goes against
    // the direction of descent, g(y)ᵀ(x − x_prev) > 0.
    // Only the sign counts: both factors are scaled by their largest component.
    double g_max = 0.0;
    double step_max = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      Vector3 g = xi_y[i];
      g(0) += s[i];
      g_max = std::max(g_max, g.cwiseAbs().maxCoeff());
      step_max = std::max(step_max, (lambda[i] - x_prev[i]).cwiseAbs().maxCoeff());
    }
    double against = 0.0;
    if (g_max > 0.0 && step_max > 0.0) {
      for (std::size_t i = 0; i < n; ++i) {
        Vector3 g = xi_y[i];
        g(0) += s[i];
        against += (g / g_max).dot((lambda[i] - x_prev[i]) / step_max);
      }
    }
    double beta = 0.0;
    if (against > 0.0 || (frictional && k - last_update >= kCycle)) {
      // Restart, and take the cone offset s = μ ‖ξ_T‖ of the current iterate: each cycle solves
      // the convex problem with a fixed s (Anitescu's relaxation shifted by s), whose fixed point
      // over the cycles is Coulomb's law.
      restart(k);
    } else {
      const double theta_next = 0.5 * (-theta * theta + theta * std::sqrt(theta * theta + 4.0));
      beta = theta * (1.0 - theta) / (theta * theta + theta_next);
      theta = theta_next;
    }
    // ξ is affine in Λ, so ξ(y) follows from ξ(x) and ξ(x_prev) without another product.
    for (std::size_t i = 0; i < n; ++i) {
      y[i] = lambda[i] + beta * (lambda[i] - x_prev[i]);
      xi_y[i] = xi_x[i] + beta * (xi_x[i] - xi_prev[i]);
    }
    x_prev = lambda;
    xi_prev = xi_x;
    L *= 0.9;
    model.record(xi_x, options.criterion == Criterion::velocity_change);
    if (monitor.after(k)) {
      if (result.diverged || !frictional || options.criterion == Criterion::natural_residual) break;
      // Percussions or velocities that stopped changing within a cycle are the solution of this
      // cycle's convex problem, with the offset s frozen; they solve Coulomb's law only if s is
      // also the offset μ ‖ξ_T‖ of the iterate itself. Otherwise refresh s, restart and go on.
      bool consistent = true;
      for (std::size_t i = 0; i < n && consistent; ++i) {
        const double s_now = offset(i, xi_x[i]);
        consistent = std::abs(s_now - s[i]) <= options.abs_tol + options.rel_tol * s_now;
      }
      if (consistent) break;
      result.converged = false;
      restart(k);
      y = lambda;
      xi_y = xi_x;
    }
    if (k == options.max_iterations) break;
  }
  model.done();
  monitor.finish();
  result.seconds = seconds_since(start);
  return result;
}

SolverResult solve_body(const ContactProblem& problem, ContactSolution& solution,
                        const SolverOptions& options, const char* name,
                        SolverResult (*method)(BodyModel&, std::vector<Vector3>&,
                                               const SolverOptions&)) {
  validate_options(options, name);
  validate(problem);
  prepare_guess(solution.lambda, problem.contacts.size(), name);
  BodyModel model(problem, solution.lambda);
  SolverResult result = method(model, solution.lambda, options);
  solution.u = std::move(model.u);
  return result;
}

SolverResult solve_local(const LocalProblem& problem, std::vector<Vector3>& lambda,
                         const SolverOptions& options, const char* name,
                         SolverResult (*method)(LocalModel&, std::vector<Vector3>&,
                                                const SolverOptions&)) {
  validate_options(options, name);
  validate(problem);
  prepare_guess(lambda, problem.q.size(), name);
  LocalModel model(problem, lambda);
  return method(model, lambda, options);
}

}  // namespace

std::vector<RFactors> r_factors(const ContactProblem& problem, RFactorStrategy strategy,
                                double alpha) {
  // The solvers check these once before they compute r-factors; here the caller gets the same.
  SolverOptions options;
  options.alpha = alpha;
  validate_options(options, "r_factors");
  validate(problem);
  std::vector<Vector3> none;
  return model_r_factors(BodyModel(problem, none), strategy, alpha);
}

std::string describe(const SolverResult& result) {
  char line[256];
  std::snprintf(line, sizeof line,
                "%s %s after %d iterations: residual %.3e, relative to |q| %.3e, to max(|q|, "
                "|r|, |u|) %.3e, %.3f ms",
                result.solver.c_str(),
                result.converged  ? "converged"
                : result.diverged ? "DIVERGED (an iterate is not finite)"
                                  : "did NOT converge",
                result.iterations, result.residual, result.relative_residual(),
                result.scaled_residual(), 1e3 * result.seconds);
  return line;
}

SolverResult solve_sor(const ContactProblem& problem, ContactSolution& solution,
                       const SolverOptions& options) {
  return solve_body(problem, solution, options, "solve_sor", run_sor<BodyModel>);
}
SolverResult solve_jor(const ContactProblem& problem, ContactSolution& solution,
                       const SolverOptions& options) {
  return solve_body(problem, solution, options, "solve_jor", run_jor<BodyModel>);
}
SolverResult solve_apgd(const ContactProblem& problem, ContactSolution& solution,
                        const SolverOptions& options) {
  return solve_body(problem, solution, options, "solve_apgd", run_apgd<BodyModel>);
}
SolverResult solve_sor(const LocalProblem& problem, std::vector<Vector3>& lambda,
                       const SolverOptions& options) {
  return solve_local(problem, lambda, options, "solve_sor", run_sor<LocalModel>);
}
SolverResult solve_jor(const LocalProblem& problem, std::vector<Vector3>& lambda,
                       const SolverOptions& options) {
  return solve_local(problem, lambda, options, "solve_jor", run_jor<LocalModel>);
}
SolverResult solve_apgd(const LocalProblem& problem, std::vector<Vector3>& lambda,
                        const SolverOptions& options) {
  return solve_local(problem, lambda, options, "solve_apgd", run_apgd<LocalModel>);
}

}  // namespace grbd::contact
