#pragma once
/// \file
/// \brief Small scenes for the chapter-6 tests: spheres, boxes and capsules of uniform density as
/// BodySpecs, a floor, and a settled-pile generator.

#include <cmath>
#include <cstdint>
#include <random>

#include "grbd/body/mass_properties.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/materials.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::test {

/// A dynamic sphere of radius r and density ρ at I_r with velocity u.
inline timestep::BodySpec sphere_body(timestep::GlobalId id, double r, const Vector3& I_r,
                                      const Vector6& u = Vector6::Zero(), double rho = 2500.0,
                                      timestep::MaterialId material = 0) {
  const body::MassProperties mp = body::sphere_mass_properties(r, rho);
  timestep::BodySpec spec;
  spec.id = id;
  spec.state.q << I_r, 1.0, 0.0, 0.0, 0.0;
  spec.state.u = u;
  spec.inertia = {mp.mass, mp.M_Theta_S.diagonal()};
  spec.shape = collision::Sphere{r};
  spec.material = material;
  return spec;
}

/// A dynamic box of half extents h and density ρ at I_r, axes along I.
inline timestep::BodySpec box_body(timestep::GlobalId id, const Vector3& h, const Vector3& I_r,
                                   double rho = 1000.0) {
  const double m = rho * 8.0 * h.prod();
  timestep::BodySpec spec;
  spec.id = id;
  spec.state.q << I_r, 1.0, 0.0, 0.0, 0.0;
  spec.state.u.setZero();
  spec.inertia = {m, Vector3(m / 3.0 * (h.y() * h.y() + h.z() * h.z()),
                             m / 3.0 * (h.x() * h.x() + h.z() * h.z()),
                             m / 3.0 * (h.x() * h.x() + h.y() * h.y()))};
  spec.shape = collision::Box{h};
  return spec;
}

/// The floor z = 0 as static object `id`.
inline timestep::StaticObject floor_object(timestep::GlobalId id = 0,
                                           timestep::MaterialId material = 0) {
  timestep::StaticObject floor;
  floor.id = id;
  floor.shape = collision::HalfSpace{Vector3::UnitZ(), 0.0};
  floor.material = material;
  return floor;
}

/// One material "m" whose pairs with itself have the law (μ, ε_N, ε_T).
inline timestep::MaterialTable one_material(double mu, double eps_N = 0.0, double eps_T = 0.0) {
  timestep::MaterialTable table;
  const timestep::MaterialId m = table.add("m");
  table.set_pair(m, m, {mu, eps_N, eps_T});
  return table;
}

/// Spheres of radius r on a jittered cubic lattice of nx × ny × nz sites above the floor, inside
/// walls x, y ∈ [0, L], dropped from rest: after a few hundred steps, a settled pile. Ids 1…N in
/// lattice order; seeded.
inline void add_sphere_lattice(timestep::BodySystem& system, int nx, int ny, int nz, double r,
                               std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.1 * r, 0.1 * r);
  const double a = 2.4 * r;
  timestep::GlobalId id = 1;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const Vector3 c(r + 0.2 * r + a * i + jitter(rng), r + 0.2 * r + a * j + jitter(rng),
                        1.1 * r + a * k);
        system.add(sphere_body(id++, r, c));
      }
    }
  }
}

/// The floor and four walls of a box [0, Lx] × [0, Ly] open at the top, static ids 0–4.
inline void add_open_box(timestep::StaticGeometry& statics, double Lx, double Ly) {
  statics.add(floor_object(0));
  const auto wall = [&](timestep::GlobalId id, const Vector3& n, double offset) {
    timestep::StaticObject w;
    w.id = id;
    // The solid is { x : nᵀx ≤ offset }: the wall's outward normal points into the box.
    w.shape = collision::HalfSpace{n, offset};
    statics.add(w);
  };
  wall(1, Vector3::UnitX(), 0.0);
  wall(2, -Vector3::UnitX(), -Lx);
  wall(3, Vector3::UnitY(), 0.0);
  wall(4, -Vector3::UnitY(), -Ly);
}

}  // namespace grbd::test
