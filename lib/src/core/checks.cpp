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

std::string regular_file_problem(const std::filesystem::path& path, std::string_view what) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  const std::string name(what);
  if (!std::filesystem::exists(status)) {
    if (error && error != std::errc::no_such_file_or_directory) {
      return "cannot examine the " + name + ": " + error.message();
    }
    return "no such " + name;
  }
  if (!std::filesystem::is_regular_file(status)) return "is not a regular file, as a " + name + " is";
  return {};
}

void require_positive_finite(std::string_view where, std::string_view name, double x) {
  if (!(x > 0.0) || !std::isfinite(x)) {
    std::string message(where);
    message.append(": expected a finite ").append(name).append(" > 0, found ");
    throw InvalidArgument(message + format_number(x));
  }
}

}  // namespace grbd
