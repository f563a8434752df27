/// \file
/// \brief Chapter 3 exercise on convergence studies: the observed order of accuracy.

#include "grbd/ode/convergence.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

#include <cmath>
#include <cstddef>
#include <string>

namespace grbd::ode {

double observed_order(std::span<const double> h, std::span<const double> errors) {
  // BEGIN EXERCISE 3.3: the observed order of convergence
  // Hint: e = C h^p is the straight line log e = log C + p log h in a log–log plot.
  // Hint: the least-squares slope of y over x is Σ(x − x̄)(y − ȳ) / Σ(x − x̄)².
  if (h.size() != errors.size()) {
    throw InvalidArgument("observed_order: " + std::to_string(h.size()) + " step sizes but " +
                          std::to_string(errors.size()) + " errors");
  }
  if (h.size() < 2) {
    throw InvalidArgument(
        "observed_order: a slope needs at least two pairs (h, e), but there are " +
        std::to_string(h.size()));
  }
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (!(h[i] > 0.0) || !std::isfinite(h[i]) || !(errors[i] > 0.0) || !std::isfinite(errors[i])) {
      throw InvalidArgument("observed_order: pair " + std::to_string(i) +
                            " must have a positive, finite h and error, but h = " +
                            format_number(h[i]) + " and e = " + format_number(errors[i]));
    }
  }
  const auto n = static_cast<double>(h.size());
  double x_mean = 0.0;
  double y_mean = 0.0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    x_mean += std::log(h[i]) / n;
    y_mean += std::log(errors[i]) / n;
  }
  // Centred sums: the slope stays accurate when log h is far from 0 (h = 1e-6: log h ≈ −14).
  double sxy = 0.0;
  double sxx = 0.0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double dx = std::log(h[i]) - x_mean;
    sxy += dx * (std::log(errors[i]) - y_mean);
    sxx += dx * dx;
  }
  if (sxx == 0.0) {
    throw InvalidArgument(
        "observed_order: all step sizes are equal; a slope needs two different h");
  }
  return sxy / sxx;
  // END EXERCISE 3.3
}

}  // namespace grbd::ode
