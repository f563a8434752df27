// Chapter 8 demo: where a layer on the rough incline stops, h_stop(θ), and Pouliquen's flow rule.
//
// ch08_incline_run has run the incline scene for layers of several depths at each angle (and
// with frictionless beads): incline_<θ>_<n>[_mu<μ>].h5 in the data directory; the deep layers
// of the steady-flow study, incline_<θ>.h5, are in the study's directory. For each layer this
// program measures over the second half of its run (incline::layer_profile): the depth h, the
// depth-averaged velocity ū and the Froude number ū/√(gh), and whether it flows:
//
//   - at rest: the fastest bead of the last record is slower than 1 mm/s (chapter 7's heaps);
//   - flowing: ū is at least 5 % of √(gd), the speed a grain gains falling by half its diameter;
//   - creeping otherwise (slow, coming to rest).
//
// h_stop(θ) lies between the deepest layer at θ that does not flow and the shallowest that does;
// the flow rule ū/√(gh) = β h/h_stop(θ) is then fitted (β, through the origin) over the flowing
// layers with h_stop at the middle of its bracket. For the frictionless layers, the angle at
// which a layer of given depth stops is bracketed the same way.
//
// Output in the data directory: layers.csv (one line per layer), hstop.csv (the brackets per
// angle), rule.csv (the flowing layers' h/h_stop, with h_stop at either end of its bracket, and
// Froude numbers), energy.csv (kinetic energy
// per bead against time, one block per layer) and values.txt.
//
// Usage: `ch08_hstop <data directory> <scene.toml> <study directory> <layer>...`, a layer written
// θ (the study's deep layer at θ), θ:n or θ:n:μ (incline.hpp).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "grbd/io/output.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd_demo/demo.hpp"
#include "incline.hpp"

