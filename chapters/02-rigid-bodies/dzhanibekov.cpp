// Chapter 2 demo: the Dzhanibekov effect (tennis-racket theorem). A body with three distinct
// principal moments Θ1 < Θ2 < Θ3, set spinning about its intermediate axis, flips over again and
// again; the body-frame component ω2 changes sign every 2K(m)/λ (Landau–Lifshitz, Mechanics §37).
//
// The body is a phone-sized box, half-extents (0.08, 0.04, 0.01) m, density 1000 kg/m³, built as
// a mesh with grbd::body::box_mesh() (the box.obj of ch02_make_meshes) and given its principal
// frame by grbd::body::rigid_body_from_mesh(). It starts with K_omega = Ω (ε, 1, ε),
// Ω = 2π rad/s, ε = 0.01, torque-free, and is integrated with the Lie–Poisson splitting
// (grbd::body::lie_poisson_step) with h = 1 ms for 20 s.
//
// The reference is the closed form on the branch L² > 2E·Θ2 (which this start is on):
//   λ = √((Θ3 − Θ2)(L² − 2E Θ1)/(Θ1 Θ2 Θ3)),  m = (Θ2 − Θ1)(2E Θ3 − L²)/((Θ3 − Θ2)(L² − 2E Θ1)),
//   ω2(t) = A2 sn(λ t + u0 | m),  A2 = √((2E Θ3 − L²)/(Θ2 (Θ3 − Θ2))),
// with u0 = F(arcsin(ω2(0)/A2) | m) ∈ [0, K(m)] (ω1, ω2, ω3 all start positive, so ω2 is still
// rising at t = 0). ω2 vanishes at λ t + u0 = 2K(m) j, j = 1, 2, …: the first flip comes at
// (2K − u0)/λ, and then one every 2K(m)/λ. K and F are std::comp_ellint_1 and std::ellint_1
// (C++17 mathematical special functions), which take the modulus k = √m.
//
// Files written to the data directory:
//   omega.csv   t_s, omega1, omega2, omega3: K_omega [rad/s], every 10 steps
//   flips.csv   j, t_predicted_s, t_measured_s: the j-th zero of ω2, from the closed form and
//               measured in the simulation (linear interpolation between steps)
//   values.txt  the numbers the chapter quotes, key = value lines read by the book at build time
//               (\demo{ch02_dzhanibekov/values.txt#KEY} in chapter.md): Theta1..3 [1e-4 kg m²],
//               lambda, sigma (the linear growth rate Ω √((Θ2 − Θ1)(Θ3 − Θ2)/(Θ1 Θ3)) [1/s]),
//               lambda_sigma (|λ − σ|/σ), one_minus_m, flips, half_period_measured,
//               half_period_predicted [s], half_period_error (relative), flip_time_error [ms],
//               energy_error, momentum_error (largest relative errors)
// and a one-line summary with the measured and predicted half-periods.
//
// Usage: `ch02_dzhanibekov <data directory>`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/body/integrators.hpp"
#include "grbd/body/rigid_body.hpp"
#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Vector3;
namespace body = grbd::body;
namespace kin = grbd::kinematics;

constexpr double kPi = std::numbers::pi;
constexpr double kDensity = 1000.0;  // kg/m³
constexpr double kStep = 1e-3;       // h [s]
constexpr double kEndTime = 20.0;    // s
constexpr int kOutputEvery = 10;     // steps per row of omega.csv

// The closed-form reference of the torque-free asymmetric body on the branch L² > 2E Θ2.
struct Reference {
  double lambda;       // λ [1/s]
  double m;            // parameter m of the elliptic functions [-]
  double K;            // K(m) [-]
  double u0;           // phase at t = 0 [-]
  double half_period;  // 2K/λ [s]
};

