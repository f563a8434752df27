/// \file
/// \brief Restarted GMRES for the Newton systems of chapter 5's semismooth Newton method.

#include <algorithm>
#include <cmath>

#include "grbd/contact/newton.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

namespace {

double dot(std::span<const double> a, std::span<const double> b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

double norm(std::span<const double> a) { return std::sqrt(dot(a, a)); }

}  // namespace

GmresResult gmres(const LinearOperator& J, std::span<const double> b, std::span<double> x,
                  double tolerance, int restart, int max_iterations, GmresWorkspace& ws) {
  if (x.size() != b.size()) {
    throw InvalidArgument("gmres: x and b must have the same size; found " +
                          std::to_string(x.size()) + " and " + std::to_string(b.size()));
  }
  if (restart < 1 || max_iterations < 0 || !(tolerance >= 0.0)) {
    throw InvalidArgument("gmres: expected restart >= 1, max_iterations >= 0 and a tolerance >= "
                          "0; found " + std::to_string(restart) + ", " +
                          std::to_string(max_iterations) + " and " + std::to_string(tolerance));
  }
  const std::size_t n = b.size();
  const auto m = static_cast<std::size_t>(restart);
  ws.basis.resize((m + 1) * n);
  ws.hessenberg.resize((m + 1) * m);
  ws.cs.resize(m);
  ws.sn.resize(m);
  ws.g.resize(m + 1);
  ws.y.resize(m);
  ws.w.resize(n);
  ws.z.resize(n);
  const auto V = [&](std::size_t j) { return std::span<double>(ws.basis).subspan(j * n, n); };
  const auto H = [&](std::size_t i, std::size_t j) -> double& { return ws.hessenberg[j * (m + 1) + i]; };

  std::fill(x.begin(), x.end(), 0.0);
  GmresResult result;
  // r = b − J x; with x = 0 at the start, r = b.
  std::copy(b.begin(), b.end(), ws.w.begin());
  double beta = norm(ws.w);
  result.residual = beta;
  while (beta > tolerance && result.iterations < max_iterations) {
    // One cycle: the Arnoldi process on J P⁻¹ from v_0 = r/β, with Givens rotations that keep
    // the least-squares problem min ‖β e_1 − H y‖ triangular, its residual |g_{j+1}|.
    for (std::size_t i = 0; i < n; ++i) V(0)[i] = ws.w[i] / beta;
    std::fill(ws.g.begin(), ws.g.end(), 0.0);
    ws.g[0] = beta;
    std::size_t k = 0;  // Krylov vectors of this cycle
    while (k < m && result.iterations < max_iterations) {
      J.precondition(V(k), ws.z);
      J.apply(ws.z, ws.w);
      ++result.iterations;
      // Modified Gram–Schmidt against v_0 … v_k.
      for (std::size_t i = 0; i <= k; ++i) {
        H(i, k) = dot(ws.w, V(i));
        for (std::size_t l = 0; l < n; ++l) ws.w[l] -= H(i, k) * V(i)[l];
      }
      H(k + 1, k) = norm(ws.w);
      if (H(k + 1, k) > 0.0) {
        for (std::size_t l = 0; l < n; ++l) V(k + 1)[l] = ws.w[l] / H(k + 1, k);
      }
      // The earlier rotations on the new column, then the rotation that zeroes H(k + 1, k).
      for (std::size_t i = 0; i < k; ++i) {
        const double t = ws.cs[i] * H(i, k) + ws.sn[i] * H(i + 1, k);
        H(i + 1, k) = -ws.sn[i] * H(i, k) + ws.cs[i] * H(i + 1, k);
        H(i, k) = t;
      }
      const double r = std::hypot(H(k, k), H(k + 1, k));
      ws.cs[k] = r > 0.0 ? H(k, k) / r : 1.0;
      ws.sn[k] = r > 0.0 ? H(k + 1, k) / r : 0.0;
      H(k, k) = r;
      H(k + 1, k) = 0.0;
      ws.g[k + 1] = -ws.sn[k] * ws.g[k];
      ws.g[k] = ws.cs[k] * ws.g[k];
      ++k;
      result.residual = std::abs(ws.g[k]);
      // A zero subdiagonal made the rotation trivial and the residual zero: the Krylov space
      // holds the solution (a "lucky breakdown"), and the test below ends the cycle.
      if (result.residual <= tolerance) break;
    }
    // y = H⁻¹ g (upper triangular k × k), x += P⁻¹ V y. A zero diagonal (J singular on the Krylov
    // space) ends the solve with what the earlier columns give.
    std::size_t used = k;
    for (std::size_t i = 0; i < k; ++i) {
      if (!(std::abs(H(i, i)) > 0.0)) {
        used = i;
        break;
      }
    }
    for (std::size_t ii = used; ii-- > 0;) {
      double s = ws.g[ii];
      for (std::size_t j = ii + 1; j < used; ++j) s -= H(ii, j) * ws.y[j];
      ws.y[ii] = s / H(ii, ii);
    }
    std::fill(ws.w.begin(), ws.w.end(), 0.0);
    for (std::size_t j = 0; j < used; ++j) {
      for (std::size_t l = 0; l < n; ++l) ws.w[l] += ws.y[j] * V(j)[l];
    }
    J.precondition(ws.w, ws.z);
    for (std::size_t l = 0; l < n; ++l) x[l] += ws.z[l];
    if (used < k || result.residual <= tolerance || result.iterations >= max_iterations) break;
    // Restart from the true residual r = b − J x.
    J.apply(x, ws.w);
    for (std::size_t l = 0; l < n; ++l) ws.w[l] = b[l] - ws.w[l];
    beta = norm(ws.w);
    result.residual = beta;
  }
  result.converged = result.residual <= tolerance;
  return result;
}

}  // namespace grbd::contact
