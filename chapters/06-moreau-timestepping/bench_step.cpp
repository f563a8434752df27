// Chapter 6: the cost of one Moreau step of a settled sphere pile (pile.hpp), by stage.
//
//   BM_hooks/n  the solve of the same pile without solver hooks, with a velocity hook and with an
//               after_iteration hook that do nothing: velocity_hook_over_none and
//               iteration_hook_over_none, the solve times against the one without, same run.
//   BM_skin/n   detection with and without a candidate list (skin r/5), same pile, same run:
//               detection_skin_over_none, step_skin_over_none.
//   BM_add/N    assembling N spheres: BodySystem::add (id check, validation) and
//               CollisionWorld::add (the supported-pair check, O(1) per collider); seconds for N.
//   BM_step/n   one step of the pile of n × n × n FCC cells (4n³ spheres, ≈ 6 contacts per
//               sphere) at a fixed 100 SOR iterations with warm start. Counters:
//               ns_per_body     wall time of a step per sphere
//               detection, assembly, solve, update, midpoint   the stages, ms per step
//               sweeps_100      100 bare sor_sweep() calls on each timed step's problem from the
//                               warm start its solve began with, ms per step, timed in the same
//                               run: the floor a step cannot go below
//               ns_per_update   a contact update in those sweeps
//               body_form_over_compact   chapter 5's body-form sweep over the last problem
//                               divided by the compact sweep, same state, same run
//               step_over_sweeps   the steps divided by their 100 sweeps (the target is 1.05)
//               solve_over_sweeps  the solver's share of it: its passes besides the sweeps
//               allocs_per_step    heap allocations (operator new) during the timed steps
//               bytes_per_body     heap in use per sphere after the steps (mallinfo2)
//
// Run: ch06_bench_step [--benchmark_filter=...] (or the target run_ch06_bench_step);
// GRBD_BENCH_MILLION=1 ch06_bench_step --benchmark_filter=BM_step/63 adds the 10⁶-sphere step.

#include <benchmark/benchmark.h>
#include <malloc.h>

#include <chrono>
#include <memory>
#include <cstdlib>
#include <span>
#include <string_view>
#include <type_traits>
#include <vector>

#include "grbd/collision/world.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/timestep/stepper.hpp"
#include "grbd_demo/allocation_counter.hpp"
#include "pile.hpp"

namespace {

using namespace grbd;

double heap_in_use() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd);
}

