#pragma once
// Chapter 6: the scenes of the validation cases, shared by the demo ch06_validation and the tests
// (tests/06-moreau-timestepping): spheres and boxes of uniform density as BodyRecords, the floor and
// other half-spaces, one-material tables, the tight solver settings of the closed-form checks,
// tilted gravity for the incline, the Painlevé rod, and a jittered lattice of spheres in an open
// box.

#include <cmath>
#include <numbers>
#include <cstdint>
#include <random>

#include "grbd/body/mass_properties.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/materials.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::demo {

/// A dynamic sphere of radius r and density ρ at I_r with velocity u.
inline timestep::BodyRecord sphere_body(timestep::GlobalId id, double r, const Vector3& I_r,
                                      const Vector6& u = Vector6::Zero(), double rho = 2500.0,
                                      timestep::MaterialId material = 0) {
  const body::MassProperties mp = body::sphere_mass_properties(r, rho);
  timestep::BodyRecord spec;
  spec.id = id;
  spec.state.q << I_r, 1.0, 0.0, 0.0, 0.0;
  spec.state.u = u;
  spec.inertia = {mp.mass, mp.M_Theta_S.diagonal()};
  spec.shape = collision::Sphere{r};
  spec.material = material;
  return spec;
}

/// A dynamic box of half extents h and density ρ at I_r, axes along I.
inline timestep::BodyRecord box_body(timestep::GlobalId id, const Vector3& h, const Vector3& I_r,
                                   double rho = 1000.0) {
  const double m = rho * 8.0 * h.prod();
  timestep::BodyRecord spec;
  spec.id = id;
  spec.state.q << I_r, 1.0, 0.0, 0.0, 0.0;
  spec.state.u.setZero();
  spec.inertia = {m, Vector3(m / 3.0 * (h.y() * h.y() + h.z() * h.z()),
                             m / 3.0 * (h.x() * h.x() + h.z() * h.z()),
                             m / 3.0 * (h.x() * h.x() + h.y() * h.y()))};
  spec.shape = collision::Box{h};
  return spec;
}

/// The half-space nᵀx ≤ offset (outward normal n) as static object `id`.
inline timestep::StaticObject half_space(timestep::GlobalId id, const Vector3& n, double offset,
                                         timestep::MaterialId material = 0) {
  timestep::StaticObject object;
  object.id = id;
  object.shape = collision::HalfSpace{n, offset};
  object.material = material;
  return object;
}

/// The floor z = 0 as static object `id`.
inline timestep::StaticObject floor_object(timestep::GlobalId id = 0,
                                           timestep::MaterialId material = 0) {
  return half_space(id, Vector3::UnitZ(), 0.0, material);
}

/// One material "m" whose pairs with itself have the law (μ, ε_N, ε_T).
inline timestep::MaterialTable one_material(double mu, double eps_N = 0.0, double eps_T = 0.0) {
  timestep::MaterialTable table;
  const timestep::MaterialId m = table.add("m");
  table.set_pair(m, m, {mu, eps_N, eps_T});
  return table;
}

/// Solver settings for the closed-form checks: tolerances far below the effects measured, and a
/// step that does not converge stops the run.
inline timestep::StepSettings tight(double dt) {
  timestep::StepSettings s;
  s.dt = dt;
  s.solver.abs_tol = 1e-15;
  s.solver.rel_tol = 1e-12;
  s.solver.max_iterations = 100000;
  s.on_non_convergence = timestep::NonConvergence::stop;
  return s;
}

/// Gravity g = 9.81 m/s² tilted by θ about y: the floor z = 0 becomes an incline of angle θ,
/// downhill along +x.
inline Vector3 tilted_gravity(double theta) {
  return 9.81 * Vector3(std::sin(theta), 0.0, -std::cos(theta));
}

/// A uniform rod (a capsule of radius 1 cm and half length 0.5 m, 1 kg) leaning forward at 45°
/// with its lower end touching the floor, sliding at 2 m/s: with μ = 1.5 > 4/3 it is in the
/// Painlevé window of a rod (k = m l²/I = 3: μ > 2√(1 + k)/k; Stewart 2000).
inline timestep::BodyRecord painleve_rod() {
  const double l = 0.5;
  const double r = 0.01;
  const double m = 1.0;
  const double tilt = std::numbers::pi / 4.0;
  timestep::BodyRecord rod;
  rod.id = 1;
  rod.shape = collision::Capsule{r, l};
  rod.inertia = {m, Vector3(m * l * l / 3.0, m * l * l / 3.0, 1e-3 * m * r * r)};
  rod.state.q << (r + l * std::cos(tilt)) * Vector3::UnitZ(),
      kinematics::quaternion_from_axis_angle(Vector3::UnitY(), tilt).coeffs();
  rod.state.u << -2.0, 0.0, 0.0, 0.0, 0.0, 0.0;
  return rod;
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
  // The solid of each wall is { x : nᵀx ≤ offset }: its outward normal points into the box.
  statics.add(floor_object(0));
  statics.add(half_space(1, Vector3::UnitX(), 0.0));
  statics.add(half_space(2, -Vector3::UnitX(), -Lx));
  statics.add(half_space(3, Vector3::UnitY(), 0.0));
  statics.add(half_space(4, -Vector3::UnitY(), -Ly));
}

}  // namespace grbd::demo
