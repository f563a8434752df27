/// \file
/// \brief Warm starts keyed by contact identity.

#include "grbd/contact/warm_start.hpp"

#include <string>

#include "grbd/core/error.hpp"

namespace grbd::contact {

void WarmStart::store(std::span<const collision::ContactKey> keys,
                      std::span<const Vector3> lambda) {
  if (keys.size() != lambda.size()) {
    throw InvalidArgument("WarmStart::store: expected one percussion per key; found " +
                          std::to_string(keys.size()) + " keys and " +
                          std::to_string(lambda.size()) + " percussions");
  }
  stored_.clear();
  stored_.reserve(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) stored_[keys[i]] = lambda[i];
}

std::size_t WarmStart::initialize(std::span<const collision::ContactKey> keys,
                                  std::vector<Vector3>& lambda) const {
  lambda.assign(keys.size(), Vector3::Zero());
  std::size_t found = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const auto it = stored_.find(keys[i]);
    if (it != stored_.end()) {
      lambda[i] = it->second;
      ++found;
    }
  }
  return found;
}

}  // namespace grbd::contact
