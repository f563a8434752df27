/// \file
/// \brief JOR, SOR, APGD and semismooth Newton for the body form and the local form of the
/// contact problem.
///
/// One driver (iterate()) runs the loop of all four methods; each method is a policy with one
/// iteration, the synchronisation of u for the hook, the acceptance of a met criterion (APGD's
/// cone-offset check) and the end. The policies are written once, over a small "model" that
/// knows how to evaluate the contact velocities ξ(Λ) of one form and how to do a Gauss–Seidel
/// sweep in it: BodyModel keeps the body velocities u in step with Λ (u = u_free + M⁻¹ W Λ),
/// LocalModel reads block rows of W. Every buffer lives in a Workspace that keeps its capacity
/// between solves (ContactSolver), so that a repeated solve allocates nothing.

#include "grbd/contact/solver.hpp"

#include "grbd/contact/compact.hpp"

#include <Eigen/SparseLU>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "grbd/contact/delassus.hpp"
#include "grbd/contact/newton.hpp"
#include "grbd/contact/prox.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/norms.hpp"

namespace grbd::contact {

/// The buffers of every solve, kept between solves by ContactSolver. Each is resized (never
/// shrunk) to the problem at hand; vector::assign and resize reuse the capacity.
struct detail::SolverWorkspace {
  std::vector<Matrix3> G;             ///< body form: G_ii, computed by ContactSolver::solve()
  std::vector<RFactors> r;            ///< r-factors of JOR and SOR
  std::vector<double> mu;             ///< μ_i, for the natural map
  std::vector<Vector3> xi;            ///< ξ of the monitor (‖c‖, residual)
  std::vector<Vector3> lambda_old;    ///< Λ before the iteration (percussion criterion)
  std::vector<double> velocity_old;   ///< u or ξ before the iteration (velocity criterion)
  std::vector<Vector6> v;             ///< body form: scratch body velocities
  std::vector<Vector3> seen;          ///< local form: ξ of the last iteration
  std::vector<Vector3> jor_xi;        ///< JOR: ξ of the old iterate
  std::vector<Vector3> x_prev, y, xi_x, xi_prev, xi_y;  ///< APGD iterates and their ξ
  std::vector<double> s;              ///< APGD: cone offsets
  std::vector<Vector3> power_x, power_y;  ///< power iteration
  /// Newton: Φ and the Jacobian blocks per contact, the preconditioner's blocks, the direction d
  /// and W d, the trial point and its ξ, the merits of the last iterates, GMRES's buffers, the
  /// assembled J and its factorization (direct)
  std::vector<AlartCurnierJacobian> ac;
  std::vector<Matrix3> precond;
  std::vector<Vector3> d, wd, trial, trial_xi, x3, y3;
  std::vector<double> merits, rhs, step;
  GmresWorkspace gmres;
  BlockSparseMatrix W;                ///< W assembled (body and compact forms, direct)
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::SparseMatrix<double> jacobian;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
};

namespace {

using Workspace = detail::SolverWorkspace;

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

/// natural_map_residual() without its allocation in the rare cases: the same sum in the same
/// order, so the same result; an exactly zero F (a solve that ends on the exact solution) is 0
/// here, and only a sum that over- or underflows is handed to natural_map_residual(), which
/// rescales.
double residual_norm(std::span<const Vector3> lambda, std::span<const Vector3> xi,
                     std::span<const double> mu) {
  double sum = 0.0;
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    sum += natural_map(lambda[i], xi[i], mu[i]).squaredNorm();
  }
  if (sum >= std::numeric_limits<double>::min() && sum <= std::numeric_limits<double>::max()) {
    return std::sqrt(sum);
  }
  if (sum == 0.0) {
    bool zero = true;
    for (std::size_t i = 0; i < lambda.size() && zero; ++i) {
      zero = natural_map(lambda[i], xi[i], mu[i]).isZero(0.0);
    }
    if (zero) return 0.0;
  }
  return natural_map_residual(lambda, xi, mu);
}

/// Refuses bad options; builds a message (and allocates) only when it throws.
void validate_options(const SolverOptions& o, const char* solver) {
  const auto where = [&] { return std::string(solver) + ": "; };
  if (o.min_iterations < 0 || o.max_iterations < 1 || o.max_iterations < o.min_iterations) {
    throw InvalidArgument(where() +
                          "expected 0 <= min_iterations <= max_iterations and "
                          "max_iterations >= 1; found min_iterations = " +
                          std::to_string(o.min_iterations) +
                          ", max_iterations = " + std::to_string(o.max_iterations));
  }
  if (!(o.abs_tol >= 0.0) || !(o.rel_tol >= 0.0) || !std::isfinite(o.abs_tol) ||
      !std::isfinite(o.rel_tol)) {
    throw InvalidArgument(where() + "expected finite tolerances >= 0; found abs_tol = " +
                          format_number(o.abs_tol) + ", rel_tol = " + format_number(o.rel_tol));
  }
  if (!(o.alpha > 0.0 && o.alpha < 2.0)) {
    throw InvalidArgument(where() + "expected the relaxation alpha in (0, 2); found " +
                          format_number(o.alpha));
  }
  // An enum holds any value of its underlying type: a cast or a corrupted options struct would
  // otherwise fall through every switch.
  const auto refuse_enum = [&](const char* name, int value, const char* expected) {
    throw InvalidArgument(where() + "expected " + name + " to be one of " + expected +
                          "; found the value " + std::to_string(value));
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
    case RFactorStrategy::spectral:
    case RFactorStrategy::automatic:
      break;
    default:
      refuse_enum("r_strategy", static_cast<int>(o.r_strategy),
                  "per_contact, global, spectral, automatic");
  }
  switch (o.form) {
    case ProxForm::alart_curnier:
    case ProxForm::de_saxce:
      break;
    default:
      refuse_enum("form", static_cast<int>(o.form), "alart_curnier, de_saxce");
  }
  switch (o.newton.linear_solver) {
    case LinearSolver::automatic:
    case LinearSolver::direct:
    case LinearSolver::gmres:
      break;
    default:
      refuse_enum("newton.linear_solver", static_cast<int>(o.newton.linear_solver),
                  "automatic, direct, gmres");
  }
  const NewtonOptions& n = o.newton;
  if (n.krylov_restart < 1 || n.max_linear_iterations < 1 || n.line_search_memory < 1 ||
      n.fallback_sweeps < 1) {
    throw InvalidArgument(where() +
                          "expected newton.krylov_restart, max_linear_iterations, "
                          "line_search_memory and fallback_sweeps >= 1; found " +
                          std::to_string(n.krylov_restart) + ", " +
                          std::to_string(n.max_linear_iterations) + ", " +
                          std::to_string(n.line_search_memory) + ", " +
                          std::to_string(n.fallback_sweeps));
  }
  if (n.hybrid_sweeps < 0 || !(n.hybrid_stagnation > 0.0 && n.hybrid_stagnation <= 1.0)) {
    throw InvalidArgument(where() +
                          "expected newton.hybrid_sweeps >= 0 and newton.hybrid_stagnation in "
                          "(0, 1]; found " +
                          std::to_string(n.hybrid_sweeps) + ", " +
                          format_number(n.hybrid_stagnation));
  }
}

void validate_method(Method method, const char* where) {
  switch (method) {
    case Method::sor:
    case Method::jor:
    case Method::apgd:
    case Method::newton:
      return;
  }
  throw InvalidArgument(std::string(where) +
                        ": expected the method to be one of sor, jor, apgd, newton; found the "
                        "value " +
                        std::to_string(static_cast<int>(method)));
}

/// `automatic` made concrete for `method`.
RFactorStrategy resolve(RFactorStrategy strategy, Method method) {
  if (strategy != RFactorStrategy::automatic) return strategy;
  return method == Method::jor ? RFactorStrategy::spectral : RFactorStrategy::per_contact;
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

/// Before the first iteration, in passes over all contacts: the per-contact r-factors into *r
/// (when r is given), u in step with the initial Λ, and ‖c‖ = ‖ξ(0)‖, returned.
template <class Model>
double prepare_in_passes(Model& model, std::vector<RFactors>* r, double alpha, Workspace& ws) {
  if (r != nullptr) {
    r->resize(model.size());
    for (std::size_t i = 0; i < r->size(); ++i) (*r)[i] = r_factors(model.delassus(i), alpha);
  }
  model.synchronize();
  model.free_velocities(ws.xi);
  return norm(ws.xi);
}

/// μ_i of every contact into ws.mu, for the natural map.
template <class Model>
void gather_mu(const Model& model, Workspace& ws) {
  ws.mu.resize(model.size());
  for (std::size_t i = 0; i < ws.mu.size(); ++i) ws.mu[i] = model.mu(i);
}

/// After the last iteration, in passes: ξ(Λ) evaluated afresh from Λ, the natural residual,
/// norm_max = max(‖c‖, ‖Λ‖, ‖ξ‖). A non-finite Λ or residual is divergence, never convergence.
template <class Model>
void summarize_in_passes(Model& model, Workspace& ws, SolverResult& result) {
  gather_mu(model, ws);
  const std::span<const Vector3> lambda = model.lambda();
  model.velocities(lambda, ws.xi);
  result.residual = residual_norm(lambda, ws.xi, ws.mu);
  result.norm_max = std::max({result.norm_c, norm(lambda), norm(ws.xi)});
  if (!all_finite(lambda) || !std::isfinite(result.residual)) {
    result.diverged = true;
    result.converged = false;
  }
}

/// A sum of squares with its largest magnitude: the plain square root where the sum is neither
/// zero nor out of range, else "ask the careful pass" (−1), as euclidean_norm() decides.
struct SquareSum {
  double sum = 0.0;
  double largest = 0.0;
  void add(const Vector3& v) {
    for (int k = 0; k < 3; ++k) sum += v(k) * v(k);
    largest = std::max(largest, v.cwiseAbs().maxCoeff());
  }
  double norm() const {
    if (largest == 0.0 && sum == 0.0) return 0.0;
    if (sum >= std::numeric_limits<double>::min() && sum <= std::numeric_limits<double>::max()) {
      return std::sqrt(sum);
    }
    return -1.0;
  }
};

/// The body form: Λ and the body velocities u that go with it (the caller's ContactSolution).
class BodyModel {
 public:
  BodyModel(const ContactProblem& problem, std::span<const Matrix3> G, std::span<Vector3> lambda,
            std::vector<Vector6>& u, Workspace& ws)
      : problem_(problem), G_(G), lambda_(lambda), u_(u), ws_(ws) {}

  std::size_t size() const { return problem_.contacts.size(); }
  double mu(std::size_t i) const { return problem_.contacts[i].mu; }
  const Matrix3& delassus(std::size_t i) const { return G_[i]; }
  std::span<Vector3> lambda() const { return lambda_; }
  std::span<Vector6> u() const { return u_; }

  /// ξ(Λ) for the given percussions (not necessarily the model's own): the same operations as
  /// contact_velocities(problem, velocities_from_percussions(problem, Λ)), into the workspace.
  void velocities(std::span<const Vector3> lambda, std::vector<Vector3>& xi) {
    body_velocities(lambda, ws_.v);
    contact_velocities_of(ws_.v, xi);
  }
  /// ξ(0) = c, the free contact velocities.
  void free_velocities(std::vector<Vector3>& xi) {
    ws_.v.assign(problem_.u_free.begin(), problem_.u_free.end());
    contact_velocities_of(ws_.v, xi);
  }
  /// y = G x = Wᵀ M⁻¹ W x, the linear part of ξ(Λ), without u_free or restitution.
  void apply_G(std::span<const Vector3> x, std::vector<Vector3>& y) {
    std::vector<Vector6>& v = ws_.v;
    v.assign(problem_.M_inv.size(), Vector6::Zero());
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
  /// W = Wᵀ M⁻¹ W assembled, for Newton's direct linear solver.
  void assemble(BlockSparseMatrix& W) const { assemble_delassus(problem_, W); }
  /// Makes u consistent with Λ.
  void synchronize() { body_velocities(lambda_, u_); }
  /// Brings the body velocities u of the hook up to date with Λ.
  void update_u() { synchronize(); }
  /// After JOR or APGD changed all of Λ at once: u follows Λ only when the velocity criterion
  /// reads it, and once more at the end (done()), instead of a full pass every iteration.
  void record(const std::vector<Vector3>& /*xi*/, bool velocity_watched) {
    if (velocity_watched) synchronize();
  }
  /// Brings u up to date with the returned Λ.
  void done() { synchronize(); }
  void sor_sweep(std::span<const RFactors> r, ProxForm form) {
    contact::sor_sweep(problem_, r, form, u_, lambda_);
  }
  /// What the velocity criterion watches.
  std::span<const double> watched_velocity() const { return flat(std::span<const Vector6>(u_)); }
  /// Whether every percussion is finite (the divergence test of every iteration).
  bool lambda_finite() const { return all_finite(lambda_); }
  /// Λ or u changed outside the model (the hook).
  void touched() {}
  /// r-factors, u and ‖c‖ before the first iteration (prepare_in_passes()).
  double prepare(std::vector<RFactors>* r, double alpha) {
    return prepare_in_passes(*this, r, alpha, ws_);
  }
  /// Residual and norms after the last (summarize_in_passes()).
  void summarize(SolverResult& result) { summarize_in_passes(*this, ws_, result); }

 private:
  /// u = u_free + M⁻¹ W Λ, as velocities_from_percussions() computes it.
  void body_velocities(std::span<const Vector3> lambda, std::vector<Vector6>& u) const {
    u.assign(problem_.u_free.begin(), problem_.u_free.end());
    for (std::size_t i = 0; i < lambda.size(); ++i) {
      const ContactConstraint& c = problem_.contacts[i];
      if (c.body_a != kStatic) u[c.body_a] += problem_.M_inv[c.body_a].apply(c.W_a * lambda[i]);
      if (c.body_b != kStatic) u[c.body_b] -= problem_.M_inv[c.body_b].apply(c.W_b * lambda[i]);
    }
  }
  /// ξ_i = W_iᵀ u + ε_i ∘ γ_A,i, as contact_velocities() computes it.
  void contact_velocities_of(std::span<const Vector6> u, std::vector<Vector3>& xi) const {
    xi.resize(size());
    for (std::size_t i = 0; i < xi.size(); ++i) {
      const ContactConstraint& c = problem_.contacts[i];
      Vector3 gamma = Vector3::Zero();
      if (c.body_a != kStatic) gamma += c.W_a.transpose() * u[c.body_a];
      if (c.body_b != kStatic) gamma -= c.W_b.transpose() * u[c.body_b];
      xi[i] = impact_velocity(gamma, c.gamma_A, c.eps_N, c.eps_T);
    }
  }

  const ContactProblem& problem_;
  std::span<const Matrix3> G_;
  std::span<Vector3> lambda_;
  std::vector<Vector6>& u_;
  Workspace& ws_;
};

/// The local form ξ = W Λ + q.
class LocalModel {
 public:
  LocalModel(const LocalProblem& problem, std::span<Vector3> lambda, Workspace& ws)
      : problem_(problem), lambda_(lambda), ws_(ws) {}

  std::size_t size() const { return problem_.q.size(); }
  double mu(std::size_t i) const { return problem_.mu[i]; }
  const Matrix3& delassus(std::size_t i) const {
    return problem_.W.blocks[static_cast<std::size_t>(problem_.W.diagonal[i])];
  }
  std::span<Vector3> lambda() const { return lambda_; }
  /// No body velocities in the local form.
  std::span<Vector6> u() const { return {}; }

  void velocities(std::span<const Vector3> lambda, std::vector<Vector3>& xi) const {
    xi.resize(size());
    multiply(problem_.W, lambda, xi);
    for (std::size_t i = 0; i < xi.size(); ++i) xi[i] += problem_.q[i];
  }
  /// ξ(0) = q.
  void free_velocities(std::vector<Vector3>& xi) const {
    xi.assign(problem_.q.begin(), problem_.q.end());
  }
  /// y = W x, the linear part of ξ(Λ).
  void apply_G(std::span<const Vector3> x, std::vector<Vector3>& y) const {
    y.resize(size());
    multiply(problem_.W, x, y);
  }
  void synchronize() { ws_.seen.assign(size(), Vector3::Zero()); }
  /// No body velocities to bring up to date.
  void update_u() {}
  void sor_sweep(std::span<const RFactors> r, ProxForm form) {
    const BlockSparseMatrix& W = problem_.W;
    for (std::size_t i = 0; i < size(); ++i) {
      Vector3 xi = problem_.q[i];
      for (std::int64_t k = W.row_start[i]; k < W.row_start[i + 1]; ++k) {
        xi.noalias() += W.blocks[k] * lambda_[W.column[k]];
      }
      ws_.seen[i] = xi;
      lambda_[i] = prox_update(form, lambda_[i], xi, r[i], problem_.mu[i]);
    }
  }
  std::span<const double> watched_velocity() const {
    return flat(std::span<const Vector3>(ws_.seen));
  }
  /// After JOR or APGD changed all of Λ at once: keeps the velocities ξ of the iteration for the
  /// velocity criterion.
  void record(const std::vector<Vector3>& xi, bool velocity_watched) {
    if (velocity_watched) ws_.seen.assign(xi.begin(), xi.end());
  }
  /// Nothing to bring up to date: the local form has no body velocities.
  void done() {}
  /// Whether every percussion is finite (the divergence test of every iteration).
  bool lambda_finite() const { return all_finite(lambda_); }
  /// Λ changed outside the model (the hook).
  void touched() {}
  /// r-factors, the seen ξ and ‖q‖ before the first iteration (prepare_in_passes()).
  double prepare(std::vector<RFactors>* r, double alpha) {
    return prepare_in_passes(*this, r, alpha, ws_);
  }
  /// Residual and norms after the last (summarize_in_passes()).
  void summarize(SolverResult& result) { summarize_in_passes(*this, ws_, result); }
  /// W itself, for Newton's direct linear solver.
  const BlockSparseMatrix& block_matrix() const { return problem_.W; }

 private:
  const LocalProblem& problem_;
  std::span<Vector3> lambda_;
  Workspace& ws_;
};

/// The compact form (chapter 6): world-frame body velocities and contacts that keep their frame
/// and lever arms. The same operations as BodyModel, with W applied from (n, t1, r).
class CompactModel {
 public:
  CompactModel(const CompactProblem& problem, std::span<Vector3> lambda, std::vector<Vector6>& u,
               Workspace& ws)
      : problem_(problem), lambda_(lambda), u_(u), ws_(ws) {}

  std::size_t size() const { return problem_.contacts.size(); }
  double mu(std::size_t i) const { return problem_.contacts[i].mu; }
  /// G_ii, computed when asked (the r-factors ask once per solve): not stored.
  Matrix3 delassus(std::size_t i) const { return delassus_block(problem_.contacts[i], problem_.M_inv); }
  std::span<Vector3> lambda() const { return lambda_; }
  std::span<Vector6> u() const { return u_; }

  void velocities(std::span<const Vector3> lambda, std::vector<Vector3>& xi) {
    body_velocities(lambda, ws_.v);
    contact_velocities_of(ws_.v, xi);
  }
  void free_velocities(std::vector<Vector3>& xi) {
    ws_.v.assign(problem_.u_free.begin(), problem_.u_free.end());
    contact_velocities_of(ws_.v, xi);
  }
  /// ξ from the body velocities as they are (SOR keeps them in step with Λ).
  void current_velocities(std::vector<Vector3>& xi) const { contact_velocities_of(u_, xi); }
  void apply_G(std::span<const Vector3> x, std::vector<Vector3>& y) {
    std::vector<Vector6>& v = ws_.v;
    v.assign(problem_.M_inv.size(), Vector6::Zero());
    for (std::size_t i = 0; i < size(); ++i) {
      add_percussion(problem_.contacts[i], x[i], problem_.M_inv, v);
    }
    y.resize(size());
    for (std::size_t i = 0; i < size(); ++i) y[i] = contact_velocity(problem_.contacts[i], v);
  }
  /// W = Wᵀ M⁻¹ W assembled, for Newton's direct linear solver.
  void assemble(BlockSparseMatrix& W) const { assemble_delassus(problem_, W); }
  void synchronize() { body_velocities(lambda_, u_); }
  void update_u() { synchronize(); }
  void record(const std::vector<Vector3>& /*xi*/, bool velocity_watched) {
    if (velocity_watched) synchronize();
  }
  void done() { synchronize(); }
  void sor_sweep(std::span<const RFactors> r, ProxForm form) {
    sweep_ = contact::sor_sweep(problem_, r, form, u_, lambda_, change_abs_, change_rel_,
                                residual_in_sweep_);
    sweep_fresh_ = true;
    residual_fresh_ = true;
  }
  /// Whether the next sweeps also sum the natural map of the contacts they update
  /// (SweepReport::residual), which the natural-residual criterion reads before it pays for ‖F‖.
  void sum_residual_in_sweep(bool on) { residual_in_sweep_ = on; }
  /// The last sweep's natural-map residual, or −1 when it was not summed or Λ was changed since.
  double sweep_residual() const { return residual_fresh_ ? sweep_.residual : -1.0; }
  /// From now on each sweep also applies the percussion criterion to its own change of Λ (the
  /// monitor then keeps no copy of Λ).
  void test_change_in_sweep(double abs_tol, double rel_tol) {
    change_abs_ = abs_tol;
    change_rel_ = rel_tol;
  }
  /// The last sweep's verdict on the percussion criterion.
  bool sweep_settled() const { return sweep_.settled; }

  /// The caller's reference ‖c‖ (CompactProblem::reference_norm; 0: none).
  double reference_norm() const { return problem_.reference_norm; }

  /// One pass over the contacts instead of three (start_solve()): r-factors from the diagonal of
  /// G_ii (when r is given), c_i = ξ_i(0) for ‖c‖, and the initial percussions added to
  /// u = u_free + M⁻¹ W Λ. A sum of squares that is zero or out of range goes to the careful
  /// passes.
  double prepare(std::vector<RFactors>* r, double alpha) {
    if (r != nullptr) r->resize(size());
    const double sum = start_solve(problem_, lambda_, alpha,
                                   r != nullptr ? std::span<RFactors>(*r) : std::span<RFactors>(),
                                   u_);
    if (sum >= std::numeric_limits<double>::min() && sum <= std::numeric_limits<double>::max()) {
      return std::sqrt(sum);
    }
    free_velocities(ws_.xi);
    return norm(ws_.xi);
  }

  /// One pass instead of five: ξ = Wᵀu + xi_A from the u the solver returns, which every method
  /// keeps in step with Λ (SOR after each update, JOR and APGD in done()), the natural map and
  /// the norms. The residual is that of (Λ, u) as returned; it differs from one evaluated with u
  /// recomputed from Λ by the rounding of the accumulated updates. Sums that are zero or out of
  /// range, and non-finite ones, go to the careful passes.
  void summarize(SolverResult& result) {
    SquareSum F, lambda, xi;
    bool F_zero = true;
    for (std::size_t i = 0; i < size(); ++i) {
      const CompactContact& c = problem_.contacts[i];
      const Vector3 x = contact_velocity(c, u_) + c.xi_A;
      const Vector3 f = natural_map(lambda_[i], x, c.mu);
      F.sum += f.squaredNorm();
      F_zero = F_zero && f.isZero(0.0);
      lambda.add(lambda_[i]);
      xi.add(x);
    }
    const double norm_l = lambda.norm();
    const double norm_x = xi.norm();
    const bool F_ok = (F.sum == 0.0 && F_zero) || (F.sum >= std::numeric_limits<double>::min() &&
                                                   F.sum <= std::numeric_limits<double>::max());
    if (!F_ok || norm_l < 0.0 || norm_x < 0.0) {
      summarize_in_passes(*this, ws_, result);
      return;
    }
    result.residual = std::sqrt(F.sum);
    result.norm_max = std::max({result.norm_c, norm_l, norm_x});
  }
  std::span<const double> watched_velocity() const { return flat(std::span<const Vector6>(u_)); }
  /// After a sweep the sweep's own test (no second pass over Λ); else a pass.
  bool lambda_finite() {
    if (sweep_fresh_) {
      sweep_fresh_ = false;
      return sweep_.finite;
    }
    return all_finite(lambda_);
  }
  /// The hook may have changed Λ: the sweep's test no longer speaks for it.
  void touched() {
    sweep_fresh_ = false;
    residual_fresh_ = false;
  }

 private:
  void body_velocities(std::span<const Vector3> lambda, std::vector<Vector6>& u) const {
    velocities_from_percussions(problem_, lambda, u);
  }
  void contact_velocities_of(std::span<const Vector6> u, std::vector<Vector3>& xi) const {
    xi.resize(size());
    for (std::size_t i = 0; i < xi.size(); ++i) {
      const CompactContact& c = problem_.contacts[i];
      xi[i] = contact_velocity(c, u) + c.xi_A;
    }
  }

  const CompactProblem& problem_;
  std::span<Vector3> lambda_;
  std::vector<Vector6>& u_;
  Workspace& ws_;
  bool sweep_fresh_ = false;
  SweepReport sweep_;
  double change_abs_ = std::numeric_limits<double>::infinity();  // no test unless asked
  double change_rel_ = 0.0;
  bool residual_in_sweep_ = false;
  bool residual_fresh_ = false;  // sweep_.residual is that of the last sweep, Λ untouched since
};

/// How the power iteration starts.
enum class Start {
  apgd,       ///< (1, 0.5, 0.25) for every contact: APGD's estimate, as it always was
  scrambled,  ///< the same magnitudes with pseudo-random signs (spectral r-factors)
};

/// A sign ±1 from a hash of (i, k) (SplitMix64's finaliser): deterministic, no allocation.
double scrambled_sign(std::size_t i, int k) {
  std::uint64_t z = 3 * static_cast<std::uint64_t>(i) + static_cast<std::uint64_t>(k) +
                    0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return (z & 1U) != 0U ? -1.0 : 1.0;
}

/// λ_max(G) by power iteration from a fixed start vector, with the linear part G of ξ(Λ) applied
/// directly (Model::apply_G), not as ξ(x) − ξ(0): that difference loses G x in the rounding
/// of ξ(0) = c when ‖G x‖ ≪ ‖c‖ (a problem with c ≈ 10²⁰⁰, or with G ≈ 10⁻³⁰⁰).
template <class Model>
double largest_eigenvalue(Model& model, int iterations, Start start, Workspace& ws) {
  const std::size_t n = model.size();
  std::vector<Vector3>& x = ws.power_x;
  std::vector<Vector3>& y = ws.power_y;
  x.assign(n, Vector3(1.0, 0.5, 0.25));
  if (start == Start::scrambled) {
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) x[i](k) *= scrambled_sign(i, k);
    }
  }
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

/// The r-factors of `strategy` (not automatic) into ws.r.
template <class Model>
void compute_r_factors(Model& model, RFactorStrategy strategy, double alpha, Workspace& ws) {
  std::vector<RFactors>& r = ws.r;
  r.resize(model.size());
  if (strategy == RFactorStrategy::per_contact) {
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = r_factors(model.delassus(i), alpha);
    return;
  }
  double largest = 0.0;
  if (strategy == RFactorStrategy::global) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      largest = std::max(largest, model.delassus(i).diagonal().maxCoeff());
    }
  } else {  // spectral
    largest = spectral::kSafety *
              largest_eigenvalue(model, spectral::kPowerIterations, Start::scrambled, ws);
    if (!(largest > 0.0) || !std::isfinite(largest)) {
      // The start vector in the null space of G, or an overflow: trace(G) ≥ λ_max(G) for a
      // positive semidefinite G is a safe (if pessimistic) bound.
      largest = 0.0;
      for (std::size_t i = 0; i < r.size(); ++i) largest += model.delassus(i).trace();
    }
  }
  std::fill(r.begin(), r.end(), RFactors{alpha / largest, alpha / largest});
}

