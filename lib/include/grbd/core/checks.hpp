#pragma once
/// \file
/// \brief Argument checks and the formatting of numbers shared by the error messages of grbd.

#include <filesystem>
#include <string>
#include <string_view>

namespace grbd {

/// The double x with 17 significant digits, as printf's `%.17g` writes it in the C locale (the
/// current locale plays no part): 17 digits identify every double, so the number reads back as
/// exactly x. Non-finite values read "inf", "-inf", "nan" or "-nan".
std::string format_number(double x);

/// Throws InvalidArgument with the message "<where>: expected a finite <name> > 0, found <x>"
/// unless 0 < x < ∞ (NaN included in the failures). `where` names the function that checks, e.g.
/// "sphere_mass_properties"; `name` what x is, e.g. "radius".
void require_positive_finite(std::string_view where, std::string_view name, double x);

/// What keeps `path` from being read as a `what` ("scene file", "checkpoint file"): "no such
/// <what>", "cannot examine the <what>: <reason>", or "is not a regular file, as a <what> is" (a
/// FIFO would block a reader, a device never end); "" when it is a regular file.
std::string regular_file_problem(const std::filesystem::path& path, std::string_view what);

}  // namespace grbd
