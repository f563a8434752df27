// Chapter 8 demo: a model of the time per step of the parallel step, calibrated on the timings of
// ch08_bench_parallel, and its prediction for 10⁶ spheres on 64 to 512 cores.
//
// One averaged SOR sweep of a process with n = N/P bodies costs
//   t_sweep(P) = c_s n + S(n) (c_i + b/β) + τ (2 n_nb + 2 ⌈log₂ P⌉),
// the sweep over its own bodies (c_s per body), its split bodies S(n) (c_i each for their
// averaging, and b = 96 bytes through the network: 6 doubles to the owner and back), and the
// latency τ of the 2 n_nb messages of the reverse and forward exchanges with its m neighbours and
// of the allreduce of the verdict. For a cubic subdomain in a dense packing S(n) = 6 n^{2/3} (one
// layer of bodies on each face; n_nb = 26 neighbours). A step adds c_p n for its other stages.
//
// Calibration (ch08_bench_parallel, the settled FCC pile of 97 556 spheres, 100 sweeps a step,
// measured once by hand on two cores of one machine; chapter 8, "What it costs"): one process
// 2431.0 ms a step of which 2241.8 ms solve; two processes 1381.3 ms a step with 3363 split
// bodies. Hence c_s = 2241.8 ms / (100 · 97 556), c_p = (2431.0 − 2241.8) ms / 97 556, and c_i the
// time two processes take beyond half of one, per split body and sweep (on shared memory, where τ
// and β are small). τ and β of a cluster are not measured here: the demo takes 2 µs and 5 GB/s
// (InfiniBand) and, for comparison, 50 µs and 0.1 GB/s (gigabit Ethernet).
//
// The prediction is set against GRSFramework's published run of the reference chute: 10⁶ beads
// on 384 cores, 1000 SOR sweeps a step, 12 h for 9000 steps (about 4.8 s a step).
//
// Output in the data directory: cost_model.csv (P, predicted s per step with InfiniBand and with
// Ethernet, ideal scaling from one core, parallel efficiency) and values.txt (key = value, read by
// the book; chute_full_hours: the 12 000 steps of chute_full.toml on 384 cores with InfiniBand).
//
// Usage: `ch08_cost_model <data directory>`.

#include <cmath>
#include <cstdio>
#include <string>

#include "grbd_demo/demo.hpp"

