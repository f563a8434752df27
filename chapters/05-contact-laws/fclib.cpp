// Chapter 5 bench program: grbd's solvers on FCLIB problems, the community benchmark of
// frictional contact (Acary, Brémond, Huber 2018).
//
// Every FCLIB file given (or every *.hdf5 in a folder) is read, a global problem converted to
// local form (W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w), and solved from λ = 0 by
//   SOR-AC   Gauss–Seidel with the Alart–Curnier prox, r = α/G_ii, α = 1
//   SOR-DS   Gauss–Seidel with the De Saxcé prox
//   JOR      Jacobi with the Alart–Curnier prox, one global r, α = 0.5
//   APGD     accelerated projected gradient with adaptive restart
// until the natural-map residual ‖F‖ ≤ tol ‖q‖ (FCLIB's and Siconos' classic measure; default
// tol = 10⁻⁸) or max_iterations. For each run it reports the iterations, ‖F‖/‖q‖,
// ‖F‖/max(‖q‖, ‖λ‖, ‖ξ‖) and the wall time; where the file holds a guess (/guesses/1) SOR-AC is
// also run warm from it.
//
// Usage:
//   ch05_fclib <data directory> <FCLIB file or folder>... [--tol T] [--max-iterations N]
// with T a finite number > 0 and N a whole number from 1 to INT_MAX (CLI11 reads the command
// line); a bad argument exits with 2 and a message that names it.
// Output, in the data directory:
//   fclib.txt   the table printed to standard output
//   fclib.csv   problem, solver, k, ‖F‖/‖q‖: every run's history, one row per iteration
//   values.txt  the table's numbers that the chapter quotes, key = value lines read by the book at
//               build time (\demo{ch05_fclib/values.txt#KEY} in chapter.md): per problem (the
//               file's stem) and solver (spaces as '_'), <problem>.<solver>.{contacts,
//               iterations ("> N" where the solver stopped at the cap), relative (‖F‖/‖q‖),
//               scaled (‖F‖/max), ms (the wall time)}

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "grbd/contact/fclib_bench.hpp"
#include "grbd/core/error.hpp"
#include "grbd_demo/demo.hpp"

namespace {

namespace fs = std::filesystem;

constexpr const char* kProgram = "ch05_fclib";
constexpr const char* kUsage =
    "usage: ch05_fclib <data directory> <FCLIB file or folder>... [--tol T] [--max-iterations N]\n"
    "  solves FCLIB problems with SOR, JOR, APGD and Newton; writes fclib.txt, fclib.csv and "
    "values.txt\n";

/// CLI11's help, which starts with the usage line of the other demos instead of CLI11's own.
class Help : public CLI::Formatter {
 public:
  std::string make_usage(const CLI::App* /*app*/, std::string /*name*/) const override {
    return kUsage;
  }
};

/// Prints `problem` and the usage to std::cerr; returns the exit code 2 of a bad command line.
int refuse(const std::string& problem) {
  std::cerr << kProgram << ": " << problem << '\n' << kUsage;
  return 2;
}

/// The value of --max-iterations: a whole number in decimal from 1 to INT_MAX, nothing else
/// ("1e3", "2.7", "inf", "0x10" and "3e9" are refused). CLI11 on its own would read integers with
/// strtoll's base 0, "0x10" as 16 and "010" as 8, so the accepted text is also rewritten in plain
/// decimal before CLI11 converts it.
CLI::Validator whole_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const char* const end = text.data() + text.size();
        int value = 0;
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (text.empty() || stop != end || error == std::errc::invalid_argument) {
          return "expects a whole number, found '" + text + "'";
        }
        if (error == std::errc::result_out_of_range || value < 1) {
          return "expects a whole number from 1 to " + std::to_string(INT_MAX) + ", found '" +
                 text + "'";
        }
        text = std::to_string(value);
        return {};
      },
      "");  // no description: the option's own says what it takes
}

