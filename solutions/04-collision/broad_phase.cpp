/// \file
/// \brief Chapter 4 exercise on the broad phase: the Morton code of a grid cell, which orders
/// the bodies along a Z-order curve so that neighbours in space are neighbours in memory.

#include "grbd/collision/broad_phase.hpp"
#include "grbd/core/error.hpp"

#include <cstdint>
#include <string>

namespace grbd::collision {

std::uint64_t morton_code(std::uint32_t i, std::uint32_t j, std::uint32_t k) {
  // BEGIN EXERCISE 4.6: the Morton code of a grid cell
  // Hint: first refuse coordinates ≥ 2²¹ (grbd::InvalidArgument): 3 × 21 bits fill 63 of 64.
  // Hint: spread one coordinate so that bit b lands on bit 3b, then combine x | y << 1 | z << 2.
  // Hint: a loop over the 21 bits is fine; five shift-and-mask steps do it without a loop.
  constexpr std::uint32_t kLimit = std::uint32_t{1} << 21;
  if (i >= kLimit || j >= kLimit || k >= kLimit) {
    throw InvalidArgument("morton_code: expected cell coordinates < 2^21 = 2097152, found (" +
                          std::to_string(i) + ", " + std::to_string(j) + ", " + std::to_string(k) +
                          ")");
  }
  // Spread the 21 bits of v to every third bit: each step moves the upper half of every group
  // of bits up by twice as many places as the next step, until a bit b sits at 3b.
  const auto spread = [](std::uint64_t v) {
    v = (v | v << 32) & 0x001f00000000ffffULL;
    v = (v | v << 16) & 0x001f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  return spread(i) | spread(j) << 1 | spread(k) << 2;
  // END EXERCISE 4.6
}

}  // namespace grbd::collision
