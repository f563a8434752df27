// Chapter 3 demo: the closed-form references against the integrators, and the heavy top.
//
// Five closed forms of grbd/ode/references.hpp are set against runs of the SUNDIALS wrapper, so
// that each checks the other:
//
//   - DETEST B5 (Hull et al. 1972) to t = 20: CVODE BDF and Adams and ARKODE order 8 at
//     rtol 1e-10, atol 1e-12, against (sn, cn, dn)(t | 0.51);
//   - the tumbling body of tumbling_body.hpp for 100 s (8.5 periods of ω): the CVODE reference
//     (BDF, rtol 1e-12, projected) against the elliptic solution, sampled every 0.1 s;
//   - the Dzhanibekov flip of chapter 2 (a box 0.16 × 0.08 × 0.02 m of density 1000 kg/m³ spun
//     at 2π (0.01, 1, 0.01) rad/s) for 20 s: the zeros of ω2 of a CVODE run (BDF, rtol 1e-10,
//     located on its dense output) against the flip interval 2K(m)/λ;
//   - a free symmetric top, K_Theta = (1, 1, 2) kg m², K_omega = (1, 0, 3) rad/s, for 20 s: the
//     angle swept by its symmetry axis about the fixed L (CVODE BDF, rtol 1e-10) against the
//     precession rate |L|/Θ⊥;
//   - a heavy symmetric top (m = 0.5 kg, l = 4 cm, Θ⊥ = 2e-4 kg m², Θ3 = 3e-4 kg m²) released
//     at a tilt of 30° spinning at ω3 = 150 rad/s with no other motion, for 1.5 s (about one turn
//     of its precession): the range of
//     u = cos ϑ of a CVODE run (BDF, rtol 1e-10, projected) against the roots of the nutation
//     cubic.
//
// The heavy top's run is written to `heavy_top.csv` in the data directory, one row per 1 ms:
//
//   t_s       time [s]
//   u         cos ϑ, ϑ the angle between the symmetry axis and the vertical [-]
//   axis_x    horizontal components of the unit symmetry axis A_IK e3 (the path of its tip seen
//   axis_y    from above) [-]
//
// and the nutation band to `nutation_bounds.csv` (columns u_min, u_max). The numbers are
// printed in one summary line, and those the chapter quotes written to `values.txt` (key = value
// lines read by the book at build time: \demo{ch03_closed_forms/values.txt#KEY} in chapter.md):
// b5.{bdf,adams,arkode8}.{error,steps}, b5.ratio (the smaller CVODE error over ARKODE's),
// euler.deviation [rad/s], flip.{predicted [s],zeros,intervals,error (relative)},
// precession.{predicted [rad/s],error (relative)}, nutation.{u_min,u_max,difference (the largest
// difference between the measured and the predicted bounds),tilt_max [°],nods (minima of cos ϑ),
// p_error}, and seconds, the wall time of the whole program.
//
// Usage: `ch03_closed_forms <data directory>`.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "grbd/core/error.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/ode/references.hpp"
#include "grbd_demo/demo.hpp"
#include "tumbling_body.hpp"

