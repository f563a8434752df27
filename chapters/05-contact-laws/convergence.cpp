// Chapter 5 demo: how fast JOR, SOR, APGD and Newton converge on a granular contact problem, the
// effect of the relaxation α, and what a warm start saves.
//
// Two problems of glass spheres of radius 1 mm in FCC blocks (sphere_pile.hpp), each the step
// h = 0.2 ms under gravity:
//   frictional  8 × 8 × 1 cells (256 spheres, two layers), μ = 0.5: the step from rest, then,
//               after one crude explicit step with its solution (advance()), the second step's
//               problem, solved cold (λ = 0) and warm (the first step's percussions by contact
//               key, WarmStart);
//   deep        8 × 8 × 4 cells (1024 spheres, eight layers), frictionless, from rest, cold;
//   hard        the same block with μ = 0.5, where the prox solvers stall (SOR, APGD, Newton).
//
// Output, in the data directory (one row per iteration k; an empty field once a solver stopped):
//   convergence.csv  k, SOR, JOR, APGD, Newton, then the same _warm: the natural-map residual
//                    ‖F‖/‖c‖ after iteration k on the frictional problem
//   deep.csv         k, SOR, JOR, APGD, Newton on the deep frictionless pile
//   hard.csv         k, SOR, APGD, Newton on the deep frictional pile
//   alpha.csv        k, then ‖F‖/‖c‖ of SOR for α = 0.3, 0.6, 1.0, 1.3, 1.6, 1.9 (frictional, cold)
//   convergence.txt  a table: solver, start, iterations to ‖F‖ ≤ 10⁻⁶ ‖c‖, residuals, time
//   values.txt       the numbers the chapter quotes, key = value lines read by the book at build
//                    time (\demo{ch05_convergence/values.txt#KEY} in chapter.md):
//                    {frictional,deep}.{spheres,contacts}; iterations to the tolerance,
//                    "> 3000 (residual)" where a solver stopped at the cap, under
//                    {cold,warm,deep}.{SOR,JOR,APGD,Newton}, hard.{SOR,APGD,Newton} and
//                    alpha<α>, with .ms the times; Newton's .linear (GMRES products) and
//                    hard.Newton.fallbacks; the warm start's savings cold/warm as factors,
//                    saving.{SOR,APGD}; deep.SOR_over_APGD
//
// Usage: ch05_convergence <data directory>.

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "grbd/contact/solver.hpp"
#include "grbd/contact/warm_start.hpp"
#include "grbd_demo/demo.hpp"
#include "sphere_pile.hpp"

