/// \file
/// \brief The O(N) broad phase: cell lists on a uniform grid (counting sort, half-shell
/// neighbour search), Morton reordering, and the brute-force reference.

#include "grbd/collision/broad_phase.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::collision {

namespace {

constexpr std::int64_t kMaxCellsPerAxis = std::int64_t{1} << 21;  // the range of morton_code

/// The overlap test shared by CellGrid and brute_force_pairs: the same operations in the same
/// order (the differences enter squared, so their sign does not matter), hence the same answer.
inline bool overlaps(double dx, double dy, double dz, double contact_distance) {
  return dx * dx + dy * dy + dz * dz < contact_distance * contact_distance;
}

void require_finite_centres(std::string_view where, std::span<const Vector3> centres) {
  for (std::size_t i = 0; i < centres.size(); ++i) {
    if (!centres[i].allFinite()) {
      throw InvalidArgument(std::string(where) + ": expected finite centres, found centre " +
                            std::to_string(i) + " = (" + format_number(centres[i].x()) + ", " +
                            format_number(centres[i].y()) + ", " + format_number(centres[i].z()) +
                            ")");
    }
  }
}

void require_spheres(std::string_view where, std::span<const Vector3> centres,
                     std::span<const double> radii, double margin) {
  if (radii.size() != centres.size()) {
    throw InvalidArgument(std::string(where) + ": expected as many radii as centres, found " +
                          std::to_string(radii.size()) + " radii and " +
                          std::to_string(centres.size()) + " centres");
  }
  if (centres.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    throw InvalidArgument(std::string(where) + ": expected at most 2³¹ − 1 spheres, found " +
                          std::to_string(centres.size()));
  }
  if (!(margin >= 0.0) || !std::isfinite(margin)) {
    throw InvalidArgument(std::string(where) + ": expected a finite margin ≥ 0, found " +
                          format_number(margin));
  }
  for (const double r : radii) require_positive_finite(where, "radius", r);
  require_finite_centres(where, centres);
}

/// The bounding box [lo, hi] of the centres (not empty).
std::pair<Vector3, Vector3> bounding_box(std::span<const Vector3> centres) {
  Vector3 lo = centres.front();
  Vector3 hi = lo;
  for (const Vector3& c : centres) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  return {lo, hi};
}

/// Cells per axis for a box of the given extent and cell edge h, as doubles (no overflow).
Eigen::Vector3d cells_per_axis(const Vector3& extent, double h) {
  return (extent / h).array().floor() + 1.0;
}

/// Cell coordinate floor(t) of t = (x − origin)/h, clamped to [0, n − 1]. The clamp comes
/// before the conversion: converting a double outside the range of int32 is undefined.
inline std::int32_t cell_coordinate(double t, std::int32_t n) {
  if (!(t > 0.0)) return 0;  // also NaN, which the callers' checks exclude
  if (t >= static_cast<double>(n - 1)) return n - 1;
  return static_cast<std::int32_t>(t);  // 0 < t < n − 1: truncation is floor
}

/// The bounding box of the centres, refused (InvalidArgument) when its extent overflows: the
/// centres are finite, but their differences, and with them any grid over them, are not
/// representable (centres at ±10³⁰⁸).
std::pair<Vector3, Vector3> grid_box(std::string_view where, std::span<const Vector3> centres) {
  const auto [lo, hi] = bounding_box(centres);
  const Vector3 extent = hi - lo;
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(extent[k])) {
      throw InvalidArgument(std::string(where) + ": the centres span more than the largest "
                            "double along axis " + std::to_string(k) + ", from " +
                            format_number(lo[k]) + " to " + format_number(hi[k]) +
                            "; expected coordinates whose differences are finite (a grid over "
                            "them cannot be represented)");
    }
  }
  return {lo, hi};
}

}  // namespace

namespace {

// morton_codes() with the caller's name in its messages.
void checked_morton_codes(std::string_view where, std::span<const Vector3> points,
                          double cell_size, std::span<std::uint64_t> codes) {
  require_positive_finite(where, "cell size", cell_size);
  if (codes.size() != points.size()) {
    throw InvalidArgument(std::string(where) + ": expected one code per point, found room for " +
                          std::to_string(codes.size()) + " codes and " +
                          std::to_string(points.size()) + " points");
  }
  require_finite_centres(where, points);
  if (points.empty()) return;
  const auto [lo, hi] = grid_box(where, points);
  // Coarsen the cells where the box would need more than 2²¹ of them along an axis.
  const double h = std::max(cell_size, (hi - lo).maxCoeff() / double(kMaxCellsPerAxis - 1));
  const auto cells = static_cast<std::int32_t>(kMaxCellsPerAxis);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vector3 t = (points[i] - lo) / h;
    codes[i] = morton_code(static_cast<std::uint32_t>(cell_coordinate(t.x(), cells)),
                           static_cast<std::uint32_t>(cell_coordinate(t.y(), cells)),
                           static_cast<std::uint32_t>(cell_coordinate(t.z(), cells)));
  }
}

}  // namespace

