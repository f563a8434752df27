/// \file
/// \brief The FCLIB bench of chapter 5.

#include "grbd/contact/fclib_bench.hpp"

#include <algorithm>
#include <cstdio>
#include <system_error>

#include "grbd/contact/fclib.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

namespace fs = std::filesystem;

// The std::error_code overloads of std::filesystem throughout: the throwing ones would end the
// program on a symbolic-link loop, an overlong name or an unreadable folder.
std::vector<fs::path> fclib_files(const std::string& argument) {
  std::error_code error;
  const fs::file_status status = fs::status(argument, error);
  if (error) {
    throw Error("cannot use '" + argument + "' as an FCLIB file or folder: " + error.message());
  }
  if (fs::is_regular_file(status)) return {fs::path(argument)};
  if (!fs::is_directory(status)) {
    throw Error("'" + argument + "' is neither an FCLIB file nor a folder");
  }
  std::vector<fs::path> found;
  for (fs::directory_iterator entry(argument, error), end; !error && entry != end;
       entry.increment(error)) {
    if (entry->path().extension() == ".hdf5") found.push_back(entry->path());
  }
  if (error) throw Error("cannot read the folder '" + argument + "': " + error.message());
  if (found.empty()) throw Error("the folder '" + argument + "' holds no *.hdf5 file");
  std::sort(found.begin(), found.end());
  return found;
}

namespace {


struct Run {
  std::string name;
  SolverOptions options;
  Method method = Method::sor;
  bool warm = false;
};

}  // namespace

void fclib_bench(const std::vector<fs::path>& files, const FclibBenchOptions& options,
                 const std::function<void(const FclibBenchRow&)>& row) {
  std::vector<Run> runs(6);
  for (Run& run : runs) {
    run.options.criterion = Criterion::natural_residual;
    run.options.abs_tol = 0.0;
    run.options.rel_tol = options.tol;
    run.options.max_iterations = options.max_iterations;
    run.options.record_history = options.record_history;
  }
  runs[0].name = "SOR-AC";
  runs[1].name = "SOR-DS";
  runs[1].options.form = ProxForm::de_saxce;
  runs[2].name = "JOR";
  runs[2].method = Method::jor;
  runs[2].options.alpha = 0.5;
  runs[2].options.r_strategy = RFactorStrategy::global;
  runs[3].name = "APGD";
  runs[3].method = Method::apgd;
  runs[4].name = "Newton";
  runs[4].method = Method::newton;
  runs[5].name = "Newton-GMRES";
  runs[5].method = Method::newton;
  runs[5].options.newton.linear_solver = LinearSolver::gmres;
  // A Newton iteration is a linear solve: kFclibNewtonIterations of them are as much work as tens of
  // thousands of sweeps (GMRES's products with W cost a JOR iteration each).
  for (Run& run : runs) {
    if (run.method == Method::newton) {
      run.options.max_iterations = std::min(options.max_iterations, kFclibNewtonIterations);
    }
  }

  for (const fs::path& file : files) {
    const FclibInfo info = read_fclib_info(file);
    const LocalProblem problem = read_fclib_as_local(file);
    std::vector<Run> these = runs;
    if (info.guess) {
      Run warm = runs[0];
      warm.name = "SOR-AC warm";
      warm.warm = true;
      these.push_back(warm);
    }
    for (const Run& run : these) {
      std::vector<Vector3> lambda;
      if (run.warm) lambda = *info.guess;
      ContactSolver solver(run.method, run.options);
      const SolverResult result = solver.solve(problem, lambda);
      FclibBenchRow out;
      out.problem = file.stem().string();
      out.solver = run.name;
      out.contacts = problem.q.size();
      out.iterations = result.iterations;
      out.linear_iterations = result.linear_iterations;
      out.relative_residual = result.relative_residual();
      out.scaled_residual = result.scaled_residual();
      out.seconds = result.seconds;
      out.converged = result.converged;
      for (double h : result.history) out.history.push_back(h / result.norm_c);
      row(out);
    }
  }
}

std::string fclib_table_header(int max_iterations) {
  char line[256];
  std::snprintf(line, sizeof line, "%-44s %-12s %4s %9s %10s %10s %10s %s", "problem", "solver",
                "n", "iter", "|F|/|q|", "|F|/max", "time [ms]", "");
  std::string header = line;
  if (max_iterations > 0) {
    header += "caps: " + std::to_string(max_iterations) + " iterations, Newton " +
              std::to_string(std::min(max_iterations, kFclibNewtonIterations));
  }
  return header + '\n';
}

std::string fclib_table_line(const FclibBenchRow& row) {
  char line[512];
  std::snprintf(line, sizeof line, "%-44s %-12s %4zu %9d %10.2e %10.2e %10.2f %s\n",
                row.problem.c_str(), row.solver.c_str(), row.contacts, row.iterations,
                row.relative_residual, row.scaled_residual, 1e3 * row.seconds,
                row.converged ? "" : "NOT converged");
  return line;
}

}  // namespace grbd::contact
