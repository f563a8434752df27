// Ten Moreau steps of two spheres over a floor, built against an installed grbd: one rests on the
// floor and must stay at rest, the other falls freely, z = z0 − g t²/2 (exact for the midpoint
// scheme under constant gravity, up to round-off). Exit code 0 when both hold.
#include <cmath>
#include <cstdio>

#include "grbd/body/mass_properties.hpp"
#include "grbd/timestep/stepper.hpp"
#include "grbd/version.hpp"

int main() {
  using namespace grbd;
  timestep::BodySystem system;
  timestep::StaticGeometry statics;
  timestep::MaterialTable materials;
  const timestep::MaterialId glass = materials.add("glass");
  materials.set_pair(glass, glass, {0.5, 0.0, 0.0});
  statics.add({0, collision::HalfSpace{}, {}, glass});  // the floor z ≤ 0
  const double r = 0.01;
  const body::MassProperties mp = body::sphere_mass_properties(r, 2500.0);
  const double heights[2] = {r, 1.0};  // on the floor; a metre above it
  for (int i = 0; i < 2; ++i) {
    timestep::BodyRecord sphere;
    sphere.id = static_cast<timestep::GlobalId>(i);
    sphere.state.q << 0.1 * i, 0.0, heights[i], 1.0, 0.0, 0.0, 0.0;
    sphere.state.u.setZero();
    sphere.inertia = {mp.mass, mp.M_Theta_S.diagonal()};
    sphere.shape = collision::Sphere{r};
    sphere.material = glass;
    system.add(sphere);
  }
  timestep::StepSettings settings;
  settings.dt = 1e-3;
  timestep::MoreauStepper stepper(system, statics, materials, settings);
  for (int step = 0; step < 10; ++step) stepper.step();
  const double t = stepper.time(), g = -settings.I_g.z();
  const auto rest = system.states()[system.index_of(0)];
  const auto fall = system.states()[system.index_of(1)];
  const double rest_error = std::abs(rest.q.z() - r) + rest.u.norm();
  const double fall_error = std::abs(fall.q.z() - (1.0 - 0.5 * g * t * t)) +
                            std::abs(fall.u.z() + g * t);
  std::printf("grbd %s: after %llu steps, resting sphere off by %.1e, falling sphere by %.1e\n",
              GRBD_VERSION, static_cast<unsigned long long>(stepper.steps()), rest_error,
              fall_error);
  return stepper.steps() == 10 && rest_error < 1e-12 && fall_error < 1e-12 ? 0 : 1;
}
