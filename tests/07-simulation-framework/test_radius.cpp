/// \file
/// \brief Chapter 7: the radius distributions of the generators, against independent references:
/// closed-form moments of the uniform distribution, the moments of the truncated normal by
/// numerical quadrature of its density, the interval probabilities and mean diameter of the
/// reference chute's distribution (shared/REFERENCES.md: GRSFramework's 10⁶-bead study, mean
/// diameter ≈ 1.5 mm), and samples tested with the Kolmogorov–Smirnov statistic.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/scene/radius.hpp"

namespace grbd::scene {
namespace {

/// ∫_a^b f by composite Simpson with n (even) panels.
template <class F>
double simpson(F f, double a, double b, int n) {
  const double h = (b - a) / n;
  double sum = f(a) + f(b);
  for (int k = 1; k < n; ++k) sum += (k % 2 == 1 ? 4.0 : 2.0) * f(a + k * h);
  return sum * h / 3.0;
}

/// The Kolmogorov–Smirnov statistic sup |F_n − F| of `samples` (sorted here) against d.cdf.
double ks_statistic(std::vector<double> samples, const RadiusDistribution& d) {
  std::sort(samples.begin(), samples.end());
  const double n = static_cast<double>(samples.size());
  double D = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double F = d.cdf(samples[i]);
    D = std::max({D, (static_cast<double>(i) + 1.0) / n - F, F - static_cast<double>(i) / n});
  }
  return D;
}

std::vector<double> draw(const RadiusDistribution& d, std::uint64_t seed, int n) {
  Random random(seed);
  std::vector<double> out(static_cast<std::size_t>(n));
  for (double& r : out) r = d.sample(random);
  return out;
}

std::vector<RadiusDistribution> examples() {
  return {RadiusDistribution::fixed(1e-3), RadiusDistribution::uniform(0.9e-3, 1.1e-3),
          RadiusDistribution::truncated_normal(1e-3, 0.1e-3, 0.8e-3, 1.3e-3),
          RadiusDistribution::truncated_normal(1e-3, 0.1e-3, 1.3e-3, 1.5e-3),  // upper tail
          RadiusDistribution::piecewise_constant({0.59e-3, 0.70e-3, 0.85e-3, 1.00e-3, 1.18e-3},
                                                 {1.3681, 1.9913, 0.29116, 0.03956})};
}

// Truncated normals N(mean, sd²) on [lo, hi]: around the mean, far in the upper tail, entirely
// below the mean, and narrow; with the unnormalised density exp(−z²/2), z = (r − mean)/sd.
struct NormalCase {
  double mean, sd, lo, hi;
  double density(double r) const {
    const double z = (r - mean) / sd;
    return std::exp(-0.5 * z * z);
  }
};
constexpr NormalCase kNormalCases[] = {{1e-3, 0.1e-3, 0.8e-3, 1.3e-3},
                                       {1e-3, 0.1e-3, 1.3e-3, 1.5e-3},
                                       {1e-3, 0.5e-3, 0.1e-3, 0.4e-3},
                                       {1e-3, 1e-5, 0.9e-3, 1.1e-3}};

TEST(RadiusDistribution, UniformMomentsAreTheClosedForms) {
  const double a = 0.9e-3;
  const double b = 1.1e-3;
  const RadiusDistribution d = RadiusDistribution::uniform(a, b);
  EXPECT_NEAR(d.mean(), 0.5 * (a + b), 1e-18);
  EXPECT_NEAR(d.second_moment(), (a * a + a * b + b * b) / 3.0, 1e-20);
  EXPECT_NEAR(d.third_moment(), (a + b) * (a * a + b * b) / 4.0, 1e-23);
  const RadiusDistribution f = RadiusDistribution::fixed(2e-3);
  EXPECT_EQ(f.mean(), 2e-3);
  EXPECT_EQ(f.third_moment(), 8e-9);
}

// The moments of the truncated normal from the recurrence of its standard moments, against
// Simpson quadrature of r^j φ((r − μ)/σ) / (σ Z) over [lo, hi], also far in the upper tail.
TEST(RadiusDistribution, TruncatedNormalMomentsAgreeWithQuadrature) {
  for (const NormalCase& c : kNormalCases) {
    const RadiusDistribution d = RadiusDistribution::truncated_normal(c.mean, c.sd, c.lo, c.hi);
    const auto density = [&](double r) { return c.density(r); };
    const double Z = simpson(density, c.lo, c.hi, 20000);
    for (int j = 1; j <= 3; ++j) {
      const double expected =
          simpson([&](double r) { return std::pow(r, j) * density(r); }, c.lo, c.hi, 20000) / Z;
      const double got = j == 1 ? d.mean() : j == 2 ? d.second_moment() : d.third_moment();
      EXPECT_NEAR(got, expected, 1e-11 * expected) << "moment " << j << " of case lo = " << c.lo;
    }
    // cdf agrees with the quadrature.
    const double mid = 0.5 * (c.lo + c.hi);
    EXPECT_NEAR(d.cdf(mid), simpson(density, c.lo, mid, 20000) / Z, 1e-12);
  }
}

// The reference chute (shared/REFERENCES.md): densities 1.3681, 1.9913, 0.29116, 0.03956 on
// [0.59, 0.70], [0.70, 0.85], [0.85, 1.00], [1.00, 1.18] mm; density × width sums to 0.5 (to the
// digits given), the interval probabilities are density × width normalised, about 0.30, 0.60,
// 0.087 and 0.014, and the mean diameter is about 1.5 mm.
TEST(RadiusDistribution, TheReferenceChuteDistributionHasItsIntervalProbabilities) {
  const std::vector<double> edges = {0.59e-3, 0.70e-3, 0.85e-3, 1.00e-3, 1.18e-3};
  const std::vector<double> density = {1.3681, 1.9913, 0.29116, 0.03956};
  const RadiusDistribution d = RadiusDistribution::piecewise_constant(edges, density);
  double sum = 0.0;
  for (std::size_t k = 0; k < density.size(); ++k)
    sum += density[k] * (edges[k + 1] - edges[k]) * 1e3;
  EXPECT_NEAR(sum, 0.5, 1e-4);  // to the digits the densities are given with
  const std::vector<double> p = d.interval_probabilities();
  for (std::size_t k = 0; k < density.size(); ++k) {
    EXPECT_NEAR(p[k], density[k] * (edges[k + 1] - edges[k]) * 1e3 / sum, 1e-15) << k;
  }
  EXPECT_NEAR(p[0], 0.30, 0.005);
  EXPECT_NEAR(p[1], 0.60, 0.005);
  EXPECT_NEAR(p[2], 0.087, 0.001);
  EXPECT_NEAR(p[3], 0.014, 0.001);
  EXPECT_NEAR(2.0 * d.mean(), 1.5e-3, 0.01e-3);
  EXPECT_EQ(d.min(), 0.59e-3);
  EXPECT_EQ(d.max(), 1.18e-3);
}

// Exercise 7.1: the quantile of the truncated normal inverts the cdf (closed form in Φ), also
// far in the upper tail where Φ ≈ 1; its median agrees with the median of the density found by
// Simpson quadrature and bisection, an independent reference; samples pass Kolmogorov–Smirnov.
TEST(Exercise7_1, TruncatedNormalQuantileInvertsTheCdfAlsoInTheUpperTail) {
  for (const NormalCase& c : kNormalCases) {
    const RadiusDistribution d = RadiusDistribution::truncated_normal(c.mean, c.sd, c.lo, c.hi);
    for (double u = 0.0; u <= 1.0; u += 0.0625) {
      const double r = d.quantile(u);
      ASSERT_GE(r, c.lo);
      ASSERT_LE(r, c.hi);
      EXPECT_NEAR(d.cdf(r), u, 1e-12) << "u = " << u << ", lo = " << c.lo;
    }
    EXPECT_NEAR(d.quantile(0.0), c.lo, 1e-12 * c.lo);
    EXPECT_NEAR(d.quantile(1.0), c.hi, 1e-12 * c.hi);
    const auto density = [&](double r) { return c.density(r); };
    const double Z = simpson(density, c.lo, c.hi, 20000);
    double a = c.lo, b = c.hi;
    for (int i = 0; i < 60; ++i) {
      const double m = 0.5 * (a + b);
      (simpson(density, c.lo, m, 20000) / Z < 0.5 ? a : b) = m;
    }
    EXPECT_NEAR(d.quantile(0.5), 0.5 * (a + b), 1e-9 * c.hi) << "median, lo = " << c.lo;
    EXPECT_LT(ks_statistic(draw(d, 11, 20000), d), 1.95 / std::sqrt(20000.0));
  }
}

// Exercise 7.2: the piecewise-constant distribution of the reference chute: samples fall in each
// interval with its probability; the quantile inverts the cdf, gives the edges at the cumulative
// probabilities, and never a radius inside an interval of density 0.
TEST(Exercise7_2, PiecewiseConstantQuantileDrawsEachIntervalWithItsProbability) {
  const std::vector<double> edges = {0.59e-3, 0.70e-3, 0.85e-3, 1.00e-3, 1.18e-3};
  const std::vector<double> density = {1.3681, 1.9913, 0.29116, 0.03956};
  const RadiusDistribution d = RadiusDistribution::piecewise_constant(edges, density);
  const std::vector<double> p = d.interval_probabilities();
  double cumulative = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_NEAR(d.quantile(cumulative), edges[k], 1e-15) << "edge " << k;
    cumulative += p[k];
  }
  EXPECT_NEAR(d.quantile(1.0), edges.back(), 1e-15);
  for (double u = 0.0; u <= 1.0; u += 1.0 / 64.0) {
    EXPECT_NEAR(d.cdf(d.quantile(u)), u, 1e-12) << u;
  }
  // Samples: the fraction in each interval within 5 standard errors of its probability.
  const int n = 200000;
  const std::vector<double> r = draw(d, 42, n);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double in =
        static_cast<double>(std::count_if(
            r.begin(), r.end(), [&](double x) { return x >= edges[k] && x < edges[k + 1]; })) /
        n;
    EXPECT_NEAR(in, p[k], 5.0 * std::sqrt(p[k] * (1.0 - p[k]) / n)) << "interval " << k;
  }
  EXPECT_LT(ks_statistic(r, d), 1.95 / std::sqrt(static_cast<double>(n)));
  // Densities 1, 0, 1 on [1, 2], [2, 3], [3, 4] mm: nothing in (2, 3) mm, monotone.
  const RadiusDistribution gap =
      RadiusDistribution::piecewise_constant({1e-3, 2e-3, 3e-3, 4e-3}, {1.0, 0.0, 1.0});
  double last = 0.0;
  for (double u = 0.0; u <= 1.0; u += 1.0 / 1024.0) {
    const double x = gap.quantile(u);
    EXPECT_FALSE(x > 2e-3 && x < 3e-3) << "u = " << u << " gives " << x;
    EXPECT_GE(x, last);
    last = x;
  }
  for (const double u : {0.5 - 1e-15, 0.5, 0.5 + 1e-15}) {
    const double x = gap.quantile(u);
    EXPECT_FALSE(x > 2e-3 && x < 3e-3) << "u = " << u << " gives " << x;
  }
  EXPECT_NEAR(gap.quantile(0.25), 1.5e-3, 1e-15);
  EXPECT_NEAR(gap.quantile(0.75), 3.5e-3, 1e-15);
}

