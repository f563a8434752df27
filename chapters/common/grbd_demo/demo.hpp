#pragma once
/// \file
/// \brief What every chapter demo does the same way: answer `--help`, check its command line, write
/// its output files, and turn an exception into a message and an exit code (0 help, 2 bad
/// arguments, 3 a missing exercise, 1 any other error).
///
/// Every message a demo prints starts with the program's name exactly once: report_exception() and
/// the argument checks add it, so the messages of the exceptions a demo throws never start with it.

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

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

/// Why `path` is not an existing directory, or std::nullopt when it is one: the system's reason
/// ("No such file or directory", "Not a directory" for a path through a regular file, "Too many
/// levels of symbolic links", "File name too long", "Permission denied", ...) or "not a directory"
/// for an existing file of another type. Never throws: it asks std::filesystem::status with a
/// std::error_code, since the throwing overloads of std::filesystem end a demo with an uncaught
/// std::filesystem::filesystem_error on a symbolic-link loop or an overlong name.
inline std::optional<std::string> not_a_directory(const std::filesystem::path& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (error) return error.message();
  if (!std::filesystem::is_directory(status)) return std::string("not a directory");
  return std::nullopt;
}

/// The message for an unusable directory argument: "cannot use the <what> '<path>': <reason>".
inline std::string directory_message(std::string_view what, const std::filesystem::path& path,
                                     std::string_view reason) {
  return "cannot use the " + std::string(what) + " '" + path.string() + "': " + std::string(reason);
}

/// Checks `program <data directory> [further arguments]`: from `least` (at least 1) to `most`
/// arguments, the first an existing directory. `arguments` names them for the usage line (the
/// optional ones in brackets; the last may stand for several), `writes` says what the demo
/// writes. Returns std::nullopt when main should go on; otherwise the exit code main returns: 0
/// after printing the usage to std::cout for `-h` or `--help`, 2 after printing the usage or the
/// problem to std::cerr. The program is named by `program`, never by the path it was started with.
inline std::optional<int> check_arguments(int argc, char** argv, std::string_view program,
                                          std::initializer_list<std::string_view> arguments,
                                          std::string_view writes, std::size_t least,
                                          std::size_t most) {
  const auto print_usage = [&](std::ostream& out) {
    out << "usage: " << program;
    for (const std::string_view argument : arguments) out << ' ' << argument;
    out << "\n  " << writes << '\n';
  };
  if (wants_help(argc, argv)) {
    print_usage(std::cout);
    return 0;
  }
  if (argc < 2 || static_cast<std::size_t>(argc - 1) < least ||
      static_cast<std::size_t>(argc - 1) > most) {
    print_usage(std::cerr);
    return 2;
  }
  if (const auto reason = not_a_directory(argv[1])) {
    std::cerr << program << ": " << directory_message("data directory", argv[1], *reason) << '\n';
    return 2;
  }
  return std::nullopt;
}

/// check_arguments() for exactly arguments.size() arguments.
inline std::optional<int> check_arguments(int argc, char** argv, std::string_view program,
                                          std::initializer_list<std::string_view> arguments,
                                          std::string_view writes) {
  return check_arguments(argc, argv, program, arguments, writes, arguments.size(),
                         arguments.size());
}

/// A number on a demo's command line: the whole of `text` must be a finite decimal number, else
/// grbd::Error names the argument (`what`), what was expected and what was found.
inline double parse_number(std::string_view text, std::string_view what) {
  const std::string copy(text);
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(copy, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != copy.size() || !std::isfinite(value)) {
    throw Error(std::string(what) + ": expected a finite number, found \"" + copy + "\"");
  }
  return value;
}

/// A file a demo writes: a std::ofstream that knows its path and reports every failure as a
/// grbd::Error naming the file, with the system's reason where there is one. A stream only reports
/// a failed write once its buffer reaches the disk, which for the last few kilobytes is at the
/// close: a file is therefore complete, and checked, only after finish(), which every demo calls
/// once it has written everything (the destructor closes silently, after an exception).
class OutputFile : public std::ofstream {
 public:
  /// Opens (or truncates) `path` for writing; throws grbd::Error if it cannot. A non-empty
  /// `header` is written as the first line and flushed at once, so that a file that cannot be
  /// written (a full disk) fails here, before the demo computes what goes into it.
  explicit OutputFile(std::filesystem::path path, std::string_view header = {})
      : path_(std::move(path)) {
    errno = 0;
    open(path_);
    if (!is_open()) raise("cannot open", " for writing");
    if (!header.empty()) {
      *this << header << '\n';
      errno = 0;
      flush();
      if (!good()) raise("cannot write", "");
    }
  }

  // Movable (a function may open and return one), written out because the defaulted move would
  // copy the virtual base std::basic_ios.
  OutputFile(OutputFile&& other) noexcept
      : std::ofstream(std::move(other)), path_(std::move(other.path_)) {}
  OutputFile& operator=(OutputFile&&) = delete;

  /// The file's path.
  const std::filesystem::path& path() const noexcept { return path_; }

  /// Flushes and closes the file; throws grbd::Error naming it if this or any earlier write failed.
  void finish() {
    errno = 0;
    close();  // flushes the buffer; sets failbit if that fails
    if (fail()) raise("cannot write", "");
  }

 private:
  [[noreturn]] void raise(std::string_view what, std::string_view how) const {
    const int reason = errno;
    throw Error(std::string(what) + " '" + path_.string() + "'" + std::string(how) +
                (reason != 0 ? ": " + std::generic_category().message(reason) : std::string()));
  }

  std::filesystem::path path_;
};

/// Call from a `catch (...)` block: prints the exception being handled and returns the demo's exit
/// code, 3 for grbd::NotImplemented (the student build before the exercises the demo `needs` are
/// done) and 1 for anything else.
/// The numbers a chapter quotes from a demo: one `key = value` line each, written to a file
/// `values.txt` in the demo's figure folder, which the book filter reads when the book is built
/// (`\demo{FOLDER/values.txt#KEY}` in chapter.md), so that no number is copied by hand.
class Values {
 public:
  /// Adds `key = ` the printf-formatted value.
  template <class... Args>
  void set(std::string_view key, const char* format, Args... args) {
    char text[256];
    std::snprintf(text, sizeof text, format, args...);
    text_ += std::string(key) + " = " + text + "\n";
  }
  /// Writes them (throws grbd::Error naming the file if it cannot).
  void write(const std::filesystem::path& file) const {
    OutputFile out(file);
    out << text_;
    out.finish();
  }

 private:
  std::string text_;
};

/// x > 0 as TeX with two significant digits, "8.6\cdot10^{-7}".
inline std::string tex_power(double x) {
  const int exponent = static_cast<int>(std::floor(std::log10(x)));
  char text[64];
  std::snprintf(text, sizeof text, "%.1f\\cdot10^{%d}", x / std::pow(10.0, exponent), exponent);
  return text;
}

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
