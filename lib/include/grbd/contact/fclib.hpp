#pragma once
/// \file
/// \brief A reader of FCLIB files (chapter 5): the HDF5 format of the Frictional Contact Library
/// (Acary, Brémond, Huber), local problems (W, q, μ) and global problems (M, H, f, w, μ).
///
/// The reader follows the format exactly and uses grbd's own (parallel) HDF5 library; Debian's
/// libfclib is linked against the serial HDF5 and cannot share a process with it. Sparse matrices
/// are stored as `{m, n, nz, nzmax, p, i, x}`: nz = −1 compressed columns (p has n + 1 entries,
/// i row indices), nz = −2 compressed rows (p has m + 1 entries, i column indices), nz ≥ 0
/// triplets (i row, p column, nz entries). Only 3D problems without equality constraints are
/// read.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/SparseCore>

#include "grbd/contact/local_problem.hpp"
#include "grbd/core/types.hpp"

namespace grbd::contact {

/// The kind of problem a file holds.
enum class FclibKind {
  local,   ///< group /fclib_local
  global,  ///< group /fclib_global
};

/// What an FCLIB file holds besides the problem.
struct FclibInfo {
  FclibKind kind = FclibKind::local;  ///< local or global
  int contacts = 0;                   ///< number of contacts n
  std::string title;                  ///< /fclib_*/info/title, if present
  std::string description;            ///< /fclib_*/info/description, if present
  std::string math_info;              ///< /fclib_*/info/math_info, if present
  /// /guesses/1/r, the first stored guess of the percussions, if present (a warm start only).
  std::optional<std::vector<Vector3>> guess;
};

/// The kind and header data of the FCLIB file at `path`. Throws grbd::Error naming the file and
/// the missing or malformed group or dataset.
FclibInfo read_fclib_info(const std::filesystem::path& path);

/// Reads a local problem. Throws grbd::Error naming the file and the group or dataset that is
/// missing, has the wrong type or shape, or holds inconsistent indices, and refuses problems
/// that are not 3D or have equality constraints.
LocalProblem read_fclib_local(const std::filesystem::path& path);

/// Reads a global problem, with the same checks.
GlobalProblem read_fclib_global(const std::filesystem::path& path);

/// Reads either kind and returns it in local form (converting a global one with to_local()).
LocalProblem read_fclib_as_local(const std::filesystem::path& path);

/// Reads the FCLIB sparse matrix stored in group `group` (e.g. "/fclib_local/W") of the file at
/// `path`, in any of the three storage kinds; duplicate triplets are summed.
Eigen::SparseMatrix<double> read_fclib_matrix(const std::filesystem::path& path,
                                              const std::string& group);

}  // namespace grbd::contact
