/// \file
/// \brief The hash of a contact key.

#include "grbd/collision/contact.hpp"

namespace grbd::collision {

namespace {

// The finaliser of SplitMix64: every input bit affects every output bit.
std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

}  // namespace

std::size_t ContactKeyHash::operator()(const ContactKey& key) const noexcept {
  const std::uint64_t colliders =
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.collider_a)) << 32) |
      static_cast<std::uint32_t>(key.collider_b);
  std::uint64_t h = mix(colliders);
  h = mix(h ^ key.feature_a);
  h = mix(h ^ (key.feature_b + 0x9e3779b97f4a7c15ULL));
  return static_cast<std::size_t>(h);
}

}  // namespace grbd::collision
