/// \file
/// \brief The local contact problem ξ = W λ + q: the block-sparse Delassus matrix, its checks, and
/// the conversion of a global problem (M, H, f, w) to local form.

#include "grbd/contact/local_problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <string>

#include <Eigen/SparseCholesky>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// The relative tolerance of the symmetry check of M in to_local().
constexpr double kMassSymmetryTolerance = 1e-8;
/// Entries of W = Hᵀ M⁻¹ H at most this times max |W| are rounding noise and dropped.
constexpr double kPruneTolerance = 1e-14;
/// The unit roundoff of double precision (2⁻⁵²).
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

std::string index_pair(std::int64_t i, std::int64_t j) {
  return "(" + std::to_string(i) + ", " + std::to_string(j) + ")";
}

std::string size_text(Eigen::Index rows, Eigen::Index cols) {
  return std::to_string(rows) + " × " + std::to_string(cols);
}

/// The largest absolute value stored in A (0 if none is stored).
double max_abs(const SparseMatrix& A) {
  double result = 0.0;
  for (Eigen::Index c = 0; c < A.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
      result = std::max(result, std::abs(it.value()));
    }
  }
  return result;
}

/// Throws InvalidArgument "to_local: <name> has a non-finite entry <name>(i, j) = x" if A has one.
void require_finite(const SparseMatrix& A, const char* name) {
  for (Eigen::Index c = 0; c < A.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
      if (!std::isfinite(it.value())) {
        throw InvalidArgument(std::string("to_local: ") + name + " has a non-finite entry " + name +
                              index_pair(it.row(), it.col()) + " = " + format_number(it.value()));
      }
    }
  }
}

/// Throws InvalidArgument if the vector v has a non-finite entry.
void require_finite(const Eigen::VectorXd& v, const char* name) {
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v[k])) {
      throw InvalidArgument(std::string("to_local: ") + name + " has a non-finite entry " + name +
                            "[" + std::to_string(k) + "] = " + format_number(v[k]));
    }
  }
}

/// Throws InvalidArgument if the computed matrix A (`what`, e.g. "W = Hᵀ M⁻¹ H") has a non-finite
/// entry: its inputs were finite, so M is too ill-conditioned or H too large for double precision.
void require_finite_result(const SparseMatrix& A, const char* what) {
  for (Eigen::Index c = 0; c < A.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
      if (!std::isfinite(it.value())) {
        throw InvalidArgument(std::string("to_local: ") + what + " has a non-finite entry W" +
                              index_pair(it.row(), it.col()) + " = " + format_number(it.value()) +
                              ": M is too ill-conditioned, or H too large, for double precision");
      }
    }
  }
}

/// Checks the structure of W (offsets, columns, diagonal indices) against n block rows.
void validate_structure(const BlockSparseMatrix& W) {
  const std::size_t n = W.size();
  if (W.row_start.empty()) {
    if (!W.column.empty() || !W.blocks.empty() || !W.diagonal.empty()) {
      throw InvalidArgument(
          "validate: W has no row_start offsets but stores blocks or diagonal indices");
    }
    return;
  }
  if (W.row_start.front() != 0) {
    throw InvalidArgument("validate: W.row_start[0] = " + std::to_string(W.row_start.front()) +
                          ", expected 0");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (W.row_start[i + 1] < W.row_start[i]) {
      throw InvalidArgument("validate: W.row_start is not monotone: row_start[" +
                            std::to_string(i) + "] = " + std::to_string(W.row_start[i]) +
                            " > row_start[" + std::to_string(i + 1) +
                            "] = " + std::to_string(W.row_start[i + 1]));
    }
  }
  const auto stored = static_cast<std::size_t>(W.row_start.back());
  if (W.column.size() != stored || W.blocks.size() != stored) {
    throw InvalidArgument("validate: W.row_start[n] = " + std::to_string(stored) + " but W has " +
                          std::to_string(W.column.size()) + " block columns and " +
                          std::to_string(W.blocks.size()) + " blocks");
  }
  if (W.diagonal.size() != n) {
    throw InvalidArgument("validate: W has " + std::to_string(n) + " block rows but " +
                          std::to_string(W.diagonal.size()) + " diagonal indices");
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t previous = -1;
    for (auto k = W.row_start[i]; k < W.row_start[i + 1]; ++k) {
      const std::int32_t j = W.column[static_cast<std::size_t>(k)];
      if (j < 0 || static_cast<std::size_t>(j) >= n) {
        throw InvalidArgument("validate: W block row " + std::to_string(i) + " has block column " +
                              std::to_string(j) + " out of range [0, " + std::to_string(n) + ")");
      }
      if (j <= previous) {
        throw InvalidArgument("validate: the block columns of W block row " + std::to_string(i) +
                              " are not strictly increasing (" + std::to_string(previous) +
                              " then " + std::to_string(j) + ")");
      }
      previous = j;
    }
    const std::int64_t d = W.diagonal[i];
    if (d < W.row_start[i] || d >= W.row_start[i + 1] ||
        W.column[static_cast<std::size_t>(d)] != static_cast<std::int32_t>(i)) {
      throw InvalidArgument("validate: W.diagonal[" + std::to_string(i) +
                            "] = " + std::to_string(d) + " is not the index of block " +
                            index_pair(static_cast<std::int64_t>(i), static_cast<std::int64_t>(i)));
    }
  }
}

}  // namespace