// Every distribution's samples pass the Kolmogorov–Smirnov test at the 0.1 % level
// (D < 1.95/√n) and lie in [min, max]; their mean is within 5 standard errors of mean().
TEST(RadiusDistribution, SamplesFollowTheDistribution) {
  const int n = 100000;
  for (const RadiusDistribution& d : examples()) {
    const std::vector<double> r = draw(d, 7, n);
    double mean = 0.0;
    for (const double x : r) {
      ASSERT_GE(x, d.min()) << d.describe();
      ASSERT_LE(x, d.max()) << d.describe();
      mean += x / n;
    }
    const double variance = d.second_moment() - d.mean() * d.mean();
    EXPECT_NEAR(mean, d.mean(), 5.0 * std::sqrt(std::max(variance, 0.0) / n) + 1e-10 * d.mean())
        << d.describe();
    if (d.kind() != RadiusDistribution::Kind::fixed) {
      EXPECT_LT(ks_statistic(r, d), 1.95 / std::sqrt(n)) << d.describe();
    }
  }
}

TEST(RadiusDistribution, TheSameSeedGivesTheSameRadiiAnotherSeedOthers) {
  for (const RadiusDistribution& d : examples()) {
    if (d.kind() == RadiusDistribution::Kind::fixed) continue;
    EXPECT_EQ(draw(d, 123, 1000), draw(d, 123, 1000)) << d.describe();
    EXPECT_NE(draw(d, 123, 1000), draw(d, 124, 1000)) << d.describe();
  }
  Random random(5);
  for (int k = 0; k < 100000; ++k) {
    const double u = random.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    ASSERT_EQ(u * 0x1.0p53, std::floor(u * 0x1.0p53));  // a multiple of 2⁻⁵³
  }
}

