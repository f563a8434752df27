#pragma once
/// \file
/// \brief The message of the grbd::InvalidArgument a call throws, for tests that check what a
/// refusal says.

#include <functional>
#include <string>

#include "grbd/core/error.hpp"

namespace grbd::test {

/// The what() of the InvalidArgument that f throws, or "(no exception)".
inline std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace grbd::test
