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
// Output, in the data directory:
//   fclib.txt   the table printed to standard output
//   fclib.csv   problem, solver, k, ‖F‖/‖q‖: every run's history, one row per iteration

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "grbd/contact/fclib.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd_demo/demo.hpp"

namespace {

namespace fs = std::filesystem;
using grbd::Vector3;
using grbd::contact::LocalProblem;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

constexpr const char* kProgram = "ch05_fclib";

/// Prints the usage, after `problem` if there is one, to `out`; returns the exit code 2.
int usage(const std::string& problem, std::ostream& out = std::cerr) {
  if (!problem.empty()) out << kProgram << ": " << problem << '\n';
  out << "usage: " << kProgram
      << " <data directory> <FCLIB file or folder>... [--tol T] [--max-iterations N]\n"
         "  solves FCLIB problems with SOR, JOR and APGD; writes fclib.txt and fclib.csv\n";
  return 2;
}

/// Parses a number option's value or returns false.
bool parse_number(const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size();
}

struct Run {
  std::string name;
  SolverOptions options;
  bool jor = false;
  bool apgd = false;
};

}  // namespace

int main(int argc, char** argv) {
  if (grbd::demo::wants_help(argc, argv)) {
    usage("", std::cout);
    return 0;
  }
  if (argc < 3) return usage("");
  const fs::path dir = argv[1];
  if (!fs::is_directory(dir)) {
    return usage("the data directory '" + dir.string() + "' does not exist or is not a directory");
  }
  double tol = 1e-8;
  double max_iterations = 20000;
  std::vector<fs::path> files;
  for (int a = 2; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--tol" || arg == "--max-iterations") {
      double value = 0.0;
      if (a + 1 >= argc || !parse_number(argv[a + 1], value) || !(value > 0.0)) {
        return usage(arg + " expects a positive number, found '" +
                     (a + 1 < argc ? std::string(argv[a + 1]) : std::string()) + "'");
      }
      (arg == "--tol" ? tol : max_iterations) = value;
      ++a;
    } else if (arg.starts_with("--")) {
      return usage("unknown option '" + arg + "'");
    } else if (fs::is_directory(arg)) {
      std::vector<fs::path> found;
      for (const auto& entry : fs::directory_iterator(arg)) {
        if (entry.path().extension() == ".hdf5") found.push_back(entry.path());
      }
      std::sort(found.begin(), found.end());
      if (found.empty()) return usage("the folder '" + arg + "' holds no *.hdf5 file");
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(arg)) {
      files.emplace_back(arg);
    } else {
      return usage("'" + arg + "' is neither an FCLIB file nor a folder");
    }
  }
  if (files.empty()) return usage("no FCLIB file given");

  try {
    std::ofstream table(dir / "fclib.txt");
    std::ofstream history(dir / "fclib.csv");
    history << "problem,solver,k,relative_residual\n";
    char line[512];
    std::snprintf(line, sizeof line, "%-44s %-12s %4s %9s %10s %10s %10s %s\n", "problem",
                  "solver", "n", "iter", "|F|/|q|", "|F|/max", "time [ms]", "");
    table << line;
    std::cout << line;

    std::vector<Run> runs(4);
    for (Run& run : runs) {
      run.options.criterion = grbd::contact::Criterion::natural_residual;
      run.options.abs_tol = 0.0;
      run.options.rel_tol = tol;
      run.options.max_iterations = static_cast<int>(max_iterations);
      run.options.record_history = true;
    }
    runs[0].name = "SOR-AC";
    runs[1].name = "SOR-DS";
    runs[1].options.form = grbd::contact::ProxForm::de_saxce;
    runs[2].name = "JOR";
    runs[2].jor = true;
    runs[2].options.alpha = 0.5;
    runs[2].options.r_strategy = grbd::contact::RFactorStrategy::global;
    runs[3].name = "APGD";
    runs[3].apgd = true;

    for (const fs::path& file : files) {
      const grbd::contact::FclibInfo info = grbd::contact::read_fclib_info(file);
      const LocalProblem problem = grbd::contact::read_fclib_as_local(file);
      const std::string name = file.stem().string();
      std::vector<Run> these = runs;
      if (info.guess) {
        Run warm = runs[0];
        warm.name = "SOR-AC warm";
        these.push_back(warm);
      }
      for (const Run& run : these) {
        std::vector<Vector3> lambda;
        if (run.name.ends_with("warm")) lambda = *info.guess;
        const SolverResult result =
            run.apgd  ? grbd::contact::solve_apgd(problem, lambda, run.options)
            : run.jor ? grbd::contact::solve_jor(problem, lambda, run.options)
                      : grbd::contact::solve_sor(problem, lambda, run.options);
        std::snprintf(line, sizeof line, "%-44s %-12s %4zu %9d %10.2e %10.2e %10.2f %s\n",
                      name.c_str(), run.name.c_str(), problem.q.size(), result.iterations,
                      result.relative_residual(), result.scaled_residual(),
                      1e3 * result.seconds, result.converged ? "" : "NOT converged");
        table << line;
        std::cout << line;
        for (std::size_t k = 0; k < result.history.size(); ++k) {
          std::snprintf(line, sizeof line, "%s,%s,%zu,%.6e\n", name.c_str(), run.name.c_str(),
                        k + 1, result.history[k] / result.norm_c);
          history << line;
        }
      }
    }
    if (!table || !history) throw std::runtime_error("cannot write fclib.txt or fclib.csv");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "Exercises 5.1-5.8");
  }
}
