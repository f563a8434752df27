/// \file
/// \brief Chapter 8 exercise: the flow count of the chute study.

#include "grbd/parallel/chute.hpp"

#include "grbd/core/error.hpp"

#include <cmath>

namespace grbd::parallel {

std::size_t flow_count(std::span<const Vector3> centres, const ChuteGeometry& chute) {
  // BEGIN EXERCISE 8.4: the flow count
  // Hint: a bead is past the kink when its centre's x is below chute.kink_x (the beads flow
  //   towards −x); count them.
  std::size_t past = 0;
  for (const Vector3& c : centres) {
    if (c.x() < chute.kink_x) ++past;
  }
  return past;
  // END EXERCISE 8.4
}

std::optional<std::array<int, 2>> pixel_of(const CameraGrid& camera, const ChuteGeometry& chute,
                                           const Vector3& position) {
  // BEGIN EXERCISE 8.5: a bead's pixel on the camera grid
  // Hint: chute.runout(position) gives x', y' (and the height z', which the projection drops);
  //   the column counts pixels of 1/s downstream from x0, the row pixels of 1/s from y0; use
  //   std::floor, and answer std::nullopt outside [0, columns) × [0, rows).
  const Vector3 local = chute.runout(position);
  const double s = camera.pixels_per_metre;
  const double column = std::floor((camera.x0 - local.x()) * s);
  const double row = std::floor((local.y() - camera.y0) * s);
  if (!(column >= 0.0 && column < camera.columns && row >= 0.0 && row < camera.rows)) {
    return std::nullopt;
  }
  return std::array<int, 2>{static_cast<int>(column), static_cast<int>(row)};
  // END EXERCISE 8.5
}

}  // namespace grbd::parallel