namespace {

using grbd::contact::ContactProblem;
using grbd::contact::ContactSolution;
using grbd::contact::Criterion;
using grbd::contact::RFactorStrategy;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

constexpr const char* kProgram = "ch05_convergence";
constexpr int kMaxIterations = 3000;
constexpr int kNewtonMaxIterations = 100;
constexpr int kHardNewtonIterations = 30;
constexpr double kTolerance = 1e-6;

SolverOptions options_for(const std::string& solver) {
  SolverOptions options;
  options.criterion = Criterion::natural_residual;
  options.abs_tol = 0.0;
  options.rel_tol = kTolerance;
  options.max_iterations = kMaxIterations;
  options.record_history = true;
  if (solver == "Newton") {
    // A Newton iteration costs up to max_linear_iterations products with G (GMRES in body form):
    // 100 iterations are as much work as thousands of sweeps.
    options.max_iterations = kNewtonMaxIterations;
  }
  if (solver == "JOR") {
    // Each sphere has up to 12 contacts; Jacobi with α/G_ii overshoots, so one global r.
    options.r_strategy = RFactorStrategy::global;
    options.alpha = 0.3;
  }
  return options;
}

/// Iterations to the tolerance as the chapter's tables show them: "618", or "> 3000 (2.9e-3)" as
/// TeX where the solver stopped at the cap with that relative residual.
std::string iterations_text(const SolverResult& r) {
  char text[96];
  if (r.converged) {
    std::snprintf(text, sizeof text, "%d", r.iterations);
  } else {
    std::snprintf(text, sizeof text, "> %d (\\f$%s\\f$)", r.iterations,
                  grbd::demo::tex_power(r.relative_residual()).c_str());
  }
  return text;
}

SolverResult solve(const std::string& solver, const ContactProblem& problem,
                   ContactSolution& solution, const SolverOptions& options) {
  if (solver == "SOR") return grbd::contact::solve_sor(problem, solution, options);
  if (solver == "JOR") return grbd::contact::solve_jor(problem, solution, options);
  if (solver == "Newton") return grbd::contact::solve_newton(problem, solution, options);
  return grbd::contact::solve_apgd(problem, solution, options);
}

/// Writes histories as columns; a history that ended leaves its field empty.
void write_columns(const std::filesystem::path& path, const std::vector<std::string>& names,
                   const std::vector<SolverResult>& results) {
  std::string header = "k";
  for (const std::string& name : names) header += ',' + name;
  grbd::demo::OutputFile out(path, header);
  std::size_t rows = 0;
  for (const SolverResult& r : results) rows = std::max(rows, r.history.size());
  char field[32];
  for (std::size_t k = 0; k < rows; ++k) {
    out << k + 1;
    for (const SolverResult& r : results) {
      out << ',';
      if (k < r.history.size()) {
        std::snprintf(field, sizeof field, "%.6e", r.history[k] / r.norm_c);
        out << field;
      }
    }
    out << '\n';
  }
  out.finish();
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>"},
          "writes convergence.csv, deep.csv, alpha.csv, convergence.txt and values.txt")) {
    return *exit_code;
  }
  try {
    const std::filesystem::path dir = argv[1];
    grbd::demo::SpherePile pile = grbd::demo::sphere_pile(8, 8, 1);
    grbd::contact::WarmStart previous;
    const SolverResult first_result =
        grbd::demo::solve_and_advance(pile, options_for("SOR"), previous);

    grbd::demo::OutputFile table(dir / "convergence.txt");
    char line[256];
    std::snprintf(line, sizeof line, "%zu spheres, %zu contacts; first step: %s\n",
                  pile.problem.M_inv.size(), pile.problem.contacts.size(),
                  grbd::contact::describe(first_result).c_str());
    table << line;
    std::cout << line;

    grbd::demo::Values values;
    values.set("frictional.spheres", "%zu", pile.problem.M_inv.size());
    values.set("frictional.contacts", "%zu", pile.problem.contacts.size());
    std::vector<std::string> names;
    std::vector<SolverResult> results;
    for (const bool warm : {false, true}) {
      for (const std::string solver : {"SOR", "JOR", "APGD", "Newton"}) {
        ContactSolution solution;
        std::size_t found = 0;
        if (warm) found = previous.initialize(pile.problem.keys, solution.lambda);
        const SolverResult result = solve(solver, pile.problem, solution, options_for(solver));
        std::snprintf(line, sizeof line, "%-5s %-4s (%zu of %zu contacts warm): %s\n",
                      solver.c_str(), warm ? "warm" : "cold", found, pile.problem.contacts.size(),
                      grbd::contact::describe(result).c_str());
        table << line;
        std::cout << line;
        names.push_back(warm ? solver + "_warm" : solver);
        results.push_back(result);
        values.set(std::string(warm ? "warm." : "cold.") + solver, "%s",
                   iterations_text(result).c_str());
      }
    }
    write_columns(dir / "convergence.csv", names, results);
    // results: SOR, JOR, APGD, Newton cold, then warm.
    values.set("saving.SOR", "%.0f", double(results[0].iterations) / results[4].iterations);
    values.set("saving.APGD", "%.0f", double(results[2].iterations) / results[6].iterations);
    for (std::size_t k = 0; k < results.size(); ++k) {
      values.set((k < 4 ? "cold." : "warm.") + names[k % 4] + ".ms", "%.3g",
                 1e3 * results[k].seconds);
    }
    values.set("cold.Newton.linear", "%d", results[3].linear_iterations);
    values.set("warm.Newton.linear", "%d", results[7].linear_iterations);

    const grbd::demo::SpherePile deep = grbd::demo::sphere_pile(8, 8, 4, 1e-3, 2e-4, 0.0);
    std::vector<SolverResult> deep_results;
    for (const std::string solver : {"SOR", "JOR", "APGD", "Newton"}) {
      ContactSolution solution;
      const SolverResult result = solve(solver, deep.problem, solution, options_for(solver));
      std::snprintf(line, sizeof line, "deep frictionless pile (%zu spheres, %zu contacts): %s\n",
                    deep.problem.M_inv.size(), deep.problem.contacts.size(),
                    grbd::contact::describe(result).c_str());
      table << line;
      std::cout << line;
      deep_results.push_back(result);
      values.set("deep." + std::string(solver), "%s", iterations_text(result).c_str());
      values.set("deep." + std::string(solver) + ".ms", "%.3g", 1e3 * result.seconds);
    }
    values.set("deep.Newton.linear", "%d", deep_results[3].linear_iterations);
    values.set("deep.spheres", "%zu", deep.problem.M_inv.size());
    values.set("deep.contacts", "%zu", deep.problem.contacts.size());
    values.set("deep.SOR_over_APGD", "%.0f",
               double(deep_results[0].iterations) / deep_results[2].iterations);
    write_columns(dir / "deep.csv", {"SOR", "JOR", "APGD", "Newton"}, deep_results);

    // The hard case: the deep block with friction, where the prox solvers stall.
    const grbd::demo::SpherePile hard = grbd::demo::sphere_pile(8, 8, 4, 1e-3, 2e-4, 0.5);
    std::vector<SolverResult> hard_results;
    for (const std::string solver : {"SOR", "APGD", "Newton"}) {
      ContactSolution solution;
      SolverOptions options = options_for(solver);
      // Each Newton iteration here costs GMRES's full 300 products: 30 show where it stalls.
      if (solver == "Newton") options.max_iterations = kHardNewtonIterations;
      const SolverResult result = solve(solver, hard.problem, solution, options);
      std::snprintf(line, sizeof line, "deep frictional pile (%zu spheres, %zu contacts): %s\n",
                    hard.problem.M_inv.size(), hard.problem.contacts.size(),
                    grbd::contact::describe(result).c_str());
      table << line;
      std::cout << line;
      hard_results.push_back(result);
      values.set("hard." + std::string(solver), "%s", iterations_text(result).c_str());
      values.set("hard." + std::string(solver) + ".ms", "%.3g", 1e3 * result.seconds);
    }
    values.set("hard.Newton.linear", "%d", hard_results[2].linear_iterations);
    values.set("hard.Newton.fallbacks", "%d", hard_results[2].fallbacks);
    write_columns(dir / "hard.csv", {"SOR", "APGD", "Newton"}, hard_results);

    std::vector<std::string> alpha_names;
    std::vector<SolverResult> alpha_results;
    for (const double alpha : {0.3, 0.6, 1.0, 1.3, 1.6, 1.9}) {
      SolverOptions options = options_for("SOR");
      options.alpha = alpha;
      ContactSolution solution;
      const SolverResult result = grbd::contact::solve_sor(pile.problem, solution, options);
      std::snprintf(line, sizeof line, "SOR alpha = %.1f: %s\n", alpha,
                    grbd::contact::describe(result).c_str());
      table << line;
      std::cout << line;
      std::snprintf(line, sizeof line, "alpha=%.1f", alpha);
      alpha_names.emplace_back(line);
      std::snprintf(line, sizeof line, "alpha%.1f", alpha);
      values.set(line, "%s", iterations_text(result).c_str());
      alpha_results.push_back(result);
    }
    write_columns(dir / "alpha.csv", alpha_names, alpha_results);
    table.finish();
    values.write(dir / "values.txt");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "Exercises 5.1-5.8");
  }
}
