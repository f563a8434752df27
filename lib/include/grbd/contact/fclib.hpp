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
///
/// The reader trusts nothing in the file before checking it, and refuses with a grbd::Error whose
/// message starts with the file's path and names the group or dataset at fault:
/// - the path must be a regular file (a FIFO, a device or a directory is refused before HDF5
///   opens it); "no such file", "is not a regular file" and "cannot be opened (reason)" are told
///   apart;
/// - every group and dataset is reached through hard links only: soft and external links (which
///   could name any file, a pipe that blocks forever included), external storage and virtual
///   datasets are refused;
/// - every element type is a standard 1- to 8-byte integer or an IEEE 754 single or double (a
///   damaged type size is refused at once), and uncompressed data cannot declare more bytes than
///   the file holds;
/// - sizes are checked against each other before anything is allocated: n contacts from W
///   (3n × 3n) or H (m × 3n), m from M (m × m); mu must have n entries, q and w 3n, f m; a sparse
///   matrix at most nzmax entries, each dataset at least as many as its header declares;
/// - a local problem read passes validate() (a W with a zero diagonal is refused naming the file
///   and /fclib_local/W); read_fclib_as_local() names the file and /fclib_global/M when the
///   global problem cannot be put in local form (M singular or ill-conditioned).

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

/// The kind and header data of the FCLIB file at `path` (the contacts counted from the header of W
/// or H, and mu checked to have one entry each). Throws grbd::Error naming the file and the
/// missing or malformed group or dataset.
FclibInfo read_fclib_info(const std::filesystem::path& path);

/// Reads a local problem and checks it with validate(). Throws grbd::Error naming the file and the
/// group or dataset that is missing, has the wrong type or shape, holds inconsistent indices or
/// gives an invalid problem, and refuses problems that are not 3D or have equality constraints.
LocalProblem read_fclib_local(const std::filesystem::path& path);

/// Reads a global problem, with the same checks.
GlobalProblem read_fclib_global(const std::filesystem::path& path);

/// Reads either kind and returns it in local form (converting a global one with to_local(), whose
/// result is checked with validate()); a global problem that cannot be converted is refused with
/// an InvalidArgument naming the file and /fclib_global/M.
LocalProblem read_fclib_as_local(const std::filesystem::path& path);

/// Reads the FCLIB sparse matrix stored in group `group` (e.g. "/fclib_local/W") of the file at
/// `path`, in any of the three storage kinds; duplicate triplets are summed. A row or column
/// count larger than the file's size in bytes is refused (nothing in the file backs it).
Eigen::SparseMatrix<double> read_fclib_matrix(const std::filesystem::path& path,
                                              const std::string& group);

}  // namespace grbd::contact