/// Converts the 3n × 3n sparse matrix W to compressed block rows of 3 × 3 blocks. A block is stored
/// when at least one of its entries is stored with a non-zero value (an explicitly stored zero does
/// not create a block; NaN does); every diagonal block is stored, zero if absent. Throws
/// InvalidArgument unless W is square with a multiple of 3 rows.
BlockSparseMatrix to_block_sparse(const Eigen::SparseMatrix<double>& W) {
  if (W.rows() != W.cols() || W.rows() % 3 != 0) {
    throw InvalidArgument("to_block_sparse: expected a square 3n × 3n matrix, found " +
                          size_text(W.rows(), W.cols()));
  }
  const Eigen::Index n = W.rows() / 3;
  if (n > std::numeric_limits<std::int32_t>::max()) {
    throw InvalidArgument("to_block_sparse: " + std::to_string(n) +
                          " block rows do not fit the 32-bit block column indices");
  }
  // Row-major storage visits the entries by rows; the 3 scalar rows of a block row are merged.
  const Eigen::SparseMatrix<double, Eigen::RowMajor> R(W);
  BlockSparseMatrix B;
  B.row_start.assign(static_cast<std::size_t>(n) + 1, 0);
  B.diagonal.assign(static_cast<std::size_t>(n), -1);
  std::vector<std::int32_t> columns;
  for (Eigen::Index i = 0; i < n; ++i) {
    columns.clear();
    columns.push_back(static_cast<std::int32_t>(i));
    for (int r = 0; r < 3; ++r) {
      for (decltype(R)::InnerIterator it(R, 3 * i + r); it; ++it) {
        if (it.value() != 0.0) columns.push_back(static_cast<std::int32_t>(it.col() / 3));
      }
    }
    std::sort(columns.begin(), columns.end());
    columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
    const auto first = static_cast<std::int64_t>(B.column.size());
    for (const std::int32_t j : columns) {
      if (j == i)
        B.diagonal[static_cast<std::size_t>(i)] = static_cast<std::int64_t>(B.column.size());
      B.column.push_back(j);
      B.blocks.push_back(Matrix3::Zero());
    }
    for (int r = 0; r < 3; ++r) {
      for (decltype(R)::InnerIterator it(R, 3 * i + r); it; ++it) {
        if (it.value() == 0.0) continue;
        const auto j = static_cast<std::int32_t>(it.col() / 3);
        const auto k = std::lower_bound(columns.begin(), columns.end(), j) - columns.begin();
        B.blocks[static_cast<std::size_t>(first + k)](r, it.col() % 3) += it.value();
      }
    }
    B.row_start[static_cast<std::size_t>(i) + 1] = static_cast<std::int64_t>(B.column.size());
  }
  return B;
}

