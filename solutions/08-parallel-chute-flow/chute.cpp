/// \file
/// \brief Chapter 8 exercise: the flow count of the chute study.

#include "grbd/parallel/chute.hpp"

#include "grbd/core/error.hpp"

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

}  // namespace grbd::parallel
