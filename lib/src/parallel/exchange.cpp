/// \file
/// \brief Body communication among processes: migration, borders, forward.

#include "grbd/parallel/exchange.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/timestep/body_record.hpp"

namespace grbd::parallel {

namespace {

// One ghost in a borders() message: the packed body and its image code.
constexpr std::size_t kGhostBytes = timestep::kPackedBodyBytes + 8;
// One state in a forward() message: q and u.
constexpr std::size_t kStateBytes = 13 * sizeof(double);

void append(std::vector<std::byte>& out, const void* data, std::size_t n) {
  const auto* bytes = static_cast<const std::byte*>(data);
  out.insert(out.end(), bytes, bytes + n);
}

void append_body(std::vector<std::byte>& out, const timestep::BodyRecord& record) {
  timestep::PackedBody packed;
  timestep::pack(record, packed);
  append(out, packed.data(), packed.size());
}

timestep::BodyRecord body_at(const std::vector<std::byte>& in, std::size_t offset) {
  return timestep::unpack(std::span<const std::byte, timestep::kPackedBodyBytes>(
      in.data() + offset, timestep::kPackedBodyBytes));
}

}  // namespace

BodyExchange::BodyExchange(const Communicator& comm, const Partition& partition, double margin,
                           double max_radius)
    : comm_(comm), partition_(partition), margin_(margin), max_radius_(max_radius) {
  if (partition.size() != comm.size()) {
    throw InvalidArgument("BodyExchange: the partition has " + std::to_string(partition.size()) +
                          " subdomains for " + std::to_string(comm.size()) + " processes");
  }
  if (!(margin >= 0.0) || !std::isfinite(margin)) {
    throw InvalidArgument("BodyExchange: expected a finite margin >= 0, found " +
                          format_number(margin));
  }
  require_positive_finite("BodyExchange", "max_radius", max_radius);
  neighbours_ = partition.neighbours(comm.rank(), contact_reach(max_radius, margin));
  const std::size_t m = neighbours_.size();
  sent_.resize(m);
  ghost_start_.assign(m, 0);
  ghost_count_.assign(m, 0);
  out_.resize(m);
}

// [migrate]
std::size_t BodyExchange::migrate(timestep::BodySystem& system) {
  system.clear_ghosts();
  layout_ = ~std::uint64_t{0};
  const int me = comm_.rank();
  for (auto& message : out_) message.clear();
  std::vector<std::size_t> leaving;
  leaving_.clear();
  const auto states = system.states();
  for (std::size_t i = 0; i < system.owned_count(); ++i) {
    Vector3 c = states[i].q.head<3>();
    const Vector3 wrapped = partition_.wrap(c);
    if (wrapped != c) states[i].q.head<3>() = wrapped;  // crossed a periodic boundary
    const int owner = partition_.owner_of(wrapped);
    if (owner == me) continue;
    const auto k = std::lower_bound(neighbours_.begin(), neighbours_.end(), owner);
    if (k == neighbours_.end() || *k != owner) {
      throw Error("BodyExchange::migrate: body " + std::to_string(system.ids()[i]) +
                  " moved from the subdomain of process " + std::to_string(me) +
                  " into that of process " + std::to_string(owner) +
                  ", which is not a neighbour: it crossed a whole subdomain since the last "
                  "migration (shorten the time step or the skin)");
    }
    append_body(out_[static_cast<std::size_t>(k - neighbours_.begin())], system.record(i));
    leaving.push_back(i);
    leaving_.emplace_back(system.ids()[i], static_cast<std::size_t>(k - neighbours_.begin()));
  }
  system.remove(leaving);
  comm_.exchange(neighbours_, out_, in_);
  for (const std::vector<std::byte>& message : in_) {
    for (std::size_t at = 0; at + timestep::kPackedBodyBytes <= message.size();
         at += timestep::kPackedBodyBytes) {
      system.add(body_at(message, at));
    }
  }
  return leaving.size();
}
// [migrate]

std::size_t BodyExchange::migrate(timestep::BodySystem& system, timestep::WarmStartTable& warm) {
  const std::size_t sent = migrate(system);
  // The contacts a leaving body decides go with it: key (4 words) and percussion (3 doubles).
  std::sort(leaving_.begin(), leaving_.end());
  for (auto& message : out_) message.clear();
  std::vector<timestep::ContactKey> kept_keys;
  std::vector<Vector3> kept_lambda;
  const auto keys = warm.keys();
  const auto lambda = warm.lambda();
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const timestep::GlobalId decider = solving_side(keys[k]);
    const auto it = std::lower_bound(leaving_.begin(), leaving_.end(),
                                     std::pair<timestep::GlobalId, std::size_t>{decider, 0});
    if (it != leaving_.end() && it->first == decider) {
      append(out_[it->second], &keys[k], sizeof(timestep::ContactKey));
      append(out_[it->second], lambda[k].data(), 3 * sizeof(double));
    } else {
      kept_keys.push_back(keys[k]);
      kept_lambda.push_back(lambda[k]);
    }
  }
  comm_.exchange(neighbours_, out_, in_);
  constexpr std::size_t kEntry = sizeof(timestep::ContactKey) + 3 * sizeof(double);
  for (const std::vector<std::byte>& message : in_) {
    for (std::size_t at = 0; at + kEntry <= message.size(); at += kEntry) {
      timestep::ContactKey key;
      Vector3 l;
      std::memcpy(&key, message.data() + at, sizeof key);
      std::memcpy(l.data(), message.data() + at + sizeof key, 3 * sizeof(double));
      kept_keys.push_back(key);
      kept_lambda.push_back(l);
    }
  }
  warm.store(kept_keys, kept_lambda);
  return sent;
}

