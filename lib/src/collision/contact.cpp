/// \file
/// \brief The hash of a contact key.

#include "grbd/collision/contact.hpp"

#include "grbd/core/hash.hpp"

namespace grbd::collision {

std::size_t ContactKeyHash::operator()(const ContactKey& key) const noexcept {
  const std::uint64_t colliders =
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.collider_a)) << 32) |
      static_cast<std::uint32_t>(key.collider_b);
  std::uint64_t h = mix64(colliders);
  h = mix64(h ^ key.feature_a);
  h = mix64(h ^ (key.feature_b + 0x9e3779b97f4a7c15ULL));
  return static_cast<std::size_t>(h);
}

}  // namespace grbd::collision
