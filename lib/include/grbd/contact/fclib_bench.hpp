#pragma once
/// \file
/// \brief The FCLIB bench (chapter 5, run by `grbd fclib` and the demo ch05_fclib): grbd's
/// solvers on problems of the community benchmark of frictional contact (Acary, Brémond and
/// Huber 2018), each from λ = 0 (and warm from the file's guess when it has one).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace grbd::contact {

/// The most iterations the bench gives Newton's methods (each iteration is a linear solve):
/// min(FclibBenchOptions::max_iterations, this).
inline constexpr int kFclibNewtonIterations = 200;

/// How the bench solves.
struct FclibBenchOptions {
  double tol = 1e-8;            ///< stop once ‖F‖ ≤ tol ‖q‖ (the natural-map residual)
  int max_iterations = 20000;   ///< per solver and problem
  bool record_history = false;  ///< keep ‖F_k‖/‖q‖ of every iteration
};

/// One solver on one problem.
struct FclibBenchRow {
  std::string problem;           ///< the file's stem
  /// SOR-AC, SOR-DS, JOR, APGD, Newton (sparse LU), Newton-GMRES or "SOR-AC warm"
  std::string solver;
  std::size_t contacts = 0;      ///< n
  int iterations = 0;            ///< iterations done
  int linear_iterations = 0;     ///< Newton: factorizations (LU) or products with J (GMRES)
  double relative_residual = 0;  ///< ‖F‖/‖q‖
  double scaled_residual = 0;    ///< ‖F‖/max(‖q‖, ‖λ‖, ‖ξ‖)
  double seconds = 0;            ///< wall time of the solve
  bool converged = false;        ///< reached tol
  std::vector<double> history;   ///< ‖F_k‖/‖q‖, with record_history
};

/// The FCLIB files `argument` names: the file itself, or every *.hdf5 in the folder, in name
/// order. Throws grbd::Error naming the argument when it is neither, or a folder cannot be read or
/// holds no *.hdf5 file.
std::vector<std::filesystem::path> fclib_files(const std::string& argument);

/// Solves every problem of `files` with SOR (Alart–Curnier and De Saxcé prox), JOR (α = 0.5,
/// one global r), APGD, Newton with the sparse LU and Newton with GMRES (at most
/// kFclibNewtonIterations Newton iterations, or max_iterations if fewer), and SOR warm from the file's guess where it holds one;
/// calls `row` after each solve. Throws what the FCLIB reader throws for a file it cannot read.
void fclib_bench(const std::vector<std::filesystem::path>& files, const FclibBenchOptions& options,
                 const std::function<void(const FclibBenchRow&)>& row);

/// The header of the bench's table: fixed-width columns, ending in a newline; with
/// `max_iterations` > 0 it ends in the caps of the run ("caps: N iterations, Newton min(N, 200)").
std::string fclib_table_header(int max_iterations = 0);
/// A row of the bench's table, in the columns of fclib_table_header().
std::string fclib_table_line(const FclibBenchRow& row);

}  // namespace grbd::contact