// [borders]
std::size_t BodyExchange::borders(timestep::BodySystem& system) {
  system.clear_ghosts();
  const int me = comm_.rank();
  const Box mine = partition_.owned_region(me);
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    out_[k].clear();
    sent_[k].rows.clear();
  }
  const auto states = system.states();
  const auto radii = system.bounding_radii();
  for (std::size_t i = 0; i < system.owned_count(); ++i) {
    const Vector3 c = states[i].q.head<3>();
    const double reach = radii[i] + max_radius_ + margin_;
    // Deep inside its own subdomain, a body reaches no other and no image: the common case
    // (with a relative 10⁻¹² to spare, so that no rounding skips a body overlaps() would send).
    const Vector3 inside = (c - mine.min()).cwiseMin(mine.max() - c);
    if (inside.minCoeff() > reach * (1.0 + 1e-12)) continue;
    for (std::size_t k = 0; k < neighbours_.size(); ++k) {
      const Box box = partition_.owned_region(neighbours_[k]);
      for (const std::array<int, 3>& s : partition_.image_shifts()) {
        const bool plain = s == std::array<int, 3>{0, 0, 0};
        if (plain && neighbours_[k] == me) continue;  // the body itself
        if (!overlaps(c + partition_.shift(s), reach, box)) continue;
        append_body(out_[k], system.record(i));
        const std::uint64_t code = image_code(s);
        append(out_[k], &code, sizeof code);
        sent_[k].rows.push_back(i);
      }
    }
  }
  comm_.exchange(neighbours_, out_, in_);
  std::size_t received = 0;
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    ghost_start_[k] = system.size();
    const std::vector<std::byte>& message = in_[k];
    for (std::size_t at = 0; at + kGhostBytes <= message.size(); at += kGhostBytes) {
      std::uint64_t code = 0;
      std::memcpy(&code, message.data() + at + timestep::kPackedBodyBytes, sizeof code);
      const auto image = static_cast<std::uint32_t>(code);
      system.add_ghost(body_at(message, at), partition_.shift(image_shift(image)), image);
    }
    ghost_count_[k] = system.size() - ghost_start_[k];
    received += ghost_count_[k];
  }
  layout_ = system.layout_version();
  return received;
}
// [borders]

namespace {

void require_layout(const timestep::BodySystem& system, std::uint64_t layout, const char* what) {
  if (system.layout_version() != layout) {
    throw InvalidArgument(std::string("BodyExchange::") + what +
                          ": the bodies were added, "
                          "removed or reordered since borders(): rebuild the ghosts (migrate, "
                          "borders) first");
  }
}

}  // namespace

