#pragma once
// Chapter 8's steady-flow study: what its two programs share — ch08_incline_run runs the incline
// scene at each angle, ch08_incline measures the runs.

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "grbd/scene/scene.hpp"

namespace incline {

/// The stem of the run at `angle` [°]: incline_<angle>.
inline std::string run_name(double angle) {
  char name[64];
  std::snprintf(name, sizeof name, "incline_%g", angle);
  return name;
}

// The scene at angle θ: gravity of the same size tilted to g (sin θ, 0, −cos θ), contacts output.
inline grbd::scene::Scene tilted(const grbd::scene::Scene& base, double angle) {
  grbd::scene::Scene scene = base;
  const double a = angle * std::numbers::pi / 180.0;
  scene.settings.I_g = base.settings.I_g.norm() * grbd::Vector3(std::sin(a), 0.0, -std::cos(a));
  scene.output.contacts = true;
  return scene;
}

}  // namespace incline
