/// \file
/// \brief Radius distributions and the generators' random numbers; chapter 7 exercises: sampling
/// the truncated normal and the piecewise-constant distribution by inversion.

#include "grbd/scene/radius.hpp"

#include <algorithm>
#include <boost/math/special_functions/erf.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::scene {

namespace {

[[noreturn]] void refuse(const std::string& where, const std::string& what) {
  throw InvalidArgument("RadiusDistribution::" + where + ": " + what);
}

void require_radius(const std::string& where, const char* name, double r) {
  if (!(r > 0.0) || !std::isfinite(r)) {
    refuse(where,
           std::string("expected a finite radius ") + name + " > 0 [m], found " + format_number(r));
  }
}

void require_interval(const std::string& where, double lo, double hi) {
  require_radius(where, "lo", lo);
  require_radius(where, "hi", hi);
  if (!(lo < hi)) {
    refuse(where,
           "expected lo < hi, found lo = " + format_number(lo) + ", hi = " + format_number(hi));
  }
}

/// ∫ r^j dr / (b − a) over [a, b]: the j-th moment of the uniform distribution on [a, b].
double uniform_moment(double a, double b, int j) {
  return (std::pow(b, j + 1) - std::pow(a, j + 1)) / ((j + 1) * (b - a));
}

double normal_pdf(double z) { return std::exp(-0.5 * z * z) / std::sqrt(2.0 * std::numbers::pi); }
/// Φ(z) and the upper tail Q(z) = 1 − Φ(z), each without cancellation.
double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::numbers::sqrt2); }
double normal_tail(double z) { return 0.5 * std::erfc(z / std::numbers::sqrt2); }

std::string millimetres(double r) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", 1e3 * r);
  return text;
}

}  // namespace

