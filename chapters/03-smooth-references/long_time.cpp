// Chapter 3 demo: long-time behaviour, drift against bounded oscillation.
//
// The torque-free asymmetric body of tumbling_body.hpp (K_Theta = (2, 3, 4) kg m²), spun up to
// |K_omega(0)| = 2π · 20 rad/s along (1, 1, 1): one turn takes P = 2π/|ω| = 0.05 s. It is
// integrated for T = 500 s = 10⁴ turns
//
//   - by three integrators of chapter 2 with h = 1 ms (50 steps per turn, h|ω| = 0.126):
//     explicit_exp_map (whose angular velocities, hence energy and |L|, are exactly those of
//     symplectic_exp_map and explicit_euler_normalized), lie_poisson and implicit_gyroscopic;
//   - by CVODE, BDF (|p| projected) and Adams (not projected: CVODE projects only with BDF), at
//     the moderate tolerance rtol = 1e-6, atol = 1e-9.
//
// explicit_exp_map gains energy in every step; its run is stopped once the energy has grown
// a thousandfold.
//
// For every method the file `<method>.csv` is written to the data directory, one row per output
// window. The windows last at least 4 turns, longer than the period of ω (3.2 turns), so that the
// maximum over a window is the envelope of the error's oscillation, and grow geometrically (each
// ends 2 % later than the one before), so that a logarithmic time axis gets evenly spaced rows; the
// fixed-step schemes are sampled after every step, CVODE's dense output every 5 ms. The columns:
//
//   t_s                       end of the window [s]
//   turns                     t / P
//   energy_rel_error          max over the window of |E − E(0)| / E(0) [-]
//   momentum_rel_error        max over the window of ||L| − |L(0)|| / |L(0)| [-]
//   energy_signed_rel_error   (E − E(0)) / E(0) at the end of the window [-]
//   momentum_signed_rel_error (|L| − |L(0)|) / |L(0)| at the end of the window [-]
//
// The final relative errors (and the run times) are printed in one summary line. The numbers the
// chapter quotes are written to `values.txt` (key = value lines read by the book at build time:
// \demo{ch03_long_time/values.txt#KEY} in chapter.md):
//
//   <method>.energy, .momentum   signed relative errors of E and |L| at the end
//   <method>.max_energy          the largest relative energy error
//   <method>.first_energy        the largest relative energy error of the first window (4 turns)
//   <method>.steps, .seconds     steps, and the run time [s]
//   explicit_exp_map.doubled, .stopped, .momentum_end
//                                turns when the energy had doubled and when the run stopped; the
//                                relative error of |L| then
//   implicit_gyroscopic.halved   turns until E ≤ E(0)/2
//   implicit_gyroscopic.final_energy, .steady_spin
//                                E/E(0) at the end, and a bound (at least 1e-15) on
//                                |E − L²/(2Θ3)|/E, the distance from a steady spin about axis 3
//   cvode_{bdf,adams}.crossing   turns after which their energy error exceeds lie_poisson's largest
//   cvode_{bdf,adams}.time_share lie_poisson's run time over theirs [%]
//   seconds                      the wall time of the whole program [s]
//
// Usage: `ch03_long_time <data directory>`.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "grbd/body/integrators.hpp"
#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_demo/demo.hpp"
#include "tumbling_body.hpp"

