// Chapter 7 demo: Janssen's silo. Runs a scene file (a square silo of side D filled with beads
// that settle) through grbd::io::run, the same driver as `grbd run`, with its HDF5 + XDMF output
// in the data directory; after the last step it measures, from the contact percussions Λ of that
// step (forces F = Λ/Δt), in horizontal slices of the fill:
//   - the mean stress by Love's formula σ = (1/V) Σ_bodies Σ_contacts r ⊗ F, r the lever arm from
//     the body's centre to the contact point, V the slice volume D² h;
//   - the bulk density ρ_b (mass of the bodies whose centres lie in the slice over V);
//   - the stress ratio K = σ_h/σ_v, σ_h = (σ_xx + σ_yy)/2, σ_v = σ_zz (compressive positive);
//   - the mobilised wall friction μ_mob = Σ F_z / Σ F_N over the contacts with the side walls (the
//     vertical friction force that carries weight, over the normal force);
// fits Janssen's length λ in σ_v(d) = ρ_b g λ (1 − e^(−d/λ)) (d the depth below the free surface)
// by least squares, and compares it with Janssen's λ = D/(4 μ K) for μ = μ_w and μ = μ_mob.
// Checks the balance of the whole fill: the walls and the floor carry its weight.
//
// Usage: ch07_janssen <data directory> <scene.toml> [end_time]
// Writes silo.h5, silo.xmf, silo.ckpt.h5 (the run), janssen.csv (per slice), janssen.txt and
// values.txt (the numbers the chapter quotes).

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "grbd/io/run.hpp"
#include "grbd/scene/measure.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd_demo/demo.hpp"

