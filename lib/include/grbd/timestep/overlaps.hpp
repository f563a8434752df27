#pragma once
/// \file
/// \brief The distribution of the contacts' overlaps max(0, −g_N) in a step or a run (chapter 6,
/// "Accuracy of a step"): a histogram on a logarithmic scale in units of a length r, the
/// smallest radius of the scene, which sums over steps and over processes exactly.

#include <array>
#include <cstdint>
#include <span>

namespace grbd::timestep {

// [overlap histogram]
/// Counts of overlaps δ = max(0, −g_N) in bins of δ/r: bin 0 holds δ/r < 10⁻⁸ (touching,
/// separating and round-off), bins 1 … kBins − 2 split each decade from 10⁻⁸ to 1 into
/// kPerDecade bins of equal ratio 10^(1/kPerDecade) (12 %), the last bin holds δ/r ≥ 1.
/// Quantiles are read as the upper edge of the bin that holds them: never below the true
/// quantile, at most 12 % above it.
class OverlapHistogram {
 public:
  static constexpr int kPerDecade = 20;                       ///< bins per decade
  static constexpr int kDecades = 8;                           ///< 10⁻⁸ r … r
  static constexpr int kBins = kPerDecade * kDecades + 2;     ///< with the two end bins

  /// Counts the overlap δ ≥ 0 [m] in units of r > 0 [m].
  void add(double overlap, double r) { ++counts_[bin(overlap / r)]; }
  /// Adds the counts of another histogram (steps of a run, processes of a step).
  void add(const OverlapHistogram& other);
  /// The number of overlaps counted.
  std::uint64_t count() const;
  /// The upper edge, in units of r, of the bin that holds the p-quantile (p ∈ [0, 1]) of the
  /// counted overlaps; 0 when nothing was counted or the quantile lies in bin 0 (below 10⁻⁸ r);
  /// +∞ when it lies in the last bin (an overlap of a radius or more).
  double quantile(double p) const;
  /// The bin of δ/r.
  static int bin(double overlap_over_r);
  /// The upper edge of bin b in units of r (10^(−8 + b/kPerDecade); +∞ for the last bin).
  static double upper_edge(int b);
  /// The counts, bin by bin.
  std::span<const std::uint64_t, kBins> counts() const { return counts_; }
  /// The counts, to fill (a reduction over processes).
  std::span<std::uint64_t, kBins> counts() { return counts_; }

  /// Equal when every count is.
  friend bool operator==(const OverlapHistogram&, const OverlapHistogram&) = default;

 private:
  std::array<std::uint64_t, kBins> counts_{};
};
// [overlap histogram]

}  // namespace grbd::timestep
