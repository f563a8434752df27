// Chapter 2 demo: a space donut tumbling in free space, integrated with every integrator of
// grbd::body (the list grbd::body::integrators()).
//
// The body is the torus of space_donut.obj (written by ch02_make_meshes: R = 0.3 m, r = 0.1 m),
// read with grbd::body::read_obj() and given density 1000 kg/m³; its mass, centre of mass and
// principal frame come from grbd::body::rigid_body_from_mesh(). It is thrown spinning mostly about
// a diameter, K_omega = 2π (1, 0.1, 0.4) rad/s in the principal frame (Θ1 ≈ Θ2 are the diameters,
// Θ3 the symmetry axis), so that it wobbles: the angular velocity is not along a principal axis.
// No force and no torque act. Every integrator runs with the same step h = 2 ms for T = 300 s,
// about 325 turns of the body (|K_omega| = 6.8 rad/s).
//
// For every integrator the file `<name>.csv` (name as in grbd::body::integrator_name) is written
// to the data directory, one row per output interval of 0.5 s (and one for t = 0), with the
// columns
//
//   t_s                        end of the output interval [s]
//   energy_rel_error           max over the interval of |T − T(0)| / T(0), T the kinetic energy [-]
//   momentum_rel_error         max over the interval of |I_L − I_L(0)| / |I_L(0)|, I_L the angular
//                              momentum about S in the inertial frame [-]
//   p_norm_error               max over the interval of ||p| − 1| [-]
//   energy_signed_rel_error    (T − T(0)) / T(0) at the end of the interval [-]
//
// The maxima over each interval keep the envelope of errors that oscillate within one turn, which
// a plain sample every 250 steps would alias. The exact torque-free solution keeps T and I_L.
// The program also checks the exact energy law of explicit velocity updates (the chapter's
// (h²/2) ω̇ᵀ Θ ω̇ per step) on explicit_exp_map and prints a one-line summary. The numbers the
// chapter quotes go to `values.txt` (key = value lines, read by the book at build time:
// \demo{ch02_space_donut/values.txt#KEY} in chapter.md): the body (m, Theta1..3, omega, turns),
// per integrator name the largest relative errors of the energy and of I_L (energy_error,
// momentum_error) and the share of |I_L| lost by the end (momentum_loss [%]); for explicit_exp_map
// the final energy over the initial (energy_factor_end) and its largest momentum error as a plain
// number (momentum_factor); the energy lost by implicit_gyroscopic (energy_loss [%]);
// explicit_energy_law, the largest relative deviation from the energy law; p_error, the largest
// ||p| − 1| of all integrators; energy_error_ratio, the largest energy error of explicit_exp_map
// over that of lie_poisson.
//
// Usage: `ch02_space_donut <data directory> <path to space_donut.obj>`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include "grbd/body/integrators.hpp"
#include "grbd/body/rigid_body.hpp"
#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Vector3;
using grbd::Vector6;
namespace body = grbd::body;
namespace kin = grbd::kinematics;

constexpr double kPi = std::numbers::pi;
constexpr double kDensity = 1000.0;  // kg/m³
constexpr double kStep = 2e-3;       // h [s]
constexpr double kEndTime = 300.0;   // T [s]
constexpr int kOutputEvery = 250;    // steps per output row: 0.5 s

struct Summary {
  std::string name;
  double max_energy_error = 0.0;
  double final_energy_error = 0.0;  // signed
  double max_momentum_error = 0.0;
  double max_p_norm_error = 0.0;
  double final_momentum_length = 1.0;  // |I_L(T)| / |I_L(0)|
};