namespace {

using namespace ch03;
using grbd::Matrix3;

constexpr double kPi = std::numbers::pi;

struct Detest {
  std::string name;
  double error = 0.0;  // |y(20) − exact|
  long steps = 0;
};

std::vector<Detest> detest_b5() {
  constexpr double kEnd = 20.0;
  ode::Tolerances tolerances;
  tolerances.rtol = 1e-10;
  tolerances.atol = 1e-12;
  const Eigen::VectorXd y0 = Eigen::Vector3d(0.0, 1.0, 1.0);
  const Vector3 exact = ode::detest_b5_exact(kEnd);
  std::vector<Detest> results;
  for (const ode::CvodeMethod method : {ode::CvodeMethod::bdf, ode::CvodeMethod::adams}) {
    ode::Cvode cvode(ode::detest_b5(), 0.0, y0, method, tolerances);
    const Eigen::VectorXd y = cvode.advance(kEnd);
    results.push_back({method == ode::CvodeMethod::bdf ? "CVODE BDF" : "CVODE Adams",
                       (Vector3(y) - exact).norm(), cvode.statistics().steps});
  }
  ode::Arkode arkode(ode::detest_b5(), ode::RhsFunction{}, 0.0, y0, 8, tolerances);
  const Eigen::VectorXd y = arkode.advance(kEnd);
  results.push_back({"ARKODE order 8", (Vector3(y) - exact).norm(), arkode.statistics().steps});
  return results;
}

/// The largest |ω − ω_closed form| of the CVODE reference on the tumbling body over 100 s.
double euler_top_deviation() {
  const body::RigidBody rb = tumbling_body();
  const body::State x0 = tumbling_start();
  const ode::EulerTop top = ode::euler_top(rb.K_Theta, kin::angular_velocity(x0.u));
  ode::Tolerances tolerances;
  tolerances.rtol = 1e-12;
  tolerances.atol = 1e-14;
  ode::Cvode cvode(ode::free_body(rb), 0.0, ode::pack(x0), ode::CvodeMethod::bdf, tolerances);
  cvode.set_projection(ode::quaternion_projection_at(3));
  cvode.set_max_steps(10'000'000);
  double deviation = 0.0;
  for (int n = 1; n <= 1000; ++n) {
    const double t = 0.1 * n;
    const body::State x = ode::unpack(cvode.advance(t));
    deviation =
        std::max(deviation, (kin::angular_velocity(x.u) - ode::euler_top_omega(top, t)).norm());
  }
  return deviation;
}

struct Flip {
  double predicted = 0.0;  // 2K(m)/λ [s]
  double measured = 0.0;   // mean interval between the zeros of ω2 [s]
  int flips = 0;
};

Flip dzhanibekov() {
  // The phone of chapter 2: a box with half-extents (0.08, 0.04, 0.01) m, density 1000 kg/m³.
  const double m = 1000.0 * 8.0 * 0.08 * 0.04 * 0.01;
  const auto moment = [m](double a, double b) { return m * (a * a + b * b) / 3.0; };
  const body::RigidBody rb{m, Vector3(moment(0.04, 0.01), moment(0.08, 0.01), moment(0.08, 0.04))};
  const body::State x0{kin::make_q(Vector3::Zero(), kin::Quaternion()),
                       kin::make_u(Vector3::Zero(), 2.0 * kPi * Vector3(0.01, 1.0, 0.01))};
  Flip flip;
  flip.predicted = ode::flip_interval(ode::euler_top(rb.K_Theta, kin::angular_velocity(x0.u)));
  ode::Tolerances tolerances;
  tolerances.rtol = 1e-10;
  tolerances.atol = 1e-12;
  ode::Cvode cvode(ode::free_body(rb), 0.0, ode::pack(x0), ode::CvodeMethod::bdf, tolerances);
  cvode.set_projection(ode::quaternion_projection_at(3));
  cvode.set_max_steps(10'000'000);
  // ω2 on a 1 ms grid of CVODE's dense output; a zero is located by the secant through the two
  // samples around it (an error of O(dt²) = 1e-6 of ω2's curvature, far below the flip's scale).
  constexpr double kDt = 1e-3;
  double t_prev = 0.0;
  double w_prev = kin::angular_velocity(x0.u)[1];
  std::vector<double> zeros;
  for (int n = 1; n <= 20000; ++n) {
    const double t = n * kDt;
    const double w = ode::unpack(cvode.advance(t)).u[4];
    if ((w_prev > 0.0) != (w > 0.0)) {
      zeros.push_back(t_prev + (t - t_prev) * w_prev / (w_prev - w));
    }
    t_prev = t;
    w_prev = w;
  }
  flip.flips = static_cast<int>(zeros.size());
  if (zeros.size() >= 2) {
    flip.measured = (zeros.back() - zeros.front()) / static_cast<double>(zeros.size() - 1);
  }
  return flip;
}

struct Precession {
  double predicted = 0.0;  // |L|/Θ⊥ [rad/s]
  double measured = 0.0;   // angle swept by e3 about L, over the time [rad/s]
};

Precession symmetric_top() {
  const body::RigidBody rb{1.0, Vector3(1.0, 1.0, 2.0)};
  const kin::Quaternion p0 = kin::quaternion_from_axis_angle(Vector3(1.0, 2.0, 0.5), 0.6);
  const body::State x0{kin::make_q(Vector3::Zero(), p0),
                       kin::make_u(Vector3::Zero(), Vector3(1.0, 0.0, 3.0))};
  Precession precession;
  precession.predicted =
      ode::symmetric_top_precession_rate(rb.K_Theta, kin::angular_velocity(x0.u));
  const Vector3 I_L = body::I_angular_momentum(rb, x0);
  const Vector3 e_L = I_L.normalized();
  // An orthonormal frame (e1, e2, e_L) in which the axis' azimuth about L is measured.
  const Vector3 e1 = e_L.unitOrthogonal();
  const Vector3 e2 = e_L.cross(e1);
  const auto azimuth = [&](const body::State& x) {
    const Vector3 axis = kin::rotation_matrix(kin::orientation(x.q)).col(2);
    return std::atan2(axis.dot(e2), axis.dot(e1));
  };
  ode::Tolerances tolerances;
  tolerances.rtol = 1e-10;
  tolerances.atol = 1e-12;
  ode::Cvode cvode(ode::free_body(rb), 0.0, ode::pack(x0), ode::CvodeMethod::bdf, tolerances);
  cvode.set_projection(ode::quaternion_projection_at(3));
  constexpr double kEnd = 20.0;
  constexpr int kSamples = 2000;  // 10 ms: far less than a quarter turn between samples
  double swept = 0.0;
  double previous = azimuth(x0);
  for (int n = 1; n <= kSamples; ++n) {
    const double angle = azimuth(ode::unpack(cvode.advance(kEnd * n / kSamples)));
    swept += std::remainder(angle - previous, 2.0 * kPi);  // unwrap
    previous = angle;
  }
  precession.measured = swept / kEnd;
  return precession;
}

struct Nutation {
  ode::NutationBounds predicted;
  ode::NutationBounds measured{1.0, -1.0};
  double max_p_norm_error = 0.0;
  int nods = 0;  // local minima of u = cos ϑ over the run
};

Nutation heavy_top(const std::filesystem::path& data_dir) {
  const ode::HeavyTop top{0.5, 0.04, 2e-4, 3e-4, 9.81};
  // Tilted by 30° about the inertial x axis, spinning about its own axis only: the axis starts
  // at rest, at the top of the nutation band, and traces cusps.
  const kin::Quaternion p0 = kin::quaternion_from_axis_angle(Vector3::UnitX(), kPi / 6.0);
  Eigen::VectorXd y0(7);
  y0 << p0.coeffs(), 0.0, 0.0, 150.0;
  Nutation nutation;
  nutation.predicted = ode::heavy_top_nutation_bounds(top, y0);
  {
    grbd::demo::OutputFile bounds = open_csv(data_dir / "nutation_bounds.csv", "u_min,u_max");
    bounds << nutation.predicted.u_min << ',' << nutation.predicted.u_max << '\n';
    bounds.finish();
  }
  grbd::demo::OutputFile out = open_csv(data_dir / "heavy_top.csv", "t_s,u,axis_x,axis_y");
  ode::Tolerances tolerances;
  tolerances.rtol = 1e-10;
  tolerances.atol = 1e-12;
  ode::Cvode cvode(ode::heavy_top(top), 0.0, y0, ode::CvodeMethod::bdf, tolerances);
  cvode.set_projection(ode::quaternion_projection_at(0));
  cvode.set_max_steps(10'000'000);
  std::vector<double> u_last;  // the last two values of u, to count its minima
  const auto record = [&](double t, const Eigen::VectorXd& y) {
    const kin::Quaternion p(grbd::Vector4(y.head<4>()));
    const Vector3 axis = kin::rotation_matrix(p).col(2);
    if (u_last.size() == 2 && u_last[1] < u_last[0] && u_last[1] <= axis.z()) {
      ++nutation.nods;
    }
    u_last.push_back(axis.z());
    if (u_last.size() > 2) u_last.erase(u_last.begin());
    nutation.measured.u_min = std::min(nutation.measured.u_min, axis.z());
    nutation.measured.u_max = std::max(nutation.measured.u_max, axis.z());
    nutation.max_p_norm_error = std::max(nutation.max_p_norm_error, std::abs(p.norm() - 1.0));
    out << t << ',' << axis.z() << ',' << axis.x() << ',' << axis.y() << '\n';
  };
  record(0.0, y0);
  for (int n = 1; n <= 1500; ++n) {
    const double t = 1e-3 * n;
    record(t, cvode.advance(t));
  }
  out.finish();
  return nutation;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code =
          grbd::demo::check_arguments(argc, argv, "ch03_closed_forms", {"<data directory>"},
                                      "writes heavy_top.csv, nutation_bounds.csv and values.txt")) {
    return *exit_code;
  }
  const std::filesystem::path data_dir = argv[1];
  try {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<Detest> b5 = detest_b5();
    const double euler = euler_top_deviation();
    const Flip flip = dzhanibekov();
    const Precession precession = symmetric_top();
    const Nutation nutation = heavy_top(data_dir);

    std::printf("ch03_closed_forms: DETEST B5, |y(20) - exact| at rtol 1e-10:");
    for (const Detest& d : b5) {
      std::printf(" %s %.1e (%ld steps);", d.name.c_str(), d.error, d.steps);
    }
    std::printf(" tumbling body, max |omega - closed form| over 100 s %.1e rad/s;", euler);
    std::printf(
        " Dzhanibekov flip: %d zeros of omega2, mean interval %.7f s, 2K(m)/lambda "
        "%.7f s (rel. diff. %.1e);",
        flip.flips, flip.measured, flip.predicted,
        std::abs(flip.measured - flip.predicted) / flip.predicted);
    std::printf(
        " symmetric top precession %.9f rad/s, |L|/Theta_perp %.9f rad/s (rel. diff. "
        "%.1e);",
        precession.measured, precession.predicted,
        std::abs(precession.measured - precession.predicted) / precession.predicted);
    std::printf(
        " heavy top cos(theta) in [%.7f, %.7f], cubic roots [%.7f, %.7f], max ||p|-1| "
        "%.1e\n",
        nutation.measured.u_min, nutation.measured.u_max, nutation.predicted.u_min,
        nutation.predicted.u_max, nutation.max_p_norm_error);

    // The numbers the chapter quotes.
    grbd::demo::Values values;
    const char* const b5_keys[] = {"b5.bdf", "b5.adams", "b5.arkode8"};  // the order of detest_b5
    for (std::size_t i = 0; i < b5.size(); ++i) {
      values.set(std::string(b5_keys[i]) + ".error", "%s", tex_or_zero(b5[i].error).c_str());
      values.set(std::string(b5_keys[i]) + ".steps", "%ld", b5[i].steps);
    }
    values.set("b5.ratio", "%.0f", std::min(b5[0].error, b5[1].error) / b5[2].error);
    values.set("euler.deviation", "%s", tex_or_zero(euler).c_str());
    values.set("flip.predicted", "%.7f", flip.predicted);
    values.set("flip.zeros", "%d", flip.flips);
    values.set("flip.intervals", "%d", flip.flips - 1);
    values.set("flip.error", "%s",
               tex_or_zero(std::abs(flip.measured - flip.predicted) / flip.predicted).c_str());
    values.set("precession.predicted", "%.9f", precession.predicted);
    values.set("precession.error", "%s",
               tex_or_zero(std::abs(precession.measured - precession.predicted) /
                           precession.predicted)
                   .c_str());
    values.set("nutation.u_min", "%.7f", nutation.predicted.u_min);
    values.set("nutation.u_max", "%.7f", nutation.predicted.u_max);
    values.set("nutation.difference", "%s",
               tex_or_zero(std::max(std::abs(nutation.measured.u_min - nutation.predicted.u_min),
                                    std::abs(nutation.measured.u_max - nutation.predicted.u_max)))
                   .c_str());
    values.set("nutation.tilt_max", "%.1f", std::acos(nutation.predicted.u_min) * 180.0 / kPi);
    values.set("nutation.nods", "%d", nutation.nods);
    values.set("nutation.p_error", "%s", tex_or_zero(nutation.max_p_norm_error).c_str());
    values.set("seconds", "%.2f", seconds_since(start));
    values.write(data_dir / "values.txt");
  } catch (...) {
    return grbd::demo::report_exception("ch03_closed_forms", "the exercises of chapters 1 to 3");
  }
  return 0;
}