/// What the stopping test found after an iteration.
enum class Verdict { diverged, met, not_met };

/// The stopping test and the bookkeeping shared by the three methods.
template <class Model>
class Monitor {
 public:
  /// result.norm_c must be set (Model::prepare()). With `change_in_sweep` the model's sweep
  /// applies the percussion criterion itself (Model::sweep_settled()) and no copy of Λ is kept,
  /// or sums the natural-map residual of its updates (Model::sweep_residual()).
  /// `tolerance` is the natural-residual criterion's, this process's share of it (run()).
  Monitor(Model& model, const SolverOptions& options, Workspace& ws, SolverResult& result,
          bool change_in_sweep, double tolerance)
      : model_(model),
        options_(options),
        ws_(ws),
        result_(result),
        change_in_sweep_(change_in_sweep),
        tolerance_(tolerance) {
    // μ for the natural map of the iterations, where it is read.
    if (options.record_history || options.criterion == Criterion::natural_residual) {
      gather_mu(model, ws);
    }
  }

  /// Call before iteration k changes Λ. Before min_iterations the criterion is not read, so
  /// nothing is saved: a solve at a fixed number of iterations (min = max) pays for the test
  /// once.
  void before(int k) {
    if (k < options_.min_iterations) return;
    if (options_.criterion == Criterion::percussion_change && !change_in_sweep_) {
      const std::span<const Vector3> lambda = model_.lambda();
      ws_.lambda_old.assign(lambda.begin(), lambda.end());
    }
    if (options_.criterion == Criterion::velocity_change) {
      const auto v = model_.watched_velocity();
      ws_.velocity_old.assign(v.begin(), v.end());
    }
    if constexpr (requires { model_.sum_residual_in_sweep(true); }) {
      if (change_in_sweep_ && options_.criterion == Criterion::natural_residual) {
        model_.sum_residual_in_sweep(k >= next_residual_);
      }
    }
  }

