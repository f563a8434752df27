// Chapter 4 demo: the normal contact velocity γ_N = W_Nᵀ u is the time derivative of the gap g_N.
//
// A sphere (body a, radius 0.1 m) flies past a box (body b, half-extents (0.3, 0.2, 0.1) m) that
// tumbles and drifts. Both move with constant u = (I_v_S, K_omega), so the exact motion is the
// exponential-map update of Chapter 1, q(t) = exp_map_step(q(0), u, t). At every sample time t the
// demo computes the contact geometry with grbd::collision::sphere_box, the tangent basis with
// tangent_basis, the lever arms K_rho of both contact points and the Jacobians W_a, W_b with
// contact_jacobian, and
//
//   γ = W_aᵀ u_a − W_bᵀ u_b                          (the chapter's contact velocity),
//   ġ_N ≈ (g_N(t + δ) − g_N(t − δ)) / (2δ), δ = 1e-5 s  (a central difference of the gap).
//
// The sphere's centre stays outside the box, where the distance to the box is continuously
// differentiable although the closest feature changes between faces, edges and vertices; the demo
// records which one (0 inside, 1 face, 2 edge, 3 vertex: how many box coordinates of the centre
// lie beyond the half-extents), independently of the library's feature ids.
//
// Output: `contact_velocity.csv` in the data directory, one row per sample, with the columns
//
//   t_s            time [s]
//   g_N            gap [m]
//   gamma_N        W_aᵀu_a − W_bᵀu_b, normal component [m/s]
//   g_N_dot        central difference of g_N [m/s]
//   region         0 inside, 1 face, 2 edge, 3 vertex region of the box
//   gamma_T1       first tangential component of γ [m/s]
//   gamma_T2       second tangential component of γ [m/s]
//
// and a one-line summary: the largest |γ_N − ġ_N| over the run. The numbers the chapter quotes go
// to `values.txt` (key = value lines read by the book at build time:
// \demo{ch04_contact_velocity/values.txt#KEY} in chapter.md): feature_changes (how often the
// region changes between samples), dip (the deepest overlap [mm]), dip_from, dip_to (the first and
// the last sample with g_N < 0 [s]), gamma_min, gamma_max [m/s], median_deviation and
// away_deviation (the median of |γ_N − ġ_N| and its largest value over the samples whose
// difference quotient does not straddle a change of region [m/s]), spike, spike_t (the largest
// value and its time [s]), spike_from, spike_to (the regions at t − δ and t + δ there, in words).
//
// Usage: `ch04_contact_velocity <data directory>`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "grbd/collision/contact.hpp"
#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/shapes.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Matrix3;
using grbd::Vector3;
using grbd::Vector6;
using grbd::Vector7;
namespace collision = grbd::collision;
namespace kin = grbd::kinematics;

constexpr double kRadius = 0.1;   // sphere radius [m]
constexpr double kEndTime = 4.0;  // [s]
constexpr int kSamples = 2000;    // sample intervals over [0, kEndTime]
constexpr double kDelta = 1e-5;   // central-difference step [s]

const collision::Box kBox{Vector3(0.3, 0.2, 0.1)};

struct Motion {
  Vector7 q0;
  Vector6 u;
  Vector7 q(double t) const { return kin::exp_map_step(q0, u, t); }
};

// The sphere: centre from (−1, −0.3, 0.5) m across the box, spinning (the spin must not change
// γ_N: the sphere's contact point moves normal to n only with its centre).
const Motion kSphere{kin::make_q(Vector3(-1.0, -0.3, 0.5), kin::Quaternion::identity()),
                     kin::make_u(Vector3(0.5, 0.12, -0.06), Vector3(3.0, -2.0, 1.0))};
// The box: tilted, drifting slowly, tumbling at about 1.6 rad/s.
const Motion kBoxMotion{
    kin::make_q(Vector3::Zero(), kin::quaternion_from_axis_angle(Vector3(1, 1, 0), 0.3)),
    kin::make_u(Vector3(0.02, 0.0, 0.0), Vector3(0.4, 0.3, 1.5))};

collision::ContactGeometry geometry(double t) {
  const Vector7 q_a = kSphere.q(t);
  const Vector7 q_b = kBoxMotion.q(t);
  const collision::Placement box{kin::position(q_b), kin::rotation_matrix(kin::orientation(q_b))};
  return collision::sphere_box(kin::position(q_a), kRadius, kBox, box);
}

// How many box-frame coordinates of the sphere's centre lie beyond the half-extents.
int region(double t) {
  const Vector7 q_a = kSphere.q(t);
  const Vector7 q_b = kBoxMotion.q(t);
  const Vector3 C_x = kin::rotation_matrix(kin::orientation(q_b)).transpose() *
                      (kin::position(q_a) - kin::position(q_b));
  return static_cast<int>((C_x.cwiseAbs().array() > kBox.half_extents.array()).count());
}

// "a face", "an edge", "a vertex" (or "the inside") for a region number.
const char* region_words(int r) {
  static const char* const words[] = {"the inside", "a face", "an edge", "a vertex"};
  return words[r];
}