void morton_codes(std::span<const Vector3> points, double cell_size,
                  std::span<std::uint64_t> codes) {
  checked_morton_codes("morton_codes", points, cell_size, codes);
}

std::vector<std::int32_t> morton_order(std::span<const Vector3> centres, double cell_size) {
  std::vector<std::uint64_t> codes(centres.size());
  checked_morton_codes("morton_order", centres, cell_size, codes);
  std::vector<std::pair<std::uint64_t, std::int32_t>> keys(centres.size());
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = {codes[i], static_cast<std::int32_t>(i)};
  std::sort(keys.begin(), keys.end());  // by code, then by index
  std::vector<std::int32_t> order(centres.size());
  for (std::size_t m = 0; m < order.size(); ++m) order[m] = keys[m].second;
  return order;
}

// [cell grid build]
void CellGrid::build(std::span<const Vector3> centres, std::span<const double> radii,
                     double margin) {
  require_spheres("CellGrid::build", centres, radii, margin);
  const auto n = static_cast<std::int32_t>(centres.size());
  margin_ = margin;
  if (n == 0) {
    h_ = 0.0;
    origin_.setZero();
    dims_.setZero();
    cell_start_.assign(1, 0);
    balls_.clear(), index_.clear(), cell_of_.clear();
    return;
  }
  // A pair within reach, |c_i − c_j| < r_i + r_j + margin ≤ 2 r_max + margin, lies in the same
  // or in adjacent cells when h ≥ 2 r_max + margin; the relative 1e-6 absorbs the rounding of
  // (x − origin)/h, which is below 1e-9 cell edges for up to 2²¹ cells per axis.
  const double r_max = *std::max_element(radii.begin(), radii.end());
  const auto [lo, hi] = grid_box("CellGrid::build", centres);
  const Vector3 extent = hi - lo;
  double h = (2.0 * r_max + margin) * (1.0 + 1e-6);
  // O(N) memory: at most 2N + 64 cells (and 2³⁰) and 2²¹ per axis; a sparse box gets larger cells.
  const double max_cells = std::min(2.0 * n + 64.0, 0x1p30);
  h = std::max(h, extent.maxCoeff() / double(kMaxCellsPerAxis - 1));
  for (Eigen::Vector3d d = cells_per_axis(extent, h); d.prod() > max_cells;
       d = cells_per_axis(extent, h)) {
    h *= 1.01 * std::cbrt(d.prod() / max_cells);
  }
  h_ = h;
  origin_ = lo;
  dims_ = cells_per_axis(extent, h).cast<int>();
  const std::int32_t nx = dims_.x(), ny = dims_.y(), nz = dims_.z();
  const std::int32_t cells = nx * ny * nz;

  // Counting sort by cell: count, exclusive prefix sum, scatter. The cell index is linear with
  // x fastest, so that the three cells (x − 1 … x + 1, y, z) are contiguous in the sorted order.
  const double inv_h = 1.0 / h;
  cell_of_.resize(n);
  cell_start_.assign(static_cast<std::size_t>(cells) + 1, 0);
  for (std::int32_t i = 0; i < n; ++i) {
    const Vector3 t = (centres[i] - lo) * inv_h;
    const std::int32_t c = cell_coordinate(t.x(), nx) +
                           nx * (cell_coordinate(t.y(), ny) + ny * cell_coordinate(t.z(), nz));
    cell_of_[i] = c;
    ++cell_start_[c + 1];
  }
  for (std::int32_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  balls_.resize(n), index_.resize(n);
  // Scatter with cell_start_[c] as the running insertion point of cell c; afterwards it holds
  // the end of cell c, i.e. the start of cell c + 1, and one shift restores the starts.
  for (std::int32_t i = 0; i < n; ++i) {
    const std::int32_t slot = cell_start_[cell_of_[i]]++;
    balls_[slot] = {centres[i].x(), centres[i].y(), centres[i].z(), radii[i]};
    index_[slot] = i;
  }
  std::copy_backward(cell_start_.begin(), cell_start_.end() - 1, cell_start_.end());
  cell_start_[0] = 0;
}
// [cell grid build]

// [cell grid pairs]
void CellGrid::find_pairs(std::vector<IndexPair>& pairs) const {
  pairs.clear();
  const std::int32_t nx = dims_.x(), ny = dims_.y(), nz = dims_.z();
  if (index_.empty()) return;
  const Ball* balls = balls_.data();
  const std::int32_t* start = cell_start_.data();
  const double margin = margin_;

  // The half shell of cell (i, j, k): the cell itself (pairs a < b), (i + 1, j, k), and the rows
  // of three cells (i − 1 … i + 1) at (j + 1, k), (j − 1, k + 1), (j, k + 1), (j + 1, k + 1): 13
  // neighbours, so each unordered pair of adjacent cells is visited once. A row of three cells
  // is one contiguous range of balls_. The ranges are gathered into one short array `near`,
  // the cell's own balls first, so that each ball of the cell runs a single loop (few
  // mispredicted loop exits), and every test writes its pair unconditionally to `pairs`, kept
  // long enough, and keeps it only on a hit (no unpredictable branch). `near` is a member that
  // keeps its capacity: after the first call, finding pairs allocates nothing (chapter 6).
  std::vector<Ball>& near = near_;
  std::vector<std::int32_t>& near_index = near_index_;
  std::size_t count = 0;
  const auto gather = [&](std::int32_t begin, std::int32_t end) {
    near.insert(near.end(), balls + begin, balls + end);
    near_index.insert(near_index.end(), index_.begin() + begin, index_.begin() + end);
  };
  for (std::int32_t k = 0; k < nz; ++k) {
    for (std::int32_t j = 0; j < ny; ++j) {
      const std::int32_t row = nx * (j + ny * k);
      for (std::int32_t i = 0; i < nx; ++i) {
        const std::int32_t c = row + i;
        const std::int32_t a_begin = start[c], a_end = start[c + 1];
        if (a_begin == a_end) continue;
        near.clear();
        near_index.clear();
        gather(a_begin, i + 1 < nx ? start[c + 2] : a_end);  // own cell and (i + 1, j, k)
        const std::int32_t i_lo = i > 0 ? i - 1 : 0;
        const std::int32_t i_hi = i + 1 < nx ? i + 2 : nx;  // one past the last cell of the row
        const auto gather_row = [&](std::int32_t jj, std::int32_t kk) {
          if (jj < 0 || jj >= ny || kk >= nz) return;
          const std::int32_t base = nx * (jj + ny * kk);
          gather(start[base + i_lo], start[base + i_hi]);
        };
        gather_row(j + 1, k);
        gather_row(j - 1, k + 1);
        gather_row(j, k + 1);
        gather_row(j + 1, k + 1);

        const auto m = static_cast<std::int32_t>(near.size());
        const std::int32_t own = a_end - a_begin;
        const std::size_t most = static_cast<std::size_t>(own) * static_cast<std::size_t>(m);
        // Room for every test of this cell; the vector's storage grows geometrically and is
        // kept by the caller from call to call.
        if (pairs.size() < count + most) pairs.resize(count + most + 1024);
        IndexPair* out = pairs.data();
        for (std::int32_t a = 0; a < own; ++a) {
          const Ball ba = near[a];
          const std::int32_t ia = near_index[a];
          for (std::int32_t b = a + 1; b < m; ++b) {
            const Ball& bb = near[b];
            const std::int32_t ib = near_index[b];
            // (min, max) by masks: a compare-and-branch would be mispredicted in random order.
            const std::int32_t lo = ib ^ ((ia ^ ib) & -static_cast<std::int32_t>(ia < ib));
            out[count] = {lo, ia ^ ib ^ lo};
            count += overlaps(bb.x - ba.x, bb.y - ba.y, bb.z - ba.z, (bb.r + ba.r) + margin);
          }
        }
      }
    }
  }
  pairs.resize(count);
}
// [cell grid pairs]

std::vector<IndexPair> brute_force_pairs(std::span<const Vector3> centres,
                                         std::span<const double> radii, double margin) {
  require_spheres("brute_force_pairs", centres, radii, margin);
  std::vector<IndexPair> pairs;
  const auto n = static_cast<std::int32_t>(centres.size());
  for (std::int32_t i = 0; i < n; ++i) {
    for (std::int32_t j = i + 1; j < n; ++j) {
      const Vector3& ci = centres[i];
      const Vector3& cj = centres[j];
      if (overlaps(cj.x() - ci.x(), cj.y() - ci.y(), cj.z() - ci.z(),
                   (radii[j] + radii[i]) + margin)) {
        pairs.emplace_back(i, j);
      }
    }
  }
  return pairs;
}

}  // namespace grbd::collision