namespace {

// The calibration: ch08_bench_parallel, 97 556 spheres, 100 sweeps a step.
constexpr double kSpheres = 97556.0;
constexpr double kSweeps = 100.0;
constexpr double kStepOne = 2431.0e-3;   // s, one process
constexpr double kSolveOne = 2241.8e-3;  // s, one process
constexpr double kStepTwo = 1381.3e-3;   // s, two processes
constexpr double kSplitTwo = 3363.0;     // split bodies, two processes

// The reference run (GRSFramework, the reference chute).
constexpr double kBodies = 1e6;
constexpr double kSweepsReference = 1000.0;
constexpr double kCoresReference = 384.0;
constexpr double kSecondsReference = 12.0 * 3600.0 / 9000.0;  // s a step

struct Network {
  double tau;   // latency [s]
  double beta;  // bandwidth [bytes/s]
};
constexpr Network kInfiniBand{2e-6, 5e9};
constexpr Network kEthernet{50e-6, 0.1e9};
constexpr double kBytesPerSplitBody = 96.0;
constexpr double kNeighbours = 26.0;

struct Constants {
  double c_s;  // s per body and sweep
  double c_p;  // s per body and step, besides the sweeps
  double c_i;  // s per split body and sweep
};

Constants calibrate() {
  Constants c{};
  c.c_s = kSolveOne / (kSweeps * kSpheres);
  c.c_p = (kStepOne - kSolveOne) / kSpheres;
  c.c_i = (kStepTwo - 0.5 * kStepOne) / (kSweeps * kSplitTwo);
  return c;
}

// Seconds a step of N bodies on P processes at K sweeps a step.
double step_seconds(const Constants& c, const Network& net, double N, double P, double K) {
  const double n = N / P;
  const double split = P > 1.0 ? 6.0 * std::pow(n, 2.0 / 3.0) : 0.0;
  const double messages = P > 1.0 ? 2.0 * kNeighbours + 2.0 * std::ceil(std::log2(P)) : 0.0;
  const double sweep =
      c.c_s * n + split * (c.c_i + kBytesPerSplitBody / net.beta) + net.tau * messages;
  return K * sweep + c.c_p * n;
}

void run(const std::string& dir) {
  const Constants c = calibrate();
  grbd::demo::OutputFile csv(dir + "/cost_model.csv");
  csv << "# P seconds_infiniband seconds_ethernet seconds_ideal efficiency_infiniband\n";
  const double one = step_seconds(c, kInfiniBand, kBodies, 1.0, kSweepsReference);
  for (double P = 16.0; P <= 4096.0; P *= std::sqrt(2.0)) {
    const double ib = step_seconds(c, kInfiniBand, kBodies, P, kSweepsReference);
    const double eth = step_seconds(c, kEthernet, kBodies, P, kSweepsReference);
    csv << P << ' ' << ib << ' ' << eth << ' ' << one / P << ' ' << one / (P * ib) << '\n';
  }
  csv.finish();

  grbd::demo::Values values;
  values.set("c_s", "%.3f", 1e6 * c.c_s);
  values.set("c_p", "%.2f", 1e6 * c.c_p);
  values.set("c_i", "%.3f", 1e6 * c.c_i);
  values.set("one_core_hours", "%.1f", one * 9000.0 / 3600.0);
  for (const int P : {64, 128, 256, 384, 512}) {
    const double p = P;
    const double ib = step_seconds(c, kInfiniBand, kBodies, p, kSweepsReference);
    const double eth = step_seconds(c, kEthernet, kBodies, p, kSweepsReference);
    const double n = kBodies / p;
    char name[16];
    std::snprintf(name, sizeof name, "p%d", P);
    const std::string k = name;
    values.set(k + ".bodies", "%.0f", n);
    values.set(k + ".split_percent", "%.0f", 100.0 * 6.0 * std::pow(n, 2.0 / 3.0) / n);
    values.set(k + ".ib", "%.2f", ib);
    values.set(k + ".eth", "%.2f", eth);
    values.set(k + ".efficiency", "%.0f", 100.0 * one / (p * ib));
    values.set(k + ".hours", "%.1f", ib * 9000.0 / 3600.0);
  }
  const double at_reference =
      step_seconds(c, kInfiniBand, kBodies, kCoresReference, kSweepsReference);
  values.set("reference_seconds", "%.1f", kSecondsReference);
  values.set("reference_ratio", "%.1f", kSecondsReference / at_reference);
  // chute_full.toml: 0.6 s behind the gate and 1.8 s of flow, 12 000 steps of 0.2 ms.
  values.set("chute_full_hours", "%.1f", at_reference * 12000.0 / 3600.0);
  values.write(dir + "/values.txt");
  std::printf(
      "ch08_cost_model: c_s = %.3f us per body-sweep, c_p = %.2f us per body-step, c_i = %.3f us "
      "per split body-sweep; 10^6 bodies, 1000 sweeps: %.2f s a step on 384 cores (InfiniBand), "
      "%.2f s (Ethernet); GRSFramework's run %.1f s a step\n",
      1e6 * c.c_s, 1e6 * c.c_p, 1e6 * c.c_i, at_reference,
      step_seconds(c, kEthernet, kBodies, kCoresReference, kSweepsReference), kSecondsReference);
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch08_cost_model", {"<data directory>"},
          "writes cost_model.csv and values.txt into the existing directory")) {
    return *exit_code;
  }
  try {
    run(argv[1]);
  } catch (...) {
    return grbd::demo::report_exception("ch08_cost_model", "nothing");
  }
  return 0;
}