  /// Call after iteration k (1-based) with the model up to date: `met` when the criterion holds
  /// from min_iterations on; `diverged` (and result.diverged) when an iterate is not finite,
  /// which stops the solver at once, whatever max_iterations says.
  Verdict after(int k) {
    result_.iterations = k;
    const std::span<const Vector3> lambda = model_.lambda();
    if (!model_.lambda_finite()) {
      result_.diverged = true;
      return Verdict::diverged;
    }
    double residual = -1.0;
    if (options_.record_history) {
      residual = natural_residual();
      result_.history.push_back(residual);
    }
    // Before min_iterations the criterion is not evaluated (before() saved nothing for it).
    if (k < options_.min_iterations) return Verdict::not_met;
    if (options_.criterion == Criterion::natural_residual && residual < 0.0) {
      // A sweep that summed its own residual: ‖F‖ is evaluated only once that sum has met the
      // tolerance (both vanish together at the solution), which saves a pass over the contacts
      // and the bodies in every sweep but the last few.
      if constexpr (requires { model_.sweep_residual(); }) {
        if (change_in_sweep_ && !sweep_residual_met(k)) return Verdict::not_met;
      }
      residual = natural_residual();
      next_residual_ = k + 1;  // a sweep that met it but ‖F‖ not: look again at the next
    }
    bool met = false;
    switch (options_.criterion) {
      case Criterion::percussion_change:
        if constexpr (requires { model_.sweep_settled(); }) {
          if (change_in_sweep_) {
            met = model_.sweep_settled();
            break;
          }
        }
        met = has_converged(flat(std::span<const Vector3>(ws_.lambda_old)), flat(lambda),
                            options_.abs_tol, options_.rel_tol);
        break;
      case Criterion::velocity_change:
        met = has_converged(ws_.velocity_old, model_.watched_velocity(), options_.abs_tol,
                            options_.rel_tol);
        break;
      case Criterion::natural_residual:
        met = residual <= tolerance_;
        break;
    }
    return met && k >= options_.min_iterations ? Verdict::met : Verdict::not_met;
  }