/// The value of --tol: a finite positive number in decimal notation ("inf", "nan", "-1", "0" and
/// hexadecimal are refused). The accepted text is rewritten with 17 significant digits, which
/// CLI11's conversion (strtold) reads back as exactly the double std::from_chars found.
CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const bool plus = text.starts_with('+');  // strtod, which this option used, took a '+'
        const char* const first = text.data() + (plus ? 1 : 0);
        const char* const end = text.data() + text.size();
        double value = 0.0;
        const auto [stop, error] = std::from_chars(first, end, value);
        if (first == end || stop != end || error == std::errc::invalid_argument ||
            (plus && *first == '-')) {
          return "expects a number, found '" + text + "'";
        }
        if (error == std::errc::result_out_of_range || !std::isfinite(value) || !(value > 0.0)) {
          return "expects a finite positive number, found '" + text + "'";
        }
        char digits[32];
        const auto written =
            std::to_chars(digits, digits + sizeof digits, value, std::chars_format::general, 17);
        text.assign(digits, written.ptr);
        return {};
      },
      "");
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_directory;
  std::vector<std::string> inputs;
  double tol = 1e-8;
  int max_iterations = 20000;
  CLI::App app("", kProgram);  // no description: the help starts with the usage line
  app.formatter(std::make_shared<Help>());
  app.add_option("data directory", data_directory,
                 "an existing folder, where fclib.txt and fclib.csv are written")
      ->type_name("")
      ->required();
  app.add_option("FCLIB file or folder", inputs,
                 "FCLIB problems (HDF5), or folders whose *.hdf5 files are all solved")
      ->type_name("")
      ->required();
  app.add_option("--tol", tol, "stop once |F| <= T |q|; T a finite number > 0, by default 1e-8")
      ->transform(finite_positive())
      ->type_name("T")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--max-iterations", max_iterations,
                 "at most N iterations per solver and problem; N a whole number from 1 to " +
                     std::to_string(INT_MAX) + ", by default 20000")
      ->transform(whole_number())
      ->type_name("N")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  if (grbd::demo::wants_help(argc, argv)) {  // any -h or --help, as in every demo
    std::cout << app.help();
    return 0;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::ParseError& e) {
    return refuse(e.what());
  }

  const fs::path dir = data_directory;
  if (const auto reason = grbd::demo::not_a_directory(dir)) {
    return refuse(grbd::demo::directory_message("data directory", dir, *reason));
  }
  std::vector<fs::path> files;
  for (const std::string& input : inputs) {
    try {
      const std::vector<fs::path> found = grbd::contact::fclib_files(input);
      files.insert(files.end(), found.begin(), found.end());
    } catch (const grbd::Error& e) {
      return refuse(e.what());
    }
  }

  try {
    grbd::demo::OutputFile table(dir / "fclib.txt");
    grbd::demo::OutputFile history(dir / "fclib.csv", "problem,solver,k,relative_residual");
    table << grbd::contact::fclib_table_header();
    std::cout << grbd::contact::fclib_table_header();
    grbd::demo::Values values;
    grbd::contact::FclibBenchOptions options;
    options.tol = tol;
    options.max_iterations = max_iterations;
    options.record_history = true;
    grbd::contact::fclib_bench(files, options, [&](const grbd::contact::FclibBenchRow& row) {
      table << grbd::contact::fclib_table_line(row);
      std::cout << grbd::contact::fclib_table_line(row);
      std::string key = row.problem;
      key += '.';
      for (const char c : row.solver) key += c == ' ' ? '_' : c;
      key += '.';
      values.set(key + "contacts", "%zu", row.contacts);
      values.set(key + "iterations", row.converged ? "%d" : "> %d", row.iterations);
      // "9.8e-09" as in the table; a residual that stayed large as "2.4".
      values.set(key + "relative", row.relative_residual >= 0.01 ? "%.2g" : "%.1e",
                 row.relative_residual);
      values.set(key + "scaled", "%.1e", row.scaled_residual);
      values.set(key + "ms", "%.3g", 1e3 * row.seconds);
      values.set(key + "linear", "%d", row.linear_iterations);  // Newton's linear solves' work
      char line[512];
      for (std::size_t k = 0; k < row.history.size(); ++k) {
        std::snprintf(line, sizeof line, "%s,%s,%zu,%.6e\n", row.problem.c_str(),
                      row.solver.c_str(), k + 1, row.history[k]);
        history << line;
      }
    });
    table.finish();
    history.finish();
    values.write(dir / "values.txt");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "Exercises 5.1-5.8");
  }
}
