/// \file
/// \brief The table of per-pair contact materials.

#include "grbd/timestep/materials.hpp"

#include <algorithm>
#include <cmath>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::timestep {

namespace {

void require_law(const contact::ContactMaterial& law, const std::string& where) {
  if (!(law.mu >= 0.0) || !std::isfinite(law.mu)) {
    throw InvalidArgument(where + ": expected a finite friction coefficient mu >= 0, found " +
                          format_number(law.mu));
  }
  if (!(law.eps_N >= 0.0 && law.eps_N <= 1.0)) {
    throw InvalidArgument(where + ": expected a normal restitution eps_N in [0, 1], found " +
                          format_number(law.eps_N));
  }
  if (!(law.eps_T >= -1.0 && law.eps_T <= 1.0)) {
    throw InvalidArgument(where + ": expected a tangential restitution eps_T in [-1, 1], found " +
                          format_number(law.eps_T));
  }
}

}  // namespace

MaterialId MaterialTable::add(std::string_view name) {
  if (name.empty()) throw InvalidArgument("MaterialTable::add: expected a name, found \"\"");
  if (find(name)) {
    throw InvalidArgument("MaterialTable::add: the material \"" + std::string(name) +
                          "\" is declared twice");
  }
  if (size() >= kMaxMaterials) {
    throw InvalidArgument("MaterialTable::add: at most " + std::to_string(kMaxMaterials) +
                          " materials, found one more: \"" + std::string(name) + "\"");
  }
  const std::size_t old_n = size();
  if (old_n == stride_) {
    const std::size_t stride = std::max<std::size_t>(8, 2 * stride_);
    std::vector<std::uint32_t> table(stride * stride, kNone);
    std::vector<std::uint8_t> set(stride * stride, 0);
    for (std::size_t a = 0; a < old_n; ++a) {
      for (std::size_t b = 0; b < old_n; ++b) {
        table[a * stride + b] = table_[a * stride_ + b];
        set[a * stride + b] = set_[a * stride_ + b];
      }
    }
    table_.swap(table);
    set_.swap(set);
    stride_ = stride;
  }
  names_.emplace_back(name);
  ids_.emplace(names_.back(), static_cast<MaterialId>(old_n));
  return static_cast<MaterialId>(old_n);
}

void MaterialTable::require_known(MaterialId id, std::string_view where) const {
  if (id >= size()) {
    throw InvalidArgument(std::string(where) + ": unknown material id " + std::to_string(id) +
                          " (" + std::to_string(size()) + " materials are declared)");
  }
}

void MaterialTable::set_pair(MaterialId a, MaterialId b, const contact::ContactMaterial& law) {
  require_known(a, "MaterialTable::set_pair");
  require_known(b, "MaterialTable::set_pair");
  require_law(law, "MaterialTable::set_pair (\"" + names_[a] + "\", \"" + names_[b] + "\")");
  const std::size_t n = stride_;
  std::uint32_t slot = table_[a * n + b];
  if (slot == kNone) {
    laws_.push_back(law);
    slot = static_cast<std::uint32_t>(laws_.size() - 1);
  } else {
    laws_[slot] = law;
  }
  table_[a * n + b] = table_[b * n + a] = slot;
  set_[a * n + b] = set_[b * n + a] = 1;
}

void MaterialTable::set_default(const contact::ContactMaterial& law) {
  require_law(law, "MaterialTable::set_default");
  laws_[kNone] = law;
  has_default_ = true;
}

const contact::ContactMaterial& MaterialTable::pair(MaterialId a, MaterialId b) const {
  require_known(a, "MaterialTable::pair");
  require_known(b, "MaterialTable::pair");
  if (!set_[a * stride_ + b] && !has_default_) {
    throw InvalidArgument("MaterialTable: no contact law for the pair of materials \"" +
                          names_[a] + "\" and \"" + names_[b] +
                          "\" and no default declared: set the pair or a default");
  }
  return pair_unchecked(a, b);
}

void MaterialTable::require_pairs(std::span<const MaterialId> a,
                                  std::span<const MaterialId> b) const {
  for (const MaterialId x : a) require_known(x, "MaterialTable::require_pairs");
  for (const MaterialId y : b) require_known(y, "MaterialTable::require_pairs");
  for (const MaterialId x : a) {
    for (const MaterialId y : b) (void)pair(x, y);
  }
}

const std::string& MaterialTable::name(MaterialId id) const {
  require_known(id, "MaterialTable::name");
  return names_[id];
}

std::optional<MaterialId> MaterialTable::find(std::string_view name) const {
  const auto it = ids_.find(std::string(name));
  if (it == ids_.end()) return std::nullopt;
  return it->second;
}

}  // namespace grbd::timestep