/// 100 bare sweeps over `problem` (the compact problem of the step just taken, or its body form)
/// from the warm start its solve began with, `before` looked up by the step's keys, and the
/// velocities that go with it; seconds.
template <class Problem>
double hundred_sweeps(const Problem& problem, const contact::CompactProblem& compact,
                      const timestep::WarmStartTable& before,
                      std::span<const timestep::ContactKey> keys) {
  std::vector<Vector3> lambda(compact.contacts.size());
  before.initialize(keys, lambda);
  std::vector<contact::RFactors> r(compact.contacts.size());
  for (std::size_t i = 0; i < r.size(); ++i) {
    r[i] = contact::r_factors(contact::delassus_block(compact.contacts[i], compact.M_inv), 1.0);
  }
  std::vector<Vector6> u;  // u_free + M⁻¹ W Λ₀
  if constexpr (std::is_same_v<Problem, contact::CompactProblem>) {
    contact::velocities_from_percussions(problem, lambda, u);
  } else {
    u = contact::velocities_from_percussions(problem, lambda);
  }
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < 100; ++k) {
    contact::sor_sweep(problem, r, contact::ProxForm::alart_curnier, u, lambda);
  }
  benchmark::DoNotOptimize(lambda.data());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void BM_step(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double heap_before = heap_in_use();
  timestep::BodySystem system;
  timestep::StaticGeometry statics;
  demo::fcc_pile(system, statics, n, n, n);
  const timestep::MaterialTable materials = demo::glass_materials();
  timestep::StepSettings settings;
  settings.dt = 2e-4;
  settings.solver.min_iterations = 100;
  settings.solver.max_iterations = 100;
  timestep::MoreauStepper stepper(system, statics, materials, settings);
  for (int warm = 0; warm < 3; ++warm) stepper.step();  // buffers grow, warm starts fill

  // Each timed step, and beside it its floor: 100 bare sweeps over the same problem from the
  // same warm start (the percussions of the step before, looked up by key), timed after the
  // step. The copy of the warm starts and the floor's buffers are outside the step's timing
  // and its allocation count.
  timestep::StepTimes sum;
  double sweeps = 0.0;
  double contact_updates = 0.0;
  std::size_t contacts = 0;
  long allocations = 0;
  double bytes = 0.0;  // heap in use after a step, the copy of the warm starts not counted
  for (auto _ : state) {
    const double heap_at_copy = heap_in_use();
    const timestep::WarmStartTable before = stepper.warm_starts();
    const double copy = heap_in_use() - heap_at_copy;
    const long allocations_before = demo::allocations();
    const timestep::StepReport r = stepper.step();
    allocations += demo::allocations() - allocations_before;
    bytes = heap_in_use() - heap_before - copy;
    sum.midpoint += r.seconds.midpoint;
    sum.detection += r.seconds.detection;
    sum.assembly += r.seconds.assembly;
    sum.solve += r.seconds.solve;
    sum.update += r.seconds.update;
    sum.total += r.seconds.total;
    contacts = r.contacts;
    sweeps += hundred_sweeps(stepper.problem(), stepper.problem(), before, stepper.keys());
    contact_updates += 100.0 * static_cast<double>(r.contacts);
  }
  const double steps = static_cast<double>(state.iterations());

  // Chapter 5's sweep over the problem of one more step in body form (two 6 × 3 Jacobians per
  // contact, contact::body_form), beside the compact sweep once more, from the same state.
  const timestep::WarmStartTable before = stepper.warm_starts();
  stepper.step();
  const contact::CompactProblem& problem = stepper.problem();
  std::vector<Matrix3> A_IK(system.size());
  for (std::size_t i = 0; i < A_IK.size(); ++i) {
    A_IK[i] = kinematics::rotation_matrix(kinematics::orientation(system.states()[i].q));
  }
  const contact::ContactProblem body = contact::body_form(problem, system.M_inv(), A_IK);
  const double compact_once = hundred_sweeps(problem, problem, before, stepper.keys());
  const double body_once = hundred_sweeps(body, problem, before, stepper.keys());

  const auto N = static_cast<double>(system.size());
  state.counters["spheres"] = N;
  state.counters["contacts"] = static_cast<double>(contacts);
  state.counters["ns_per_body"] = 1e9 * sum.total / steps / N;
  state.counters["midpoint_ms"] = 1e3 * sum.midpoint / steps;
  state.counters["detection_ms"] = 1e3 * sum.detection / steps;
  state.counters["assembly_ms"] = 1e3 * sum.assembly / steps;
  state.counters["solve_ms"] = 1e3 * sum.solve / steps;
  state.counters["update_ms"] = 1e3 * sum.update / steps;
  state.counters["sweeps_100_ms"] = 1e3 * sweeps / steps;
  state.counters["ns_per_update"] = 1e9 * sweeps / contact_updates;
  state.counters["body_form_over_compact"] = body_once / compact_once;
  state.counters["step_over_sweeps"] = sum.total / sweeps;
  state.counters["solve_over_sweeps"] = sum.solve / sweeps;
  state.counters["allocs_per_step"] = static_cast<double>(allocations) / steps;
  state.counters["bytes_per_body"] = bytes / N;
}

// A pile of n × n × n FCC cells with its own stepper (Δt = 2·10⁻⁴ s, exactly 100 SOR iterations a
// step), stepped three times so that its buffers and warm starts are in place: the copies that
// BM_hooks and BM_skin step in turn.
struct SteppedPile {
  timestep::BodySystem system;
  timestep::StaticGeometry statics;
  timestep::MaterialTable materials = demo::glass_materials();
  std::unique_ptr<timestep::MoreauStepper> stepper;
};

std::unique_ptr<SteppedPile> stepped_pile(int n, double skin, timestep::StepHooks hooks = {}) {
  auto pile = std::make_unique<SteppedPile>();
  demo::fcc_pile(pile->system, pile->statics, n, n, n);
  timestep::StepSettings settings;
  settings.dt = 2e-4;
  settings.solver.min_iterations = 100;
  settings.solver.max_iterations = 100;
  settings.skin = skin;
  pile->stepper = std::make_unique<timestep::MoreauStepper>(pile->system, pile->statics,
                                                            pile->materials, settings, hooks);
  for (int warm = 0; warm < 3; ++warm) pile->stepper->step();
  return pile;
}

