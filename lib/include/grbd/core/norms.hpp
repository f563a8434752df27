#pragma once
/// \file
/// \brief Euclidean norms that neither overflow nor underflow in their intermediate squares.
///
/// sqrt(a² + b²) overflows to ∞ for |a| ≳ 1.3·10¹⁵⁴ and loses every digit for |a| ≲ 10⁻¹⁶²,
/// although the norm itself is representable. A contact solver that meets such numbers (a file
/// with q ≈ 10²⁰⁰, a denormal mass) would then project onto the wrong point of the friction cone
/// or report a NaN residual. These functions take the plain sum of squares when it lies in the
/// normal range — the common case, at the cost of one comparison — and rescale otherwise.

#include <cmath>
#include <limits>
#include <span>

namespace grbd {

/// ‖(a, b)‖ without spurious overflow or underflow: sqrt(a² + b²) when a² + b² is a normal
/// finite number, std::hypot(a, b) otherwise (∞ if a or b is infinite, NaN if one is NaN and
/// neither is infinite).
inline double norm2d(double a, double b) {
  const double s = a * a + b * b;
  if (s >= std::numeric_limits<double>::min() && s <= std::numeric_limits<double>::max()) {
    return std::sqrt(s);
  }
  return std::hypot(a, b);
}

/// ‖x‖₂ of a flat array without spurious overflow or underflow: the plain sum of squares when
/// it is a normal finite number, otherwise a second pass scaled by max |x_k| (as LAPACK's
/// dnrm2). ∞ if an entry is infinite, NaN if an entry is NaN (and none is infinite).
double euclidean_norm(std::span<const double> x);

}  // namespace grbd
