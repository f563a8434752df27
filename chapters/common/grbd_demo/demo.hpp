#pragma once
/// \file
/// \brief What every chapter demo does the same way: answer `--help`, check its command line, and
/// turn an exception into a message and an exit code (0 help, 2 bad arguments, 3 a missing
/// exercise, 1 any other error).

#include <exception>
#include <filesystem>
#include <initializer_list>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>

#include "grbd/core/error.hpp"

namespace grbd::demo {

/// True when the command line asks for help: any argument `-h` or `--help`.
inline bool wants_help(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    if (argument == "-h" || argument == "--help") return true;
  }
  return false;
}

/// Checks `program <data directory> [further arguments]`: exactly arguments.size() arguments, the
/// first an existing directory. `arguments` names them for the usage line, `writes` says what the
/// demo writes. Returns std::nullopt when main should go on; otherwise the exit code main returns:
/// 0 after printing the usage to std::cout for `-h` or `--help`, 2 after printing the usage or the
/// problem to std::cerr. The program is named by `program`, never by the path it was started with.
inline std::optional<int> check_arguments(int argc, char** argv, std::string_view program,
                                          std::initializer_list<std::string_view> arguments,
                                          std::string_view writes) {
  const auto print_usage = [&](std::ostream& out) {
    out << "usage: " << program;
    for (const std::string_view argument : arguments) out << ' ' << argument;
    out << "\n  " << writes << '\n';
  };
  if (wants_help(argc, argv)) {
    print_usage(std::cout);
    return 0;
  }
  if (argc != static_cast<int>(arguments.size()) + 1) {
    print_usage(std::cerr);
    return 2;
  }
  std::error_code error;  // is_directory without an error code throws on a symlink loop
  if (!std::filesystem::is_directory(argv[1], error)) {
    std::cerr << program << ": the data directory '" << argv[1] << "' does not exist or is not a "
              << "directory" << (error ? " (" + error.message() + ")" : std::string()) << '\n';
    return 2;
  }
  return std::nullopt;
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
