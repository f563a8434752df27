// Chapter 7 demo: the angle of repose. Pours the heap of repose.toml (beads poured onto a table of
// fixed beads between two frictionless walls) once per friction coefficient μ between the beads,
// goes on after the pour until every bead is at rest, then measures the heap's surface: in bins
// one diameter wide along the table, the highest centre of a bead; a straight line fitted by
// least squares to that height against |x| on both flanks (clear of the pouring point and of the
// table's ends) gives the angle θ = atan(−slope).
//
// Usage: ch07_repose <data directory> <scene.toml> [t_max mu...]
// Writes profile.csv (the surface per μ), relax.csv (the angle while the heap comes to rest),
// repose.csv (θ per μ) and repose.txt.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"
#include "grbd_demo/demo.hpp"

namespace {

constexpr const char* kProgram = "ch07_repose";
constexpr double kDegree = 180.0 / std::numbers::pi;

struct Surface {
  std::vector<double> x, top;  // bin centres and the highest centre in each [m]
  double angle = 0.0;          // [degrees]
  double rms = 0.0;            // of the straight line [m]
};

// [repose measure]
// The heap's surface: the highest centre of a dynamic bead in each bin of width w along x over
// [−L, L]; then the least-squares line z = a + b |x| over the bins with x_min ≤ |x| ≤ x_max,
// and θ = atan(−b).
Surface measure(const grbd::scene::Simulation& sim, double L, double w, double x_min,
                double x_max) {
  Surface s;
  const auto bins = static_cast<std::size_t>(std::round(2.0 * L / w));
  s.top.assign(bins, 0.0);
  s.x.resize(bins);
  const auto states = sim.system().states();
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (!sim.system().dynamic(i)) continue;  // the table's beads
    const double k = std::floor((states[i].q[0] + L) / w);
    if (k < 0.0 || k >= static_cast<double>(bins)) continue;
    double& top = s.top[static_cast<std::size_t>(k)];
    top = std::max(top, states[i].q[2]);
  }
  double n = 0.0, sx = 0.0, sz = 0.0, sxx = 0.0, sxz = 0.0;
  const auto in_fit = [&](std::size_t k) {
    const double r = std::abs(s.x[k]);
    return r >= x_min && r <= x_max && s.top[k] > 0.0;
  };
  for (std::size_t k = 0; k < bins; ++k) {
    s.x[k] = -L + (static_cast<double>(k) + 0.5) * w;
    if (!in_fit(k)) continue;
    const double r = std::abs(s.x[k]);
    n += 1.0;
    sx += r;
    sz += s.top[k];
    sxx += r * r;
    sxz += r * s.top[k];
  }
  if (n < 3.0) return s;  // no heap yet: angle 0
  const double b = (n * sxz - sx * sz) / (n * sxx - sx * sx);
  const double a = (sz - b * sx) / n;
  double sq = 0.0;
  for (std::size_t k = 0; k < bins; ++k) {
    if (in_fit(k)) sq += std::pow(s.top[k] - a - b * std::abs(s.x[k]), 2);
  }
  s.rms = std::sqrt(sq / n);
  s.angle = std::atan(-b) * kDegree;
  return s;
}
// [repose measure]

// [repose rest]
// At rest: every dynamic body slower than `speed` [m/s]. With ε_N = 0 and a converged solver a
// heap at rest has velocities of round-off size, so the threshold only has to be well below the
// velocity g Δt that one step of gravity gives (3.9 mm/s here).
bool at_rest(const grbd::scene::Simulation& sim, double speed) {
  const auto states = sim.system().states();
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (sim.system().dynamic(i) && states[i].u.head<3>().norm() >= speed) return false;
  }
  return true;
}
// [repose rest]

// The half length of the table: the static box named "table".
double table_half_length(const grbd::scene::Scene& scene) {
  for (const auto& s : scene.statics) {
    const auto* box = std::get_if<grbd::collision::Box>(&s.shape);
    if (box != nullptr && s.name == "table") return box->half_extents.x();
  }
  throw grbd::Error(scene.file.string() + ": expected a static box named \"table\"");
}

// The time the pour stops: the end of the last inflow.
double pour_end(const grbd::scene::Scene& scene) {
  double end = 0.0;
  for (const auto& g : scene.groups) {
    if (g.generator.kind == grbd::scene::GeneratorKind::inflow) {
      end = std::max(end, g.generator.stop);
    }
  }
  if (end <= 0.0) throw grbd::Error(scene.file.string() + ": expected an inflow with a stop time");
  return end;
}

