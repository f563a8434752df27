/// \file
/// \brief Argument checks and the formatting of numbers in error messages.

#include "grbd/core/checks.hpp"

#include <charconv>
#include <cmath>

#include "grbd/core/error.hpp"

namespace grbd {

std::string format_number(double x) {
  // std::to_chars does not depend on the C locale; 32 characters hold any "%.17g".
  char buffer[32];
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, x, std::chars_format::general, 17);
  return std::string(buffer, result.ptr);
}

void require_positive_finite(std::string_view where, std::string_view name, double x) {
  if (!(x > 0.0) || !std::isfinite(x)) {
    std::string message(where);
    message.append(": expected a finite ").append(name).append(" > 0, found ");
    throw InvalidArgument(message + format_number(x));
  }
}

}  // namespace grbd
