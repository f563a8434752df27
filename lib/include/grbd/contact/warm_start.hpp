#pragma once
/// \file
/// \brief Warm starts (chapter 5): the percussions of the previous step, keyed by the identity of
/// each contact, as the initial guess of the next solve.

#include <cstddef>
#include <span>
#include <unordered_map>
#include <vector>

#include "grbd/collision/contact.hpp"
#include "grbd/core/types.hpp"

namespace grbd::contact {

/// Percussions of the contacts of one step, in their contact frames, keyed by ContactKey.
class WarmStart {
 public:
  /// Replaces what is stored by these contacts and percussions (same length, else
  /// InvalidArgument). A key given twice keeps the last percussion.
  void store(std::span<const collision::ContactKey> keys, std::span<const Vector3> lambda);
  /// Resizes `lambda` to keys.size() and fills it with the stored percussion of each key, or
  /// zero for a contact that is new. Returns how many keys were found.
  std::size_t initialize(std::span<const collision::ContactKey> keys,
                         std::vector<Vector3>& lambda) const;
  /// Number of stored contacts.
  std::size_t size() const { return stored_.size(); }
  /// Forgets everything.
  void clear() { stored_.clear(); }

 private:
  std::unordered_map<collision::ContactKey, Vector3, collision::ContactKeyHash> stored_;
};

}  // namespace grbd::contact
