// Chapter 5: the cost of the prox solvers on sphere packings (sphere_pile.hpp).
//
//   BM_sor_sweep/n   one Gauss–Seidel sweep (sor_sweep, Alart–Curnier) over all contacts of a
//                    pile of n × n × n FCC cells: 4n³ spheres, about 6 contacts per sphere.
//                    items_per_second is contact updates per second (CPU time of the thread);
//                    the counter ns_per_update is its inverse.
//   BM_sweep_de_saxce/n   the same with the De Saxcé update.
//   BM_solve/solver/warm  a whole solve of the second step of the frictional two-layer pile of
//                    ch05_convergence (8 × 8 × 1 cells, 256 spheres, μ = 0.5) to a natural-map
//                    residual of 10⁻⁶ ‖c‖ (SOR, JOR with α = 0.3 and the global r, APGD), cold
//                    (λ = 0) or warm (the percussions of the first step, by contact key); the
//                    counters report the iterations and the relative residual reached.
//
// Run: ch05_bench_sor [--benchmark_filter=...] (or the target run_ch05_bench_sor).

#include <benchmark/benchmark.h>

#include <cstdint>
#include <string>
#include <vector>

#include "grbd/contact/solver.hpp"
#include "grbd/contact/warm_start.hpp"
#include "sphere_pile.hpp"

namespace {

using grbd::Vector3;
using grbd::Vector6;
using grbd::contact::ContactSolution;
using grbd::contact::ProxForm;
using grbd::contact::RFactors;
using grbd::contact::RFactorStrategy;
using grbd::contact::SolverOptions;
using grbd::contact::SolverResult;

void sweep(benchmark::State& state, ProxForm form) {
  const int n = static_cast<int>(state.range(0));
  const grbd::demo::SpherePile pile = grbd::demo::sphere_pile(n, n, n);
  const auto& problem = pile.problem;
  const std::vector<RFactors> r =
      grbd::contact::r_factors(problem, RFactorStrategy::per_contact, 1.0);
  std::vector<Vector6> u = problem.u_free;
  std::vector<Vector3> lambda(problem.contacts.size(), Vector3::Zero());
  for (auto _ : state) {
    grbd::contact::sor_sweep(problem, r, form, u, lambda);
    benchmark::DoNotOptimize(lambda.data());
    benchmark::ClobberMemory();
  }
  const auto contacts = static_cast<std::int64_t>(problem.contacts.size());
  state.SetItemsProcessed(state.iterations() * contacts);
  state.counters["spheres"] = static_cast<double>(problem.M_inv.size());
  state.counters["contacts"] = static_cast<double>(contacts);
  // A rate of contacts·10⁻⁹ per iteration, inverted: nanoseconds per contact update.
  state.counters["ns_per_update"] =
      benchmark::Counter(1e-9 * static_cast<double>(contacts),
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_sor_sweep(benchmark::State& state) { sweep(state, ProxForm::alart_curnier); }
void BM_sweep_de_saxce(benchmark::State& state) { sweep(state, ProxForm::de_saxce); }

BENCHMARK(BM_sor_sweep)->Arg(6)->Arg(14)->Arg(29)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_sweep_de_saxce)->Arg(29)->Unit(benchmark::kMillisecond);

enum Solver : std::int64_t { kSor, kJor, kApgd };

void BM_solve(benchmark::State& state) {
  const auto solver = static_cast<Solver>(state.range(0));
  const bool warm = state.range(1) != 0;
  // First step from rest, then the second step, whose solve is timed.
  grbd::demo::SpherePile pile = grbd::demo::sphere_pile(8, 8, 1);
  SolverOptions options;
  options.criterion = grbd::contact::Criterion::natural_residual;
  options.abs_tol = 0.0;
  options.rel_tol = 1e-6;
  options.max_iterations = 20000;
  grbd::contact::WarmStart previous;
  grbd::demo::solve_and_advance(pile, options, previous);
  if (solver == kJor) {
    options.alpha = 0.3;
    options.r_strategy = RFactorStrategy::global;
  }
  SolverResult result;
  for (auto _ : state) {
    ContactSolution solution;
    if (warm) previous.initialize(pile.problem.keys, solution.lambda);
    switch (solver) {
      case kSor: result = grbd::contact::solve_sor(pile.problem, solution, options); break;
      case kJor: result = grbd::contact::solve_jor(pile.problem, solution, options); break;
      case kApgd: result = grbd::contact::solve_apgd(pile.problem, solution, options); break;
    }
    benchmark::DoNotOptimize(solution.lambda.data());
  }
  state.SetLabel(std::string(warm ? "warm " : "cold ") + result.solver);
  state.counters["iterations"] = result.iterations;
  state.counters["converged"] = result.converged ? 1.0 : 0.0;
  state.counters["relative_residual"] = result.relative_residual();
  state.counters["contacts"] = static_cast<double>(pile.problem.contacts.size());
}

BENCHMARK(BM_solve)
    ->ArgsProduct({{kSor, kJor, kApgd}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
