// Chapter 7 demo: Beverloo's discharge. Runs the silo of beverloo.toml (a square silo whose floor,
// the mesh orifice.obj, has a circular orifice, kept full by an inflow) once per orifice diameter
// D, the floor rescaled to D; measures after each step the mass the outlet removed below the
// floor, and the bulk density of the fill in a slab above the orifice region; takes the steady
// mass flow rate W as the slope of the discharged mass after t_start (scene::steady_rate, with the
// error of batch means), fits Beverloo's law W = C ρ_b √g (D − k d)^(5/2) to the rates
// (scene::fit_beverloo) and compares C and k with Beverloo, Leniger and van de Velde (1961).
//
// Usage: ch07_beverloo <data directory> <scene.toml> [end_time t_start D_mm...]
// Writes discharge.csv (the discharged mass against time, one column per D), beverloo.csv (per D:
// W, its error, ρ_b, the fitted and the literature law), beverloo_curve.csv (both laws on a fine
// grid of D at the mean ρ_b) and beverloo.txt.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd/io/output.hpp"
#include "grbd/scene/measure.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"
#include "grbd_demo/accuracy.hpp"
#include "grbd_demo/demo.hpp"

namespace {

constexpr const char* kProgram = "ch07_beverloo";

// Beverloo, Leniger and van de Velde (1961), for spheres (Nedderman, Statics and kinematics of
// granular materials, 1992, ch. 10): C ≈ 0.58, k ≈ 1.5.
constexpr double kLiteratureC = 0.58;
constexpr double kLiteratureK = 1.5;

struct Discharge {
  double D = 0.0;                       // orifice diameter [m]
  std::vector<double> t, mass;          // discharged mass after each step [s, kg]
  grbd::scene::Rate W;                  // the steady rate [kg/s]
  grbd::io::RunAccuracy accuracy;       // the solver's convergence and the overlaps, every step
  double rho_b = 0.0;                   // bulk density of the fill [kg/m³]
  std::uint64_t bodies = 0, steps = 0;  // at the end
  double seconds = 0.0;
};

// [beverloo floor]
// The scene with its floor (the static named "floor", a mesh of a plate with a hole of diameter 1
// at the origin) scaled to an orifice of diameter D.
grbd::scene::Scene with_orifice(const grbd::scene::Scene& base, double D) {
  grbd::scene::Scene scene = base;
  auto floor = std::find_if(scene.statics.begin(), scene.statics.end(),
                            [](const auto& s) { return s.name == "floor"; });
  if (floor == scene.statics.end() || floor->mesh_file.empty()) {
    throw grbd::Error(scene.file.string() + ": expected a static mesh named \"floor\"");
  }
  grbd::body::TriangleMesh plate = grbd::body::read_obj(floor->mesh_file);
  plate.V *= D;
  floor->shape = std::make_shared<const grbd::collision::StaticMesh>(std::move(plate));
  return scene;
}
// [beverloo floor]

Discharge discharge(const grbd::scene::Scene& base, double D, double t_start, double slab_lo,
                    double slab_hi) {
  Discharge out;
  out.D = D;
  const grbd::scene::Scene scene = with_orifice(base, D);
  const double width = grbd::scene::silo_width(scene);
  const grbd::scene::Slices slab{slab_lo, slab_hi - slab_lo, 1, width * width};
  grbd::scene::Simulation sim(scene);
  std::size_t samples = 0;
  const auto start = std::chrono::steady_clock::now();
  while (!sim.finished()) {
    out.accuracy.add(sim.step());
    sim.created().clear();  // no output: nobody needs the new bodies' constants
    const double t = sim.stepper().time();
    out.t.push_back(t);
    out.mass.push_back(sim.mass_removed());
    if (t >= t_start && sim.stepper().steps() % 10 == 0) {
      out.rho_b += grbd::scene::slice_masses(sim, slab)[0] / (slab.area * slab.h);
      ++samples;
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.rho_b /= static_cast<double>(samples);
  out.W = grbd::scene::steady_rate(out.t, out.mass, t_start);
  out.bodies = sim.system().size();
  out.steps = sim.stepper().steps();
  out.accuracy.unit = sim.stepper().overlap_unit();
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<scene.toml>", "[end_time t_start D_mm...]"},
          "runs Beverloo's silo for each orifice diameter and fits C and k; writes discharge.csv, "
          "beverloo.csv, beverloo_curve.csv and beverloo.txt",
          2, static_cast<std::size_t>(argc))) {
    return *exit;
  }
  try {
    const std::filesystem::path dir = argv[1];
    grbd::scene::Scene scene = grbd::scene::load_scene(argv[2]);
    double t_start = 0.2;
    std::vector<double> sizes = {0.020, 0.024, 0.028, 0.032};
    if (argc >= 4) scene.end_time = grbd::demo::parse_number(argv[3], "end_time");
    if (argc >= 5) t_start = grbd::demo::parse_number(argv[4], "t_start");
    if (argc >= 6) {
      sizes.clear();
      for (int i = 5; i < argc; ++i) sizes.push_back(1e-3 * grbd::demo::parse_number(argv[i], "D_mm"));
    }
    // The mean diameter of the fill's distribution, and the slab of the bulk density: the upper
    // half of the bed, clear of the orifice's flowing zone and of the inflow region.
    const auto& fill = scene.groups.front();
    const double d = 2.0 * fill.radius.mean();
    const double g = -scene.settings.I_g.z();
    std::vector<Discharge> runs;
    for (double D : sizes) {
      runs.push_back(discharge(scene, D, t_start, 0.035, 0.06));
      const Discharge& r = runs.back();
      std::cout << kProgram << ": D = " << r.D * 1e3 << " mm (D/d = " << r.D / d
                << "): W = " << r.W.rate << " ± " << r.W.error << " kg/s, rho_b = " << r.rho_b
                << " kg/m^3, " << r.bodies << " bodies at the end, " << r.steps << " steps in "
                << r.seconds << " s\n";
    }
    std::vector<double> D, W, rho;
    for (const auto& r : runs) {
      D.push_back(r.D);
      W.push_back(r.W.rate);
      rho.push_back(r.rho_b);
    }
    const grbd::scene::BeverlooFit fit = grbd::scene::fit_beverloo(D, W, rho, g, d);

    grbd::demo::OutputFile series(dir / "discharge.csv");
    series << "# t_s";
    for (const auto& r : runs) series << " mass_kg_D" << std::lround(r.D * 1e3) << "mm";
    series << '\n';
    for (std::size_t k = 0; k < runs.front().t.size(); k += 5) {
      series << runs.front().t[k];
      for (const auto& r : runs) series << ' ' << r.mass[k];
      series << '\n';
    }
    series.finish();
    grbd::demo::OutputFile table(dir / "beverloo.csv");
    table << "# D_m W_kg_s W_error_kg_s rho_b_kg_m3 W_fit_kg_s W_literature_kg_s\n";
    for (const auto& r : runs) {
      table << r.D << ' ' << r.W.rate << ' ' << r.W.error << ' ' << r.rho_b << ' '
            << grbd::scene::beverloo_rate(fit.C, fit.k, r.rho_b, g, r.D, d) << ' '
            << grbd::scene::beverloo_rate(kLiteratureC, kLiteratureK, r.rho_b, g, r.D, d) << '\n';
    }
    table.finish();
    // The two laws on a fine grid of D, at the mean bulk density of the runs.
    double rho_mean = 0.0;
    for (double x : rho) rho_mean += x / static_cast<double>(rho.size());
    grbd::demo::OutputFile curve(dir / "beverloo_curve.csv");
    curve << "# D_m W_fit_kg_s W_literature_kg_s (rho_b = " << rho_mean << " kg/m^3)\n";
    const double D_lo = *std::min_element(D.begin(), D.end()) - 0.1 * d;
    const double D_hi = *std::max_element(D.begin(), D.end()) + 0.1 * d;
    for (int i = 0; i <= 100; ++i) {
      const double x = D_lo + (D_hi - D_lo) * i / 100.0;
      curve << x << ' ' << grbd::scene::beverloo_rate(fit.C, fit.k, rho_mean, g, x, d) << ' '
            << grbd::scene::beverloo_rate(kLiteratureC, kLiteratureK, rho_mean, g, x, d) << '\n';
    }
    curve.finish();
    std::ostringstream text;
    text << std::setprecision(4) << kProgram << ": d = " << d * 1e3 << " mm, silo width "
         << grbd::scene::silo_width(scene) * 1e3 << " mm, " << runs.size()
         << " orifices; fitted C = " << fit.C << ", k = " << fit.k << " (rms " << fit.rms * 100.0
         << " %), against C = " << kLiteratureC << ", k = " << kLiteratureK
         << " (Beverloo et al. 1961)\n";
    std::cout << text.str();
    grbd::demo::OutputFile summary(dir / "beverloo.txt");
    summary << text.str();
    summary.finish();
    // What the chapter quotes (\demo{ch07_beverloo/values.txt#KEY}), per orifice by its diameter
    // in millimetres.
    grbd::demo::Values values;
    double worst = 0.0;
    for (const auto& r : runs) {
      char prefix[32];
      std::snprintf(prefix, sizeof prefix, "D%ld.", std::lround(r.D * 1e3));
      const std::string key = prefix;
      const double literature =
          grbd::scene::beverloo_rate(kLiteratureC, kLiteratureK, r.rho_b, g, r.D, d);
      values.set(key + "D_over_d", "%.0f", r.D / d);
      values.set(key + "W", "%.1f", r.W.rate * 1e3);
      values.set(key + "W_error", "%.1f", r.W.error * 1e3);
      values.set(key + "rho_b", "%.0f", r.rho_b);
      values.set(key + "literature", "%.1f", literature * 1e3);
      values.set(key + "ratio", "%.2f", r.W.rate / literature);
      grbd::demo::set_accuracy(values, key, r.accuracy);
      worst = std::max(worst, std::abs(r.W.rate / literature - 1.0));
    }
    values.set("C", "%.2f", fit.C);
    values.set("k", "%.2f", fit.k);
    values.set("rms_percent", "%.1f", fit.rms * 100.0);
    values.set("worst_percent", "%.0f", worst * 100.0);
    values.write(dir / "values.txt");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 7 framework");
  }
}
