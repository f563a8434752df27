/// \file
/// \brief The Cartesian decomposition of the domain; chapter 8 exercises: the owner of a position,
/// the overlap of a body with a subdomain, and the process that solves a contact.

#include "grbd/parallel/decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::parallel {

namespace {

void require_extent(const Vector3& extent, const char* where) {
  for (int d = 0; d < 3; ++d) {
    if (!(extent[d] > 0.0) || !std::isfinite(extent[d])) {
      throw InvalidArgument(std::string(where) +
                            ": expected a domain of positive, finite extent, "
                            "found " +
                            format_number(extent[0]) + " × " + format_number(extent[1]) + " × " +
                            format_number(extent[2]) + " m");
    }
  }
}

}  // namespace

std::array<int, 3> grid_dims(int processes, const Vector3& extent) {
  if (processes < 1) {
    throw InvalidArgument("grid_dims: expected at least one process, found " +
                          std::to_string(processes));
  }
  require_extent(extent, "grid_dims");
  const Vector3 cross(extent.y() * extent.z(), extent.x() * extent.z(), extent.x() * extent.y());
  std::array<int, 3> best{processes, 1, 1};
  double best_area = std::numeric_limits<double>::infinity();
  for (int nx = processes; nx >= 1; --nx) {
    if (processes % nx != 0) continue;
    for (int ny = processes / nx; ny >= 1; --ny) {
      if ((processes / nx) % ny != 0) continue;
      const int nz = processes / nx / ny;
      const double area = (nx - 1) * cross.x() + (ny - 1) * cross.y() + (nz - 1) * cross.z();
      if (area < best_area * (1.0 - 1e-12)) {  // ties keep the earlier: more cuts along x, then y
        best_area = area;
        best = {nx, ny, nz};
      }
    }
  }
  return best;
}

CartesianGrid::CartesianGrid(const Box& domain, const std::array<int, 3>& dims,
                             const std::array<bool, 3>& periodic)
    : Partition(domain, periodic, "CartesianGrid"), dims_(dims) {
  for (int d = 0; d < 3; ++d) {
    if (dims[d] < 1) {
      throw InvalidArgument(
          "CartesianGrid: expected at least one subdomain along each axis, "
          "found " +
          std::to_string(dims[0]) + " × " + std::to_string(dims[1]) + " × " +
          std::to_string(dims[2]));
    }
    std::vector<double>& b = boundaries_[d];
    b.resize(static_cast<std::size_t>(dims[d]) + 1);
    for (int i = 0; i <= dims[d]; ++i) {
      b[static_cast<std::size_t>(i)] =
          i == dims[d] ? domain.max()[d]
                       : domain.min()[d] + (domain.max()[d] - domain.min()[d]) * i / dims[d];
    }
  }
}

CartesianGrid::CartesianGrid(const Box& domain,
                             const std::array<std::vector<double>, 3>& boundaries,
                             const std::array<bool, 3>& periodic)
    : Partition(domain, periodic, "CartesianGrid"), boundaries_(boundaries) {
  for (int d = 0; d < 3; ++d) {
    const std::vector<double>& b = boundaries_[d];
    bool valid = b.size() >= 2 && b.front() == domain.min()[d] && b.back() == domain.max()[d];
    for (std::size_t i = 1; valid && i < b.size(); ++i) valid = b[i - 1] < b[i];
    if (!valid) {
      throw InvalidArgument("CartesianGrid: expected boundaries along axis " + std::to_string(d) +
                            " that increase strictly from the domain's min to its max");
    }
    dims_[d] = static_cast<int>(b.size()) - 1;
  }
}

std::array<int, 3> CartesianGrid::cell_of(int rank) const {
  if (rank < 0 || rank >= size()) {
    throw InvalidArgument("CartesianGrid: expected a rank in [0, " + std::to_string(size()) +
                          "), found " + std::to_string(rank));
  }
  return {rank % dims_[0], (rank / dims_[0]) % dims_[1], rank / (dims_[0] * dims_[1])};
}

int CartesianGrid::rank_of(const std::array<int, 3>& cell) const {
  return cell[0] + dims_[0] * (cell[1] + dims_[1] * cell[2]);
}

Box CartesianGrid::subdomain(int rank) const {
  const std::array<int, 3> c = cell_of(rank);
  Vector3 lo, hi;
  for (int d = 0; d < 3; ++d) {
    lo[d] = boundaries_[d][static_cast<std::size_t>(c[d])];
    hi[d] = boundaries_[d][static_cast<std::size_t>(c[d]) + 1];
  }
  return Box(lo, hi);
}

int CartesianGrid::owner_of(const Vector3& position) const {
  // BEGIN EXERCISE 8.1: the owner of a position
  // Hint: wrap() the position; along each axis d count the interior boundaries b_1 … b_{n−1}
  //   (boundaries_[d]) that are ≤ x_d (std::upper_bound): that count is the cell index, already
  //   clamped to [0, n − 1]; then rank_of(cell).
  const Vector3 x = wrap(position);
  std::array<int, 3> cell{};
  for (int d = 0; d < 3; ++d) {
    // The interior boundaries b_1 … b_{n−1} at or below x: the cell whose [b_i, b_{i+1}) holds x,
    // clamped to the first and last cell outside the domain.
    const std::vector<double>& b = boundaries_[d];
    const auto above = std::upper_bound(b.begin() + 1, b.end() - 1, x[d]);
    cell[d] = static_cast<int>(above - (b.begin() + 1));
  }
  return rank_of(cell);
  // END EXERCISE 8.1
}

bool overlaps(const Vector3& centre, double reach, const Box& box) {
  // BEGIN EXERCISE 8.2: does a body reach into a subdomain?
  // Hint: the point of the box closest to the centre is the centre clamped to [min, max] axis by
  //   axis; compare squared distances, so that no square root rounds a touching body away.
  // The point of the box closest to the centre is the centre clamped to the box.
  const Vector3 closest = centre.cwiseMax(box.min()).cwiseMin(box.max());
  return (closest - centre).squaredNorm() <= reach * reach;
  // END EXERCISE 8.2
}

bool solves_contact(const timestep::BodySystem& system, const timestep::DetectedContact& c) {
  // BEGIN EXERCISE 8.3: which process solves a contact?
  // Hint: the side that decides is side a (row_a), unless side a is a static object (row −1):
  //   then side b. A process solves the contact when it owns that side (BodySystem::owned).
  const int row = c.row_a >= 0 ? c.row_a : c.row_b;
  return row >= 0 && system.owned(static_cast<std::size_t>(row));
  // END EXERCISE 8.3
}

}  // namespace grbd::parallel
