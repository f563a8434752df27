// Chapter 8 demo: steady flow down a rough incline, and the laws of dense granular flow.
//
// ch08_incline_run has run incline.toml — a layer of glass beads on a base of fixed beads, in a
// box periodic along and across the flow — tilted to each angle θ (g (sin θ, 0, −cos θ), the flow
// along +x) into incline_<θ>.h5 in the data directory, with the contacts in its records. This
// program measures each run over the second half of its time, when the flow is steady: the
// profiles across the depth in slabs of half a grain (parallel::DepthProfile: solid fraction,
// velocity, the stresses of the contact percussions and of the weight above), the layer's base
// and surface, Bagnold's profile fitted to the velocity (Exercise 8.6), the stress ratio and the
// inertial number in the bulk (Exercise 8.7), the solver's work; and over all angles the friction
// law μ(I).
//
// The base, the surface and the depth h: incline::layer_profile. The bulk: the slabs from 20 % to
// 80 % of the depth h.
//
// Output in the data directory: profile_<θ>.csv (z above the base, φ, u, σ_xz, σ_zz, the weight's
// σ_zz, the fitted Bagnold u, the local μ and I), energy.csv (t and kinetic energy per body of
// each run), study.csv (one line per flowing angle), mu_points.csv, mu_fit.csv and values.txt.
//
// Usage: `ch08_incline <data directory> <scene.toml> <angle in degrees>...`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/io/output.hpp"
#include "grbd/parallel/flow_profile.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd_demo/demo.hpp"
#include "incline.hpp"

