#pragma once
/// \file
/// \brief Broad phase for many spheres: a uniform grid of cell lists, O(N) in time and memory,
/// with Morton (Z-order) reordering so that neighbours are close in memory (chapter 4).

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "grbd/core/types.hpp"

namespace grbd::collision {

/// A candidate pair of spheres (i < j).
using IndexPair = std::pair<std::int32_t, std::int32_t>;

// [morton declaration]
/// \brief <b>Exercise 4.6</b>: the Morton code of a grid cell.
///
/// Interleaves the bits of the cell coordinates, bit b of i, j, k going to bits 3b, 3b + 1,
/// 3b + 2 of the code, for i, j, k < 2²¹ (else grbd::InvalidArgument): cells close in space get
/// close codes (Z-order curve).
std::uint64_t morton_code(std::uint32_t i, std::uint32_t j, std::uint32_t k);
// [morton declaration]

/// The Morton code of each point's cell, the cells of edge `cell_size` counted from the points'
/// bounding box (where the box would need more than 2²¹ cells per axis the cells grow to fit):
/// codes[i] for points[i]. Allocates nothing. Needs a finite cell_size > 0, finite points whose
/// differences are finite, and codes.size() == points.size(), else grbd::InvalidArgument. The
/// smallest positive cell size gives the finest grid, 2²¹ cells along the longest axis.
void morton_codes(std::span<const Vector3> points, double cell_size,
                  std::span<std::uint64_t> codes);

/// The permutation that sorts the points by the Morton code of their cell of size `cell_size`
/// (relative to the points' bounding box): order[n] is the index of the n-th point in Z-order,
/// ties broken by index. Where the box would need more than 2²¹ cells per axis the cells grow to
/// fit. Needs a finite cell_size > 0 and finite centres, else grbd::InvalidArgument.
std::vector<std::int32_t> morton_order(std::span<const Vector3> centres, double cell_size);

/// Cell lists on a uniform grid for spheres of bounded radius. build() bins the centres into
/// cubic cells of edge h ≥ 2 r_max + margin (larger by a relative 10⁻⁶, so that rounding cannot
/// put a pair two cells apart) with a counting sort (O(N + cells), no per-sphere allocation; the
/// buffers are reused by the next build) and copies the centres and radii into one array in cell
/// order; find_pairs() then tests each sphere against the spheres of its own and the 13
/// "forward" neighbour cells, streaming through that array. The grid covers the bounding box
/// of the centres; its memory is O(N) because the number of cells is capped at 2N + 64 (cells
/// grow when the box is sparse) and at 2²¹ per axis. The grid keeps copies, not references, of
/// the input.
class CellGrid {
 public:
  /// Bins the spheres; radii.size() == centres.size(), radii > 0, margin ≥ 0, all finite, else
  /// grbd::InvalidArgument.
  void build(std::span<const Vector3> centres, std::span<const double> radii, double margin);
  /// Every pair i < j with |c_i − c_j| < r_i + r_j + margin, each once, in no particular order;
  /// `pairs` is cleared first (its capacity is kept). The test is evaluated as
  /// |c_i − c_j|² < (r_i + r_j + margin)² in the same floating-point operations as
  /// brute_force_pairs(), so both find exactly the same pairs.
  void find_pairs(std::vector<IndexPair>& pairs) const;
  /// Number of cells per axis.
  Eigen::Vector3i cells() const { return dims_; }
  /// The cell edge h [m].
  double cell_size() const { return h_; }

 private:
  double margin_ = 0.0;
  double h_ = 0.0;
  Vector3 origin_ = Vector3::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<std::int32_t> cell_start_;  // size cells + 1: start of each cell in balls_
  std::vector<std::int32_t> cell_of_;     // cell of each sphere (input order)
  // Centre and radius of each sphere in cell order, 32 bytes each: find_pairs streams through
  // contiguous memory, and build scatters each sphere with a single cache-line write.
  struct Ball {
    double x, y, z, r;
  };
  std::vector<Ball> balls_;
  std::vector<std::int32_t> index_;  // input index of each ball
  // Scratch of find_pairs(): the balls of one cell's neighbourhood, kept between calls.
  mutable std::vector<Ball> near_;
  mutable std::vector<std::int32_t> near_index_;
};

/// Every pair i < j with |c_i − c_j| < r_i + r_j + margin by testing all N(N − 1)/2 pairs: the
/// reference for CellGrid, sorted by (i, j).
std::vector<IndexPair> brute_force_pairs(std::span<const Vector3> centres,
                                         std::span<const double> radii, double margin);

}  // namespace grbd::collision