  /// The sweeps' own residual (SOR): summing it costs about half a sweep, so the sweeps sum it
  /// only where it may have met the tolerance. From two sums r₁ (sweep k₁) and r₂ (sweep k₂) the
  /// rate ρ = (r₂/r₁)^{1/(k₂−k₁)} predicts the sweeps n = ln(tol/r₂)/ln ρ still needed; the next
  /// sum is taken after half of them (1 to kMaxResidualStride sweeps), every sweep once within
  /// reach. True when this sweep summed its residual and it met the tolerance.
  bool sweep_residual_met(int k) {
    static constexpr int kMaxResidualStride = 16;
    const double r = model_.sweep_residual();
    if (r < 0.0) return false;  // not summed in this sweep
    if (r <= tolerance_) return true;
    int stride = 1;
    if (last_residual_ > 0.0 && r < last_residual_) {
      const double rate = std::log(r / last_residual_) / (k - last_residual_sweep_);
      const double needed = std::log(tolerance_ / r) / rate;
      stride = static_cast<int>(std::clamp(needed / 2.0, 1.0, double{kMaxResidualStride}));
    }
    last_residual_ = r;
    last_residual_sweep_ = k;
    next_residual_ = k + stride;
    return false;
  }

  /// ‖F(Λ)‖ of the current percussions. SOR's sweeps keep u in step with Λ, and a hook may have
  /// changed u since (the averaged velocities of split bodies, chapter 8): ξ from that u.
  double natural_residual() {
    if constexpr (requires { model_.current_velocities(ws_.xi); }) {
      if (change_in_sweep_) {
        model_.current_velocities(ws_.xi);
        return residual_norm(model_.lambda(), ws_.xi, ws_.mu);
      }
    }
    model_.velocities(model_.lambda(), ws_.xi);
    return residual_norm(model_.lambda(), ws_.xi, ws_.mu);
  }

  /// Fills residual and norm_max for the returned Λ (Model::summarize()). A non-finite Λ or
  /// residual is divergence, never convergence.
  void finish() { model_.summarize(result_); }

 private:
  Model& model_;
  const SolverOptions& options_;
  Workspace& ws_;
  SolverResult& result_;
  bool change_in_sweep_;
  double tolerance_;             // of the natural-residual criterion, this process's share
  int next_residual_ = 0;        // the next sweep that sums its residual
  double last_residual_ = -1.0;  // the last sum, and its sweep
  int last_residual_sweep_ = 0;
};

/// SOR: one Gauss–Seidel sweep per iteration; u is always in step with Λ.
template <class Model>
class SorPolicy {
 public:
  SorPolicy(Model& model, const SolverOptions& options, const Workspace& ws)
      : model_(model), form_(options.form), r_(ws.r) {}
  void iterate(int /*k*/) { model_.sor_sweep(r_, form_); }
  void synchronize_for_hook() {}
  bool accept(int /*k*/) { return true; }
  void finish() {}

 private:
  Model& model_;
  ProxForm form_;
  std::span<const RFactors> r_;
};