Reference reference(const Vector3& Theta, const Vector3& omega) {
  const double I1 = Theta(0);
  const double I2 = Theta(1);
  const double I3 = Theta(2);
  const Vector3 L = Theta.cwiseProduct(omega);
  const double twoE = omega.dot(L);
  const double L2 = L.squaredNorm();
  if (!(I1 < I2 && I2 < I3)) {
    throw grbd::Error("the principal moments must be distinct");
  }
  if (!(L2 > twoE * I2)) {
    throw grbd::Error(
        "the initial angular velocity is not on the branch L^2 > 2E Theta2 that the reference "
        "formula covers");
  }
  Reference r{};
  r.lambda = std::sqrt((I3 - I2) * (L2 - twoE * I1) / (I1 * I2 * I3));
  r.m = (I2 - I1) * (twoE * I3 - L2) / ((I3 - I2) * (L2 - twoE * I1));
  const double k = std::sqrt(r.m);
  r.K = std::comp_ellint_1(k);
  const double A2 = std::sqrt((twoE * I3 - L2) / (I2 * (I3 - I2)));
  r.u0 = std::ellint_1(k, std::asin(std::min(1.0, omega(1) / A2)));
  r.half_period = 2.0 * r.K / r.lambda;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch02_dzhanibekov", {"<data directory>"},
          "writes omega.csv, flips.csv and values.txt into the existing directory")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];

  try {
    const Vector3 half_extents(0.08, 0.04, 0.01);
    const body::BodyFromMesh box =
        body::rigid_body_from_mesh(body::box_mesh(half_extents), kDensity, "box");
    const body::RigidBody& rb = box.body;

    const double Omega = 2.0 * kPi;  // rad/s
    const double eps = 0.01;
    const Vector3 K_omega0 = Omega * Vector3(eps, 1.0, eps);
    const Reference ref = reference(rb.K_Theta, K_omega0);

    body::State x{kin::make_q(Vector3::Zero(), kin::Quaternion::identity()),
                  kin::make_u(Vector3::Zero(), K_omega0)};
    const body::Loads no_loads;
    const double T0 = body::kinetic_energy(rb, x.u);
    const double L0 = rb.K_Theta.cwiseProduct(K_omega0).norm();

    grbd::demo::OutputFile out(data_dir / "omega.csv", "t_s,omega1,omega2,omega3");
    out.precision(10);
    out << 0.0 << ',' << K_omega0(0) << ',' << K_omega0(1) << ',' << K_omega0(2) << '\n';

    std::vector<double> zeros;  // measured zeros of ω2
    double max_energy_error = 0.0;
    double max_momentum_error = 0.0;
    const int steps = static_cast<int>(std::lround(kEndTime / kStep));
    for (int n = 1; n <= steps; ++n) {
      const double w2_before = x.u(4);
      x = body::lie_poisson_step(rb, x, no_loads, kStep);
      const Vector3 w = kin::angular_velocity(x.u);
      if ((w2_before > 0.0) != (w(1) > 0.0)) {
        zeros.push_back((n - 1 + w2_before / (w2_before - w(1))) * kStep);
      }
      max_energy_error =
          std::max(max_energy_error, std::abs(body::kinetic_energy(rb, x.u) - T0) / T0);
      max_momentum_error =
          std::max(max_momentum_error, std::abs(rb.K_Theta.cwiseProduct(w).norm() - L0) / L0);
      if (n % kOutputEvery == 0) {
        out << n * kStep << ',' << w(0) << ',' << w(1) << ',' << w(2) << '\n';
      }
    }
    out.finish();
    if (zeros.size() < 2) {
      throw grbd::Error("omega2 changed sign fewer than twice in " + std::to_string(kEndTime) +
                        " s; no flip interval to measure");
    }

    grbd::demo::OutputFile flips(data_dir / "flips.csv", "j,t_predicted_s,t_measured_s");
    flips.precision(10);
    double max_flip_time_error = 0.0;
    for (std::size_t j = 0; j < zeros.size(); ++j) {
      const double predicted = (2.0 * ref.K * static_cast<double>(j + 1) - ref.u0) / ref.lambda;
      flips << j + 1 << ',' << predicted << ',' << zeros[j] << '\n';
      max_flip_time_error = std::max(max_flip_time_error, std::abs(zeros[j] - predicted));
    }
    flips.finish();
    const double measured_half_period =
        (zeros.back() - zeros.front()) / static_cast<double>(zeros.size() - 1);

    std::printf(
        "ch02_dzhanibekov: K_Theta = (%.4g, %.4g, %.4g) kg m^2, lambda = %.6g 1/s, "
        "1 - m = %.4g, lie_poisson h = %g s: %zu flips of omega2 in %g s, "
        "half-period measured %.6f s, predicted 2K(m)/lambda = %.6f s (rel. diff. %.1e), "
        "max flip time error %.1e s; max |dE|/E %.1e, max d|L|/|L| %.1e\n",
        rb.K_Theta(0), rb.K_Theta(1), rb.K_Theta(2), ref.lambda, 1.0 - ref.m, kStep, zeros.size(),
        kEndTime, measured_half_period, ref.half_period,
        std::abs(measured_half_period - ref.half_period) / ref.half_period, max_flip_time_error,
        max_energy_error, max_momentum_error);

    // The numbers the chapter quotes.
    const Vector3& Theta = rb.K_Theta;
    const double sigma = Omega * std::sqrt((Theta(1) - Theta(0)) * (Theta(2) - Theta(1)) /
                                           (Theta(0) * Theta(2)));
    grbd::demo::Values values;
    for (int i = 0; i < 3; ++i) {
      values.set("Theta" + std::to_string(i + 1), "%.3f", 1e4 * Theta(i));
    }
    values.set("lambda", "%.3f", ref.lambda);
    values.set("sigma", "%.3f", sigma);
    values.set("lambda_sigma", "%s", grbd::demo::tex_power(std::abs(ref.lambda - sigma) / sigma).c_str());
    values.set("one_minus_m", "%s", grbd::demo::tex_power(1.0 - ref.m).c_str());
    values.set("flips", "%zu", zeros.size());
    values.set("half_period_measured", "%.6f", measured_half_period);
    values.set("half_period_predicted", "%.6f", ref.half_period);
    values.set("half_period_error", "%s",
               grbd::demo::tex_power(std::abs(measured_half_period - ref.half_period) /
                                     ref.half_period)
                   .c_str());
    values.set("flip_time_error", "%.2f", 1e3 * max_flip_time_error);
    values.set("energy_error", "%s", grbd::demo::tex_power(max_energy_error).c_str());
    values.set("momentum_error", "%s", grbd::demo::tex_power(max_momentum_error).c_str());
    values.write(data_dir / "values.txt");
  } catch (...) {
    return grbd::demo::report_exception("ch02_dzhanibekov", "the exercises of chapters 1 and 2");
  }
  return 0;
}
