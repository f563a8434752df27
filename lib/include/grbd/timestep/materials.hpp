#pragma once
/// \file
/// \brief Per-pair contact materials (chapter 6): named materials and a table of
/// (μ, ε_N, ε_T) for each pair of them, read during the assembly of every contact.

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "grbd/contact/problem.hpp"
#include "grbd/timestep/body_system.hpp"

namespace grbd::timestep {

/// Named materials and the contact law of each pair. A contact between materials a and b takes
/// the entry of the pair {a, b} (symmetric); a pair without an entry takes the declared default,
/// or, without one, is refused by require_pairs() before the run starts, naming both materials.
class MaterialTable {
 public:
  /// At most this many materials: the pair table is dense (n² entries).
  static constexpr std::size_t kMaxMaterials = 1024;
  /// Adds a material and returns its id (0, 1, …); amortised O(1) plus the copy of the pair table
  /// when its capacity doubles. Throws InvalidArgument for an empty name, a name used twice, or
  /// more than kMaxMaterials materials.
  MaterialId add(std::string_view name);
  /// Sets the law of the pair {a, b}. Throws InvalidArgument, naming both materials, for an
  /// unknown id, μ < 0 or not finite, ε_N ∉ [0, 1], ε_T ∉ [−1, 1].
  void set_pair(MaterialId a, MaterialId b, const contact::ContactMaterial& law);
  /// Declares the law of every pair without an entry (same checks).
  void set_default(const contact::ContactMaterial& law);
  /// The law of the pair {a, b}: its entry, else the default. Throws InvalidArgument naming both
  /// materials when there is neither, or for an unknown id.
  const contact::ContactMaterial& pair(MaterialId a, MaterialId b) const;
  /// The law of {a, b} without the checks: the ids are known and require_pairs() accepted them.
  /// O(1), one load: what the assembly calls per contact.
  const contact::ContactMaterial& pair_unchecked(MaterialId a, MaterialId b) const {
    return laws_[table_[a * stride_ + b]];
  }
  /// Throws InvalidArgument unless every pair (x, y), x from `a` and y from `b`, has a law, naming
  /// the first pair without one; and unless every id is known.
  void require_pairs(std::span<const MaterialId> a, std::span<const MaterialId> b) const;
  /// The name of a material.
  const std::string& name(MaterialId id) const;
  /// The id of the material with this name, if any (O(1): a hash of the names).
  std::optional<MaterialId> find(std::string_view name) const;
  /// Number of materials.
  std::size_t size() const { return names_.size(); }

 private:
  void require_known(MaterialId id, std::string_view where) const;
  static constexpr std::uint32_t kNone = 0;  // laws_[0] is the default (or a placeholder)
  std::vector<std::string> names_;
  std::vector<contact::ContactMaterial> laws_{contact::ContactMaterial{}};  // [0]: default
  bool has_default_ = false;
  std::unordered_map<std::string, MaterialId> ids_;  // name → id
  // stride_ × stride_, of which size() × size() is used; stride_ doubles when full, so that n
  // materials cost O(n²) in all, not O(n³).
  std::size_t stride_ = 0;
  std::vector<std::uint32_t> table_;  // index into laws_, kNone for "default"
  std::vector<std::uint8_t> set_;     // 1 where an entry was set
};

}  // namespace grbd::timestep
