#pragma once
// Chapter 8's steady-flow study: what its programs share — ch08_incline_run runs the incline
// scene for each layer, ch08_incline measures the deep layers' steady flows and ch08_hstop where
// layers of several depths stop.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/io/output.hpp"
#include "grbd/parallel/flow_profile.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd_demo/demo.hpp"

namespace incline {

/// One run of the study: the incline scene at `angle` [°] with `count` beads (0: the scene's)
/// and bead–bead friction `mu` (none: the scene's). Written on the command lines as "θ", "θ:n"
/// or "θ:n:μ".
struct Layer {
  double angle = 0.0;
  std::uint64_t count = 0;
  std::optional<double> mu;
};

/// A layer from its text "θ", "θ:n" or "θ:n:μ"; grbd::Error names the text otherwise.
inline Layer parse_layer(std::string_view text) {
  Layer layer;
  std::vector<std::string> parts(1);
  for (const char c : text) {
    if (c == ':') {
      parts.emplace_back();
    } else {
      parts.back() += c;
    }
  }
  if (parts.size() > 3) {
    throw grbd::Error("layer \"" + std::string(text) + "\": expected θ, θ:n or θ:n:μ");
  }
  layer.angle = grbd::demo::parse_number(parts[0], "layer's angle");
  if (!(layer.angle > 0.0 && layer.angle < 90.0)) {
    throw grbd::Error("layer \"" + std::string(text) + "\": expected an angle in (0, 90) degrees");
  }
  if (parts.size() > 1) {
    const double n = grbd::demo::parse_number(parts[1], "layer's bead count");
    if (!(n >= 1.0 && n <= 1e9 && n == std::floor(n))) {
      throw grbd::Error("layer \"" + std::string(text) + "\": expected a whole count of beads >= 1");
    }
    layer.count = static_cast<std::uint64_t>(n);
  }
  if (parts.size() > 2) {
    layer.mu = grbd::demo::parse_number(parts[2], "layer's friction coefficient");
    if (*layer.mu < 0.0) {
      throw grbd::Error("layer \"" + std::string(text) + "\": expected a friction coefficient >= 0");
    }
  }
  return layer;
}

/// The stem of a layer's run: incline_<θ>, incline_<θ>_<n> or incline_<θ>_<n>_mu<μ>.
inline std::string run_name(const Layer& layer) {
  char name[96];
  if (layer.mu) {
    std::snprintf(name, sizeof name, "incline_%g_%llu_mu%g", layer.angle,
                  static_cast<unsigned long long>(layer.count), *layer.mu);
  } else if (layer.count > 0) {
    std::snprintf(name, sizeof name, "incline_%g_%llu", layer.angle,
                  static_cast<unsigned long long>(layer.count));
  } else {
    std::snprintf(name, sizeof name, "incline_%g", layer.angle);
  }
  return name;
}

/// The stem of the deep layer's run at `angle` [°]: incline_<angle>.
inline std::string run_name(double angle) { return run_name(Layer{angle, 0, std::nullopt}); }

/// The group of the moving beads (the first group that is not fixed).
template <class SceneType>
auto& beads(SceneType& scene) {
  for (auto& g : scene.groups) {
    if (!g.fixed) return g;
  }
  throw grbd::Error("the incline scene has no group of moving beads");
}

// The scene at angle θ: gravity of the same size tilted to g (sin θ, 0, −cos θ), contacts output.
inline grbd::scene::Scene tilted(const grbd::scene::Scene& base, double angle) {
  grbd::scene::Scene scene = base;
  const double a = angle * std::numbers::pi / 180.0;
  scene.settings.I_g = base.settings.I_g.norm() * grbd::Vector3(std::sin(a), 0.0, -std::cos(a));
  scene.output.contacts = true;
  return scene;
}

/// The scene of a layer: tilted to its angle, its count of beads (the first sites of the
/// lattice, so that a layer fills the box from the base up) and every contact law's μ.
inline grbd::scene::Scene layer_scene(const grbd::scene::Scene& base, const Layer& layer) {
  grbd::scene::Scene scene = tilted(base, layer.angle);
  if (layer.count > 0) beads(scene).generator.count = layer.count;
  if (layer.mu) {
    for (auto& law : scene.contacts) law.law.mu = *layer.mu;
  }
  return scene;
}

/// The kinetic energy's change over the second half of a run [%]: the mean of the steps' last
/// tenth over the mean of the tenth that starts at the half (0 for a run whose energy there is 0).
inline double energy_change(const std::vector<grbd::io::StepInfo>& steps) {
  const std::size_t n = steps.size(), w = std::max<std::size_t>(n / 10, 1);
  if (n < 2) throw grbd::Error("too few steps for the kinetic energy's change");
  double early = 0.0, late = 0.0;
  for (std::size_t k = 0; k < w; ++k) {
    early += steps[n / 2 + k].kinetic_energy;
    late += steps[n - 1 - k].kinetic_energy;
  }
  return early > 0.0 ? 100.0 * (late / early - 1.0) : 0.0;
}

/// A layer's profiles across the depth, averaged over the records from `first_record` on.
struct Profile {
  grbd::parallel::DepthProfile depth;  ///< φ, u and (with contacts) the stresses in slabs
  double diameter = 0.0;               ///< the beads' mean diameter [m]
  double density = 0.0;                ///< theirs [kg/m³]
  double bin = 0.0;                    ///< the slabs' thickness, half a grain [m]
  std::size_t bins = 0;                ///< slabs from z = 0 up to 10 cm
  double area = 0.0;                   ///< the box's cross-section [m²]
  double base = 0.0;                   ///< the top of the fixed beads [m]
  double surface = 0.0;                ///< where φ falls to half the bulk's [m]
  double bulk_packing = 0.0;           ///< the bulk's φ: the densest grain-thick pair of slabs
  double mean_u = 0.0;                 ///< the depth average of u over the layer [m/s]
  double surface_u = 0.0;              ///< u in the last slab below the surface [m/s]
  std::size_t first = 0;               ///< the first slab above the base
  std::size_t records = 0;             ///< records averaged
  double fastest = 0.0;                ///< the fastest bead's speed in the last record [m/s]
  double height() const { return surface - base; }
};

/// The profile of the run `output` of `scene` over its records from `first_record` on, in slabs
/// of half a grain up to 10 cm; with `contacts`, each record's contacts are added (their stresses)
/// and `on_record(profile, contacts)` is called with the profile so far and each record's contacts. The base is the top of the fixed beads
/// (the bodies whose velocity is exactly zero: a moving bead never has all three components exactly
/// zero); the bulk's φ is the largest mean of two neighbouring slabs above the base — the densest
/// grain's thickness, which a layer two grains deep has as a layer of twelve does; the surface the
/// height above it where φ falls to half of that, interpolated between slab centres.
template <class OnRecord>
Profile layer_profile(const std::filesystem::path& output, const grbd::scene::Scene& scene,
                      std::uint64_t first_record, bool contacts, OnRecord&& on_record) {
  const grbd::io::OutputSummary summary = grbd::io::read_summary(output);
  if (summary.records < first_record + 2) {
    throw grbd::Error(output.string() + ": too few records to average (" +
                      std::to_string(summary.records) + ")");
  }
  const auto& box = scene.domain.box;
  const double area = (box.max.x() - box.min.x()) * (box.max.y() - box.min.y());
  double fixed_radius = 0.0, density = 0.0, diameter = 0.0;
  for (const auto& g : scene.groups) {
    if (g.fixed) {
      fixed_radius = std::max(fixed_radius, g.radius.max());
    } else {
      density = *g.density;
      diameter = g.radius.min() + g.radius.max();  // the mean of a uniform distribution, twice
    }
  }
  const double bin = 0.5 * diameter;
  const auto bins = static_cast<std::size_t>(std::ceil(0.1 / bin));
  Profile p{grbd::parallel::DepthProfile(0.0, bin, bins, area, density), diameter, density, bin,
            bins, area};
  std::vector<grbd::Vector3> centres, velocities;
  double base = -1e300;
  for (std::uint64_t k = first_record; k < summary.records; ++k) {
    const grbd::io::Record record = grbd::io::read_record(output, k);
    centres.clear();
    velocities.clear();
    p.fastest = 0.0;
    for (const auto& x : record.states) {
      centres.push_back(x.q.head<3>());
      velocities.push_back(x.u.head<3>());
      if (x.u.head<3>().isZero(0.0)) base = std::max(base, x.q.z());
      p.fastest = std::max(p.fastest, x.u.head<3>().norm());
    }
    p.depth.add_bodies(centres, velocities, record.radius);
    if (contacts) {
      const std::vector<grbd::io::RecordContact> found = grbd::io::read_contacts(output, k);
      p.depth.add_contacts(found, scene.settings.dt);
      on_record(static_cast<const Profile&>(p), found);
    }
    ++p.records;
  }
  if (base == -1e300) throw grbd::Error(output.string() + ": no fixed beads: no base");
  p.base = base + fixed_radius;
  const std::vector<double> z = p.depth.z(), phi = p.depth.packing(), u = p.depth.velocity();
  while (p.first < z.size() && z[p.first] < p.base) ++p.first;
  std::size_t densest = p.first;
  for (std::size_t k = p.first; k + 1 < z.size(); ++k) {
    const double pair = 0.5 * (phi[k] + phi[k + 1]);
    if (pair > p.bulk_packing) {
      p.bulk_packing = pair;
      densest = k;
    }
  }
  const double level = 0.5 * p.bulk_packing;
  p.surface = -1.0;
  for (std::size_t k = densest + 1; k < z.size(); ++k) {
    if (phi[k] < level && phi[k - 1] >= level) {
      p.surface = z[k - 1] + (z[k] - z[k - 1]) * (phi[k - 1] - level) / (phi[k - 1] - phi[k]);
      break;
    }
  }
  if (p.surface < 0.0) {
    throw grbd::Error(output.string() + ": no free surface in the profile: the layer fills the box");
  }
  double sum = 0.0, n = 0.0;
  for (std::size_t k = p.first; k < z.size() && z[k] <= p.surface; ++k) {
    sum += u[k];
    n += 1.0;
    p.surface_u = u[k];
  }
  p.mean_u = n > 0.0 ? sum / n : 0.0;
  return p;
}

}  // namespace incline