namespace {

using namespace ch03;

constexpr double kTurnsPerSecond = 20.0;
constexpr double kTurn = 1.0 / kTurnsPerSecond;  // P [s]
constexpr double kEndTime = 500.0;               // T [s] = 10⁴ P
constexpr double kStep = 1e-3;                   // h [s] of the fixed-step schemes
constexpr double kCvodeSample = 5e-3;            // CVODE's dense output every 5 ms
constexpr double kMinWindow = 4.0 * kTurn;       // output windows last at least 4 turns …
constexpr double kWindowGrowth = 1.02;           // … and end 2 % later than the one before
constexpr double kGiveUp = 1e3;                  // stop once |E − E(0)| / E(0) exceeds this
constexpr double kRtol = 1e-6;

double energy(const body::RigidBody& rb, const Vector3& K_omega) {
  return 0.5 * K_omega.dot(rb.K_Theta.cwiseProduct(K_omega));
}
double momentum(const body::RigidBody& rb, const Vector3& K_omega) {
  return rb.K_Theta.cwiseProduct(K_omega).norm();
}

struct Summary {
  std::string name;
  double final_time = 0.0;
  double final_energy = 0.0;    // signed
  double final_momentum = 0.0;  // signed
  double max_energy = 0.0;
  double max_momentum = 0.0;
  double seconds = 0.0;
  double doubling_time = -1.0;  // first t with E ≥ 2 E(0), if any
  double halving_time = -1.0;   // first t with E ≤ E(0)/2, if any
  double crossing_time = -1.0;  // first t with |E − E(0)|/E(0) > the recorder's threshold, if any
  double first_window_energy = -1.0;  // max |E − E(0)|/E(0) over the first output window
  long steps = 0;
};

/// Writes the windows of one run. `next(t)` returns ω at the next sample time t.
class Recorder {
 public:
  /// `threshold`: the relative energy error whose first crossing is recorded (crossing_time).
  Recorder(const body::RigidBody& rb, const Vector3& K_omega0, const std::filesystem::path& file,
           std::string name, double threshold = std::numeric_limits<double>::infinity())
      : rb_(rb),
        threshold_(threshold),
        E0_(energy(rb, K_omega0)),
        L0_(momentum(rb, K_omega0)),
        out_(open_csv(file,
                      "t_s,turns,energy_rel_error,momentum_rel_error,"
                      "energy_signed_rel_error,momentum_signed_rel_error")) {
    summary_.name = std::move(name);
    out_ << "0,0,0,0,0,0\n";
  }

  /// Records ω at time t, ends the output window when it is due; returns false once the run
  /// should stop (and then ends the window).
  bool sample(double t, const Vector3& K_omega) {
    const double e = (energy(rb_, K_omega) - E0_) / E0_;
    const double l = (momentum(rb_, K_omega) - L0_) / L0_;
    if (!std::isfinite(e) || !std::isfinite(l)) {
      throw grbd::Error(summary_.name + " produced a non-finite state at t = " + std::to_string(t) +
                        " s");
    }
    window_energy_ = std::max(window_energy_, std::abs(e));
    window_momentum_ = std::max(window_momentum_, std::abs(l));
    summary_.max_energy = std::max(summary_.max_energy, std::abs(e));
    summary_.max_momentum = std::max(summary_.max_momentum, std::abs(l));
    if (summary_.doubling_time < 0.0 && e >= 1.0) {
      summary_.doubling_time = t;
    }
    if (summary_.halving_time < 0.0 && e <= -0.5) {
      summary_.halving_time = t;
    }
    if (summary_.crossing_time < 0.0 && std::abs(e) > threshold_) {
      summary_.crossing_time = t;
    }
    last_ = {t, e, l};
    pending_ = true;
    const bool go_on = std::abs(e) <= kGiveUp;
    if (t >= window_end_ * (1.0 - 1e-12) || !go_on) {
      end_window();
      window_end_ = std::max(t + kMinWindow, t * kWindowGrowth);
    }
    return go_on;
  }

  Summary finish(double seconds) {
    if (pending_) {
      end_window();
    }
    out_.finish();
    summary_.final_time = last_.t;
    summary_.final_energy = last_.energy;
    summary_.final_momentum = last_.momentum;
    summary_.seconds = seconds;
    return summary_;
  }

 private:
  void end_window() {
    if (summary_.first_window_energy < 0.0) {
      summary_.first_window_energy = window_energy_;
    }
    out_ << last_.t << ',' << last_.t / kTurn << ',' << window_energy_ << ',' << window_momentum_
         << ',' << last_.energy << ',' << last_.momentum << '\n';
    window_energy_ = window_momentum_ = 0.0;
    pending_ = false;
  }