// The cost of the solver's hooks: three copies of the pile stepped in turn, one without hooks,
// one with a velocities_between_sweeps hook and one with an after_iteration hook, both doing
// nothing; solve time of each against the one without, same run, same states.
void BM_hooks(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<std::unique_ptr<SteppedPile>> piles;
  for (int kind = 0; kind < 3; ++kind) {
    timestep::StepHooks hooks;
    if (kind == 1) hooks.solver.velocities_between_sweeps = [](int, std::span<Vector6>) {};
    if (kind == 2) {
      hooks.solver.after_iteration = [](int, std::span<Vector3>, std::span<Vector6>) {};
    }
    piles.push_back(stepped_pile(n, 0.0, hooks));
  }
  double solve[3] = {0.0, 0.0, 0.0};
  for (auto _ : state) {
    for (int kind = 0; kind < 3; ++kind) solve[kind] += piles[kind]->stepper->step().seconds.solve;
  }
  state.counters["velocity_hook_over_none"] = solve[1] / solve[0];
  state.counters["iteration_hook_over_none"] = solve[2] / solve[0];
}

// The candidate list: two copies of the pile stepped in turn, one detecting from scratch at every
// step, one with a skin of a fifth of the radius (StepSettings::skin); the detection stage of each
// and their ratio, same run, same states (the lists give the same contacts, bit for bit).
void BM_skin(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<std::unique_ptr<SteppedPile>> piles;
  for (const double skin : {0.0, 0.2e-3}) piles.push_back(stepped_pile(n, skin));
  double detection[2] = {0.0, 0.0};
  double total[2] = {0.0, 0.0};
  for (auto _ : state) {
    for (int kind = 0; kind < 2; ++kind) {
      const timestep::StepReport report = piles[kind]->stepper->step();
      detection[kind] += report.seconds.detection;
      total[kind] += report.seconds.total;
    }
  }
  const double steps = static_cast<double>(state.iterations());
  state.counters["detection_ms"] = 1e3 * detection[0] / steps;
  state.counters["detection_skin_ms"] = 1e3 * detection[1] / steps;
  state.counters["detection_skin_over_none"] = detection[1] / detection[0];
  state.counters["step_skin_over_none"] = total[1] / total[0];
}

void BM_add(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  double system_seconds = 0.0;
  double world_seconds = 0.0;
  for (auto _ : state) {
    timestep::BodySystem system;
    collision::CollisionWorld world;
    system.reserve(n);
    world.reserve(n + 1);
    world.add({collision::HalfSpace{}, collision::kStatic, Vector3::Zero(), Matrix3::Identity()});
    timestep::BodyRecord spec;
    spec.state.q << 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0;
    spec.state.u.setZero();
    spec.inertia = {1e-5, Vector3::Constant(4e-12)};
    spec.shape = collision::Sphere{1e-3};
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < n; ++i) {
      spec.id = i;
      spec.state.q.x() = 2e-3 * static_cast<double>(i);
      system.add(spec);
    }
    const auto t1 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < n; ++i) {
      world.add({collision::Sphere{1e-3}, static_cast<collision::BodyIndex>(i), Vector3::Zero(),
                 Matrix3::Identity()});
    }
    const auto t2 = std::chrono::steady_clock::now();
    system_seconds += std::chrono::duration<double>(t1 - t0).count();
    world_seconds += std::chrono::duration<double>(t2 - t1).count();
    benchmark::DoNotOptimize(system.size() + world.colliders().size());
  }
  const double runs = static_cast<double>(state.iterations());
  state.counters["body_system_s"] = system_seconds / runs;
  state.counters["collision_world_s"] = world_seconds / runs;
}

BENCHMARK(BM_add)->Arg(80000)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_step)->Arg(6)->Arg(14)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_step)->Arg(29)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_skin)->Arg(14)->Arg(29)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);
BENCHMARK(BM_hooks)->Arg(14)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

// One step of the 63 × 63 × 63 pile, 1 000 188 spheres (about 10 GB with the body-form copy the
// side-by-side comparison builds, and minutes to run): registered only when the environment
// sets GRBD_BENCH_MILLION=1.
const bool kMillion = [] {
  const char* on = std::getenv("GRBD_BENCH_MILLION");
  if (on != nullptr && std::string_view(on) == "1") {
    benchmark::RegisterBenchmark("BM_step/63", BM_step)
        ->Arg(63)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(1);
  }
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
