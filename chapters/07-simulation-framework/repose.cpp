// Chapter 7 demo: the angle of repose. Pours the heap of repose.toml (beads poured onto a table of
// fixed beads between two frictionless walls) once per friction coefficient μ between the beads,
// goes on after the pour until every bead is at rest, then measures the heap's surface
// (grbd::scene::heap_surface: in bins one diameter wide along the table, the highest centre of a
// bead) and fits a straight line to both flanks, clear of the pouring point and of the table's
// ends (grbd::scene::fit_flanks): θ = atan(−slope).
//
// Usage: ch07_repose <data directory> <scene.toml> [t_max mu...]
// Writes profile.csv (the surface per μ), relax.csv (the angle while the heap comes to rest),
// repose.csv (θ per μ) and repose.txt.

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "grbd/io/output.hpp"
#include "grbd/scene/measure.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"
#include "grbd_demo/accuracy.hpp"
#include "grbd_demo/demo.hpp"

namespace {

constexpr const char* kProgram = "ch07_repose";

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
  grbd::scene::HeapSurface surface;
  grbd::scene::FlankFit fit;
  double rest = -1.0;  // the time every bead was at rest [s]; −1: not by t_max
  std::size_t beads = 0;
  std::uint64_t fell = 0;
  double max_speed = 0.0;  // of a bead when the run stopped [m/s]
  double seconds = 0.0;
  grbd::io::RunAccuracy accuracy;  // the solver's convergence and the overlaps, every step
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
    // The flanks: clear of the pouring point (3 d) and of the table's ends (2 d).
    const auto measure = [&](const grbd::scene::Simulation& sim, Heap& heap) {
      heap.surface = grbd::scene::heap_surface(sim.system(), L, d);
      heap.fit = grbd::scene::fit_flanks(heap.surface, 3.0 * d, L - 2.0 * d);
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
      // [repose run]
      while (!sim.finished()) {
        const auto report = sim.step();
        sim.created().clear();  // no output
        heap.accuracy.add(report);
        if (report.step % steps_per_trace == 0 && report.t > 0.5) {
          measure(sim, heap);
          relax << report.t << ' ' << heap.fit.angle << '\n';
        }
        // At rest: every bead slower than 1 mm/s, a quarter of what one step of gravity gives.
        if (report.t > poured && report.step % steps_per_check == 0 &&
            grbd::scene::at_rest(sim.system(), 1e-3)) {
          heap.rest = report.t;
          break;
        }
      }
      // [repose run]
      heap.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      measure(sim, heap);
      heap.fell = sim.bodies_removed();
      heap.accuracy.unit = sim.stepper().overlap_unit();
      for (std::size_t i = 0; i < sim.system().size(); ++i) heap.beads += sim.system().dynamic(i);
      heap.max_speed = grbd::scene::max_speed(sim.system());
      std::cout << kProgram << ": mu = " << mu << ": angle " << heap.fit.angle << " ± "
                << heap.fit.angle_error << " degrees (rms " << heap.fit.rms * 1e3 << " mm), "
                << heap.beads << " beads on the table, " << heap.fell << " fell off, fastest "
                << heap.max_speed << " m/s, "
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
    table << "# mu angle_deg angle_error_deg rms_m rest_s beads a_m b x_min_m x_max_m "
             "max_speed_m_s\n";
    for (const auto& h : heaps) {
      table << h.mu << ' ' << h.fit.angle << ' ' << h.fit.angle_error << ' ' << h.fit.rms << ' '
            << h.rest << ' ' << h.beads << ' ' << h.fit.a << ' ' << h.fit.b << ' ' << 3.0 * d << ' '
            << L - 2.0 * d << ' ' << h.max_speed << '\n';
    }
    table.finish();
    std::ostringstream text;
    text << std::setprecision(3) << kProgram << ": table 2 x " << L * 1e3 << " mm, d = " << d * 1e3
         << " mm;";
    for (const auto& h : heaps) {
      text << " mu = " << h.mu << ": " << h.fit.angle << " ± " << h.fit.angle_error << " deg"
           << (h.rest < 0.0 ? " (still moving)" : "") << ';';
    }
    text << '\n';
    std::cout << text.str();
    grbd::demo::OutputFile summary(dir / "repose.txt");
    summary << text.str();
    summary.finish();
    // What the chapter quotes (\demo{ch07_repose/values.txt#KEY}), per heap by its μ ("mu0.5.").
    grbd::demo::Values values;
    double lo = 90.0, hi = 0.0, at_02 = 0.0, at_1 = 0.0;
    for (const auto& h : heaps) {
      char key[32];
      std::snprintf(key, sizeof key, "mu%g.", h.mu);
      values.set(std::string(key) + "angle", "%.1f", h.fit.angle);
      values.set(std::string(key) + "error", "%.1f", h.fit.angle_error);
      values.set(std::string(key) + "atan", "%.1f", std::atan(h.mu) * 180.0 / M_PI);
      values.set(std::string(key) + "beads", "%zu", h.beads);
      values.set(std::string(key) + "rest", "%.2f", h.rest);
      values.set(std::string(key) + "fastest", "%s", grbd::demo::tex_power(h.max_speed).c_str());
      grbd::demo::set_accuracy(values, key, h.accuracy);
      if (h.mu >= 0.3) {
        lo = std::min(lo, h.fit.angle);
        hi = std::max(hi, h.fit.angle);
      }
      if (h.mu == 0.2) at_02 = h.fit.angle;
      if (h.mu == 1.0) at_1 = h.fit.angle;
    }
    values.set("high_mu_low", "%.0f", std::floor(lo));
    values.set("high_mu_high", "%.0f", std::ceil(hi));
    values.set("gain_02_1", "%.1f", at_1 - at_02);
    values.write(dir / "values.txt");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 7 framework");
  }
}