/// y = W x, block row by block row. Throws InvalidArgument if x or y does not have W.size()
/// entries, if they overlap, or if the offsets of W disagree with its blocks (row_start not
/// starting at 0, not monotone, or not ending at the number of blocks and block columns). These
/// checks cost O(1) and O(n) per call; the block columns themselves are not checked (that would
/// be O(blocks) per call, as much as the product): W must come from to_block_sparse() or have
/// passed validate().
void multiply(const BlockSparseMatrix& W, std::span<const Vector3> x, std::span<Vector3> y) {
  const std::size_t n = W.size();
  if (x.size() != n || y.size() != n) {
    throw InvalidArgument("multiply: W has " + std::to_string(n) + " block rows, but x has " +
                          std::to_string(x.size()) + " and y " + std::to_string(y.size()) +
                          " entries");
  }
  if (n > 0) {
    const std::less<const Vector3*> before;
    const Vector3* x_end = x.data() + n;
    const Vector3* y_begin = y.data();
    const Vector3* y_end = y.data() + n;
    if (before(x.data(), y_end) && before(y_begin, x_end)) {
      throw InvalidArgument("multiply: x and y overlap; y = W x needs separate storage");
    }
    const auto stored = static_cast<std::int64_t>(W.blocks.size());
    if (W.row_start.front() != 0 || W.row_start.back() != stored ||
        W.column.size() != W.blocks.size()) {
      throw InvalidArgument(
          "multiply: W.row_start runs from " + std::to_string(W.row_start.front()) + " to " +
          std::to_string(W.row_start.back()) + " but W has " + std::to_string(W.blocks.size()) +
          " blocks and " + std::to_string(W.column.size()) + " block columns");
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (W.row_start[i + 1] < W.row_start[i]) {
        throw InvalidArgument("multiply: W.row_start is not monotone at block row " +
                              std::to_string(i));
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    Vector3 sum = Vector3::Zero();
    for (auto k = W.row_start[i]; k < W.row_start[i + 1]; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      sum.noalias() += W.blocks[kk] * x[static_cast<std::size_t>(W.column[kk])];
    }
    y[i] = sum;
  }
}

/// Checks, in this order: the structure of W; q and μ with one entry per block row; every entry
/// of W and q finite; each μ finite and ≥ 0; the diagonal entries of each diagonal block > 0.
/// Symmetry of W is not required (Capsules-286's W is not symmetric). Throws InvalidArgument
/// naming the first entry that fails.
void validate(const LocalProblem& problem) {
  const BlockSparseMatrix& W = problem.W;
  validate_structure(W);
  const std::size_t n = W.size();
  if (problem.q.size() != n || problem.mu.size() != n) {
    throw InvalidArgument("validate: W has " + std::to_string(n) + " block rows (contacts), q " +
                          std::to_string(problem.q.size()) + " entries and mu " +
                          std::to_string(problem.mu.size()) + "; expected the same count");
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (auto k = W.row_start[i]; k < W.row_start[i + 1]; ++k) {
      const Matrix3& block = W.blocks[static_cast<std::size_t>(k)];
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          if (!std::isfinite(block(r, c))) {
            throw InvalidArgument(
                "validate: W block " +
                index_pair(static_cast<std::int64_t>(i), W.column[static_cast<std::size_t>(k)]) +
                " entry " + index_pair(r, c) + " is " + format_number(block(r, c)) +
                ", expected a finite number");
          }
        }
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (int r = 0; r < 3; ++r) {
      if (!std::isfinite(problem.q[i][r])) {
        throw InvalidArgument("validate: q of contact " + std::to_string(i) + " entry " +
                              std::to_string(r) + " is " + format_number(problem.q[i][r]) +
                              ", expected a finite number");
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(problem.mu[i] >= 0.0) || !std::isfinite(problem.mu[i])) {
      throw InvalidArgument("validate: mu of contact " + std::to_string(i) + " is " +
                            format_number(problem.mu[i]) +
                            ", expected a finite friction coefficient >= 0");
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Matrix3& D = W.blocks[static_cast<std::size_t>(W.diagonal[i])];
    for (int r = 0; r < 3; ++r) {
      if (!(D(r, r) > 0.0)) {
        throw InvalidArgument(
            "validate: diagonal block " +
            index_pair(static_cast<std::int64_t>(i), static_cast<std::int64_t>(i)) +
            " of W has diagonal entry " + index_pair(r, r) + " = " + format_number(D(r, r)) +
            ", expected > 0");
      }
    }
  }
}

/// W = Hᵀ M⁻¹ H and q = Hᵀ M⁻¹ f + w with a sparse LDLᵀ factorization of M (fill-reducing
/// ordering). W is symmetrized, (W + Wᵀ)/2, and entries |W_ij| ≤ 1e-14 max |W| (rounding noise of
/// the products) are dropped before it is cut into blocks. Throws InvalidArgument if the sizes
/// disagree (M m × m, H m × 3n, f m, w 3n, μ n), an entry is not finite, M is not symmetric
/// (relative 1e-8), not positive definite or numerically singular (a pivot of its factorization
/// at most m ε times the largest), or if W or q come out non-finite.
LocalProblem to_local(const GlobalProblem& global) {
  const Eigen::Index m = global.M.rows();
  const auto n = static_cast<Eigen::Index>(global.mu.size());
  if (global.M.cols() != m) {
    throw InvalidArgument("to_local: expected a square mass matrix M, found M " +
                          size_text(m, global.M.cols()));
  }
  if (global.H.rows() != m || global.H.cols() != 3 * n) {
    throw InvalidArgument("to_local: expected H of m × 3n = " + size_text(m, 3 * n) +
                          " (m = " + std::to_string(m) + " from M, n = " + std::to_string(n) +
                          " contacts from mu), found H " +
                          size_text(global.H.rows(), global.H.cols()));
  }
  if (global.f.size() != m) {
    throw InvalidArgument("to_local: expected f with m = " + std::to_string(m) +
                          " entries (the size of M), found " + std::to_string(global.f.size()));
  }
  if (global.w.size() != 3 * n) {
    throw InvalidArgument("to_local: expected w with 3n = " + std::to_string(3 * n) +
                          " entries (n = " + std::to_string(n) + " contacts from mu), found " +
                          std::to_string(global.w.size()));
  }
  require_finite(global.M, "M");
  require_finite(global.H, "H");
  require_finite(global.f, "f");
  require_finite(global.w, "w");
  for (std::size_t i = 0; i < global.mu.size(); ++i) {
    if (!(global.mu[i] >= 0.0) || !std::isfinite(global.mu[i])) {
      throw InvalidArgument("to_local: mu of contact " + std::to_string(i) + " is " +
                            format_number(global.mu[i]) +
                            ", expected a finite friction coefficient >= 0");
    }
  }

  // M must be symmetric: the factorization reads its lower triangle only.
  const double scale_M = max_abs(global.M);
  const SparseMatrix asymmetry = global.M - SparseMatrix(global.M.transpose());
  for (Eigen::Index c = 0; c < asymmetry.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(asymmetry, c); it; ++it) {
      if (std::abs(it.value()) > kMassSymmetryTolerance * scale_M) {
        throw InvalidArgument("to_local: the mass matrix M is not symmetric: M" +
                              index_pair(it.row(), it.col()) + " = " +
                              format_number(global.M.coeff(it.row(), it.col())) + " but M" +
                              index_pair(it.col(), it.row()) + " = " +
                              format_number(global.M.coeff(it.col(), it.row())));
      }
    }
  }

  LocalProblem local;
  local.mu = global.mu;
  local.q.assign(static_cast<std::size_t>(n), Vector3::Zero());
  if (m == 0) {
    // No degrees of freedom: W = 0 and q = w.
    local.W = to_block_sparse(SparseMatrix(3 * n, 3 * n));
    for (Eigen::Index i = 0; i < n; ++i) {
      local.q[static_cast<std::size_t>(i)] = global.w.segment<3>(3 * i);
    }
    return local;
  }

  const Eigen::SimplicialLDLT<SparseMatrix> ldlt(global.M);
  if (ldlt.info() != Eigen::Success) {
    throw InvalidArgument("to_local: the mass matrix M (" + size_text(m, m) +
                          ") is not positive definite: its LDLᵀ factorization failed");
  }
  const Eigen::VectorXd D = ldlt.vectorD();
  // The pivot of row and column `row` of M (the factorization permutes M).
  const auto pivot_text = [&](Eigen::Index k) {
    const Eigen::Index row = ldlt.permutationPinv().indices()[k];
    return "pivot " + std::to_string(k) + " of its LDLᵀ factorization (row and column " +
           std::to_string(row) + " of M, M" + index_pair(row, row) + " = " +
           format_number(global.M.coeff(row, row)) + ") is " + format_number(D[k]);
  };
  for (Eigen::Index k = 0; k < D.size(); ++k) {
    if (!(D[k] > 0.0)) {
      throw InvalidArgument("to_local: the mass matrix M (" + size_text(m, m) +
                            ") is not positive definite: " + pivot_text(k));
    }
  }
  // The pivots of an SPD matrix lie between its extreme eigenvalues, so max D / min D is at most
  // the condition number of M: a pivot below m ε max D proves M numerically singular (cond(M) >
  // 1/(m ε)), and M⁻¹ would be all rounding error, or overflow.
  const double smallest = D.maxCoeff() * static_cast<double>(m) * kEpsilon;
  for (Eigen::Index k = 0; k < D.size(); ++k) {
    if (D[k] <= smallest) {
      throw InvalidArgument("to_local: the mass matrix M (" + size_text(m, m) +
                            ") is numerically singular: " + pivot_text(k) +
                            ", at most m ε = " + format_number(static_cast<double>(m) * kEpsilon) +
                            " times the largest pivot " + format_number(D.maxCoeff()) +
                            " (the condition number of M exceeds 1/(m ε))");
    }
  }

  const SparseMatrix X = ldlt.solve(global.H);  // M⁻¹ H
  const SparseMatrix HtX = SparseMatrix(global.H.transpose()) * X;
  // Checked before pruning, which would drop NaN entries silently.
  require_finite_result(HtX, "W = Hᵀ M⁻¹ H");
  SparseMatrix W = 0.5 * (HtX + SparseMatrix(HtX.transpose()));
  require_finite_result(W, "W = (Hᵀ M⁻¹ H + (Hᵀ M⁻¹ H)ᵀ)/2");
  const double threshold = kPruneTolerance * max_abs(W);
  W.prune([threshold](Eigen::Index, Eigen::Index, double value) {
    return std::abs(value) > threshold;
  });
  local.W = to_block_sparse(W);

  const Eigen::VectorXd Minv_f = ldlt.solve(global.f);
  const Eigen::VectorXd q = global.H.transpose() * Minv_f + global.w;
  for (Eigen::Index k = 0; k < q.size(); ++k) {
    if (!std::isfinite(q[k])) {
      throw InvalidArgument("to_local: q = Hᵀ M⁻¹ f + w has a non-finite entry q[" +
                            std::to_string(k) + "] = " + format_number(q[k]) + " (contact " +
                            std::to_string(k / 3) +
                            "): M is too ill-conditioned, or H, f or w too large, for double "
                            "precision");
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) local.q[static_cast<std::size_t>(i)] = q.segment<3>(3 * i);
  return local;
}

/// ξ = W λ + q for all contacts. Throws InvalidArgument if λ or q does not have one entry per
/// block row of W.
std::vector<Vector3> local_velocities(const LocalProblem& problem,
                                      std::span<const Vector3> lambda) {
  const std::size_t n = problem.W.size();
  if (lambda.size() != n || problem.q.size() != n) {
    throw InvalidArgument(
        "local_velocities: W has " + std::to_string(n) + " block rows (contacts), but lambda has " +
        std::to_string(lambda.size()) + " entries and q " + std::to_string(problem.q.size()));
  }
  std::vector<Vector3> xi(n);
  multiply(problem.W, lambda, xi);
  for (std::size_t i = 0; i < n; ++i) xi[i] += problem.q[i];
  return xi;
}

}  // namespace grbd::contact
