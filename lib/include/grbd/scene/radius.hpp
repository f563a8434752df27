#pragma once
/// \file
/// \brief Radius distributions of the body generators (chapter 7): a fixed radius, uniform, a
/// normal truncated to an interval, and a piecewise-constant density over radius intervals (the
/// distribution of the reference chute), sampled reproducibly from a seeded generator.

#include <cstdint>
#include <string>
#include <vector>

namespace grbd::scene {

/// The random numbers of the generators: SplitMix64 (Steele, Lea and Flood 2014), whose output
/// for a seed is fixed by its definition, so that a scene and its seed give the same bodies on
/// every machine and standard library (std::uniform_real_distribution does not promise that).
class Random {
 public:
  /// A generator whose sequence is fixed by `seed` (or by a state() saved before).
  explicit Random(std::uint64_t seed) : state_(seed) {}
  /// The next 64 random bits.
  std::uint64_t bits();
  /// A uniform number in [0, 1): the top 53 bits of bits() times 2⁻⁵³.
  double uniform();
  /// The state, for a checkpoint (chapter 7's restart continues the sequence exactly).
  std::uint64_t state() const { return state_; }

 private:
  std::uint64_t state_;
};

/// A distribution of sphere radii [m] with a bounded support [min(), max()], min() > 0.
///
/// Each kind is built by its factory, which refuses (InvalidArgument) parameters that are not
/// finite, a radius ≤ 0, an empty interval, a standard deviation ≤ 0, and densities that are
/// negative or all zero, naming the parameter, what was expected and what was found. The
/// distributions are sampled by inversion of their CDF from one uniform number per radius.
class RadiusDistribution {
 public:
  /// The four kinds, one per factory.
  enum class Kind { fixed, uniform, truncated_normal, piecewise_constant };

  /// Every radius is r.
  static RadiusDistribution fixed(double r);
  /// Uniform on [lo, hi].
  static RadiusDistribution uniform(double lo, double hi);
  /// The normal N(mean, sd²) conditioned on [lo, hi].
  static RadiusDistribution truncated_normal(double mean, double sd, double lo, double hi);
  /// The density d_k on [edges[k], edges[k + 1]), k = 0 … n − 1 (n + 1 increasing edges, n
  /// densities ≥ 0, not all zero), normalised so that it integrates to 1: interval k is drawn with
  /// probability d_k w_k / Σ_j d_j w_j, w_k = edges[k + 1] − edges[k], and uniformly within it.
  static RadiusDistribution piecewise_constant(std::vector<double> edges,
                                               std::vector<double> densities);

  /// Which factory built it.
  Kind kind() const { return kind_; }
  /// The smallest radius it can give [m].
  double min() const { return lo_; }
  /// The largest radius it can give [m].
  double max() const { return hi_; }
  /// The exact mean radius E[r] [m].
  double mean() const;
  /// The exact second moment E[r²] [m²].
  double second_moment() const;
  /// The exact third moment E[r³] [m³]: the mean volume of a sphere is (4/3) π E[r³].
  double third_moment() const;
  /// P(radius ≤ r).
  double cdf(double r) const;
  /// The radius at probability u ∈ [0, 1]: the inverse of cdf().
  double quantile(double u) const;
  /// One radius: quantile(random.uniform()).
  double sample(Random& random) const { return quantile(random.uniform()); }
  /// The probabilities of the intervals of a piecewise-constant distribution (empty otherwise).
  const std::vector<double>& interval_probabilities() const { return probability_; }
  /// One line for a scene summary, e.g. "uniform on [0.9, 1.1] mm".
  std::string describe() const;

 private:
  RadiusDistribution() = default;
  double moment(int j) const;  // E[r^j], j = 1, 2, 3

  Kind kind_ = Kind::fixed;
  double lo_ = 0.0;
  double hi_ = 0.0;
  double mean_ = 0.0;    // truncated normal: μ
  double sd_ = 0.0;      // truncated normal: σ
  double phi_lo_ = 0.0;  // truncated normal: Φ((lo − μ)/σ) and Φ((hi − μ)/σ)
  double phi_hi_ = 0.0;
  std::vector<double> edges_;
  std::vector<double> probability_;  // per interval
  std::vector<double> cumulative_;   // P(r < edges[k]), k = 0 … n
};

}  // namespace grbd::scene