// Integrates the torque-free body with `scheme` and writes `file`.
Summary integrate(const body::RigidBody& rb, const body::State& x0, body::Integrator scheme,
                  const std::filesystem::path& file, double* energy_law_deviation) {
  const body::Loads no_loads;
  const double T0 = body::kinetic_energy(rb, x0.u);
  const Vector3 I_L0 = body::I_angular_momentum(rb, x0);
  const int steps = static_cast<int>(std::lround(kEndTime / kStep));

  grbd::demo::OutputFile out(
      file, "t_s,energy_rel_error,momentum_rel_error,p_norm_error,energy_signed_rel_error");
  out.precision(10);
  out << 0.0 << ',' << 0.0 << ',' << 0.0 << ',' << std::abs(kin::orientation(x0.q).norm() - 1.0)
      << ',' << 0.0 << '\n';

  Summary s;
  s.name = std::string(body::integrator_name(scheme));
  body::State x = x0;
  double window_energy = 0.0;
  double window_momentum = 0.0;
  double window_p = 0.0;
  for (int n = 1; n <= steps; ++n) {
    if (energy_law_deviation != nullptr) {
      // Explicit velocity update: T(u + h u̇) − T(u) = (h²/2) ω̇ᵀ Θ ω̇ exactly, because the
      // gyroscopic term does no work (ωᵀ Θ ω̇ = 0).
      const double T_before = body::kinetic_energy(rb, x.u);
      const Vector3 omega_dot = body::newton_euler_u_dot(rb, x.u, no_loads).tail<3>();
      const double law = 0.5 * kStep * kStep * omega_dot.dot(rb.K_Theta.cwiseProduct(omega_dot));
      x = body::step(rb, x, no_loads, kStep, scheme);
      const double actual = body::kinetic_energy(rb, x.u) - T_before;
      *energy_law_deviation = std::max(*energy_law_deviation, std::abs(actual - law) / law);
    } else {
      x = body::step(rb, x, no_loads, kStep, scheme);
    }
    const double T = body::kinetic_energy(rb, x.u);
    const double energy_signed = (T - T0) / T0;
    const double energy = std::abs(energy_signed);
    const double momentum = (body::I_angular_momentum(rb, x) - I_L0).norm() / I_L0.norm();
    const double p_error = std::abs(kin::orientation(x.q).norm() - 1.0);
    if (!std::isfinite(T) || !std::isfinite(momentum) || !std::isfinite(p_error)) {
      throw grbd::Error(s.name +
                        " produced a non-finite state at t = " + std::to_string(n * kStep) + " s");
    }
    window_energy = std::max(window_energy, energy);
    window_momentum = std::max(window_momentum, momentum);
    window_p = std::max(window_p, p_error);
    s.max_energy_error = std::max(s.max_energy_error, energy);
    s.max_momentum_error = std::max(s.max_momentum_error, momentum);
    s.max_p_norm_error = std::max(s.max_p_norm_error, p_error);
    s.final_energy_error = energy_signed;
    s.final_momentum_length = body::I_angular_momentum(rb, x).norm() / I_L0.norm();
    if (n % kOutputEvery == 0 || n == steps) {
      out << n * kStep << ',' << window_energy << ',' << window_momentum << ',' << window_p << ','
          << energy_signed << '\n';
      window_energy = window_momentum = window_p = 0.0;
    }
  }
  out.finish();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch02_space_donut", {"<data directory>", "<space_donut.obj>"},
          "writes <integrator>.csv for every integrator and values.txt into the existing "
          "directory")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];
  const std::filesystem::path mesh_file = argv[2];

  try {
    const body::TriangleMesh mesh = body::read_obj(mesh_file);
    const body::BodyFromMesh donut = body::rigid_body_from_mesh(mesh, kDensity, mesh_file.string());
    const body::RigidBody& rb = donut.body;

    // Thrown spinning about a diameter with a wobble; a generic initial orientation.
    const Vector3 K_omega = 2.0 * kPi * Vector3(1.0, 0.1, 0.4);
    const kin::Quaternion p0 = kin::quaternion_from_axis_angle(Vector3(0.2, -0.5, 0.8), 0.7);
    const body::State x0{kin::make_q(Vector3::Zero(), p0), kin::make_u(Vector3::Zero(), K_omega)};

    double energy_law_deviation = 0.0;
    std::vector<Summary> summaries;
    for (const body::IntegratorInfo& info : body::integrators()) {
      const bool check_law = info.scheme == body::Integrator::explicit_exp_map;
      summaries.push_back(integrate(rb, x0, info.scheme,
                                    data_dir / (std::string(info.name) + ".csv"),
                                    check_law ? &energy_law_deviation : nullptr));
    }

    std::printf(
        "ch02_space_donut: m = %.4g kg, K_Theta = (%.4g, %.4g, %.4g) kg m^2, "
        "|K_omega| = %.4g rad/s, h = %g s, T = %g s;",
        rb.m, rb.K_Theta(0), rb.K_Theta(1), rb.K_Theta(2), K_omega.norm(), kStep, kEndTime);
    for (const Summary& s : summaries) {
      std::printf(" %s: max |dE|/E %.2e (final %+.2e), max |dL|/|L| %.2e, max ||p|-1| %.1e;",
                  s.name.c_str(), s.max_energy_error, s.final_energy_error, s.max_momentum_error,
                  s.max_p_norm_error);
    }
    std::printf(" explicit energy law holds to %.1e\n", energy_law_deviation);

    // The numbers the chapter quotes.
    grbd::demo::Values values;
    values.set("m", "%.2f", rb.m);
    for (int i = 0; i < 3; ++i) {
      values.set("Theta" + std::to_string(i + 1), "%.3f", rb.K_Theta(i));
    }
    values.set("omega", "%.2f", K_omega.norm());
    values.set("turns", "%.0f", K_omega.norm() * kEndTime / (2.0 * kPi));
    double p_error = 0.0;
    for (const Summary& s : summaries) {
      values.set(s.name + ".energy_error", "%s", grbd::demo::tex_power(s.max_energy_error).c_str());
      values.set(s.name + ".momentum_error", "%s",
                 grbd::demo::tex_power(s.max_momentum_error).c_str());
      values.set(s.name + ".momentum_loss", "%.0f", 100.0 * (1.0 - s.final_momentum_length));
      p_error = std::max(p_error, s.max_p_norm_error);
    }
    const auto summary_of = [&](std::string_view name) -> const Summary& {
      for (const Summary& s : summaries) {
        if (s.name == name) return s;
      }
      throw grbd::Error("no integrator " + std::string(name));
    };
    const Summary& explicit_map = summary_of("explicit_exp_map");
    const Summary& lie_poisson = summary_of("lie_poisson");
    values.set("explicit_exp_map.momentum_factor", "%.1f", explicit_map.max_momentum_error);
    values.set("explicit_exp_map.energy_factor_end", "%.1f", 1.0 + explicit_map.final_energy_error);
    values.set("implicit_gyroscopic.energy_loss", "%.0f",
               -100.0 * summary_of("implicit_gyroscopic").final_energy_error);
    values.set("explicit_energy_law", "%s", grbd::demo::tex_power(energy_law_deviation).c_str());
    values.set("p_error", "%s", grbd::demo::tex_power(p_error).c_str());
    values.set("energy_error_ratio", "%s",
               grbd::demo::tex_power(explicit_map.max_energy_error / lie_poisson.max_energy_error)
                   .c_str());
    values.write(data_dir / "values.txt");
  } catch (...) {
    return grbd::demo::report_exception("ch02_space_donut", "the exercises of chapters 1 and 2");
  }
  return 0;
}
