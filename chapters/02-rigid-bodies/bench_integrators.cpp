// Chapter 2: the cost of one time step of one rigid body with each integrator of integrators.hpp,
// and of the plain kinematic exponential-map update of chapter 1 for reference.
//
// Every iteration steps N = 1000 bodies with different masses, principal moments, states and
// loads (gravity and a torque), each from the same start state, so that the work per iteration
// does not change as the benchmark runs (no energy drift, no overflow). items_per_second is
// body-steps per second; the counter time_per_body_step is its inverse.
//
// Run: ch02_bench_integrators [--benchmark_filter=...] (or the target run_ch02_bench_integrators).

#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "grbd/body/integrators.hpp"
#include "grbd/body/rigid_body.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"

namespace {

using grbd::Vector3;
using grbd::Vector4;
using grbd::body::Integrator;
using grbd::body::Loads;
using grbd::body::RigidBody;
using grbd::body::State;

constexpr int kBodies = 1000;
constexpr double kStepSize = 1e-3;  // [s]; h|ω|/2 ≥ 1e-4 for most bodies: the general exp branch

/// N bodies with seeded random data: m ∈ [0.5, 5), Θ_i ∈ [0.05, 2), unit p, |v| and |ω| of a
/// few units, gravity plus a random torque.
struct Ensemble {
  std::vector<RigidBody> bodies;
  std::vector<State> start;
  std::vector<Loads> loads;
  std::vector<State> end;

  Ensemble() {
    std::mt19937_64 engine(20260202);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::normal_distribution<double> normal;
    const auto vector3 = [&](double scale) {
      return Vector3(scale * unit(engine), scale * unit(engine), scale * unit(engine));
    };
    for (int i = 0; i < kBodies; ++i) {
      const RigidBody body{2.75 + 2.25 * unit(engine),
                           Vector3(1.025 + 0.975 * unit(engine), 1.025 + 0.975 * unit(engine),
                                   1.025 + 0.975 * unit(engine))};
      const Vector4 p(normal(engine), normal(engine), normal(engine), normal(engine));
      bodies.push_back(body);
      start.push_back({grbd::kinematics::make_q(
                           vector3(10.0), grbd::kinematics::Quaternion(Vector4(p.normalized()))),
                       grbd::kinematics::make_u(vector3(3.0), vector3(5.0))});
      loads.push_back({body.m * Vector3(0.0, 0.0, -9.81), vector3(0.5)});
    }
    end = start;
  }
};

void report(benchmark::State& state) {
  const auto body_steps = static_cast<std::int64_t>(state.iterations()) * kBodies;
  state.SetItemsProcessed(body_steps);
  // kIsRate divides by the elapsed seconds, kInvert turns the rate into seconds per body-step
  // (printed with an SI prefix, e.g. 57.3ns).
  state.counters["time_per_body_step"] = benchmark::Counter(
      static_cast<double>(body_steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_integrator(benchmark::State& state, Integrator scheme) {
  Ensemble ensemble;
  for (auto _ : state) {
    for (int i = 0; i < kBodies; ++i) {
      ensemble.end[i] = grbd::body::step(ensemble.bodies[i], ensemble.start[i], ensemble.loads[i],
                                         kStepSize, scheme);
    }
    benchmark::DoNotOptimize(ensemble.end.data());
    benchmark::ClobberMemory();
  }
  report(state);
}

/// The kinematic update of chapter 1 alone, q⁺ = (r + h v, p exp_S3(h ω/2)): what every scheme
/// but (c) and (d) pays for its orientation.
void BM_kinematic_exp_map(benchmark::State& state) {
  Ensemble ensemble;
  for (auto _ : state) {
    for (int i = 0; i < kBodies; ++i) {
      ensemble.end[i].q =
          grbd::kinematics::exp_map_step(ensemble.start[i].q, ensemble.start[i].u, kStepSize);
    }
    benchmark::DoNotOptimize(ensemble.end.data());
    benchmark::ClobberMemory();
  }
  report(state);
}

}  // namespace

BENCHMARK(BM_kinematic_exp_map);
BENCHMARK_CAPTURE(BM_integrator, explicit_exp_map, Integrator::explicit_exp_map);
BENCHMARK_CAPTURE(BM_integrator, symplectic_exp_map, Integrator::symplectic_exp_map);
BENCHMARK_CAPTURE(BM_integrator, explicit_euler_normalized, Integrator::explicit_euler_normalized);
BENCHMARK_CAPTURE(BM_integrator, lie_poisson, Integrator::lie_poisson);
BENCHMARK_CAPTURE(BM_integrator, implicit_gyroscopic, Integrator::implicit_gyroscopic);

BENCHMARK_MAIN();
