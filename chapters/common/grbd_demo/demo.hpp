#pragma once
/// \file
/// \brief What every chapter demo does the same way: check its command line, and turn an
/// exception into a message and an exit code (2 bad arguments, 3 a missing exercise, 1 any other
/// error).

#include <exception>
#include <filesystem>
#include <initializer_list>
#include <iostream>
#include <string_view>

#include "grbd/core/error.hpp"

namespace grbd::demo {

/// Checks `program <data directory> [further arguments]`: exactly arguments.size() arguments, the
/// first an existing directory. `arguments` names them for the usage line, `writes` says what the
/// demo writes. Prints the usage or the problem to std::cerr and returns false when wrong.
inline bool check_arguments(int argc, char** argv, std::string_view program,
                            std::initializer_list<std::string_view> arguments,
                            std::string_view writes) {
  if (argc != static_cast<int>(arguments.size()) + 1) {
    std::cerr << "usage: " << program;
    for (const std::string_view argument : arguments) std::cerr << ' ' << argument;
    std::cerr << "\n  " << writes << '\n';
    return false;
  }
  if (!std::filesystem::is_directory(argv[1])) {
    std::cerr << program << ": the data directory '" << argv[1]
              << "' does not exist or is not a directory\n";
    return false;
  }
  return true;
}

/// Call from a `catch (...)` block: prints the exception being handled and returns the demo's exit
/// code, 3 for grbd::NotImplemented (the student build before the exercises the demo `needs` are
/// done) and 1 for anything else.
inline int report_exception(std::string_view program, std::string_view needs) {
  try {
    throw;
  } catch (const NotImplemented& e) {
    std::cerr << program << " needs " << needs << ": " << e.what() << '\n';
    return 3;
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << '\n';
    return 1;
  } catch (...) {
    std::cerr << program << ": unknown exception\n";
    return 1;
  }
}

}  // namespace grbd::demo
