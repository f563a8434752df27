/// \file
/// \brief Chapter 8 exercises: the Bagnold fit and the inertial number of the steady-flow study.

#include "grbd/parallel/flow_profile.hpp"

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

#include <cmath>
#include <string>

namespace grbd::parallel {

double bagnold_fit(std::span<const double> z, std::span<const double> u, double h) {
  // BEGIN EXERCISE 8.6: the Bagnold fit
  // Hint: with f_i = h^{3/2} − (h − z_i)^{3/2}, the A that minimises Σ (u_i − A f_i)² solves
  //   d/dA = 0: A = Σ u_i f_i / Σ f_i². Check the arguments first (see the declaration).
  if (z.size() != u.size()) {
    throw InvalidArgument("bagnold_fit: expected one velocity per height, found " +
                          std::to_string(u.size()) + " for " + std::to_string(z.size()));
  }
  require_positive_finite("bagnold_fit", "depth h", h);
  double uf = 0.0, ff = 0.0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (!(z[i] >= 0.0 && z[i] <= h)) {
      throw InvalidArgument("bagnold_fit: expected heights in [0, h = " + format_number(h) +
                            "], found " + format_number(z[i]));
    }
    const double f = std::pow(h, 1.5) - std::pow(h - z[i], 1.5);
    uf += u[i] * f;
    ff += f * f;
  }
  if (!(ff > 0.0)) throw InvalidArgument("bagnold_fit: expected a height above the base");
  return uf / ff;
  // END EXERCISE 8.6
}

double inertial_number(double shear_rate, double diameter, double pressure, double density) {
  // BEGIN EXERCISE 8.7: the inertial number
  // Hint: I = |γ̇| d / √(P/ρ_s), the time a grain takes to fall into a hole under the pressure P
  //   over the time the shear takes to move it by its diameter; check the arguments first.
  if (!std::isfinite(shear_rate)) {
    throw InvalidArgument("inertial_number: expected a finite shear rate, found " +
                          format_number(shear_rate));
  }
  require_positive_finite("inertial_number", "diameter", diameter);
  require_positive_finite("inertial_number", "pressure", pressure);
  require_positive_finite("inertial_number", "density", density);
  return std::abs(shear_rate) * diameter / std::sqrt(pressure / density);
  // END EXERCISE 8.7
}

}  // namespace grbd::parallel
