// Chapter 5 demo: a performance profile of SOR, APGD, Newton and the hybrid (SOR, then Newton
// where SOR stagnates) over every problem of the chapter, in the manner of Acary, Brémond and
// Huber (2018, after Dolan and Moré 2002).
//
// The problems: the three FCLIB problems of the data directory (local form, Newton with a sparse
// LU of J) and sphere packings of sphere_pile.hpp (body form, Newton with GMRES): FCC blocks of
// nx × ny × nz cells with friction μ, each the step from rest under gravity, solved from λ = 0,
// and the second step of two of them warm-started from the first one's percussions. Each solver
// runs to ‖F‖ ≤ 10⁻⁸ ‖c‖ or its cap; a problem it does not solve counts as failed.
//
// For problem p and solver s with time t_ps, the ratio r_ps = t_ps / min_s t_ps (∞ when s
// failed), and the profile ρ_s(τ) = (problems with r_ps ≤ τ) / (problems): ρ_s(1) is how often
// s is the fastest, ρ_s(τ → ∞) how often it solves the problem at all.
//
// Output, in the data directory:
//   runs.csv     problem, contacts, solver, converged, iterations, linear (Newton: GMRES
//                products or factorizations), hybrid_sweeps, ms, relative residual
//   profile.csv  tau, then ρ_s(τ) per solver, at every ratio that occurs
//   profile.txt  the runs as a table
//   values.txt   the numbers the chapter quotes (\demo{ch05_profile/values.txt#KEY}):
//                <problem>.<solver> = "iterations / ms" (Newton: "iterations (linear) / ms",
//                the hybrid: "sweeps + Newton iterations (linear) / ms", linear = LU
//                factorizations or GMRES products) or "—" (failed, with its residual),
//                <problem>.contacts, best1.<solver> (problems where s is fastest),
//                solved.<solver> (problems solved), problems, tol
//
// Usage: ch05_profile <data directory> <FCLIB folder>.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "grbd/contact/fclib.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/contact/warm_start.hpp"
#include "grbd_demo/demo.hpp"
#include "sphere_pile.hpp"