void run(const std::filesystem::path& dir) {
  grbd::demo::OutputFile out(dir / "contact_velocity.csv",
                             "t_s,g_N,gamma_N,g_N_dot,region,gamma_T1,gamma_T2");
  out.precision(12);

  double max_deviation = 0.0;
  double max_gamma = 0.0;
  double min_gap = 1e300;
  int regions_seen[4] = {0, 0, 0, 0};
  std::vector<double> deviations;
  double away_deviation = 0.0;  // largest |γ_N − ġ_N| where [t − δ, t + δ] stays in one region
  double spike_t = 0.0;
  int feature_changes = 0;
  int previous_region = -1;
  double dip_from = -1.0;
  double dip_to = -1.0;
  double min_gamma = 1e300;
  double max_gamma_signed = -1e300;
  for (int i = 0; i <= kSamples; ++i) {
    const double t = kEndTime * i / kSamples;
    const collision::ContactGeometry g = geometry(t);
    const Eigen::Matrix<double, 3, 2> T = collision::tangent_basis(g.I_n);

    const Vector7 q_a = kSphere.q(t);
    const Vector7 q_b = kBoxMotion.q(t);
    const kin::Quaternion p_a = kin::orientation(q_a);
    const kin::Quaternion p_b = kin::orientation(q_b);
    // Lever arms: the contact points relative to the centres of mass, in the body frames.
    const Vector3 K_rho_a = kin::rotation_matrix(p_a).transpose() * (g.I_r_a - kin::position(q_a));
    const Vector3 K_rho_b = kin::rotation_matrix(p_b).transpose() * (g.I_r_b - kin::position(q_b));
    const collision::ContactJacobian W_a =
        collision::contact_jacobian(p_a, K_rho_a, g.I_n, T.col(0), T.col(1));
    const collision::ContactJacobian W_b =
        collision::contact_jacobian(p_b, K_rho_b, g.I_n, T.col(0), T.col(1));
    const Vector3 gamma = W_a.transpose() * kSphere.u - W_b.transpose() * kBoxMotion.u;

    const double g_N_dot = (geometry(t + kDelta).g_N - geometry(t - kDelta).g_N) / (2.0 * kDelta);
    const int r = region(t);
    out << t << ',' << g.g_N << ',' << gamma(0) << ',' << g_N_dot << ',' << r << ',' << gamma(1)
        << ',' << gamma(2) << '\n';

    const double deviation = std::abs(gamma(0) - g_N_dot);
    if (deviation > max_deviation) spike_t = t;
    deviations.push_back(deviation);
    if (region(t - kDelta) == region(t + kDelta)) away_deviation = std::max(away_deviation, deviation);
    if (previous_region >= 0 && r != previous_region) ++feature_changes;
    previous_region = r;
    if (g.g_N < 0.0) {
      if (dip_from < 0.0) dip_from = t;
      dip_to = t;
    }
    min_gamma = std::min(min_gamma, gamma(0));
    max_gamma_signed = std::max(max_gamma_signed, gamma(0));
    max_deviation = std::max(max_deviation, deviation);
    max_gamma = std::max(max_gamma, std::abs(gamma(0)));
    min_gap = std::min(min_gap, g.g_N);
    ++regions_seen[r];
  }
  out.finish();
  std::printf(
      "ch04_contact_velocity: max |gamma_N - dg_N/dt| = %.2e m/s (max |gamma_N| = %.3f m/s), "
      "min g_N = %.4f m; samples inside/face/edge/vertex region: %d/%d/%d/%d; wrote %s\n",
      max_deviation, max_gamma, min_gap, regions_seen[0], regions_seen[1], regions_seen[2],
      regions_seen[3], out.path().string().c_str());

  // The numbers the chapter quotes.
  std::sort(deviations.begin(), deviations.end());
  const double median = deviations[deviations.size() / 2];
  grbd::demo::Values values;
  values.set("feature_changes", "%d", feature_changes);
  values.set("dip", "%.0f", -1e3 * std::min(min_gap, 0.0));
  values.set("dip_from", "%.2f", dip_from);
  values.set("dip_to", "%.2f", dip_to);
  values.set("gamma_min", "%+.2f", min_gamma);
  values.set("gamma_max", "%+.2f", max_gamma_signed);
  values.set("median_deviation", "%s", grbd::demo::tex_power(median).c_str());
  values.set("away_deviation", "%s", grbd::demo::tex_power(away_deviation).c_str());
  values.set("spike", "%s", grbd::demo::tex_power(max_deviation).c_str());
  values.set("spike_t", "%.2f", spike_t);
  values.set("spike_from", "%s", region_words(region(spike_t - kDelta)));
  values.set("spike_to", "%s", region_words(region(spike_t + kDelta)));
  values.write(dir / "values.txt");
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code =
          grbd::demo::check_arguments(argc, argv, "ch04_contact_velocity", {"<data directory>"},
                                      "writes contact_velocity.csv and values.txt into the existing "
                                      "directory")) {
    return *exit_code;
  }
  try {
    run(argv[1]);
  } catch (...) {
    return grbd::demo::report_exception("ch04_contact_velocity",
                                        "the exercises of chapters 1, 2 and 4");
  }
  return 0;
}