namespace {

namespace par = grbd::parallel;

constexpr const char* kProgram = "ch08_incline";

struct Flow {
  double angle = 0.0;         // θ [°]
  double depth = 0.0;         // h [m]
  double packing = 0.0;       // bulk φ
  double mean_u = 0.0;        // depth-averaged velocity [m/s]
  double surface_u = 0.0;     // at the surface [m/s]
  double amplitude = 0.0;     // Bagnold's A
  double bagnold_rms = 0.0;   // rms of u − fit over the layer, relative to the surface velocity
  double stress_ratio = 0.0;  // bulk −σ_xz/σ_zz
  double weight_ratio = 0.0;  // bulk σ_zz(contacts) / σ_zz(weight)
  double stress_ratio_error = 0.0, weight_ratio_error = 0.0;  // standard errors over the records
  double inertial = 0.0;                                      // bulk mean I
  double froude = 0.0;                                        // ū/√(g h)
  std::vector<double> bulk_i, bulk_mu;                        // per bulk slab
  double seconds = 0.0;
  double penetration = 0.0;  // the largest over the steps of the second half [m]
  double sweeps = 0.0;       // the solver's mean over the steps of the second half
  double converged = 0.0;    // the share of the second half's steps that met the tolerance [%]
  double mean_overlap = 0.0;  // the mean overlap over the second half's contacts [m]
  double p99_overlap = 0.0;   // the median over the second half's steps of their 99th percentile [m]
  bool stopped = false;      // the layer came to rest: no steady flow at this angle and depth
};

Flow measure(const std::filesystem::path& output, const grbd::scene::Scene& scene, double angle,
             const std::filesystem::path& csv) {
  const grbd::io::OutputSummary summary = grbd::io::read_summary(output);
  if (summary.records < 4) throw grbd::Error(output.string() + ": too few records to average");
  // The second half's profiles, and each record's contacts alone (for the errors).
  std::vector<par::DepthProfile> samples;
  const incline::Profile p = incline::layer_profile(
      output, scene, summary.records / 2, true,
      [&](const incline::Profile& so_far, const std::vector<grbd::io::RecordContact>& contacts) {
        samples.emplace_back(0.0, so_far.bin, so_far.bins, so_far.area, so_far.density);
        samples.back().add_contacts(contacts, scene.settings.dt);
      });
  Flow flow;
  flow.angle = angle;
  const double g = scene.settings.I_g.norm();
  const double g_normal = g * std::cos(angle * std::numbers::pi / 180.0);
  const double diameter = p.diameter, density = p.density, bin = p.bin, base = p.base,
               surface = p.surface;
  const std::size_t first = p.first;
  const std::vector<double> z = p.depth.z(), phi = p.depth.packing(), u = p.depth.velocity(),
                            sxz = p.depth.shear_stress(), szz = p.depth.normal_stress(),
                            weight = p.depth.weight_stress(g_normal);
  flow.depth = p.height();
  const double h = flow.depth;
  // The Bagnold fit over the slabs in the layer.
  std::vector<double> zl, ul;
  for (std::size_t k = first; k < z.size() && z[k] <= surface; ++k) {
    zl.push_back(z[k] - base);
    ul.push_back(u[k]);
  }
  flow.mean_u = p.mean_u;
  flow.surface_u = p.surface_u;
  if (flow.surface_u < 1e-3 * std::sqrt(g * diameter)) {  // at rest: nothing more to measure
    flow.stopped = true;
    return flow;
  }
  flow.amplitude = par::bagnold_fit(zl, ul, h);
  double rms = 0.0;
  for (std::size_t i = 0; i < zl.size(); ++i) {
    const double fit = flow.amplitude * (std::pow(h, 1.5) - std::pow(h - zl[i], 1.5));
    rms += (ul[i] - fit) * (ul[i] - fit);
  }
  flow.bagnold_rms = std::sqrt(rms / static_cast<double>(zl.size())) / flow.surface_u;
  flow.froude = flow.mean_u / std::sqrt(g * h);
  // The bulk: 20 % to 80 % of the depth.
  double ratio = 0.0, wratio = 0.0, inertial = 0.0, phis = 0.0;
  int n = 0;
  grbd::demo::OutputFile out(csv, "z_m,phi,u_m_s,sxz_Pa,szz_Pa,szz_weight_Pa,u_bagnold_m_s,mu,I");
  for (std::size_t k = first; k < z.size() && z[k] <= surface; ++k) {
    const double zb = z[k] - base;
    const double rate = k > 0 && k + 1 < z.size() ? (u[k + 1] - u[k - 1]) / (2.0 * bin) : 0.0;
    const double mu = szz[k] > 0.0 ? -sxz[k] / szz[k] : 0.0;  // σ_xz < 0: see DepthProfile
    const double I = szz[k] > 0.0 ? par::inertial_number(rate, diameter, szz[k], density) : 0.0;
    out << zb << ',' << phi[k] << ',' << u[k] << ',' << sxz[k] << ',' << szz[k] << ',' << weight[k]
        << ',' << flow.amplitude * (std::pow(h, 1.5) - std::pow(h - zb, 1.5)) << ',' << mu << ','
        << I << '\n';
    if (zb >= 0.2 * h && zb <= 0.8 * h) {
      ratio += mu;
      wratio += szz[k] / weight[k];
      inertial += I;
      phis += phi[k];
      flow.bulk_i.push_back(I);
      flow.bulk_mu.push_back(mu);
      ++n;
    }
  }
  out.finish();
  if (n == 0) throw grbd::Error(output.string() + ": a layer too thin to have a bulk");
  flow.stress_ratio = ratio / n;
  flow.weight_ratio = wratio / n;
  // The scatter of the records' contact samples: each record's bulk −Σσ_xz/Σσ_zz and Σσ_zz over
  // the weight's, their standard errors of the mean.
  std::vector<double> ratios, weights;
  for (const par::DepthProfile& sample : samples) {
    const std::vector<double> s_xz = sample.shear_stress(), s_zz = sample.normal_stress();
    double xz = 0.0, zz = 0.0, w = 0.0;
    for (std::size_t k = first; k < z.size() && z[k] <= surface; ++k) {
      const double zb = z[k] - base;
      if (zb < 0.2 * h || zb > 0.8 * h) continue;
      xz += s_xz[k];
      zz += s_zz[k];
      w += weight[k];
    }
    ratios.push_back(-xz / zz);
    weights.push_back(zz / w);
  }
  const auto standard_error = [](const std::vector<double>& x) {
    double mean = 0.0, var = 0.0;
    for (const double v : x) mean += v / static_cast<double>(x.size());
    for (const double v : x) var += (v - mean) * (v - mean) / static_cast<double>(x.size() - 1);
    return std::sqrt(var / static_cast<double>(x.size()));
  };
  flow.stress_ratio_error = standard_error(ratios);
  flow.weight_ratio_error = standard_error(weights);
  flow.inertial = inertial / n;
  flow.packing = phis / n;
  return flow;
}

// μ(I) = μ_s + (μ_2 − μ_s)/(I_0/I + 1) fitted to the points in least squares with μ_2 held at
// `mu_2`: for each I_0 on a fine logarithmic grid from 10⁻³ to 10 the law is linear in μ_s
// (μ − μ_2 w = μ_s (1 − w) with w = I/(I + I_0)), solved exactly; the best I_0 wins. Its error:
// the I_0 over which the sum of squares stays within the points' variance σ² of its least (a
// change of one in χ²), and μ_s's standard error at the best I_0.
struct MuFit {
  double mu_s = 0.0, mu_2 = 0.0, i0 = 0.0, rms = 0.0;
  double mu_s_error = 0.0;             // standard error at the best I_0
  double i0_low = 0.0, i0_high = 0.0;  // where the sum of squares rises by σ²
};
MuFit fit_mu(const std::vector<double>& I, const std::vector<double>& mu, double mu_2) {
  const double n = static_cast<double>(I.size());
  struct Trial {
    double i0, mu_s, squares, a;
  };
  std::vector<Trial> trials;
  for (double e = -3.0; e <= 1.0; e += 0.002) {
    const double i0 = std::pow(10.0, e);
    double a = 0.0, p = 0.0;
    for (std::size_t k = 0; k < I.size(); ++k) {
      const double w = I[k] / (I[k] + i0), v = 1.0 - w;
      a += v * v;
      p += v * (mu[k] - mu_2 * w);
    }
    const double mu_s = p / a;
    double squares = 0.0;
    for (std::size_t k = 0; k < I.size(); ++k) {
      const double m = par::mu_of_i(I[k], mu_s, mu_2, i0) - mu[k];
      squares += m * m;
    }
    trials.push_back({i0, mu_s, squares, a});
  }
  const Trial& best =
      *std::min_element(trials.begin(), trials.end(),
                        [](const auto& x, const auto& y) { return x.squares < y.squares; });
  MuFit fit;
  fit.mu_s = best.mu_s;
  fit.mu_2 = mu_2;
  fit.i0 = best.i0;
  fit.rms = std::sqrt(best.squares / n);
  const double sigma2 = best.squares / std::max(n - 2.0, 1.0);  // the points' variance
  fit.mu_s_error = std::sqrt(sigma2 / best.a);
  fit.i0_low = fit.i0_high = best.i0;
  for (const Trial& t : trials) {
    if (t.squares <= best.squares + sigma2) {
      fit.i0_low = std::min(fit.i0_low, t.i0);
      fit.i0_high = std::max(fit.i0_high, t.i0);
    }
  }
  return fit;
}

double degrees(double x) { return std::atan(x) * 180.0 / std::numbers::pi; }

// `measure`: the runs' files measured, the study's tables and values.
void measure_all(const std::filesystem::path& dir, const grbd::scene::Scene& base,
                 const std::vector<double>& angles) {
  std::vector<Flow> flows;
  std::vector<double> stopped;  // the angles at which the layer came to rest
  std::vector<double> changes;
  grbd::demo::Values values;
  grbd::demo::OutputFile energy(dir / "energy.csv", "angle,t_s,kinetic_energy_per_body_J");
  for (const double angle : angles) {
    const std::filesystem::path output = dir / (incline::run_name(angle) + ".h5");
    const grbd::scene::Scene scene = incline::tilted(base, angle);
    Flow flow = measure(output, scene, angle,
                        dir / ("profile_" + incline::run_name(angle).substr(8) + ".csv"));
    const std::vector<grbd::io::StepInfo> steps = grbd::io::read_steps(output);
    for (const auto& s : steps) {
      flow.seconds += s.seconds;
      if (s.step % 10 == 0) {
        energy << angle << ',' << s.t << ',' << s.kinetic_energy / static_cast<double>(s.bodies)
               << '\n';
      }
    }
    const double change = incline::energy_change(steps);
    // The accuracy of the second half (chapter 6, "Accuracy of a step").
    grbd::io::RunAccuracy late;
    std::vector<double> p99;
    for (std::size_t k = steps.size() / 2; k < steps.size(); ++k) {
      late.add(steps[k]);
      p99.push_back(steps[k].p99_penetration);
    }
    flow.penetration = late.max_overlap;
    flow.sweeps = late.mean_sweeps();
    flow.converged = late.converged_percent();
    flow.mean_overlap = late.mean_overlap();
    std::nth_element(p99.begin(), p99.begin() + static_cast<std::ptrdiff_t>(p99.size() / 2),
                     p99.end());
    flow.p99_overlap = p99[p99.size() / 2];
    if (flow.stopped) {
      std::printf("%s: theta = %g deg: the layer of %.1f grains came to rest\n", kProgram, angle,
                  flow.depth / 0.002);
      stopped.push_back(angle);
      continue;
    }
    std::printf(
        "%s: theta = %g deg: h = %.1f d, phi = %.3f, mean u = %.3f m/s, surface/mean = "
        "%.2f, Bagnold rms %.1f %%, -sxz/szz = %.3f (tan = %.3f), szz/weight = %.3f, I = "
        "%.3f, kinetic energy %+.0f %% over the second half (errors of the stresses %.3f, %.3f)\n",
        kProgram, angle, flow.depth / 0.002, flow.packing, flow.mean_u,
        flow.surface_u / flow.mean_u, 100.0 * flow.bagnold_rms, flow.stress_ratio,
        std::tan(angle * std::numbers::pi / 180.0), flow.weight_ratio, flow.inertial, change,
        flow.stress_ratio_error, flow.weight_ratio_error);
    flows.push_back(flow);
    changes.push_back(change);
  }
  energy.finish();
  grbd::demo::OutputFile study(dir / "study.csv",
                               "angle,tan,depth_d,phi,mean_u,surface_over_mean,bagnold_rms,"
                               "stress_ratio,weight_ratio,I,froude,energy_change_percent");
  std::vector<double> all_i, all_mu;
  const double d = 0.002, beta = 0.136;
  const double jop_s = std::tan(20.9 * std::numbers::pi / 180.0);
  const double jop_2 = std::tan(32.76 * std::numbers::pi / 180.0);
  for (std::size_t f = 0; f < flows.size(); ++f) {
    const Flow& flow = flows[f];
    const double t = std::tan(flow.angle * std::numbers::pi / 180.0);
    study << flow.angle << ',' << t << ',' << flow.depth / d << ',' << flow.packing << ','
          << flow.mean_u << ',' << flow.surface_u / flow.mean_u << ',' << flow.bagnold_rms << ','
          << flow.stress_ratio << ',' << flow.weight_ratio << ',' << flow.inertial << ','
          << flow.froude << ',' << changes[f] << '\n';
    all_i.insert(all_i.end(), flow.bulk_i.begin(), flow.bulk_i.end());
    all_mu.insert(all_mu.end(), flow.bulk_mu.begin(), flow.bulk_mu.end());
    char key[32];
    std::snprintf(key, sizeof key, "a%g.", flow.angle);
    const std::string k = key;
    values.set(k + "depth_d", "%.1f", flow.depth / d);
    values.set(k + "phi", "%.3f", flow.packing);
    values.set(k + "mean_u", "%.3f", flow.mean_u);
    values.set(k + "surface_ratio", "%.2f", flow.surface_u / flow.mean_u);
    values.set(k + "bagnold_rms", "%.1f", 100.0 * flow.bagnold_rms);
    values.set(k + "stress_ratio", "%.3f", flow.stress_ratio);
    values.set(k + "tan", "%.3f", t);
    values.set(k + "weight_ratio", "%.3f", flow.weight_ratio);
    values.set(k + "weight_error", "%.3f", flow.weight_ratio_error);
    values.set(k + "stress_error", "%.3f", flow.stress_ratio_error);
    values.set(k + "I", "%.3f", flow.inertial);
    values.set(k + "jop_mu", "%.3f", par::mu_of_i(flow.inertial, jop_s, jop_2, 0.279));
    values.set(k + "froude", "%.2f", flow.froude);
    // The h_stop that Pouliquen's flow rule ū/√(gh) = β h/h_stop gives with his β.
    if (flow.inertial > 0.01) {  // a flow, not a creep
      values.set(k + "hstop_d", "%.1f", beta * flow.depth / flow.froude / d);
    } else {
      values.set(k + "hstop_d", "%s", "—");
    }
    values.set(k + "energy_change", "%+.0f", changes[f]);
    values.set(k + "minutes", "%.1f", flow.seconds / 60.0);
    // Overlaps in µm to two significant digits: converged solves with the look-ahead leave
    // fractions of a µm, Moreau's law tens of µm.
    values.set(k + "penetration_um", "%.2g", flow.penetration * 1e6);
    values.set(k + "sweeps", "%.0f", flow.sweeps);
    values.set(k + "converged", "%.0f", flow.converged);
    values.set(k + "mean_overlap_um", "%.2g", flow.mean_overlap * 1e6);
    values.set(k + "p99_overlap_um", "%.2g", flow.p99_overlap * 1e6);
  }
  study.finish();
  std::string rest;
  for (const double a : stopped) {
    rest += (rest.empty() ? "" : ", ") + std::to_string(static_cast<int>(a)) + "°";
  }
  values.set("stopped", "%s", rest.empty() ? "none" : rest.c_str());
  values.set("flowing", "%zu", flows.size());
  values.set("points", "%zu", all_i.size());
  if (all_i.size() >= 4) {
    // μ_2 held at the glass beads' value: the flows' inertial numbers stay below I_0, where the
    // law has not yet bent towards μ_2, and a free μ_2 runs off with I_0 (both grow together).
    const MuFit fit = fit_mu(all_i, all_mu, jop_2);
    values.set("fit.mu_s", "%.3f", fit.mu_s);
    values.set("fit.mu_s_error", "%.3f", fit.mu_s_error);
    values.set("fit.mu_s_deg", "%.1f", degrees(fit.mu_s));
    values.set("fit.mu_2", "%.3f", fit.mu_2);
    values.set("fit.i0", "%.2f", fit.i0);
    values.set("fit.i0_low", "%.2f", fit.i0_low);
    values.set("fit.i0_high", "%.2f", fit.i0_high);
    values.set("fit.rms", "%.3f", fit.rms);
    values.set("max_I", "%.2f", *std::max_element(all_i.begin(), all_i.end()));
    grbd::demo::OutputFile law(dir / "mu_fit.csv", "I,mu_fit");
    for (double e = -3.0; e <= 0.0; e += 0.02) {
      const double I = std::pow(10.0, e);
      law << I << ',' << par::mu_of_i(I, fit.mu_s, fit.mu_2, fit.i0) << '\n';
    }
    law.finish();
  }
  grbd::demo::OutputFile points(dir / "mu_points.csv", "I,mu");
  for (std::size_t k = 0; k < all_i.size(); ++k) points << all_i[k] << ',' << all_mu[k] << '\n';
  points.finish();
  values.write(dir / "values.txt");
}

int run(int argc, char** argv) {
  const grbd::scene::Scene base = grbd::scene::load_scene(argv[2]);
  std::vector<double> angles;
  for (int i = 3; i < argc; ++i) angles.push_back(grbd::demo::parse_number(argv[i], "angle"));
  measure_all(argv[1], base, angles);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto code = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<scene.toml>", "<angle>..."},
          "measures the runs incline_<angle>.h5 of ch08_incline_run and writes "
          "profile_<angle>.csv, "
          "energy.csv, study.csv, mu_points.csv, mu_fit.csv and values.txt",
          3, 64)) {
    return *code;
  }
  try {
    return run(argc, argv);
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 8 steady-flow study");
  }
}