std::uint64_t Random::bits() {
  // SplitMix64: a Weyl sequence through a bijective finaliser.
  std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double Random::uniform() { return static_cast<double>(bits() >> 11) * 0x1.0p-53; }

RadiusDistribution RadiusDistribution::fixed(double r) {
  require_radius("fixed", "r", r);
  RadiusDistribution d;
  d.kind_ = Kind::fixed;
  d.lo_ = d.hi_ = r;
  return d;
}

RadiusDistribution RadiusDistribution::uniform(double lo, double hi) {
  require_interval("uniform", lo, hi);
  RadiusDistribution d;
  d.kind_ = Kind::uniform;
  d.lo_ = lo;
  d.hi_ = hi;
  return d;
}

RadiusDistribution RadiusDistribution::truncated_normal(double mean, double sd, double lo,
                                                        double hi) {
  const std::string where = "truncated_normal";
  require_interval(where, lo, hi);
  if (!std::isfinite(mean)) refuse(where, "expected a finite mean, found " + format_number(mean));
  if (!(sd > 0.0) || !std::isfinite(sd)) {
    refuse(where, "expected a finite standard deviation sd > 0, found " + format_number(sd));
  }
  RadiusDistribution d;
  d.kind_ = Kind::truncated_normal;
  d.lo_ = lo;
  d.hi_ = hi;
  d.mean_ = mean;
  d.sd_ = sd;
  const double a = (lo - mean) / sd;
  const double b = (hi - mean) / sd;
  // In the upper tail Φ is near 1 and loses its digits: work with Q = 1 − Φ there.
  d.phi_lo_ = a > 0.0 ? normal_tail(a) : normal_cdf(a);
  d.phi_hi_ = a > 0.0 ? normal_tail(b) : normal_cdf(b);
  if (!(std::abs(d.phi_hi_ - d.phi_lo_) > 0.0)) {
    refuse(where, "the interval [" + format_number(lo) + ", " + format_number(hi) +
                      "] lies so far in the tail of N(" + format_number(mean) + ", " +
                      format_number(sd) + "²) that its probability is 0 in double precision");
  }
  return d;
}

RadiusDistribution RadiusDistribution::piecewise_constant(std::vector<double> edges,
                                                          std::vector<double> densities) {
  const std::string where = "piecewise_constant";
  if (edges.size() < 2 || densities.size() != edges.size() - 1) {
    refuse(where, "expected n + 1 edges and n densities (n >= 1), found " +
                      std::to_string(edges.size()) + " edges and " +
                      std::to_string(densities.size()) + " densities");
  }
  for (std::size_t k = 0; k < edges.size(); ++k) {
    require_radius(where, ("edges[" + std::to_string(k) + "]").c_str(), edges[k]);
    if (k > 0 && !(edges[k] > edges[k - 1])) {
      refuse(where, "expected increasing edges, found edges[" + std::to_string(k - 1) +
                        "] = " + format_number(edges[k - 1]) + " and edges[" + std::to_string(k) +
                        "] = " + format_number(edges[k]));
    }
  }
  double total = 0.0;
  for (std::size_t k = 0; k < densities.size(); ++k) {
    if (!(densities[k] >= 0.0) || !std::isfinite(densities[k])) {
      refuse(where, "expected a finite density >= 0, found densities[" + std::to_string(k) +
                        "] = " + format_number(densities[k]));
    }
    total += densities[k] * (edges[k + 1] - edges[k]);
  }
  if (!(total > 0.0)) refuse(where, "expected at least one density > 0, found all zero");
  RadiusDistribution d;
  d.kind_ = Kind::piecewise_constant;
  d.probability_.resize(densities.size());
  d.cumulative_.assign(edges.size(), 0.0);
  for (std::size_t k = 0; k < densities.size(); ++k) {
    d.probability_[k] = densities[k] * (edges[k + 1] - edges[k]) / total;
    d.cumulative_[k + 1] = d.cumulative_[k] + d.probability_[k];
  }
  // The support: from the first interval with mass to the end of the last one.
  std::size_t first = 0;
  while (d.probability_[first] == 0.0) ++first;
  std::size_t last = d.probability_.size() - 1;
  while (d.probability_[last] == 0.0) --last;
  d.lo_ = edges[first];
  d.hi_ = edges[last + 1];
  d.edges_ = std::move(edges);
  return d;
}

double RadiusDistribution::moment(int j) const {
  switch (kind_) {
    case Kind::fixed:
      return std::pow(lo_, j);
    case Kind::uniform:
      return uniform_moment(lo_, hi_, j);
    case Kind::piecewise_constant: {
      double sum = 0.0;
      for (std::size_t k = 0; k < probability_.size(); ++k) {
        sum += probability_[k] * uniform_moment(edges_[k], edges_[k + 1], j);
      }
      return sum;
    }
    case Kind::truncated_normal:
      break;
  }
  // Moments m_k of the standard normal truncated to [α, β]: m_0 = 1, and by parts
  // m_k = (k − 1) m_{k−2} + (α^{k−1} φ(α) − β^{k−1} φ(β)) / Z; then E[(μ + σ z)^j].
  const double alpha = (lo_ - mean_) / sd_;
  const double beta = (hi_ - mean_) / sd_;
  const double Z = std::abs(phi_hi_ - phi_lo_);
  const double fa = normal_pdf(alpha);
  const double fb = normal_pdf(beta);
  double m[4] = {1.0, (fa - fb) / Z, 0.0, 0.0};
  m[2] = 1.0 + (alpha * fa - beta * fb) / Z;
  m[3] = 2.0 * m[1] + (alpha * alpha * fa - beta * beta * fb) / Z;
  double sum = 0.0;
  double binomial = 1.0;
  for (int k = 0; k <= j; ++k) {
    sum += binomial * std::pow(mean_, j - k) * std::pow(sd_, k) * m[k];
    binomial = binomial * (j - k) / (k + 1);
  }
  return sum;
}

double RadiusDistribution::mean() const { return moment(1); }
double RadiusDistribution::second_moment() const { return moment(2); }
double RadiusDistribution::third_moment() const { return moment(3); }

double RadiusDistribution::cdf(double r) const {
  if (std::isnan(r)) return r;
  if (r < lo_) return 0.0;
  if (r >= hi_) return 1.0;
  switch (kind_) {
    case Kind::fixed:
      return 1.0;
    case Kind::uniform:
      return (r - lo_) / (hi_ - lo_);
    case Kind::truncated_normal: {
      const double z = (r - mean_) / sd_;
      const bool tail = (lo_ - mean_) / sd_ > 0.0;
      const double phi = tail ? normal_tail(z) : normal_cdf(z);
      return std::clamp((phi - phi_lo_) / (phi_hi_ - phi_lo_), 0.0, 1.0);
    }
    case Kind::piecewise_constant: {
      const auto k = static_cast<std::size_t>(std::upper_bound(edges_.begin(), edges_.end(), r) -
                                              edges_.begin() - 1);
      return cumulative_[k] + probability_[k] * (r - edges_[k]) / (edges_[k + 1] - edges_[k]);
    }
  }
  return 0.0;
}

double RadiusDistribution::quantile(double u) const {
  if (!(u >= 0.0 && u <= 1.0)) {
    throw InvalidArgument("RadiusDistribution::quantile: expected u in [0, 1], found " +
                          format_number(u));
  }
  switch (kind_) {
    case Kind::fixed:
      return lo_;
    case Kind::uniform:
      return std::min(hi_, lo_ + u * (hi_ - lo_));
    case Kind::truncated_normal: {
      // BEGIN EXERCISE 7.1: the truncated normal by inversion
      // Hint: solve Φ(z) = Φ_lo + u (Φ_hi − Φ_lo) with Φ⁻¹(p) = −√2 erfc⁻¹(2p) (Boost.Math); in
      //   the upper tail phi_lo_ and phi_hi_ hold Q = 1 − Φ instead, and Q⁻¹(p) = √2 erfc⁻¹(2p).
      const bool tail = (lo_ - mean_) / sd_ > 0.0;
      const double target = phi_lo_ + u * (phi_hi_ - phi_lo_);
      if (!(target > 0.0)) return lo_;
      if (!(target < 1.0)) return hi_;
      const double z = tail ? std::numbers::sqrt2 * boost::math::erfc_inv(2.0 * target)
                            : -std::numbers::sqrt2 * boost::math::erfc_inv(2.0 * target);
      return std::clamp(mean_ + sd_ * z, lo_, hi_);
      // END EXERCISE 7.1
    }
    case Kind::piecewise_constant: {
      // BEGIN EXERCISE 7.2: the piecewise-constant distribution by inversion
      // Hint: find the interval k with cumulative_[k] ≤ u < cumulative_[k + 1] (skip intervals
      //   of probability 0), then go linearly from edges_[k] to edges_[k + 1] within it.
      std::size_t k = static_cast<std::size_t>(
          std::upper_bound(cumulative_.begin(), cumulative_.end() - 1, u) - cumulative_.begin());
      k = k == 0 ? 0 : k - 1;
      while (k > 0 && probability_[k] == 0.0) --k;
      while (probability_[k] == 0.0) ++k;
      const double t = std::clamp((u - cumulative_[k]) / probability_[k], 0.0, 1.0);
      return std::min(edges_[k + 1], edges_[k] + t * (edges_[k + 1] - edges_[k]));
      // END EXERCISE 7.2
    }
  }
  return lo_;
}

std::string RadiusDistribution::describe() const {
  switch (kind_) {
    case Kind::fixed:
      return "fixed radius " + millimetres(lo_) + " mm";
    case Kind::uniform:
      return "uniform on [" + millimetres(lo_) + ", " + millimetres(hi_) + "] mm";
    case Kind::truncated_normal:
      return "normal (mean " + millimetres(mean_) + " mm, sd " + millimetres(sd_) +
             " mm) truncated to [" + millimetres(lo_) + ", " + millimetres(hi_) + "] mm";
    case Kind::piecewise_constant:
      return "piecewise constant on " + std::to_string(probability_.size()) + " intervals over [" +
             millimetres(lo_) + ", " + millimetres(hi_) + "] mm, mean " + millimetres(mean()) +
             " mm";
  }
  return {};
}

}  // namespace grbd::scene