namespace {

constexpr const char* kProgram = "ch08_hstop";
constexpr double kRest = 1e-3;     // [m/s]: every bead slower than this is at rest
constexpr double kFlowing = 0.05;  // ū ≥ this × √(gd): a flow
constexpr double kBeta = 0.136;    // Pouliquen 1999, glass beads

enum class State { rest, creeping, flowing };

const char* state_name(State s) {
  switch (s) {
    case State::rest:
      return "rest";
    case State::creeping:
      return "creeping";
    case State::flowing:
      return "flowing";
  }
  return "";
}

struct Measured {
  incline::Layer layer;
  std::string name;
  double depth_d = 0.0;  // h/d
  double mean_u = 0.0;   // [m/s]
  double froude = 0.0;   // ū/√(gh)
  double fastest = 0.0;  // in the last record [m/s]
  double energy_change = 0.0;  // of the kinetic energy over the second half [%]
  State state = State::rest;
  grbd::io::RunAccuracy accuracy;  // of the whole run (chapter 6, "Accuracy of a step")
};

Measured measure(const std::filesystem::path& file, const grbd::scene::Scene& scene,
                 const incline::Layer& layer, grbd::demo::OutputFile& energy) {
  const grbd::io::OutputSummary summary = grbd::io::read_summary(file);
  const incline::Profile p =
      incline::layer_profile(file, scene, summary.records / 2, false,
                             [](const incline::Profile&, const auto&) {});
  const double g = scene.settings.I_g.norm();
  Measured m;
  m.layer = layer;
  m.name = incline::run_name(layer);
  m.depth_d = p.height() / p.diameter;
  m.mean_u = p.mean_u;
  m.froude = p.mean_u / std::sqrt(g * p.height());
  m.fastest = p.fastest;
  if (p.fastest < kRest) {
    m.state = State::rest;
  } else if (p.mean_u >= kFlowing * std::sqrt(g * p.diameter)) {
    m.state = State::flowing;
  } else {
    m.state = State::creeping;
  }
  const std::vector<grbd::io::StepInfo> steps = grbd::io::read_steps(file);
  for (const auto& s : steps) {
    m.accuracy.add(s);
    if (s.step % 25 == 0) {
      energy << m.name << ',' << layer.angle << ',' << m.depth_d << ',' << s.t << ','
             << s.kinetic_energy / static_cast<double>(s.bodies) << '\n';
    }
  }
  m.energy_change = incline::energy_change(steps);
  return m;
}

// A bracket [low, high] of where flowing starts along one coordinate (depth at fixed angle, or
// angle at fixed depth): low the largest value that does not flow, high the smallest that does,
// `ordered` false when a layer that does not flow lies above one that flows.
struct Bracket {
  double low = 0.0, high = std::numeric_limits<double>::infinity();
  bool ordered = true;
  double middle() const { return 0.5 * (low + high); }
};
Bracket bracket(const std::vector<std::pair<double, bool>>& points) {
  Bracket b;
  for (const auto& [x, flows] : points) {
    if (flows) {
      b.high = std::min(b.high, x);
    } else {
      b.low = std::max(b.low, x);
    }
  }
  b.ordered = b.low < b.high;
  return b;
}

std::string key_of(const incline::Layer& layer) { return incline::run_name(layer).substr(8); }

void measure_all(const std::filesystem::path& dir, const grbd::scene::Scene& base,
                 const std::filesystem::path& study, const std::vector<incline::Layer>& layers) {
  grbd::demo::OutputFile energy(dir / "energy.csv", "run,angle,depth_d,t_s,kinetic_energy_per_bead_J");
  grbd::demo::OutputFile table(dir / "layers.csv",
                               "run,angle,beads,mu,depth_d,mean_u_m_s,froude,fastest_m_s,state,"
                               "energy_change_percent");
  grbd::demo::Values values;
  std::vector<Measured> all;
  for (const incline::Layer& layer : layers) {
    const bool deep = layer.count == 0 && !layer.mu;
    const std::filesystem::path file =
        (deep ? study : dir) / (incline::run_name(layer) + ".h5");
    const grbd::scene::Scene scene = incline::layer_scene(base, layer);
    Measured m = measure(file, scene, layer, energy);
    const double mu = layer.mu ? *layer.mu : scene.contacts.front().law.mu;
    const std::uint64_t count = incline::beads(scene).generator.count;
    table << m.name << ',' << layer.angle << ',' << count << ',' << mu << ',' << m.depth_d << ','
          << m.mean_u << ',' << m.froude << ',' << m.fastest << ',' << state_name(m.state) << ','
          << m.energy_change << '\n';
    std::printf("%s: %s: h = %.1f d, mean u = %.4f m/s, Fr = %.3f, fastest %.2g m/s: %s\n",
                kProgram, m.name.c_str(), m.depth_d, m.mean_u, m.froude, m.fastest,
                state_name(m.state));
    const std::string k = key_of(layer) + ".";
    values.set(k + "depth_d", "%.1f", m.depth_d);
    values.set(k + "mean_u", "%.3f", m.mean_u);
    values.set(k + "froude", "%.2f", m.froude);
    values.set(k + "state", "%s", state_name(m.state));
    values.set(k + "energy_change", "%+.0f", m.energy_change);
    values.set(k + "converged", "%.0f", m.accuracy.converged_percent());
    values.set(k + "sweeps", "%.0f", m.accuracy.mean_sweeps());
    values.set(k + "largest_um", "%.2g", m.accuracy.max_overlap * 1e6);
    all.push_back(m);
  }
  energy.finish();
  table.finish();

  // h_stop(θ) of the frictional layers, and the frictionless layers' stopping angle per count.
  std::map<double, std::vector<std::pair<double, bool>>> by_angle;
  std::map<std::uint64_t, std::vector<std::pair<double, bool>>> frictionless;
  std::map<std::uint64_t, double> frictionless_depth;
  for (const Measured& m : all) {
    const bool flows = m.state == State::flowing;
    if (m.layer.mu && *m.layer.mu == 0.0) {
      frictionless[m.layer.count].push_back({m.layer.angle, flows});
      frictionless_depth[m.layer.count] = std::max(frictionless_depth[m.layer.count], m.depth_d);
    } else if (!m.layer.mu) {
      by_angle[m.layer.angle].push_back({m.depth_d, flows});
    }
  }
  grbd::demo::OutputFile brackets(dir / "hstop.csv", "angle,low_d,high_d,middle_d");
  std::map<double, Bracket> hstop;  // where the bracket is closed and ordered
  for (const auto& [angle, points] : by_angle) {
    const Bracket b = bracket(points);
    char key[32];
    std::snprintf(key, sizeof key, "a%g.", angle);
    const std::string k = key;
    values.set(k + "low_d", "%.1f", b.low);
    if (b.high < std::numeric_limits<double>::infinity()) {
      values.set(k + "high_d", "%.1f", b.high);
    } else {
      values.set(k + "high_d", "%s", "—");
    }
    if (!b.ordered) {
      std::printf("%s: theta = %g deg: a layer that does not flow lies deeper than one that "
                  "flows (%.1f d, %.1f d)\n",
                  kProgram, angle, b.low, b.high);
      values.set(k + "hstop", "%s", "—");
      continue;
    }
    if (b.high == std::numeric_limits<double>::infinity()) {
      std::printf("%s: theta = %g deg: no layer flows: h_stop > %.1f d\n", kProgram, angle, b.low);
      values.set(k + "hstop", "> %.1f", b.low);
      brackets << angle << ',' << b.low << ",," << '\n';
      continue;
    }
    if (b.low == 0.0) {
      std::printf("%s: theta = %g deg: every layer flows: h_stop < %.1f d\n", kProgram, angle,
                  b.high);
      values.set(k + "hstop", "< %.1f", b.high);
      brackets << angle << ",0," << b.high << ",\n";
      continue;
    }
    std::printf("%s: theta = %g deg: h_stop between %.1f and %.1f d\n", kProgram, angle, b.low,
                b.high);
    values.set(k + "hstop", "%.1f–%.1f", b.low, b.high);
    hstop[angle] = b;
    brackets << angle << ',' << b.low << ',' << b.high << ',' << b.middle() << '\n';
  }
  brackets.finish();

  // Pouliquen's rule over the flowing layers at the angles with a closed bracket: β through the
  // origin in least squares, Fr = β x with x = h/h_stop.
  grbd::demo::OutputFile rule(dir / "rule.csv",
                              "angle,depth_d,hstop_d,h_over_hstop,froude,h_over_high,h_over_low");
  double xx = 0.0, xf = 0.0;
  std::size_t n = 0;
  for (const Measured& m : all) {
    if (m.layer.mu || m.state != State::flowing || !hstop.contains(m.layer.angle)) continue;
    const Bracket& b = hstop[m.layer.angle];
    const double x = m.depth_d / b.middle();
    rule << m.layer.angle << ',' << m.depth_d << ',' << b.middle() << ',' << x << ',' << m.froude
         << ',' << m.depth_d / b.high << ',' << m.depth_d / b.low << '\n';
    xx += x * x;
    xf += x * m.froude;
    ++n;
  }
  rule.finish();
  values.set("rule.points", "%zu", n);
  if (n >= 2) {
    const double beta = xf / xx;
    double rss = 0.0;
    for (const Measured& m : all) {
      if (m.layer.mu || m.state != State::flowing || !hstop.contains(m.layer.angle)) continue;
      const double r = m.froude - beta * m.depth_d / hstop[m.layer.angle].middle();
      rss += r * r;
    }
    values.set("rule.beta", "%.3f", beta);
    values.set("rule.beta_error", "%.3f",
               std::sqrt(rss / static_cast<double>(n - 1) / xx));  // slope's standard error
    std::printf("%s: flow rule over %zu flowing layers: beta = %.3f (Pouliquen %.3f)\n", kProgram,
                n, beta, kBeta);
  }
  for (const auto& [count, points] : frictionless) {
    const Bracket b = bracket(points);
    const std::string k = "mu0_" + std::to_string(count) + ".";
    values.set(k + "depth_d", "%.1f", frictionless_depth[count]);
    values.set(k + "low", "%g", b.low);
    if (b.high < std::numeric_limits<double>::infinity()) values.set(k + "high", "%g", b.high);
    std::printf("%s: frictionless layers of %llu beads (up to %.1f d): stop at %g deg, flow at "
                "%g deg\n",
                kProgram, static_cast<unsigned long long>(count), frictionless_depth[count], b.low,
                b.high);
  }
  values.write(dir / "values.txt");
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto code = grbd::demo::check_arguments(
          argc, argv, kProgram,
          {"<data directory>", "<scene.toml>", "<study directory>", "<layer>..."},
          "measures the layers' runs of ch08_incline_run (θ: the study's deep layer in <study "
          "directory>; θ:n or θ:n:μ in the data directory) and writes layers.csv, hstop.csv, "
          "rule.csv, energy.csv and values.txt",
          4, 256)) {
    return *code;
  }
  try {
    const grbd::scene::Scene base = grbd::scene::load_scene(argv[2]);
    std::vector<incline::Layer> layers;
    for (int i = 4; i < argc; ++i) layers.push_back(incline::parse_layer(argv[i]));
    measure_all(argv[1], base, argv[3], layers);
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "chapter 8's layers on the incline");
  }
}