TEST(RadiusDistribution, RefusesBadParametersNamingThem) {
  const auto message = [](auto make) {
    try {
      make();
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  const auto has = [](const std::string& m, const std::string& part) {
    return m.find(part) != std::string::npos;
  };
  std::string m = message([] { RadiusDistribution::fixed(-1e-3); });
  EXPECT_TRUE(has(m, "fixed") && has(m, "radius r > 0") && has(m, "-0.001")) << m;
  m = message([] { RadiusDistribution::uniform(2e-3, 1e-3); });
  EXPECT_TRUE(has(m, "lo < hi")) << m;
  m = message([] { RadiusDistribution::uniform(1e-3, NAN); });
  EXPECT_TRUE(has(m, "hi")) << m;
  m = message([] { RadiusDistribution::truncated_normal(1e-3, 0.0, 0.5e-3, 2e-3); });
  EXPECT_TRUE(has(m, "standard deviation")) << m;
  m = message([] { RadiusDistribution::truncated_normal(1e-3, 1e-6, 0.5e-3, 0.6e-3); });
  EXPECT_TRUE(has(m, "probability is 0")) << m;
  m = message([] { RadiusDistribution::piecewise_constant({1e-3, 2e-3}, {1.0, 2.0}); });
  EXPECT_TRUE(has(m, "2 edges and 2 densities")) << m;
  m = message([] { RadiusDistribution::piecewise_constant({1e-3, 2e-3, 1.5e-3}, {1.0, 2.0}); });
  EXPECT_TRUE(has(m, "increasing edges") && has(m, "edges[2]")) << m;
  m = message([] { RadiusDistribution::piecewise_constant({1e-3, 2e-3, 3e-3}, {1.0, -2.0}); });
  EXPECT_TRUE(has(m, "densities[1]")) << m;
  m = message([] { RadiusDistribution::piecewise_constant({1e-3, 2e-3, 3e-3}, {0.0, 0.0}); });
  EXPECT_TRUE(has(m, "all zero")) << m;
  const RadiusDistribution d = RadiusDistribution::uniform(1e-3, 2e-3);
  m = message([&] { d.quantile(1.5); });
  EXPECT_TRUE(has(m, "u in [0, 1]")) << m;
  // Intervals of zero density are skipped by the sampler and trimmed from the support.
  const RadiusDistribution gaps =
      RadiusDistribution::piecewise_constant({1e-3, 2e-3, 3e-3, 4e-3, 5e-3}, {0.0, 1.0, 0.0, 1.0});
  EXPECT_EQ(gaps.min(), 2e-3);
  EXPECT_EQ(gaps.max(), 5e-3);
  for (const double r : draw(gaps, 3, 10000)) EXPECT_FALSE(r > 3e-3 && r < 4e-3) << r;
  EXPECT_EQ(gaps.quantile(0.0), 2e-3);
  EXPECT_EQ(gaps.quantile(1.0), 5e-3);
}

}  // namespace
}  // namespace grbd::scene