/// JOR: every contact updated from the velocities of the previous iterate.
template <class Model>
class JorPolicy {
 public:
  JorPolicy(Model& model, const SolverOptions& options, Workspace& ws)
      : model_(model),
        form_(options.form),
        velocity_watched_(options.criterion == Criterion::velocity_change),
        ws_(ws) {}
  void iterate(int /*k*/) {
    const std::span<Vector3> lambda = model_.lambda();
    model_.velocities(lambda, ws_.jor_xi);
    for (std::size_t i = 0; i < lambda.size(); ++i) {
      lambda[i] = prox_update(form_, lambda[i], ws_.jor_xi[i], ws_.r[i], model_.mu(i));
    }
    model_.record(ws_.jor_xi, velocity_watched_);
  }
  /// record() has synchronised u already when the velocity criterion watches it.
  void synchronize_for_hook() {
    if (!velocity_watched_) model_.update_u();
  }
  bool accept(int /*k*/) { return true; }
  void finish() { model_.done(); }

 private:
  Model& model_;
  ProxForm form_;
  bool velocity_watched_;
  Workspace& ws_;
};

/// APGD: a Nesterov step with backtracking on L and adaptive restart; the De Saxcé offset s is
/// frozen for a cycle, and a met criterion counts only when s is consistent with the iterate.
template <class Model>
class ApgdPolicy {
 public:
  ApgdPolicy(Model& model, const SolverOptions& options, Workspace& ws)
      : model_(model),
        options_(options),
        velocity_watched_(options.criterion == Criterion::velocity_change),
        ws_(ws) {
    const std::size_t n = model.size();
    // Step t = α/L. L starts from a power-iteration estimate of λ_max(G) and is doubled whenever
    // the step fails the sufficient-decrease test of the quadratic part,
    // (x − y)ᵀ G (x − y) ≤ L ‖x − y‖² (backtracking, as in Mazhar et al. 2015); it shrinks by
    // 10 % after each accepted step so that it follows the local curvature.
    L_ = largest_eigenvalue(model, apgd::kPowerIterations, Start::apgd, ws);
    if (!(L_ > 0.0)) L_ = apgd::kFallbackLipschitz;
    const std::span<const Vector3> lambda = model.lambda();
    ws.x_prev.assign(lambda.begin(), lambda.end());
    ws.y.assign(lambda.begin(), lambda.end());
    model.velocities(ws.x_prev, ws.xi_prev);
    ws.xi_y.assign(ws.xi_prev.begin(), ws.xi_prev.end());
    // The De Saxcé offset s_i = μ_i ‖ξ_T,i‖, frozen for a cycle of at most kOffsetCycle
    // iterations.
    ws.s.resize(n);
    for (std::size_t i = 0; i < n; ++i) ws.s[i] = offset(i, ws.xi_prev[i]);
    for (std::size_t i = 0; i < n; ++i) frictional_ = frictional_ || model.mu(i) > 0.0;
  }

  void iterate(int k) {
    const std::size_t n = model_.size();
    const std::span<Vector3> lambda = model_.lambda();
    std::vector<Vector3>& y = ws_.y;
    std::vector<Vector3>& x_prev = ws_.x_prev;
    std::vector<Vector3>& xi_x = ws_.xi_x;
    std::vector<Vector3>& xi_y = ws_.xi_y;
    std::vector<Vector3>& xi_prev = ws_.xi_prev;
    const std::vector<double>& s = ws_.s;
    for (int attempt = 0;; ++attempt) {
      // x = P_K(y − t (ξ(y) + μ ‖ξ_T(y)‖ e_N)): one De Saxcé prox step from the extrapolated
      // point.
      const double t = options_.alpha / L_;
      for (std::size_t i = 0; i < n; ++i) {
        Vector3 g = xi_y[i];
        g(0) += s[i];
        lambda[i] = prox_cone(y[i] - t * g, model_.mu(i));
      }
      model_.velocities(lambda, xi_x);
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
      if (curvature <= L_ * step2 * (1.0 + apgd::kDecreaseSlack) ||
          attempt == apgd::kMaxBacktracking) {
        break;
      }
      L_ *= 2.0;
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
    if (against > 0.0 || (frictional_ && k - last_update_ >= apgd::kOffsetCycle)) {
      // Restart, and take the cone offset s = μ ‖ξ_T‖ of the current iterate: each cycle solves
      // the convex problem with a fixed s (Anitescu's relaxation shifted by s), whose fixed point
      // over the cycles is Coulomb's law.
      restart(k);
    } else {
      const double theta_next =
          0.5 * (-theta_ * theta_ + theta_ * std::sqrt(theta_ * theta_ + 4.0));
      beta = theta_ * (1.0 - theta_) / (theta_ * theta_ + theta_next);
      theta_ = theta_next;
    }
    // ξ is affine in Λ, so ξ(y) follows from ξ(x) and ξ(x_prev) without another product.
    for (std::size_t i = 0; i < n; ++i) {
      y[i] = lambda[i] + beta * (lambda[i] - x_prev[i]);
      xi_y[i] = xi_x[i] + beta * (xi_x[i] - xi_prev[i]);
    }
    x_prev.assign(lambda.begin(), lambda.end());
    xi_prev.assign(xi_x.begin(), xi_x.end());
    L_ *= apgd::kShrink;
    model_.record(xi_x, velocity_watched_);
  }

  /// record() has synchronised u already when the velocity criterion watches it.
  void synchronize_for_hook() {
    if (!velocity_watched_) model_.update_u();
  }

  /// The criterion is met at iteration k. Percussions or velocities that stopped changing within
  /// a cycle are the solution of this cycle's convex problem, with the offset s frozen; they solve
  /// Coulomb's law only if s is also the offset μ ‖ξ_T‖ of the iterate itself. Otherwise refresh
  /// s, restart from the iterate and go on. (The natural residual measures Coulomb's law itself.)
  bool accept(int k) {
    if (!frictional_ || options_.criterion == Criterion::natural_residual) return true;
    const std::size_t n = model_.size();
    bool consistent = true;
    for (std::size_t i = 0; i < n && consistent; ++i) {
      const double s_now = offset(i, ws_.xi_x[i]);
      consistent = std::abs(s_now - ws_.s[i]) <= options_.abs_tol + options_.rel_tol * s_now;
    }
    if (consistent) return true;
    restart(k);
    const std::span<const Vector3> lambda = model_.lambda();
    ws_.y.assign(lambda.begin(), lambda.end());
    ws_.xi_y.assign(ws_.xi_x.begin(), ws_.xi_x.end());
    return false;
  }

  void finish() { model_.done(); }

 private:
  double offset(std::size_t i, const Vector3& xi) const {
    return model_.mu(i) * norm2d(xi(1), xi(2));
  }
  /// Restart at iteration k: drop the momentum and take the offsets of the current iterate x.
  void restart(int k) {
    theta_ = 1.0;
    for (std::size_t i = 0; i < model_.size(); ++i) ws_.s[i] = offset(i, ws_.xi_x[i]);
    last_update_ = k;
  }

  Model& model_;
  const SolverOptions& options_;
  bool velocity_watched_;
  Workspace& ws_;
  double L_ = 0.0;
  double theta_ = 1.0;
  int last_update_ = 0;
  bool frictional_ = false;
};

/// Newton: one semismooth Newton step on the Alart–Curnier function per iteration (newton.hpp),
/// with an Armijo line search on ψ = ½‖Φ‖² (non-monotone as an option) and SOR sweeps where the
/// step fails; the hybrid's SOR phase first when asked.
template <class Model>
class NewtonPolicy {
 public:
  /// `tolerance`: the natural-residual criterion's (run()).
  NewtonPolicy(Model& model, const SolverOptions& options, Workspace& ws, SolverResult& result,
               double tolerance)
      : model_(model),
        options_(options),
        tolerance_(tolerance),
        velocity_watched_(options.criterion == Criterion::velocity_change),
        ws_(ws),
        result_(result) {
    switch (options.newton.linear_solver) {
      case LinearSolver::direct:
        direct_ = true;
        break;
      case LinearSolver::gmres:
        direct_ = false;
        break;
      case LinearSolver::automatic:
        direct_ = requires { model.block_matrix(); };
        break;
    }
    ws.merits.clear();
    gather_mu(model, ws);  // for the residual of the projected percussions (accept())
    if (direct_) {
      if constexpr (requires { model.block_matrix(); }) {
        W_ = &model.block_matrix();
      } else {
        model.assemble(ws.W);
        W_ = &ws.W;
      }
      pattern();
    }
    hybrid_ = options.newton.hybrid_sweeps > 0;
  }

