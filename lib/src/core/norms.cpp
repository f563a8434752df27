/// \file
/// \brief Euclidean norms without spurious overflow or underflow.

#include "grbd/core/norms.hpp"

#include <algorithm>

namespace grbd {

double euclidean_norm(std::span<const double> x) {
  double sum = 0.0;
  for (const double v : x) sum += v * v;
  if (sum >= std::numeric_limits<double>::min() && sum <= std::numeric_limits<double>::max()) {
    return std::sqrt(sum);
  }
  // Overflow, underflow, zero, or a non-finite entry: scale by the largest magnitude.
  double largest = 0.0;
  for (const double v : x) {
    if (std::isnan(v)) return v;
    largest = std::max(largest, std::abs(v));
  }
  if (largest == 0.0 || std::isinf(largest)) return largest;
  double scaled = 0.0;
  for (const double v : x) scaled += (v / largest) * (v / largest);
  return largest * std::sqrt(scaled);
}

}  // namespace grbd