namespace {

constexpr const char* kProgram = "ch07_janssen";

using grbd::Matrix3;
using grbd::Vector3;

struct Analysis {
  double D = 0.0, h = 0.0, rho_b = 0.0, z_surface = 0.0, K = 0.0, K_wall = 0.0, mu_w = 0.0,
         mu_mob = 0.0;
  double lambda_fit = 0.0, rms = 0.0, weight = 0.0, carried = 0.0;
  std::vector<double> depth, sigma_v, sigma_h, sigma_wall, rho;
  bool done = false;
};

Analysis analyse(const grbd::scene::Simulation& sim) {
  Analysis out;
  const auto& scene = sim.scene();
  out.D = grbd::scene::silo_width(scene);
  const double area = out.D * out.D;
  double mean_diameter = 0.0, mass = 0.0, z_top = 0.0;
  const auto states = sim.system().states();
  for (std::size_t i = 0; i < sim.system().size(); ++i) {
    mean_diameter += 2.0 * sim.system().bounding_radii()[i];
    mass += sim.system().inertia()[i].m;
    z_top = std::max(z_top, states[i].q[2]);
  }
  mean_diameter /= static_cast<double>(sim.system().size());
  out.h = 2.0 * mean_diameter;
  const grbd::scene::Slices grid{0.0, out.h, static_cast<std::size_t>(std::ceil(z_top / out.h)) + 1,
                                 area};
  const std::size_t slices = grid.count;
  const std::vector<Matrix3> sigma = grbd::scene::slice_stresses(sim, grid);
  const std::vector<double> slice_mass = grbd::scene::slice_masses(sim, grid);
  // One pass over the contacts with the static geometry (side b): the force they carry (the
  // balance of the fill), and on the side walls the normal stress per slice (Σ F_N over the
  // wall area 4 D h of the slice) and the mobilised friction Σ F_z / Σ F_N.
  std::vector<double> wall(slices, 0.0);
  const auto& problem = sim.stepper().problem();
  const auto lambda = sim.stepper().percussions();
  const double dt = scene.settings.dt;
  double normal = 0.0, vertical_friction = 0.0;
  for (std::size_t c = 0; c < problem.contacts.size(); ++c) {
    const auto& contact = problem.contacts[c];
    if (contact.body_b != grbd::collision::kStatic) continue;
    const Vector3 F = grbd::scene::contact_force(contact, lambda[c], dt);
    out.carried += F.z();
    if (std::abs(contact.n.z()) > 0.5) continue;  // the floor
    normal += lambda[c][0] / dt;
    vertical_friction += F.z();  // the friction that carries weight
    const std::size_t k = grid.slice_of(states[static_cast<std::size_t>(contact.body_a)].q[2]);
    if (k < slices) wall[k] += lambda[c][0] / dt / (4.0 * out.D * out.h);
  }
  out.mu_mob = vertical_friction / normal;
  // Bulk density: the slices between the first (layered against the floor) and the last two.
  const double g = -scene.settings.I_g.z();
  std::size_t bulk = 0;
  for (std::size_t k = 1; k + 3 < slices; ++k, ++bulk) out.rho_b += slice_mass[k] / (area * out.h);
  out.rho_b /= static_cast<double>(bulk);
  out.z_surface = mass / (out.rho_b * area);
  double K_sum = 0.0, K_wall_sum = 0.0;
  std::size_t K_count = 0;
  std::vector<double> d_fit, s_fit;
  for (std::size_t k = 0; k < slices; ++k) {
    const double z = (static_cast<double>(k) + 0.5) * out.h;
    const double sv = -sigma[k](2, 2);
    const double sh = -0.5 * (sigma[k](0, 0) + sigma[k](1, 1));
    out.depth.push_back(out.z_surface - z);
    out.sigma_v.push_back(sv);
    out.sigma_h.push_back(sh);
    out.sigma_wall.push_back(wall[k]);
    out.rho.push_back(slice_mass[k] / (area * out.h));
    if (k >= 1 && k + 3 < slices) {  // the bulk, as for ρ_b
      K_sum += sh / sv;
      K_wall_sum += wall[k] / sv;
      ++K_count;
      d_fit.push_back(out.z_surface - z);
      s_fit.push_back(sv);
    }
  }
  out.K = K_sum / static_cast<double>(K_count);
  out.K_wall = K_wall_sum / static_cast<double>(K_count);
  out.lambda_fit = grbd::scene::fit_janssen_length(d_fit, s_fit, out.rho_b * g);
  double sq = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < d_fit.size(); ++k) {
    const double model =
        out.rho_b * g * out.lambda_fit * (1.0 - std::exp(-d_fit[k] / out.lambda_fit));
    sq += (s_fit[k] - model) * (s_fit[k] - model);
    scale = std::max(scale, s_fit[k]);
  }
  out.rms = std::sqrt(sq / static_cast<double>(d_fit.size())) / scale;
  out.weight = mass * g;
  for (const auto& c : scene.contacts) {
    if (c.a != c.b) out.mu_w = c.law.mu;
  }
  out.done = true;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<scene.toml>", "[end_time]"},
          "runs Janssen's silo and fits the Janssen length; writes silo.h5, silo.xmf, janssen.csv "
          "and janssen.txt",
          2, 3)) {
    return *exit;
  }
  try {
    const std::filesystem::path dir = argv[1];
    grbd::scene::Scene scene = grbd::scene::load_scene(argv[2]);
    if (argc == 4) scene.end_time = grbd::demo::parse_number(argv[3], "end_time");
    grbd::io::RunOptions options;
    options.output = dir / "silo.h5";
    options.checkpoint = dir / "silo.ckpt.h5";
    options.overwrite = true;  // a demo remakes its figures: its own earlier run is replaced
    Analysis a;
    const std::uint64_t last = scene.steps();
    options.on_step = [&](const grbd::scene::Simulation& sim,
                          const grbd::timestep::StepReport& report, std::uint64_t) {
      if (report.step == last) a = analyse(sim);
    };
    const grbd::io::RunResult result = grbd::io::run(scene, options);
    if (!a.done) throw grbd::Error("the run stopped before its last step");

    grbd::demo::OutputFile csv(dir / "janssen.csv");
    csv << "# depth_m sigma_v_Pa sigma_h_Pa rho_kg_m3 janssen_fit_Pa hydrostatic_Pa "
           "sigma_wall_Pa\n";
    const double g = -scene.settings.I_g.z();
    for (std::size_t k = 0; k < a.depth.size(); ++k) {
      if (a.depth[k] < 0.0) continue;
      const double fit = a.rho_b * g * a.lambda_fit * (1.0 - std::exp(-a.depth[k] / a.lambda_fit));
      csv << a.depth[k] << ' ' << a.sigma_v[k] << ' ' << a.sigma_h[k] << ' ' << a.rho[k] << ' '
          << fit << ' ' << a.rho_b * g * a.depth[k] << ' ' << a.sigma_wall[k] << '\n';
    }
    csv.finish();
    const double lambda_w = a.D / (4.0 * a.mu_w * a.K);
    const double lambda_mob = a.D / (4.0 * a.mu_mob * a.K);
    const double lambda_wall = a.D / (4.0 * a.mu_mob * a.K_wall);
    std::ostringstream text;
    text << std::setprecision(4) << kProgram << ": D = " << a.D * 1e3 << " mm, " << result.steps
         << " steps in " << result.seconds << " s (output " << std::setprecision(2)
         << 100.0 * result.output_seconds / result.seconds << " %), " << std::setprecision(4)
         << "fill height " << a.z_surface * 1e3 << " mm, rho_b = " << a.rho_b
         << " kg/m^3; balance: walls and floor carry " << a.carried / a.weight
         << " of the weight; K = " << a.K << ", mu_w = " << a.mu_w
         << ", mobilised mu = " << a.mu_mob << "; fitted lambda = " << a.lambda_fit * 1e3
         << " mm (rms " << a.rms * 100.0
         << " % of max sigma_v); Janssen D/(4 mu_w K) = " << lambda_w * 1e3 << " mm (ratio "
         << a.lambda_fit / lambda_w << "), D/(4 mu_mob K) = " << lambda_mob * 1e3 << " mm (ratio "
         << a.lambda_fit / lambda_mob << "); at the walls K_w = sigma_wall/sigma_v = " << a.K_wall
         << ", D/(4 mu_mob K_w) = " << lambda_wall * 1e3 << " mm (ratio "
         << a.lambda_fit / lambda_wall << ")\n";
    std::cout << text.str();
    grbd::demo::OutputFile summary(dir / "janssen.txt");
    summary << text.str();
    summary.finish();
    // What the chapter quotes (\demo{ch07_janssen/values.txt#KEY}).
    grbd::demo::Values values;
    values.set("balance", "%.3f", a.carried / a.weight);
    values.set("rho_b", "%.0f", a.rho_b);
    values.set("packing", "%.2f", a.rho_b / *scene.groups.front().density);
    values.set("fill_height", "%.1f", a.z_surface * 1e3);
    values.set("K", "%.3f", a.K);
    values.set("K_wall", "%.3f", a.K_wall);
    values.set("mu_mob", "%.3f", a.mu_mob);
    values.set("mu_w", "%.1f", a.mu_w);
    values.set("mobilised_percent", "%.0f", 100.0 * a.mu_mob / a.mu_w);
    values.set("lambda_fit", "%.1f", a.lambda_fit * 1e3);
    values.set("rms_percent", "%.1f", a.rms * 100.0);
    values.set("lambda_mob", "%.1f", lambda_mob * 1e3);
    values.set("ratio_mob", "%.3f", a.lambda_fit / lambda_mob);
    values.set("agree_mob_percent", "%.1f", 100.0 * std::abs(a.lambda_fit / lambda_mob - 1.0));
    values.set("lambda_wall", "%.1f", lambda_wall * 1e3);
    values.set("ratio_wall", "%.2f", a.lambda_fit / lambda_wall);
    values.set("agree_wall_percent", "%.0f", 100.0 * std::abs(a.lambda_fit / lambda_wall - 1.0));
    values.set("lambda_w", "%.1f", lambda_w * 1e3);
    values.set("ratio_w", "%.2f", a.lambda_fit / lambda_w);
    values.set("ratio_w_short", "%.1f", a.lambda_fit / lambda_w);
    values.write(dir / "values.txt");
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 7 framework");
  }
}
