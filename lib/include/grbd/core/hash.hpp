#pragma once
/// \file
/// \brief The 64-bit mixing function of the project's hash tables (contact keys, global ids).

#include <cstdint>

namespace grbd {

/// The finaliser of SplitMix64 (Steele, Lea and Flood 2014): a bijection of 64-bit words in which
/// every input bit affects every output bit, so that consecutive ids spread over a whole
/// open-addressing table.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace grbd