namespace {

using grbd::contact::ContactSolution;
using grbd::contact::Criterion;
using grbd::contact::Method;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

constexpr const char* kProgram = "ch05_profile";
constexpr double kTolerance = 1e-8;
/// Caps: a prox iteration costs one pass over the contacts, a Newton iteration up to 300 (GMRES)
/// or a factorization, so Newton gets fewer; every cap is far beyond what a solved problem needs.
constexpr int kProxIterations = 5000;
constexpr int kNewtonIterations = 100;
/// The hybrid's SOR phase at most (it hands over to Newton earlier where SOR stagnates).
constexpr int kHybridSweeps = 2000;

const std::vector<std::string> kSolvers = {"SOR", "APGD", "Newton", "Hybrid"};

SolverOptions options_for(const std::string& solver) {
  SolverOptions options;
  options.criterion = Criterion::natural_residual;
  options.abs_tol = 0.0;
  options.rel_tol = kTolerance;
  options.max_iterations = kProxIterations;
  if (solver == "Newton") options.max_iterations = kNewtonIterations;
  if (solver == "Hybrid") {
    options.max_iterations = 1 + kNewtonIterations;  // the SOR phase is the first iteration
    options.newton.hybrid_sweeps = kHybridSweeps;
  }
  return options;
}

Method method_of(const std::string& solver) {
  if (solver == "SOR") return Method::sor;
  if (solver == "APGD") return Method::apgd;
  return Method::newton;
}

struct Run {
  std::string problem;
  std::size_t contacts = 0;
  std::string solver;
  SolverResult result;
};

/// One problem, body or local form, with an optional initial guess.
struct Problem {
  std::string name;
  const grbd::contact::ContactProblem* body = nullptr;
  const grbd::contact::LocalProblem* local = nullptr;
  std::vector<grbd::Vector3> guess;
};

SolverResult solve(const Problem& p, const std::string& solver) {
  grbd::contact::ContactSolver contact_solver(method_of(solver), options_for(solver));
  if (p.local != nullptr) {
    std::vector<grbd::Vector3> lambda = p.guess;
    return contact_solver.solve(*p.local, lambda);
  }
  ContactSolution solution;
  solution.lambda = p.guess;
  return contact_solver.solve(*p.body, solution);
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<FCLIB folder>"},
          "writes runs.csv, profile.csv, profile.txt and values.txt")) {
    return *exit_code;
  }
  try {
    const std::filesystem::path dir = argv[1];
    const std::filesystem::path fclib = argv[2];
    // The outputs first: a file that cannot be written fails before the work.
    grbd::demo::OutputFile table(dir / "profile.txt");
    grbd::demo::OutputFile csv(dir / "runs.csv",
                               "problem,contacts,solver,converged,iterations,linear,"
                               "hybrid_sweeps,ms,relative_residual");
    std::vector<Problem> problems;

    // FCLIB, local form.
    const std::vector<std::pair<std::string, std::string>> files = {
        {"PerioBox-60", "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5"},
        {"Capsules-286", "Capsules-i125-1213.hdf5"},
        {"Spheres-356", "Spheres-i099-356-679.hdf5"}};
    std::vector<grbd::contact::LocalProblem> locals;
    locals.reserve(files.size());
    for (const auto& [name, file] : files) {
      locals.push_back(grbd::contact::read_fclib_as_local(fclib / file));
    }
    for (std::size_t k = 0; k < files.size(); ++k) {
      problems.push_back({files[k].first, nullptr, &locals[k], {}});
    }

    // Sphere packings, body form: (nx, ny, nz, μ), and a warm second step for two of them.
    struct Pile {
      const char* name;
      int nx, ny, nz;
      double mu;
      bool second_step;
    };
    const std::vector<Pile> piles = {
        {"block-8x8x1", 8, 8, 1, 0.5, true},    {"block-12x12x1", 12, 12, 1, 0.5, false},
        {"block-4x4x2-mu0.3", 4, 4, 2, 0.3, false}, {"block-8x8x2-mu0.1", 8, 8, 2, 0.1, false},
        {"block-6x6x2-mu1", 6, 6, 2, 1.0, false},   {"block-4x4x4", 4, 4, 4, 0.5, true},
        {"deep-8x8x4-mu0", 8, 8, 4, 0.0, false}};
    std::vector<grbd::demo::SpherePile> packings;
    packings.reserve(2 * piles.size());
    std::vector<std::vector<grbd::Vector3>> guesses;
    std::vector<std::string> names;
    for (const Pile& pile : piles) {
      packings.push_back(grbd::demo::sphere_pile(pile.nx, pile.ny, pile.nz, 1e-3, 2e-4, pile.mu));
      names.push_back(pile.name);
      guesses.emplace_back();
      if (pile.second_step) {
        // The second step: the first one solved (SOR to the tolerance), advanced, warm-started.
        grbd::demo::SpherePile next = packings.back();
        SolverOptions options = options_for("SOR");
        options.max_iterations = 100000;
        grbd::contact::WarmStart previous;
        grbd::demo::solve_and_advance(next, options, previous);
        std::vector<grbd::Vector3> guess;
        previous.initialize(next.problem.keys, guess);
        packings.push_back(std::move(next));
        names.push_back(std::string(pile.name) + "-warm");
        guesses.push_back(std::move(guess));
      }
    }
    for (std::size_t k = 0; k < packings.size(); ++k) {
      problems.push_back({names[k], &packings[k].problem, nullptr, guesses[k]});
    }

    std::vector<Run> runs;
    grbd::demo::Values values;
    char line[512];
    for (const Problem& p : problems) {
      const std::size_t contacts = p.local != nullptr ? p.local->q.size() : p.body->contacts.size();
      values.set(p.name + ".contacts", "%zu", contacts);
      for (const std::string& solver : kSolvers) {
        const SolverResult r = solve(p, solver);
        runs.push_back({p.name, contacts, solver, r});
        std::snprintf(line, sizeof line, "%-22s %5zu contacts  %-6s %s\n", p.name.c_str(),
                      contacts, solver.c_str(), grbd::contact::describe(r).c_str());
        table << line;
        std::cout << line;
        std::snprintf(line, sizeof line, "%s,%zu,%s,%d,%d,%d,%d,%.6g,%.6e\n", p.name.c_str(),
                      contacts, solver.c_str(), r.converged ? 1 : 0, r.iterations,
                      r.linear_iterations, r.hybrid_sweeps, 1e3 * r.seconds,
                      r.relative_residual());
        csv << line;
        // Milliseconds to three digits, whole ones from 100 on (no exponent in the table).
        const double ms = 1e3 * r.seconds;
        const char* const ms_format = ms < 100.0 ? "%.3g" : "%.0f";
        char ms_text[32];
        std::snprintf(ms_text, sizeof ms_text, ms_format, ms);
        if (r.converged && solver == "Hybrid") {
          // SOR sweeps + Newton iterations (the SOR phase is the first iteration), the linear
          // solver's work in parentheses.
          std::snprintf(line, sizeof line, "%d + %d (%d) / %s", r.hybrid_sweeps,
                        r.iterations - 1, r.linear_iterations, ms_text);
        } else if (r.converged && solver == "Newton") {
          std::snprintf(line, sizeof line, "%d (%d) / %s", r.iterations, r.linear_iterations,
                        ms_text);
        } else if (r.converged) {
          std::snprintf(line, sizeof line, "%d / %s", r.iterations, ms_text);
        } else {
          std::snprintf(line, sizeof line, "— (\\f$%s\\f$)",
                        grbd::demo::tex_power(r.relative_residual()).c_str());
        }
        values.set(p.name + "." + solver, "%s", line);
      }
    }
    table.finish();
    csv.finish();

    // The profile: per problem the best time, per run its ratio.
    const std::size_t S = kSolvers.size();
    const std::size_t P = problems.size();
    std::vector<double> ratio(P * S, std::numeric_limits<double>::infinity());
    std::vector<int> best(S, 0), solved(S, 0);
    for (std::size_t p = 0; p < P; ++p) {
      double fastest = std::numeric_limits<double>::infinity();
      for (std::size_t s = 0; s < S; ++s) {
        const SolverResult& r = runs[p * S + s].result;
        if (r.converged) fastest = std::min(fastest, r.seconds);
      }
      for (std::size_t s = 0; s < S; ++s) {
        const SolverResult& r = runs[p * S + s].result;
        if (!r.converged) continue;
        ratio[p * S + s] = r.seconds / fastest;
        ++solved[s];
        if (r.seconds == fastest) ++best[s];
      }
    }
    std::vector<double> taus;
    for (const double r : ratio) {
      if (std::isfinite(r)) taus.push_back(r);
    }
    std::sort(taus.begin(), taus.end());
    std::string header = "tau";
    for (const std::string& s : kSolvers) header += "," + s;
    grbd::demo::OutputFile profile(dir / "profile.csv", header);
    for (const double tau : taus) {
      std::snprintf(line, sizeof line, "%.6g", tau);
      profile << line;
      for (std::size_t s = 0; s < S; ++s) {
        int within = 0;
        for (std::size_t p = 0; p < P; ++p) within += ratio[p * S + s] <= tau ? 1 : 0;
        std::snprintf(line, sizeof line, ",%.6g", double(within) / double(P));
        profile << line;
      }
      profile << '\n';
    }
    profile.finish();
    for (std::size_t s = 0; s < S; ++s) {
      values.set("best1." + kSolvers[s], "%d", best[s]);
      values.set("solved." + kSolvers[s], "%d", solved[s]);
    }
    values.set("problems", "%zu", P);
    values.set("tol", "%s", grbd::demo::tex_power(kTolerance).c_str());
    values.set("cap.prox", "%d", kProxIterations);
    values.set("cap.newton", "%d", kNewtonIterations);
    values.set("cap.hybrid", "%d", kHybridSweeps);
    values.write(dir / "values.txt");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "Exercises 5.1-5.10");
  }
}
