/// \file
/// \brief The distribution of the contacts' overlaps.

#include "grbd/timestep/overlaps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace grbd::timestep {

void OverlapHistogram::add(const OverlapHistogram& other) {
  for (int b = 0; b < kBins; ++b) counts_[b] += other.counts_[b];
}

std::uint64_t OverlapHistogram::count() const {
  std::uint64_t n = 0;
  for (const std::uint64_t c : counts_) n += c;
  return n;
}

int OverlapHistogram::bin(double overlap_over_r) {
  if (!(overlap_over_r >= 1e-8)) return 0;  // NaN too: it is refused elsewhere, never counted high
  if (overlap_over_r >= 1.0) return kBins - 1;
  const int b = 1 + static_cast<int>(std::floor((std::log10(overlap_over_r) + kDecades) * kPerDecade));
  return b < 1 ? 1 : (b > kBins - 2 ? kBins - 2 : b);
}

double OverlapHistogram::upper_edge(int b) {
  if (b >= kBins - 1) return std::numeric_limits<double>::infinity();
  return std::pow(10.0, -kDecades + static_cast<double>(b) / kPerDecade);
}

double OverlapHistogram::quantile(double p) const {
  const std::uint64_t n = count();
  if (n == 0) return 0.0;
  // The smallest bin b whose cumulative count reaches ⌈p n⌉ (at least one overlap).
  const double need = std::max(1.0, std::ceil(p * static_cast<double>(n)));
  std::uint64_t seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += counts_[b];
    if (static_cast<double>(seen) >= need) return b == 0 ? 0.0 : upper_edge(b);
  }
  return upper_edge(kBins - 1);
}

}  // namespace grbd::timestep