// [forward]
void BodyExchange::forward(timestep::BodySystem& system) {
  require_layout(system, layout_, "forward");
  const auto states = system.states();
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    std::vector<std::byte>& message = out_[k];
    message.resize(sent_[k].rows.size() * kStateBytes);
    std::byte* at = message.data();
    for (const std::size_t i : sent_[k].rows) {
      std::memcpy(at, states[i].q.data(), 7 * sizeof(double));
      std::memcpy(at + 7 * sizeof(double), states[i].u.data(), 6 * sizeof(double));
      at += kStateBytes;
    }
  }
  comm_.exchange(neighbours_, out_, in_);
  const auto images = system.images();
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    if (in_[k].size() != ghost_count_[k] * kStateBytes) {
      throw Error("BodyExchange::forward: process " + std::to_string(neighbours_[k]) + " sent " +
                  std::to_string(in_[k].size() / kStateBytes) + " states for " +
                  std::to_string(ghost_count_[k]) +
                  " ghosts: the processes disagree on the "
                  "ghosts (a borders() call missing on some process)");
    }
    const std::byte* at = in_[k].data();
    for (std::size_t g = 0; g < ghost_count_[k]; ++g, at += kStateBytes) {
      const std::size_t row = ghost_start_[k] + g;
      body::State& x = states[row];
      std::memcpy(x.q.data(), at, 7 * sizeof(double));
      std::memcpy(x.u.data(), at + 7 * sizeof(double), 6 * sizeof(double));
      x.q.head<3>() += partition_.shift(image_shift(images[row]));
    }
  }
}
// [forward]

void BodyExchange::forward_values(const timestep::BodySystem& system, std::span<double> values,
                                  int width, std::span<const std::uint8_t> selected) {
  require_layout(system, layout_, "forward_values");
  const bool all = selected.empty();
  const auto w = static_cast<std::size_t>(width);
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    std::vector<std::byte>& message = out_[k];
    message.resize(sent_[k].rows.size() * w * sizeof(double));
    std::byte* at = message.data();
    for (const std::size_t i : sent_[k].rows) {
      if (!all && selected[i] == 0) continue;
      std::memcpy(at, values.data() + i * w, w * sizeof(double));
      at += w * sizeof(double);
    }
    message.resize(static_cast<std::size_t>(at - message.data()));
  }
  comm_.exchange(neighbours_, out_, in_);
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    const std::byte* from = in_[k].data();
    const std::byte* end = from + in_[k].size();
    for (std::size_t g = ghost_start_[k]; g < ghost_start_[k] + ghost_count_[k]; ++g) {
      if (!all && selected[g] == 0) continue;
      if (end - from < static_cast<std::ptrdiff_t>(w * sizeof(double))) {
        from = nullptr;  // too short
        break;
      }
      std::memcpy(values.data() + g * w, from, w * sizeof(double));
      from += w * sizeof(double);
    }
    if (from != end) {
      throw Error("BodyExchange::forward_values: process " + std::to_string(neighbours_[k]) +
                  " sent values for another number of ghosts");
    }
  }
}

// [reverse]
void BodyExchange::reverse_add(const timestep::BodySystem& system, std::span<double> values,
                               int width, std::span<const std::uint8_t> selected) {
  require_layout(system, layout_, "reverse_add");
  const bool all = selected.empty();
  const auto w = static_cast<std::size_t>(width);
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    out_[k].resize(ghost_count_[k] * w * sizeof(double));
    std::byte* at = out_[k].data();
    for (std::size_t g = ghost_start_[k]; g < ghost_start_[k] + ghost_count_[k]; ++g) {
      if (!all && selected[g] == 0) continue;
      std::memcpy(at, values.data() + g * w, w * sizeof(double));
      at += w * sizeof(double);
    }
    out_[k].resize(static_cast<std::size_t>(at - out_[k].data()));
  }
  comm_.exchange(neighbours_, out_, in_);
  for (std::size_t k = 0; k < neighbours_.size(); ++k) {
    const std::byte* from = in_[k].data();
    const std::byte* end = from + in_[k].size();
    for (const std::size_t i : sent_[k].rows) {
      if (!all && selected[i] == 0) continue;
      if (end - from < static_cast<std::ptrdiff_t>(w * sizeof(double))) {
        from = nullptr;  // too short
        break;
      }
      double* to = values.data() + i * w;
      for (std::size_t d = 0; d < w; ++d, from += sizeof(double)) {
        double x;
        std::memcpy(&x, from, sizeof x);
        to[d] += x;
      }
    }
    if (from != end) {
      throw Error("BodyExchange::reverse_add: process " + std::to_string(neighbours_[k]) +
                  " sent values for another number of ghosts");
    }
  }
}
// [reverse]

}  // namespace grbd::parallel