  void iterate(int /*k*/) {
    if (hybrid_) {
      hybrid_ = false;
      hybrid_phase();
      return;
    }
    const std::size_t n = model_.size();
    const std::span<Vector3> lambda = model_.lambda();
    // Φ and J = A + B W at the iterate. Φ is divided by its largest component, `scale_`, for the
    // merit and the linear system: percussions of 10²⁰⁰ or 10⁻²⁰⁰ would make ψ = ½‖Φ‖²
    // overflow or underflow (the system is linear, so d follows from the scaled one).
    model_.velocities(lambda, ws_.xi);
    ws_.ac.resize(n);
    scale_ = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      ws_.ac[i] = alart_curnier_jacobian(lambda[i], ws_.xi[i], ws_.r[i].r_N, ws_.r[i].r_T,
                                         model_.mu(i));
      scale_ = std::max(scale_, ws_.ac[i].phi.cwiseAbs().maxCoeff());
    }
    // Φ not finite: the problem's numbers overflow (a percussion beyond 10³⁰⁸). The prox sweeps
    // then produce the non-finite iterate that the monitor reports as divergence.
    if (!std::isfinite(scale_)) {
      fall_back();
      return;
    }
    if (scale_ == 0.0) return;           // Φ = 0: Λ solves the problem
    double psi = 0.0;  // ψ / scale²
    for (std::size_t i = 0; i < n; ++i) psi += 0.5 * (ws_.ac[i].phi / scale_).squaredNorm();
    const double norm_phi = scale_ * std::sqrt(2.0 * psi);
    if (phi0_ == 0.0) phi0_ = norm_phi;
    // The merits of the last iterates, as log ψ, so that they compare whatever their scale.
    if (static_cast<int>(ws_.merits.size()) >= options_.newton.line_search_memory) {
      ws_.merits.erase(ws_.merits.begin());
    }
    ws_.merits.push_back(std::log(psi) + 2.0 * std::log(scale_));
    double step = 0.0;
    if (direction(norm_phi) && line_search(step)) {
      // Levenberg–Marquardt's rule for the regularization: a full step lets it shrink, so that
      // near a regular solution J itself takes over and the rate is quadratic.
      if (step == 1.0) {
        epsilon_ = std::max(epsilon_ * newton::kRegularizationDecrease, newton::kMinRegularization);
      }
    } else {
      epsilon_ = std::min(epsilon_ * newton::kRegularizationIncrease, newton::kMaxRegularization);
      fall_back();
    }
  }

  void synchronize_for_hook() {
    if (!velocity_watched_) model_.update_u();
  }
  /// The criterion is met. A Newton iterate satisfies the law only to within its residual, and
  /// its percussions may lie outside the cones by as much; every solver returns percussions
  /// inside them. So Λ is projected onto the cones, and the solve ends only if the projected Λ
  /// still meets the criterion (the natural residual recomputed; for the other criteria, the
  /// projection's change within their tolerance); otherwise Newton goes on from it.
  bool accept(int /*k*/) {
    const std::span<Vector3> lambda = model_.lambda();
    ws_.trial.assign(lambda.begin(), lambda.end());
    bool moved = false;
    for (std::size_t i = 0; i < lambda.size(); ++i) {
      lambda[i] = prox_cone(lambda[i], model_.mu(i));
      moved = moved || lambda[i] != ws_.trial[i];
    }
    if (!moved) return true;
    model_.touched();
    model_.update_u();
    model_.velocities(lambda, ws_.xi);
    model_.record(ws_.xi, velocity_watched_);
    const double residual = residual_norm(lambda, ws_.xi, ws_.mu);
    if (options_.record_history && !result_.history.empty()) result_.history.back() = residual;
    if (options_.criterion == Criterion::natural_residual) {
      return residual <= tolerance_;
    }
    return has_converged(flat(std::span<const Vector3>(ws_.trial)),
                         flat(std::span<const Vector3>(lambda)), options_.abs_tol,
                         options_.rel_tol);
  }
  void finish() { model_.done(); }

 private:
  /// The hybrid's SOR phase, the whole of its first iteration: SOR sweeps until ‖F‖ fell by
  /// less than the factor hybrid_stagnation over the last newton::kHybridWindow sweeps, or (with
  /// the natural-residual criterion) meets the tolerance or would not meet it within the sweeps
  /// left at the rate of the last window, or (with the percussion criterion) the last sweep of
  /// a window met it, or hybrid_sweeps sweeps are done.
  void hybrid_phase() {
    const NewtonOptions& o = options_.newton;
    double window_residual = 0.0;  // ‖F‖ at the end of the last window
    const double tolerance =
        options_.criterion == Criterion::natural_residual ? tolerance_ : -1.0;
    const bool percussions = options_.criterion == Criterion::percussion_change;
    while (result_.hybrid_sweeps < o.hybrid_sweeps) {
      const bool last_of_window = (result_.hybrid_sweeps + 1) % newton::kHybridWindow == 0;
      if (last_of_window && percussions) {
        ws_.trial.assign(model_.lambda().begin(), model_.lambda().end());
      }
      model_.sor_sweep(ws_.r, ProxForm::alart_curnier);
      ++result_.hybrid_sweeps;
      if (!last_of_window) continue;
      // The percussion criterion met by the window's last sweep: SOR has converged.
      if (percussions && has_converged(flat(std::span<const Vector3>(ws_.trial)),
                                       flat(std::span<const Vector3>(model_.lambda())),
                                       options_.abs_tol, options_.rel_tol)) {
        break;
      }
      model_.velocities(model_.lambda(), ws_.xi);
      const double residual = residual_norm(model_.lambda(), ws_.xi, ws_.mu);
      if (!std::isfinite(residual) || residual <= tolerance) break;
      if (window_residual > 0.0) {
        const double rate = residual / window_residual;  // per window
        if (rate > o.hybrid_stagnation) break;
        // Windows to the tolerance at this rate, against the windows left.
        const double left = double(o.hybrid_sweeps - result_.hybrid_sweeps) / newton::kHybridWindow;
        if (tolerance > 0.0 && std::log(tolerance / residual) / std::log(rate) > left) break;
      }
      window_residual = residual;
    }
    model_.touched();
  }

  /// The direct solver's pattern: that of W (every diagonal block stored), analysed once.
  void pattern() {
    const auto m = static_cast<Eigen::Index>(3 * W_->size());
    fill_triplets();
    ws_.jacobian.resize(m, m);
    ws_.jacobian.setFromTriplets(ws_.triplets.begin(), ws_.triplets.end());
    ws_.lu.analyzePattern(ws_.jacobian);
  }

