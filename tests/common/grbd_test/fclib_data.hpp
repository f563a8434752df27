#pragma once
// The FCLIB problems shipped with chapter 5 (chapters/05-contact-laws/data) and what the tests of
// its solvers on them share: the files' paths, the natural-residual criterion, a vector's norm.
// GRBD_FCLIB_DATA_DIR is defined by tests/05-contact-laws/CMakeLists.txt.

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "grbd/contact/solver.hpp"
#include "grbd/core/types.hpp"

namespace grbd::test {

/// The FCLIB file `name` of the chapter's data folder.
inline std::filesystem::path fclib_file(const std::string& name) {
  return std::filesystem::path(GRBD_FCLIB_DATA_DIR) / name;
}

/// Options that stop at ‖F‖ ≤ tol ‖q‖ (natural residual, no absolute part) or max_iterations.
inline contact::SolverOptions to_tolerance(double tol, int max_iterations) {
  contact::SolverOptions options;
  options.criterion = contact::Criterion::natural_residual;
  options.abs_tol = 0.0;
  options.rel_tol = tol;
  options.max_iterations = max_iterations;
  return options;
}

/// (Σ ‖x_i‖²)^½.
inline double norm(const std::vector<Vector3>& v) {
  double sum = 0.0;
  for (const Vector3& x : v) sum += x.squaredNorm();
  return std::sqrt(sum);
}

}  // namespace grbd::test