struct Heap {
  double mu = 0.0;
  Surface surface;
  double rest = -1.0;  // the time every bead was at rest [s]; −1: not by t_max
  std::size_t beads = 0;
  std::uint64_t fell = 0;
  double seconds = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<scene.toml>", "[t_max mu...]"},
          "pours the heap of the scene for each bead friction coefficient, lets it come to rest "
          "and measures its angle of repose; writes profile.csv, relax.csv, repose.csv and "
          "repose.txt",
          2, static_cast<std::size_t>(argc))) {
    return *exit;
  }
  try {
    const std::filesystem::path dir = argv[1];
    grbd::scene::Scene base = grbd::scene::load_scene(argv[2]);
    double t_max = 6.0;
    std::vector<double> mus = {0.0, 0.1, 0.2, 0.3, 0.5, 1.0};
    if (argc >= 4) t_max = grbd::demo::parse_number(argv[3], "t_max");
    if (argc >= 5) {
      mus.clear();
      for (int i = 4; i < argc; ++i) mus.push_back(grbd::demo::parse_number(argv[i], "mu"));
    }
    base.end_time = t_max;
    const double L = table_half_length(base);
    const double d = 2.0 * base.groups.back().radius.mean();  // the poured beads
    const double poured = pour_end(base);
    const auto steps_per_check = static_cast<std::uint64_t>(std::round(0.01 / base.settings.dt));
    const auto steps_per_trace = static_cast<std::uint64_t>(std::round(0.1 / base.settings.dt));
    const auto surface = [&](const grbd::scene::Simulation& sim) {
      return measure(sim, L, d, 3.0 * d, L - 2.0 * d);
    };
    std::vector<Heap> heaps;
    grbd::demo::OutputFile relax(dir / "relax.csv", "# t_s angle_deg (one block per mu)");
    for (double mu : mus) {
      grbd::scene::Scene scene = base;
      for (auto& c : scene.contacts) {
        if (c.a == "glass" && c.b == "glass") c.law.mu = mu;
      }
      grbd::scene::Simulation sim(scene);
      const auto start = std::chrono::steady_clock::now();
      Heap heap;
      heap.mu = mu;
      relax << "\n\n# mu = " << mu << '\n';
      while (!sim.finished()) {
        const auto report = sim.step();
        sim.created().clear();  // no output
        if (report.step % steps_per_trace == 0) relax << report.t << ' ' << surface(sim).angle << '\n';
        if (report.t > poured && report.step % steps_per_check == 0 && at_rest(sim, 1e-3)) {
          heap.rest = report.t;
          break;
        }
      }
      heap.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      heap.surface = surface(sim);
      heap.fell = sim.bodies_removed();
      for (std::size_t i = 0; i < sim.system().size(); ++i) heap.beads += sim.system().dynamic(i);
      std::cout << kProgram << ": mu = " << mu << ": angle " << heap.surface.angle
                << " degrees (rms " << heap.surface.rms * 1e3 << " mm), " << heap.beads
                << " beads on the table, " << heap.fell << " fell off, "
                << (heap.rest < 0.0 ? std::string("still moving at t_max")
                                    : "at rest at t = " + std::to_string(heap.rest) + " s")
                << ", " << heap.seconds << " s" << std::endl;
      heaps.push_back(heap);
    }
    relax.finish();
    grbd::demo::OutputFile profile(dir / "profile.csv");
    profile << "# x_m";
    for (const auto& h : heaps) profile << " top_m_mu" << h.mu;
    profile << '\n';
    for (std::size_t k = 0; k < heaps.front().surface.x.size(); ++k) {
      profile << heaps.front().surface.x[k];
      for (const auto& h : heaps) profile << ' ' << h.surface.top[k];
      profile << '\n';
    }
    profile.finish();
    grbd::demo::OutputFile table(dir / "repose.csv");
    table << "# mu angle_deg rms_m rest_s beads atan_mu_deg\n";
    for (const auto& h : heaps) {
      table << h.mu << ' ' << h.surface.angle << ' ' << h.surface.rms << ' ' << h.rest << ' '
            << h.beads << ' ' << std::atan(h.mu) * kDegree << '\n';
    }
    table.finish();
    std::ostringstream text;
    text << std::setprecision(3) << kProgram << ": table 2 x " << L * 1e3 << " mm, d = " << d * 1e3
         << " mm;";
    for (const auto& h : heaps) {
      text << " mu = " << h.mu << ": " << h.surface.angle << " deg"
           << (h.rest < 0.0 ? " (still moving)" : "") << ';';
    }
    text << '\n';
    std::cout << text.str();
    grbd::demo::OutputFile summary(dir / "repose.txt");
    summary << text.str();
    summary.finish();
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 7 framework");
  }
}