  /// J's entries as triplets, block (i, j) = B_i W_ij + δ_ij A_i (zeros before the first
  /// iterate: the pattern is W's, whatever the values).
  void fill_triplets() {
    const BlockSparseMatrix& W = *W_;
    const std::size_t n = W.size();
    ws_.triplets.clear();
    const bool values = ws_.ac.size() == n;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::int64_t k = W.row_start[i]; k < W.row_start[i + 1]; ++k) {
        const auto j = static_cast<std::size_t>(W.column[k]);
        Matrix3 block = Matrix3::Zero();
        if (values) {
          block = ws_.ac[i].B * W.blocks[k];
          if (j == i) block += ws_.ac[i].A + epsilon_ * Matrix3::Identity();
        }
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) {
            ws_.triplets.emplace_back(static_cast<Eigen::Index>(3 * i + a),
                                      static_cast<Eigen::Index>(3 * j + b), block(a, b));
          }
        }
      }
    }
  }

  /// d with J d = −Φ; false when the linear solver fails (a singular J, a non-finite d). Both
  /// linear solvers work on flat vectors in the workspace: the right-hand side −Φ / scale in
  /// `rhs`, the solution d / scale in `step`.
  bool direction(double norm_phi) {
    const std::size_t n = model_.size();
    ws_.rhs.resize(3 * n);
    ws_.step.resize(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) ws_.rhs[3 * i + a] = -ws_.ac[i].phi(a) / scale_;
    }
    if (direct_) {
      fill_triplets();
      ws_.jacobian.setFromTriplets(ws_.triplets.begin(), ws_.triplets.end());
      ws_.lu.factorize(ws_.jacobian);
      ++result_.linear_iterations;
      if (ws_.lu.info() != Eigen::Success) return false;
      const auto m = static_cast<Eigen::Index>(3 * n);
      Eigen::Map<Eigen::VectorXd>(ws_.step.data(), m) =
          ws_.lu.solve(Eigen::Map<const Eigen::VectorXd>(ws_.rhs.data(), m));
      if (ws_.lu.info() != Eigen::Success) return false;
    } else {
      // GMRES on J = A + B W with the block-diagonal preconditioner (A_i + B_i W_ii)⁻¹ (the
      // identity for a block that is singular).
      ws_.precond.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const Matrix3 M =
            ws_.ac[i].A + ws_.ac[i].B * model_.delassus(i) + epsilon_ * Matrix3::Identity();
        bool invertible = false;
        double det = 0.0;
        M.computeInverseAndDetWithCheck(ws_.precond[i], det, invertible);
        if (!invertible || !ws_.precond[i].allFinite()) ws_.precond[i].setIdentity();
      }
      const Operator J(model_, ws_, epsilon_);
      const double forcing = std::min(newton::kMaxForcing, norm_phi / phi0_);
      const GmresResult g =
          gmres(J, ws_.rhs, ws_.step, forcing * norm_phi / scale_, options_.newton.krylov_restart,
                options_.newton.max_linear_iterations, ws_.gmres);
      result_.linear_iterations += g.iterations;
    }
    ws_.d.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      ws_.d[i] = Vector3(ws_.step[3 * i], ws_.step[3 * i + 1], ws_.step[3 * i + 2]);  // d / scale
    }
    return all_finite(ws_.d);
  }

  /// The step Λ + t d with the largest t = 1, ½, ¼, … whose merit passes the (non-monotone)
  /// Armijo test, t in `step`; false (Λ unchanged) when d is no descent direction or no t passes.
  bool line_search(double& step) {
    // In units of `scale_`: ws_.d holds d / scale, W d / scale follows, and the merits are
    // ψ / scale². ξ is affine in Λ: ξ(Λ + t d) = ξ + t W d, no further product.
    const std::size_t n = model_.size();
    model_.apply_G(ws_.d, ws_.wd);
    // ∇ψᵀd = Φᵀ J d, exact whatever the linear solver's accuracy.
    double slope = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      slope += (ws_.ac[i].phi / scale_).dot(ws_.ac[i].A * ws_.d[i] + ws_.ac[i].B * ws_.wd[i]);
    }
    if (!(slope < 0.0)) return false;
    const double reference = std::exp(*std::max_element(ws_.merits.begin(), ws_.merits.end()) -
                                      2.0 * std::log(scale_));
    const std::span<Vector3> lambda = model_.lambda();
    ws_.trial.resize(n);
    ws_.trial_xi.resize(n);
    double t = 1.0;
    for (int h = 0; h <= newton::kMaxHalvings; ++h, t *= 0.5) {
      double merit = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        ws_.trial[i] = lambda[i] + (t * scale_) * ws_.d[i];
        ws_.trial_xi[i] = ws_.xi[i] + (t * scale_) * ws_.wd[i];
        merit += 0.5 * (alart_curnier_function(ws_.trial[i], ws_.trial_xi[i], ws_.r[i].r_N,
                                               ws_.r[i].r_T, model_.mu(i)) /
                        scale_)
                           .squaredNorm();
      }
      if (merit <= reference + newton::kArmijo * t * slope) {
        step = t;
        std::copy(ws_.trial.begin(), ws_.trial.end(), lambda.begin());
        model_.touched();
        model_.record(ws_.trial_xi, velocity_watched_);
        return true;
      }
    }
    return false;
  }

  /// SOR sweeps in place of a failed Newton step.
  void fall_back() {
    ++result_.fallbacks;
    // The sweeps move u with Λ: u must be in step with Λ first (the Newton steps changed Λ alone).
    model_.update_u();
    for (int s = 0; s < options_.newton.fallback_sweeps; ++s) {
      model_.sor_sweep(ws_.r, ProxForm::alart_curnier);
    }
  }

  /// y = J x = A x + B (W x) on flat vectors, and the block-diagonal preconditioner.
  class Operator final : public LinearOperator {
   public:
    Operator(Model& model, Workspace& ws, double epsilon)
        : model_(model), ws_(ws), epsilon_(epsilon) {}
    void apply(std::span<const double> x, std::span<double> y) const override {
      const std::size_t n = model_.size();
      ws_.x3.resize(n);
      for (std::size_t i = 0; i < n; ++i) ws_.x3[i] = Vector3(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      model_.apply_G(ws_.x3, ws_.y3);
      for (std::size_t i = 0; i < n; ++i) {
        const Vector3 v =
            ws_.ac[i].A * ws_.x3[i] + ws_.ac[i].B * ws_.y3[i] + epsilon_ * ws_.x3[i];
        for (int a = 0; a < 3; ++a) y[3 * i + a] = v(a);
      }
    }
    void precondition(std::span<const double> x, std::span<double> y) const override {
      for (std::size_t i = 0; i < model_.size(); ++i) {
        const Vector3 v = ws_.precond[i] * Vector3(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        for (int a = 0; a < 3; ++a) y[3 * i + a] = v(a);
      }
    }

   private:
    Model& model_;
    Workspace& ws_;
    double epsilon_;
  };

  Model& model_;
  const SolverOptions& options_;
  double tolerance_;  // of the natural-residual criterion
  bool velocity_watched_;
  Workspace& ws_;
  SolverResult& result_;
  bool direct_ = false;
  const BlockSparseMatrix* W_ = nullptr;  // W for the direct solver: the problem's or ws_.W
  bool hybrid_ = false;                   // the hybrid's SOR phase is still to come
  double phi0_ = 0.0;  // ‖Φ‖ at the first iterate, the scale of GMRES's forcing term
  double epsilon_ = newton::kInitialRegularization;  // J + εI: Levenberg–Marquardt's ε
  double scale_ = 1.0;  // the largest component of Φ at the iterate
};

/// The one loop of every method: before → iteration → hook → stopping test (local, then global;
/// APGD's acceptance in between) → stop at max_iterations.
template <class Model, class Policy>
void iterate(Model& model, Policy& policy, Monitor<Model>& monitor, const SolverOptions& options,
             const SolverHooks& hooks, SolverResult& result) {
  // The test sits at the end of the body: with max_iterations = INT_MAX the loop must stop
  // before ++k overflows.
  for (int k = 1;; ++k) {
    monitor.before(k);
    policy.iterate(k);
    if (hooks.after_iteration) {
      policy.synchronize_for_hook();
      hooks.after_iteration(k, model.lambda(), model.u());
      model.touched();
    }
    // Only u changes: the sweep's own tests of Λ still hold (no touched()).
    if (hooks.velocities_between_sweeps) hooks.velocities_between_sweeps(k, model.u());
    const Verdict verdict = monitor.after(k);
    IterationStatus local = IterationStatus::running;
    if (verdict == Verdict::diverged) {
      local = IterationStatus::diverged;
    } else if (verdict == Verdict::met && policy.accept(k)) {
      local = IterationStatus::converged;
    }
    const IterationStatus global = hooks.global_status ? hooks.global_status(local) : local;
    if (global != IterationStatus::converged && global != IterationStatus::running &&
        global != IterationStatus::diverged) {
      throw InvalidArgument("SolverHooks::global_status returned " +
                            std::to_string(static_cast<int>(global)) +
                            ", not one of converged (0), running (1), diverged (2)");
    }
    if (global == IterationStatus::diverged) {
      result.diverged = true;  // here or on another process
      break;
    }
    if (global == IterationStatus::converged) {
      result.converged = true;
      break;
    }
    if (k == options.max_iterations) break;
  }
  policy.finish();
}

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Runs `method` on a model whose Λ holds the initial guess.
template <class Model>
SolverResult run(Method method, Model& model, const SolverOptions& options,
                 const SolverHooks& hooks, Workspace& ws) {
  const auto start = Clock::now();
  SolverResult result;
  result.solver = method_name(method);  // at most 6 characters, in the string itself: no allocation
  // Per-contact r-factors come with the model's first pass; the spectral ones need G applied.
  bool per_contact = false;
  if (method != Method::apgd) {
    const RFactorStrategy strategy = resolve(options.r_strategy, method);
    per_contact = strategy == RFactorStrategy::per_contact;
    if (!per_contact) compute_r_factors(model, strategy, options.alpha, ws);
  }
  result.norm_c = model.prepare(per_contact ? &ws.r : nullptr, options.alpha);
  if constexpr (requires { model.reference_norm(); }) {
    if (model.reference_norm() > 0.0) result.norm_c = model.reference_norm();
  }
  // SOR on a model whose sweep can test its own change needs no copy of Λ per iteration, unless
  // a hook may change Λ between the sweep and the test.
  bool change_in_sweep = false;
  if constexpr (requires { model.test_change_in_sweep(0.0, 0.0); }) {
    if (method == Method::sor && !hooks.after_iteration &&
        options.criterion == Criterion::percussion_change) {
      model.test_change_in_sweep(options.abs_tol, options.rel_tol);
      change_in_sweep = true;
    }
    if (method == Method::sor && !hooks.after_iteration &&
        options.criterion == Criterion::natural_residual) {
      change_in_sweep = true;  // the monitor asks the sweeps for their residual
    }
  }
  // The natural-residual tolerance, abs_tol + rel_tol ‖c‖; a problem shared by processes holds
  // each to its share of the whole problem's (SolverHooks::global_norm_c).
  double reference = result.norm_c;
  double share = 1.0;
  if (hooks.global_norm_c) {
    const GlobalNorm global = hooks.global_norm_c(result.norm_c);
    reference = global.norm_c;
    share = 1.0 / std::sqrt(static_cast<double>(std::max(1, global.processes)));
  }
  const double tolerance = (options.abs_tol + options.rel_tol * reference) * share;
  Monitor<Model> monitor(model, options, ws, result, change_in_sweep, tolerance);
  switch (method) {
    case Method::sor: {
      SorPolicy<Model> policy(model, options, ws);
      iterate(model, policy, monitor, options, hooks, result);
      break;
    }
    case Method::jor: {
      JorPolicy<Model> policy(model, options, ws);
      iterate(model, policy, monitor, options, hooks, result);
      break;
    }
    case Method::apgd: {
      ApgdPolicy<Model> policy(model, options, ws);
      iterate(model, policy, monitor, options, hooks, result);
      break;
    }
    case Method::newton: {
      NewtonPolicy<Model> policy(model, options, ws, result, tolerance);
      iterate(model, policy, monitor, options, hooks, result);
      break;
    }
  }
  monitor.finish();
  result.seconds = seconds_since(start);
  return result;
}

/// The body form after the problem is validated and G computed.
SolverResult solve_body(Method method, const ContactProblem& problem, std::span<const Matrix3> G,
                        ContactSolution& solution, const SolverOptions& options,
                        const SolverHooks& hooks, Workspace& ws, const char* where) {
  prepare_guess(solution.lambda, problem.contacts.size(), where);
  BodyModel model(problem, G, solution.lambda, solution.u, ws);
  return run(method, model, options, hooks, ws);
}

/// Validates the problem and computes its Delassus blocks into ws.G.
void prepare_problem(const ContactProblem& problem, Workspace& ws) {
  validate(problem);
  ws.G.resize(problem.contacts.size());
  for (std::size_t i = 0; i < ws.G.size(); ++i) {
    ws.G[i] = delassus_block(problem.contacts[i], problem.M_inv);
  }
}

SolverResult solve_body_once(Method method, const ContactProblem& problem,
                             ContactSolution& solution, const SolverOptions& options,
                             const char* where) {
  validate_options(options, where);
  Workspace ws;
  prepare_problem(problem, ws);
  return solve_body(method, problem, ws.G, solution, options, {}, ws, where);
}

SolverResult solve_local(Method method, const LocalProblem& problem, std::vector<Vector3>& lambda,
                         const SolverOptions& options, const SolverHooks& hooks, Workspace& ws,
                         const char* where) {
  validate(problem);
  prepare_guess(lambda, problem.q.size(), where);
  LocalModel model(problem, lambda, ws);
  return run(method, model, options, hooks, ws);
}

SolverResult solve_local_once(Method method, const LocalProblem& problem,
                              std::vector<Vector3>& lambda, const SolverOptions& options,
                              const char* where) {
  validate_options(options, where);
  Workspace ws;
  return solve_local(method, problem, lambda, options, {}, ws, where);
}

}  // namespace

