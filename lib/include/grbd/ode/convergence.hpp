#pragma once
/// \file
/// \brief Reading convergence studies: observed orders of accuracy (chapter 3).

#include <span>

namespace grbd::ode {

// [observed order declaration]
/// \brief <b>Exercise 3.3</b>: the observed order of convergence.
///
/// The least-squares slope of log e against log h over the pairs (h_i, e_i), i.e. the p of the
/// model e ≈ C h^p; for two pairs log(e1/e2)/log(h1/h2). Throws grbd::InvalidArgument for fewer
/// than two pairs, spans of different lengths, or a non-positive or non-finite entry.
double observed_order(std::span<const double> h, std::span<const double> errors);
// [observed order declaration]

}  // namespace grbd::ode
