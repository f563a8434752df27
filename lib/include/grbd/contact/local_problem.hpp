#pragma once
/// \file
/// \brief The contact problem in local form (chapter 5), as FCLIB stores it: ξ = W λ + q with a
/// sparse Delassus matrix W of 3 × 3 blocks, friction coefficients μ, and the conversion of a
/// global problem (M, H, f, w) to local form, W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/SparseCore>

#include "grbd/core/types.hpp"

namespace grbd::contact {

/// A square matrix of 3 × 3 blocks in compressed block rows: block row i holds the blocks
/// `blocks[k]` at block columns `column[k]` for k ∈ [row_start[i], row_start[i+1]), sorted by
/// column. `diagonal[i]` is the k of block (i, i).
struct BlockSparseMatrix {
  std::vector<std::int64_t> row_start;  ///< n + 1 offsets into column/blocks
  std::vector<std::int32_t> column;     ///< block column of each stored block
  std::vector<Matrix3> blocks;          ///< the stored blocks
  std::vector<std::int64_t> diagonal;   ///< index of the diagonal block of each row
  /// Number of block rows (contacts).
  std::size_t size() const { return row_start.empty() ? 0 : row_start.size() - 1; }
};

/// Converts a 3n × 3n sparse matrix to blocks; every diagonal block is stored (zero if absent).
/// Throws InvalidArgument if the matrix is not square with a multiple of 3 rows.
BlockSparseMatrix to_block_sparse(const Eigen::SparseMatrix<double>& W);

/// y = W x for per-contact vectors x, y (n entries each): the kernel of the solvers, called every
/// iteration. It checks only what costs O(1) or O(n) per call (the sizes of x and y, that they do
/// not overlap, that row_start starts at 0, is monotone and ends at the number of blocks and block
/// columns) and throws InvalidArgument if one fails. The block columns are not checked: W must come
/// from to_block_sparse() or belong to a problem that passed validate() (the solvers and the FCLIB
/// reader validate every problem); a column out of range is undefined behaviour here.
void multiply(const BlockSparseMatrix& W, std::span<const Vector3> x, std::span<Vector3> y);

/// The local problem: find λ_i ∈ K_μi with ξ = W λ + q satisfying the Coulomb law.
struct LocalProblem {
  BlockSparseMatrix W;       ///< the Delassus matrix, 3n × 3n in 3 × 3 blocks
  std::vector<Vector3> q;    ///< free velocity per contact
  std::vector<double> mu;    ///< friction coefficient per contact
};

/// Checks a local problem and throws InvalidArgument naming the first bad entry: a corrupted
/// block structure (row_start not starting at 0 or not monotone, block columns out of range or not
/// increasing, a diagonal index that is not the index of the diagonal block, fewer or more blocks
/// and block columns than row_start says), sizes that disagree, NaN or Inf in W (its diagonal
/// included) or q, μ < 0 or not finite, a diagonal block whose diagonal is not positive. A problem
/// that passes is safe for multiply() and the solvers. W need not be symmetric: FCLIB files hold W
/// as other codes computed it, and the Capsules-286 problem's W is asymmetric by 2 % within a
/// diagonal block.
void validate(const LocalProblem& problem);

/// The global problem of FCLIB: M v = H λ + f, ξ = Hᵀ v + w. M (m × m) symmetric positive
/// definite, H (m × 3n), f (m), w (3n), μ (n).
struct GlobalProblem {
  Eigen::SparseMatrix<double> M;  ///< mass matrix
  Eigen::SparseMatrix<double> H;  ///< contact directions, 3 columns per contact
  Eigen::VectorXd f;              ///< free force / momentum term
  Eigen::VectorXd w;              ///< velocity offset, 3 per contact
  std::vector<double> mu;         ///< friction coefficient per contact
};

/// W = Hᵀ M⁻¹ H and q = Hᵀ M⁻¹ f + w by a sparse Cholesky (LDLᵀ) factorization of M. Throws
/// InvalidArgument if sizes disagree, an input is not finite, M is not symmetric, not positive
/// definite or numerically singular (a pivot at most m ε times the largest: cond(M) > 1/(m ε)), or
/// if W or q come out non-finite, naming what failed.
LocalProblem to_local(const GlobalProblem& global);

/// ξ = W λ + q for all contacts.
std::vector<Vector3> local_velocities(const LocalProblem& problem, std::span<const Vector3> lambda);

}  // namespace grbd::contact