std::string_view method_name(Method method) {
  switch (method) {
    case Method::sor:
      return "SOR";
    case Method::jor:
      return "JOR";
    case Method::apgd:
      return "APGD";
    case Method::newton:
      return "Newton";
  }
  validate_method(method, "method_name");
  return {};
}

std::vector<RFactors> r_factors(const ContactProblem& problem, RFactorStrategy strategy,
                                double alpha) {
  // The solvers check these once before they compute r-factors; here the caller gets the same.
  SolverOptions options;
  options.alpha = alpha;
  options.r_strategy = strategy;
  validate_options(options, "r_factors");
  Workspace ws;
  prepare_problem(problem, ws);
  std::vector<Vector3> none;
  std::vector<Vector6> u;
  BodyModel model(problem, ws.G, none, u, ws);
  compute_r_factors(model, resolve(strategy, Method::sor), alpha, ws);
  return std::move(ws.r);
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

// ---------------------------------------------------------------------------------------------
// ContactSolver
// ---------------------------------------------------------------------------------------------

ContactSolver::ContactSolver(Method method, SolverOptions options, SolverHooks hooks)
    : method_(method),
      options_(options),
      hooks_(std::move(hooks)),
      workspace_(std::make_unique<Workspace>()) {
  validate_method(method_, "ContactSolver");
  validate_options(options_, "ContactSolver");
  if (hooks_.velocities_between_sweeps && method_ != Method::sor) {
    throw InvalidArgument(std::string("ContactSolver: the hook velocities_between_sweeps is for "
                                      "SOR only; ") + std::string(method_name(method_)) +
                          " recomputes u from the percussions and would drop its change");
  }
}

ContactSolver::~ContactSolver() = default;
ContactSolver::ContactSolver(ContactSolver&&) noexcept = default;
ContactSolver& ContactSolver::operator=(ContactSolver&&) noexcept = default;

SolverResult ContactSolver::solve(const ContactProblem& problem, ContactSolution& solution) {
  prepare_problem(problem, *workspace_);
  return solve_body(method_, problem, workspace_->G, solution, options_, hooks_, *workspace_,
                    "ContactSolver::solve");
}

SolverResult ContactSolver::solve_prepared(const ContactProblem& problem,
                                           std::span<const Matrix3> G,
                                           ContactSolution& solution) {
  if (G.size() != problem.contacts.size() || problem.u_free.size() != problem.M_inv.size()) {
    throw InvalidArgument("ContactSolver::solve_prepared: expected one Delassus block per contact "
                          "and one u_free per body; found " + std::to_string(G.size()) +
                          " blocks for " + std::to_string(problem.contacts.size()) +
                          " contacts and " + std::to_string(problem.u_free.size()) +
                          " free velocities for " + std::to_string(problem.M_inv.size()) +
                          " bodies");
  }
  return solve_body(method_, problem, G, solution, options_, hooks_, *workspace_,
                    "ContactSolver::solve_prepared");
}

SolverResult ContactSolver::solve(const CompactProblem& problem, ContactSolution& solution) {
  validate(problem);
  return solve_prepared(problem, solution);
}

SolverResult ContactSolver::solve_prepared(const CompactProblem& problem,
                                           ContactSolution& solution) {
  if (problem.u_free.size() != problem.M_inv.size()) {
    throw InvalidArgument("ContactSolver::solve_prepared: expected one u_free per body; found " +
                          std::to_string(problem.u_free.size()) + " free velocities for " +
                          std::to_string(problem.M_inv.size()) + " bodies");
  }
  prepare_guess(solution.lambda, problem.contacts.size(), "ContactSolver::solve_prepared");
  CompactModel model(problem, solution.lambda, solution.u, *workspace_);
  return run(method_, model, options_, hooks_, *workspace_);
}

SolverResult ContactSolver::solve(const LocalProblem& problem, std::vector<Vector3>& lambda) {
  if (hooks_.velocities_between_sweeps) {
    throw InvalidArgument("ContactSolver::solve: the hook velocities_between_sweeps needs body "
                          "velocities, which the local form (FCLIB) does not have");
  }
  return solve_local(method_, problem, lambda, options_, hooks_, *workspace_,
                     "ContactSolver::solve");
}

// ---------------------------------------------------------------------------------------------
// The free functions: one-shot solvers
// ---------------------------------------------------------------------------------------------

SolverResult solve_sor(const ContactProblem& problem, ContactSolution& solution,
                       const SolverOptions& options) {
  return solve_body_once(Method::sor, problem, solution, options, "solve_sor");
}
SolverResult solve_jor(const ContactProblem& problem, ContactSolution& solution,
                       const SolverOptions& options) {
  return solve_body_once(Method::jor, problem, solution, options, "solve_jor");
}
SolverResult solve_apgd(const ContactProblem& problem, ContactSolution& solution,
                        const SolverOptions& options) {
  return solve_body_once(Method::apgd, problem, solution, options, "solve_apgd");
}
SolverResult solve_sor(const LocalProblem& problem, std::vector<Vector3>& lambda,
                       const SolverOptions& options) {
  return solve_local_once(Method::sor, problem, lambda, options, "solve_sor");
}
SolverResult solve_jor(const LocalProblem& problem, std::vector<Vector3>& lambda,
                       const SolverOptions& options) {
  return solve_local_once(Method::jor, problem, lambda, options, "solve_jor");
}
SolverResult solve_apgd(const LocalProblem& problem, std::vector<Vector3>& lambda,
                        const SolverOptions& options) {
  return solve_local_once(Method::apgd, problem, lambda, options, "solve_apgd");
}
SolverResult solve_newton(const ContactProblem& problem, ContactSolution& solution,
                          const SolverOptions& options) {
  return solve_body_once(Method::newton, problem, solution, options, "solve_newton");
}
SolverResult solve_newton(const LocalProblem& problem, std::vector<Vector3>& lambda,
                          const SolverOptions& options) {
  return solve_local_once(Method::newton, problem, lambda, options, "solve_newton");
}

}  // namespace grbd::contact
