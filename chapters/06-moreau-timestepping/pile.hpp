#pragma once
// Chapter 6: a settled sphere pile as a BodySystem, for the benchmark and the demos.
//
// The packing of chapter 5 (sphere_pile.hpp): nx × ny × nz face-centred cubic cells of glass-like
// spheres (radius r, density 2500 kg/m³) on the ground z = 0, every sphere overlapping its twelve
// lattice neighbours (and the bottom layer the ground) by `overlap`·r, with about six contacts
// per sphere. Four walls hold the sides, so that the pile is at rest (without them its edges
// roll off). Global ids 1…N follow the lattice; the system is then reordered along the Morton
// curve, as the stepper does every few steps.

#include <cmath>
#include <vector>

#include "grbd/body/mass_properties.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/materials.hpp"
#include "scenes.hpp"

namespace grbd::demo {

/// The ground (static object 0, material 0) and the spheres (material 0) of an FCC pile.
inline void fcc_pile(timestep::BodySystem& system, timestep::StaticGeometry& statics, int nx,
                     int ny, int nz, double r = 1e-3, double overlap = 1e-3) {
  const double d = 2.0 * r * (1.0 - overlap);  // nearest-neighbour distance
  const double a = d * std::sqrt(2.0);         // cubic cell edge
  const Vector3 basis[4] = {{0.0, 0.0, 0.0}, {0.5, 0.5, 0.0}, {0.5, 0.0, 0.5}, {0.0, 0.5, 0.5}};
  const body::MassProperties glass = body::sphere_mass_properties(r, 2500.0);
  system.reserve(system.size() + 4 * static_cast<std::size_t>(nx * ny * nz));
  timestep::GlobalId id = 1;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        for (const Vector3& b : basis) {
          timestep::BodyRecord spec;
          spec.id = id++;
          spec.state.q << a * (Vector3(i, j, k) + b) + Vector3(0.0, 0.0, r * (1.0 - overlap)),
              1.0, 0.0, 0.0, 0.0;
          spec.state.u.setZero();
          spec.inertia = {glass.mass, glass.M_Theta_S.diagonal()};
          spec.shape = collision::Sphere{r};
          system.add(spec);
        }
      }
    }
  }
  system.reorder_morton(2.0 * r);
  // The ground and four walls touching the outermost spheres: x, y ∈ [−r, a (n − ½) + r].
  statics.add(half_space(0, Vector3::UnitZ(), 0.0));
  statics.add(half_space(1, Vector3::UnitX(), -r));
  statics.add(half_space(2, -Vector3::UnitX(), -(a * (nx - 0.5) + r)));
  statics.add(half_space(3, Vector3::UnitY(), -r));
  statics.add(half_space(4, -Vector3::UnitY(), -(a * (ny - 0.5) + r)));
}

/// One material, glass on glass and on the ground: μ = 0.5, no restitution.
inline timestep::MaterialTable glass_materials(double mu = 0.5) {
  timestep::MaterialTable table;
  const timestep::MaterialId glass = table.add("glass");
  table.set_pair(glass, glass, {mu, 0.0, 0.0});
  return table;
}

}  // namespace grbd::demo