  struct Sample {
    double t = 0.0;
    double energy = 0.0;
    double momentum = 0.0;
  };
  const body::RigidBody& rb_;
  double threshold_;
  double E0_;
  double L0_;
  grbd::demo::OutputFile out_;
  Summary summary_;
  Sample last_;
  double window_energy_ = 0.0;
  double window_momentum_ = 0.0;
  double window_end_ = kMinWindow;
  bool pending_ = false;  // samples recorded since the last row
};

/// x with its sign: "+8.2\cdot10^{-5}" as TeX for |x| < 0.1, "-0.616" with three decimals above.
std::string signed_value(double x) {
  if (std::abs(x) >= 0.1) {
    char text[32];
    std::snprintf(text, sizeof text, "%+.3f", x);
    return text;
  }
  std::string text = x < 0.0 ? "-" : "+";
  text += tex_or_zero(std::abs(x));
  return text;
}

Summary run_fixed_step(const body::RigidBody& rb, const body::State& x0, body::Integrator scheme,
                       const std::filesystem::path& data_dir) {
  const std::string name(body::integrator_name(scheme));
  const auto start = std::chrono::steady_clock::now();
  Recorder recorder(rb, kin::angular_velocity(x0.u), data_dir / (name + ".csv"), name);
  const long steps = std::lround(kEndTime / kStep);
  const body::Loads no_loads;
  body::State x = x0;
  long done = 0;
  for (long n = 1; n <= steps; ++n) {
    x = body::step(rb, x, no_loads, kStep, scheme);
    done = n;
    if (!recorder.sample(static_cast<double>(n) * kStep, kin::angular_velocity(x.u))) {
      break;
    }
  }
  Summary s = recorder.finish(seconds_since(start));
  s.steps = done;
  return s;
}

/// `threshold`: the energy error whose first crossing the summary reports (crossing_time).
Summary run_cvode(const body::RigidBody& rb, const body::State& x0, ode::CvodeMethod method,
                  const std::string& name, const std::filesystem::path& data_dir,
                  double threshold) {
  const auto start = std::chrono::steady_clock::now();
  Recorder recorder(rb, kin::angular_velocity(x0.u), data_dir / (name + ".csv"), name, threshold);
  ode::Tolerances tolerances;
  tolerances.rtol = kRtol;
  tolerances.atol = 1e-9;
  ode::Cvode cvode(ode::free_body(rb), 0.0, ode::pack(x0), method, tolerances);
  if (method == ode::CvodeMethod::bdf) {  // CVODE projects only with BDF
    cvode.set_projection(ode::quaternion_projection_at(3));
  }
  const long samples = std::lround(kEndTime / kCvodeSample);
  for (long n = 1; n <= samples; ++n) {
    const double t = static_cast<double>(n) * kCvodeSample;
    const body::State x = ode::unpack(cvode.advance(t));
    if (!recorder.sample(t, kin::angular_velocity(x.u))) {
      break;
    }
  }
  Summary s = recorder.finish(seconds_since(start));
  const ode::Statistics stats = cvode.statistics();
  s.name += " (" + std::to_string(stats.steps) + " steps)";
  s.steps = stats.steps;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch03_long_time", {"<data directory>"},
          "writes <method>.csv for three integrators of chapter 2 and CVODE, and values.txt")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];
  try {
    const auto start = std::chrono::steady_clock::now();
    const body::RigidBody rb = tumbling_body();
    const double spin = 2.0 * std::numbers::pi * kTurnsPerSecond / std::sqrt(3.0);
    const body::State x0 = tumbling_start(spin);

    std::vector<Summary> summaries;
    for (const body::Integrator scheme :
         {body::Integrator::explicit_exp_map, body::Integrator::lie_poisson,
          body::Integrator::implicit_gyroscopic}) {
      summaries.push_back(run_fixed_step(rb, x0, scheme, data_dir));
    }
    // When CVODE's drift passes the largest energy error of the Lie–Poisson splitting.
    const double splitting_error = summaries[1].max_energy;
    summaries.push_back(
        run_cvode(rb, x0, ode::CvodeMethod::bdf, "cvode_bdf", data_dir, splitting_error));
    summaries.push_back(
        run_cvode(rb, x0, ode::CvodeMethod::adams, "cvode_adams", data_dir, splitting_error));

    std::printf(
        "ch03_long_time: |omega| = %.2f rad/s, turn P = %g s, T = %g s = %g turns, "
        "h = %g s, CVODE rtol %g; relative errors at the end (energy, |L|):",
        kin::angular_velocity(x0.u).norm(), kTurn, kEndTime, kEndTime / kTurn, kStep, kRtol);
    for (const Summary& s : summaries) {
      std::printf(" %s %+.2e, %+.2e", s.name.c_str(), s.final_energy, s.final_momentum);
      if (s.final_time < kEndTime - 0.5 * kStep) {
        std::printf(" (stopped at t = %.3g s = %.3g turns; energy doubled at t = %.3g s)",
                    s.final_time, s.final_time / kTurn, s.doubling_time);
      } else {
        std::printf(" (max %.2e, %.2e)", s.max_energy, s.max_momentum);
      }
      std::printf(" [%.2f s];", s.seconds);
    }
    std::printf("\n");

    // The numbers the chapter quotes, under the methods' plain names.
    const char* const keys[] = {"explicit_exp_map", "lie_poisson", "implicit_gyroscopic",
                                "cvode_bdf", "cvode_adams"};  // the order of `summaries`
    grbd::demo::Values values;
    for (std::size_t i = 0; i < summaries.size(); ++i) {
      const Summary& s = summaries[i];
      const std::string key = keys[i];
      values.set(key + ".energy", "%s", signed_value(s.final_energy).c_str());
      values.set(key + ".momentum", "%s", signed_value(s.final_momentum).c_str());
      values.set(key + ".max_energy", "%s", tex_or_zero(s.max_energy).c_str());
      values.set(key + ".first_energy", "%s", tex_or_zero(s.first_window_energy).c_str());
      values.set(key + ".steps", "%s", grouped(s.steps).c_str());
      values.set(key + ".seconds", "%.2f", s.seconds);
    }
    const Summary& explicit_map = summaries[0];
    const Summary& lie_poisson = summaries[1];
    const Summary& implicit = summaries[2];
    values.set("explicit_exp_map.doubled", "%.0f", explicit_map.doubling_time / kTurn);
    values.set("explicit_exp_map.stopped", "%.0f", explicit_map.final_time / kTurn);
    values.set("explicit_exp_map.momentum_end", "%+.0f", explicit_map.final_momentum);
    values.set("implicit_gyroscopic.halved", "%.0f", implicit.halving_time / kTurn);
    values.set("implicit_gyroscopic.final_energy", "%.3f", 1.0 + implicit.final_energy);
    {
      // E = L²/(2Θ3) is the energy of a steady spin about the axis of the largest moment.
      const Vector3 omega0 = kin::angular_velocity(x0.u);
      const double E = energy(rb, omega0) * (1.0 + implicit.final_energy);
      const double L = momentum(rb, omega0) * (1.0 + implicit.final_momentum);
      // A bound, "10^{-15}" below it: round-off may make the difference exactly zero.
      const double difference = std::abs(E - L * L / (2.0 * rb.K_Theta(2))) / E;
      values.set("implicit_gyroscopic.steady_spin", "%s",
                 difference < 1e-15 ? "10^{-15}" : tex_or_zero(difference).c_str());
    }
    for (std::size_t i = 3; i < summaries.size(); ++i) {
      const Summary& s = summaries[i];
      const std::string key = keys[i];
      values.set(key + ".crossing", "%.0f", s.crossing_time / kTurn);
      values.set(key + ".time_share", "%.0f", 100.0 * lie_poisson.seconds / s.seconds);
    }
    values.set("seconds", "%.2f", seconds_since(start));
    values.write(data_dir / "values.txt");
  } catch (...) {
    return grbd::demo::report_exception("ch03_long_time", "the exercises of chapters 1 to 3");
  }
  return 0;
}
