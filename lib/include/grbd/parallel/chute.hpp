#pragma once
/// \file
/// \brief The chute study (chapter 8): the reference chute's geometry as its measurements need it,
/// the flow count past the kink, the front, and the times the flow takes.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include "grbd/core/types.hpp"

namespace grbd::parallel {

/// The reference chute (Nützi's experiment as GRSFramework's study set it up): an upper chute
/// whose floor is the plane z = 0, the beads flowing towards −x, and from x = kink_x on a run-out
/// `bend_degrees` flatter, its floor rising above z = 0 downstream of the kink.
struct ChuteGeometry {
  double kink_x = -0.296;      ///< where the run-out begins [m]
  double bend_degrees = 10.0;  ///< the run-out's angle to the upper floor [°]

  /// A position in the run-out's frame: origin at the kink, x' along the run-out's floor (negative
  /// downstream, as the reference gives the trees), y' = y, z' the height above that floor.
  Vector3 runout(const Vector3& position) const;
  /// The distance along the floors from the top of the upper chute (x = 0) downstream to below a
  /// position [m]: −x on the upper chute, −kink_x − x' on the run-out.
  double path(const Vector3& position) const;
};

// [flow count]
/// The flow count F: the number of beads whose centre is past the kink (x < kink_x). Exercise 8.4.
std::size_t flow_count(std::span<const Vector3> centres, const ChuteGeometry& chute);
// [flow count]

/// The experiment's camera looking down on the run-out (1000 frames/s, 800 × 600 pixels at 967.59
/// pixels per metre): a grid of pixels in the run-out's plane. Column i covers the x' from
/// x0 − (i + 1)/s to x0 − i/s (downstream from the image's upstream edge x0), row j the y' from
/// y0 + j/s to y0 + (j + 1)/s. The references give the scale, not where the camera stood: by
/// default the image starts at the kink and its rows are centred on the chute's axis.
struct CameraGrid {
  int columns = 800;                 ///< pixels along the flow
  int rows = 600;                    ///< pixels across it
  double pixels_per_metre = 967.59;  ///< s [1/m]
  double x0 = 0.0;                   ///< x' of the image's upstream edge [m]
  double y0 = -300.0 / 967.59;       ///< y' of the edge of row 0 [m]
};

// [pixel of]
/// The pixel {column, row} under a position seen from above: the position in the run-out's frame
/// (ChuteGeometry::runout), projected onto its floor along the normal; none when that falls outside
/// the image. Exercise 8.5.
std::optional<std::array<int, 2>> pixel_of(const CameraGrid& camera, const ChuteGeometry& chute,
                                           const Vector3& position);
// [pixel of]

/// The plan-view velocity field on a camera grid: per pixel (row-major, `rows` × `columns`) the
/// mean over the beads whose centres project into it of their velocity in the run-out's plane —
/// along the flow (downstream positive) and across it [m/s] — and how many there were (0: outside
/// the flow's mask).
struct VelocityField {
  CameraGrid camera;                 ///< the grid
  std::vector<double> along;         ///< mean downstream velocity [m/s] (0 where count is 0)
  std::vector<double> across;        ///< mean velocity along y' [m/s] (0 where count is 0)
  std::vector<std::uint32_t> count;  ///< beads in each pixel
};

/// The velocity field of beads with these centres and linear velocities (spans of equal length;
/// InvalidArgument otherwise, or for a camera grid without pixels or a scale that is not positive).
VelocityField velocity_field(const CameraGrid& camera, const ChuteGeometry& chute,
                             std::span<const Vector3> centres, std::span<const Vector3> velocities);

/// The front of the flow: the path() reached by the bead ahead of which lie a thousandth of the
/// beads (at least the first one) — a single bead thrown ahead does not move it [m]. 0 for no
/// beads.
double front(std::span<const Vector3> centres, const ChuteGeometry& chute);

/// The times the reference study measures on F(t) [s], each interpolated linearly between the
/// samples and absent when F never gets there.
struct FlowTimes {
  std::optional<double> entry;  ///< F reaches `entry_count` beads (150 in the reference study)
  std::optional<double> first;  ///< F reaches 1 % of the beads
  std::optional<double> last;   ///< F reaches 95 % of the beads
  /// The flow's duration, last − first, when both are there.
  std::optional<double> duration() const;
};

/// The flow times of a count F(t) sampled at increasing times `t` among `beads` beads in all.
/// Throws InvalidArgument for spans of different lengths, times that do not increase, a count
/// that is negative, not finite or above `beads`, or beads or entry_count not positive and finite.
FlowTimes flow_times(std::span<const double> t, std::span<const double> count, double beads,
                     double entry_count = 150.0);

/// A chute run's flow record by record, as its output file holds it.
struct FlowSeries {
  double beads = 0.0;          ///< beads in the first record
  std::vector<double> t;       ///< time of each record [s]
  std::vector<double> bodies;  ///< beads left in each record (the outlet removes some)
  /// F: the beads past the kink (flow_count), those the outlet removed counted as past
  std::vector<double> count;
  std::vector<double> front;  ///< front() of each record [m]
};

/// The flow series of the output file of a chute run (io::IoError naming the file when it is not
/// one, holds no record or no bead in its first).
FlowSeries flow_series(const std::filesystem::path& output, const ChuteGeometry& chute);

}  // namespace grbd::parallel
