#pragma once
// Chapter 5: the sphere packings on which the demos and the benchmark solve contact problems.
//
// A block of nx × ny × nz face-centred cubic cells of glass-like spheres (radius r, density
// 2500 kg/m³) standing on the ground z = 0, every sphere overlapping its twelve lattice
// neighbours (and the bottom layer the ground) by `overlap`·r, so that each interior sphere has
// twelve contacts. The bodies are numbered in Morton order of their cells, as a time stepper
// reorders them, and the contacts come from the collision world of chapter 4. The contact
// problem is that of one time step h under gravity from rest: u_free = h g.

#include <cmath>
#include <cstdint>
#include <vector>

#include "grbd/body/mass_properties.hpp"
#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/broad_phase.hpp"
#include "grbd/collision/world.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/contact/warm_start.hpp"
#include "grbd/kinematics/exponential.hpp"
#include "grbd/kinematics/quaternion.hpp"

namespace grbd::demo {

/// The bodies, states and contacts of a packing and its contact problem.
struct SpherePile {
  std::vector<body::RigidBody> bodies;        ///< one per sphere
  std::vector<body::State> states;            ///< at rest
  std::vector<collision::Contact> contacts;   ///< sphere–sphere and sphere–ground
  contact::ContactProblem problem;            ///< the step from rest under gravity
  collision::CollisionWorld world;            ///< the ground and one sphere per body
  double h = 0.0;                             ///< time step [s]
  double mu = 0.0;                            ///< friction coefficient
};

/// The contact problem of the step after `pile.problem`, for the end velocities u of its
/// solution: every body moves by h u (position, and orientation by the exponential map), the
/// contacts are detected anew, and u_free = u + h g. A crude explicit Moreau step, enough to give
/// the next problem a warm start its predecessor prepared (chapter 6 does this properly).
inline void advance(SpherePile& pile, const std::vector<Vector6>& u) {
  for (std::size_t b = 0; b < pile.states.size(); ++b) {
    body::State& s = pile.states[b];
    s.u = u[b];
    s.q.head<3>() += pile.h * u[b].head<3>();
    const kinematics::Quaternion p(Vector4(s.q.tail<4>()));
    s.q.tail<4>() =
        (p * kinematics::quaternion_from_rotation_vector(pile.h * u[b].tail<3>())).coeffs();
  }
  pile.world.detect(pile.states, 0.0, pile.contacts);
  std::vector<Vector6> u_free = u;
  for (Vector6& v : u_free) v(2) -= 9.81 * pile.h;
  pile.problem = contact::assemble_problem(pile.contacts, pile.bodies, pile.states, u_free,
                                           contact::ContactMaterial{pile.mu, 0.0, 0.0});
}

/// Solves the pile's problem with SOR and `options`, stores its percussions by contact key in
/// `previous` and advances the pile to the next step with its end velocities (advance()): the
/// next problem, with its warm start at hand (previous.initialize()). Returns SOR's result.
inline contact::SolverResult solve_and_advance(SpherePile& pile,
                                               const contact::SolverOptions& options,
                                               contact::WarmStart& previous) {
  contact::ContactSolution first;
  const contact::SolverResult result = contact::solve_sor(pile.problem, first, options);
  previous.store(pile.problem.keys, first.lambda);
  advance(pile, first.u);
  return result;
}

/// A pile of nx × ny × nz FCC cells (4 spheres each) of radius r, time step h, friction μ.
inline SpherePile sphere_pile(int nx, int ny, int nz, double r = 1e-3, double h = 2e-4,
                              double mu = 0.5, double overlap = 1e-3) {
  const double d = 2.0 * r * (1.0 - overlap);   // nearest-neighbour distance
  const double a = d * std::sqrt(2.0);          // cubic cell edge
  const Vector3 basis[4] = {{0.0, 0.0, 0.0}, {0.5, 0.5, 0.0}, {0.5, 0.0, 0.5}, {0.0, 0.5, 0.5}};
  std::vector<Vector3> centres;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        for (const Vector3& b : basis) {
          centres.push_back(a * (Vector3(i, j, k) + b) + Vector3(0.0, 0.0, r * (1.0 - overlap)));
        }
      }
    }
  }
  const std::vector<std::int32_t> order = collision::morton_order(centres, 2.0 * r);

  const body::MassProperties glass = body::sphere_mass_properties(r, 2500.0);
  SpherePile pile;
  pile.h = h;
  pile.mu = mu;
  collision::CollisionWorld& world = pile.world;
  world.add({collision::HalfSpace{Vector3::UnitZ(), 0.0}, collision::kStatic, Vector3::Zero(),
             Matrix3::Identity()});
  for (std::size_t b = 0; b < order.size(); ++b) {
    body::State s;
    s.q << centres[static_cast<std::size_t>(order[b])], 1.0, 0.0, 0.0, 0.0;
    s.u.setZero();
    pile.states.push_back(s);
    pile.bodies.push_back({glass.mass, glass.M_Theta_S.diagonal()});
    world.add({collision::Sphere{r}, static_cast<collision::BodyIndex>(b), Vector3::Zero(),
               Matrix3::Identity()});
  }
  world.detect(pile.states, 0.0, pile.contacts);

  std::vector<Vector6> u_free(pile.states.size(), Vector6::Zero());
  for (Vector6& u : u_free) u(2) = -9.81 * h;
  pile.problem = contact::assemble_problem(pile.contacts, pile.bodies, pile.states, u_free,
                                           contact::ContactMaterial{mu, 0.0, 0.0});
  return pile;
}

}  // namespace grbd::demo
