#pragma once
/// \file
/// \brief Contact problems shared by the chapter 5 tests: seeded random well-posed problems in
/// body form, sphere columns and pyramids assembled through the collision world, an inclined
/// contact with a closed-form answer, and dense references that share no code with the solvers:
/// the matrices W, M⁻¹, the Delassus matrix G = WᵀM⁻¹W and the free velocity
/// c = Wᵀ u_free + ε ∘ γ_A written out with Eigen, and the conversion of a body-form problem to
/// the local form ξ = G λ + c.
///
/// Conventions (problem.hpp): per contact λ and ξ are ordered normal first; body a enters with
/// +W_a, body b with −W_b, so that the column block of contact i in the global W (6N × 3n) holds
/// +W_a in the rows of body a and −W_b in the rows of body b, and u = u_free + M⁻¹ W Λ.

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/contact.hpp"
#include "grbd/collision/shapes.hpp"
#include "grbd/collision/world.hpp"
#include "grbd/contact/local_problem.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd_test/random.hpp"

namespace grbd::test {

/// What random_problem() makes.
struct RandomProblemSpec {
  int bodies = 4;                ///< N bodies
  int contacts = 4;              ///< n ≤ N contacts (more are cut to N)
  double static_fraction = 0.3;  ///< probability that side b of a contact is the fixed world
  double mu_max = 1.0;           ///< μ uniform in [0, mu_max]; 0 makes the problem frictionless
  bool restitution = false;  ///< random ε_N ∈ [0, 1], ε_T ∈ [−1, 1] and γ_A ∈ [−1, 1)³
  double u_free_scale = 1.0;  ///< each entry of u_free uniform in [−scale, scale)
};

/// A random body-form problem: N bodies with mass in [0.5, 3), principal moments in [0.1, 3)
/// (M⁻¹ = diag(1/m I₃, K_Θ⁻¹) in the body frame) and uniformly random orientations; n ≤ N
/// contacts. Contact i has side a on body π(i) of a random permutation π (every body is side a
/// of at most one contact) and side b on a random other body or, with probability
/// static_fraction, on the fixed world. The contact frame is a uniformly random unit normal with
/// collision::tangent_basis(); the lever arms K_ρ are random in [−1, 1)³; W_a, W_b come from
/// collision::contact_jacobian() at the body orientations. keys stay empty.
///
/// Well-posedness: G = WᵀM⁻¹W is positive definite (for generic random numbers). Proof sketch:
/// let WΛ = 0. A body that is side a of its contact and side b of none (or of contacts whose λ
/// is already known to vanish) balances λ of that one contact alone, and W_a has full column
/// rank, so λ = 0; peeling such bodies leaves only cycles of the graph a → b, on which every
/// body carries two forces, which must be equal and opposite along the line through its two
/// contact points — lines of random directions, hence λ = 0 there too. With G positive definite
/// the Coulomb problem has a solution for every u_free, ε and γ_A (Acary, Cadoux, Lemaréchal
/// and Malick 2011, the full-rank case), and for μ = 0 exactly one. Measured with the defaults,
/// N = 5n/4 + 1 and n ≤ 200 (120 problems): λ_min(G) ≥ 0.015, λ_max(G) ≤ 39.
///
/// The lever arms are long for the inertias (|K_ρ|²/Θ up to 30 against 1/m ≤ 2), so the blocks
/// G_ii are dominated by rotation and strongly coupled between normal and tangential directions:
/// harder for the per-contact r-factors of SOR than spheres, whose G_ii are diagonal.
inline contact::ContactProblem random_problem(Random& rng, const RandomProblemSpec& spec) {
  contact::ContactProblem problem;
  std::vector<kinematics::Quaternion> orientation;
  for (int b = 0; b < spec.bodies; ++b) {
    contact::InverseMass M_inv;
    M_inv.inv_m = 1.0 / rng.uniform(0.5, 3.0);
    const Vector3 Theta(rng.uniform(0.1, 3.0), rng.uniform(0.1, 3.0), rng.uniform(0.1, 3.0));
    M_inv.K_Theta_inv = Theta.cwiseInverse();
    problem.M_inv.push_back(M_inv);
    Vector6 u;
    for (int k = 0; k < 6; ++k) u[k] = rng.uniform(-spec.u_free_scale, spec.u_free_scale);
    problem.u_free.push_back(u);
    orientation.push_back(rng.unit_quaternion());
  }
  std::vector<int> side_a(static_cast<std::size_t>(spec.bodies));
  for (int b = 0; b < spec.bodies; ++b) side_a[static_cast<std::size_t>(b)] = b;
  std::shuffle(side_a.begin(), side_a.end(), rng.engine());
  const int contacts = std::min(spec.contacts, spec.bodies);
  for (int i = 0; i < contacts; ++i) {
    contact::ContactConstraint c;
    c.body_a = side_a[static_cast<std::size_t>(i)];
    if (spec.bodies < 2 || rng.uniform(0.0, 1.0) < spec.static_fraction) {
      c.body_b = contact::kStatic;
    } else {
      do {
        c.body_b = std::min(static_cast<int>(rng.uniform(0.0, spec.bodies)), spec.bodies - 1);
      } while (c.body_b == c.body_a);
    }
    const Vector3 n = rng.unit_vector3();
    const Eigen::Matrix<double, 3, 2> T = collision::tangent_basis(n);
    c.W_a = collision::contact_jacobian(orientation[static_cast<std::size_t>(c.body_a)],
                                        rng.vector3(), n, T.col(0), T.col(1));
    if (c.body_b != contact::kStatic) {
      c.W_b = collision::contact_jacobian(orientation[static_cast<std::size_t>(c.body_b)],
                                          rng.vector3(), n, T.col(0), T.col(1));
    }
    c.mu = spec.mu_max > 0.0 ? rng.uniform(0.0, spec.mu_max) : 0.0;
    if (spec.restitution) {
      c.eps_N = rng.uniform(0.0, 1.0);
      c.eps_T = rng.uniform(-1.0, 1.0);
      c.gamma_A = rng.vector3();
    }
    problem.contacts.push_back(c);
  }
  return problem;
}

/// Number of generalized velocities of a problem, 6N.
inline Eigen::Index dofs(const contact::ContactProblem& problem) {
  return 6 * static_cast<Eigen::Index>(problem.M_inv.size());
}

/// Number of contact unknowns, 3n.
inline Eigen::Index unknowns(const contact::ContactProblem& problem) {
  return 3 * static_cast<Eigen::Index>(problem.contacts.size());
}

/// The global force directions W (6N × 3n): column block i holds +W_a in the rows of body a and
/// −W_b in the rows of body b (static sides contribute nothing).
inline Eigen::MatrixXd dense_W(const contact::ContactProblem& problem) {
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(dofs(problem), unknowns(problem));
  for (std::size_t i = 0; i < problem.contacts.size(); ++i) {
    const contact::ContactConstraint& c = problem.contacts[i];
    const auto col = 3 * static_cast<Eigen::Index>(i);
    if (c.body_a != contact::kStatic) W.block<6, 3>(6 * c.body_a, col) += c.W_a;
    if (c.body_b != contact::kStatic) W.block<6, 3>(6 * c.body_b, col) -= c.W_b;
  }
  return W;
}

/// The block-diagonal inverse mass matrix M⁻¹ (6N × 6N).
inline Eigen::MatrixXd dense_M_inv(const contact::ContactProblem& problem) {
  Eigen::MatrixXd M_inv = Eigen::MatrixXd::Zero(dofs(problem), dofs(problem));
  for (std::size_t b = 0; b < problem.M_inv.size(); ++b) {
    const auto r = 6 * static_cast<Eigen::Index>(b);
    M_inv.block<3, 3>(r, r) = problem.M_inv[b].inv_m * Matrix3::Identity();
    M_inv.block<3, 3>(r + 3, r + 3) = Matrix3(problem.M_inv[b].K_Theta_inv.asDiagonal());
  }
  return M_inv;
}

/// The stacked free velocities u_free (6N).
inline Eigen::VectorXd dense_u_free(const contact::ContactProblem& problem) {
  Eigen::VectorXd u(dofs(problem));
  for (std::size_t b = 0; b < problem.u_free.size(); ++b) {
    u.segment<6>(6 * static_cast<Eigen::Index>(b)) = problem.u_free[b];
  }
  return u;
}

/// The Delassus matrix G = Wᵀ M⁻¹ W (3n × 3n), symmetrized (G + Gᵀ)/2 against rounding.
inline Eigen::MatrixXd dense_delassus(const contact::ContactProblem& problem) {
  const Eigen::MatrixXd W = dense_W(problem);
  const Eigen::MatrixXd M_inv = dense_M_inv(problem);
  // M⁻¹ W body by body: M⁻¹ is block diagonal, and a dense 6N × 6N product would cost O(N³).
  Eigen::MatrixXd M_inv_W(W.rows(), W.cols());
  for (Eigen::Index r = 0; r < W.rows(); r += 6) {
    M_inv_W.middleRows(r, 6) = M_inv.block<6, 6>(r, r) * W.middleRows(r, 6);
  }
  const Eigen::MatrixXd G = W.transpose() * M_inv_W;
  return 0.5 * (G + G.transpose());
}

/// The free contact velocity c = Wᵀ u_free + ε ∘ γ_A (3n), ε = (ε_N, ε_T, ε_T) per contact: the
/// impact-law velocity ξ at Λ = 0, so that ξ = G Λ + c.
inline Eigen::VectorXd dense_free_velocity(const contact::ContactProblem& problem) {
  Eigen::VectorXd c = dense_W(problem).transpose() * dense_u_free(problem);
  for (std::size_t i = 0; i < problem.contacts.size(); ++i) {
    const contact::ContactConstraint& k = problem.contacts[i];
    const auto r = 3 * static_cast<Eigen::Index>(i);
    c[r] += k.eps_N * k.gamma_A[0];
    c[r + 1] += k.eps_T * k.gamma_A[1];
    c[r + 2] += k.eps_T * k.gamma_A[2];
  }
  return c;
}

/// The smallest eigenvalue of a symmetric matrix (0 for an empty one).
inline double smallest_eigenvalue(const Eigen::MatrixXd& G) {
  if (G.size() == 0) return 0.0;
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .minCoeff();
}

/// Per-contact vectors (n entries) stacked into one 3n vector.
inline Eigen::VectorXd stack(const std::vector<Vector3>& x) {
  Eigen::VectorXd v(3 * static_cast<Eigen::Index>(x.size()));
  for (std::size_t i = 0; i < x.size(); ++i) v.segment<3>(3 * static_cast<Eigen::Index>(i)) = x[i];
  return v;
}

/// A 3n vector split into per-contact vectors.
inline std::vector<Vector3> unstack(const Eigen::VectorXd& v) {
  std::vector<Vector3> x(static_cast<std::size_t>(v.size() / 3));
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = v.segment<3>(3 * static_cast<Eigen::Index>(i));
  return x;
}

/// The local form of a body-form problem: W = G = Wᵀ M⁻¹ W (dense_delassus(), exact zeros of
/// uncoupled contacts dropped) cut into blocks by contact::to_block_sparse(), q = c
/// (dense_free_velocity()), μ copied. Its solutions λ are those of the body form, with the same
/// ξ = G λ + q.
inline contact::LocalProblem to_local_form(const contact::ContactProblem& problem) {
  contact::LocalProblem local;
  const Eigen::SparseMatrix<double> G = dense_delassus(problem).sparseView();
  local.W = contact::to_block_sparse(G);
  local.q = unstack(dense_free_velocity(problem));
  for (const contact::ContactConstraint& c : problem.contacts) local.mu.push_back(c.mu);
  return local;
}

/// A scene of spheres assembled through the collision world: the bodies, their states, the
/// detected contacts and the contact problem of contact::assemble_problem().
struct SphereScene {
  std::vector<body::RigidBody> bodies;       ///< one per sphere
  std::vector<body::State> states;           ///< at rest, identity orientation
  std::vector<collision::Contact> contacts;  ///< from CollisionWorld::detect()
  contact::ContactProblem problem;           ///< assembled with u_free = (0, 0, −g h, 0, 0, 0)
};

/// Solid-sphere inertia, Θ = 2/5 m r² about every axis.
inline body::RigidBody solid_sphere(double mass, double radius) {
  return {mass, Vector3::Constant(0.4 * mass * radius * radius)};
}

/// Assembles a SphereScene: spheres of radius r and mass m at the given centres (at rest) and the
/// ground, the half-space n_groundᵀ x ≤ 0 (default: z ≤ 0); contacts within margin 0.01 r;
/// u_free = u_A − g h e_z (the gravity impulse of one step with u_A = 0, gravity along −e_z
/// whatever the ground's normal); material `material` for every contact.
inline SphereScene sphere_scene(const std::vector<Vector3>& centres, double radius, double mass,
                                double g_h, const contact::ContactMaterial& material,
                                const Vector3& ground_normal = Vector3::UnitZ()) {
  SphereScene scene;
  collision::CollisionWorld world;
  world.add({collision::HalfSpace{ground_normal, 0.0}});
  for (std::size_t b = 0; b < centres.size(); ++b) {
    world.add({collision::Sphere{radius}, static_cast<collision::BodyIndex>(b)});
    scene.bodies.push_back(solid_sphere(mass, radius));
    scene.states.push_back(
        {kinematics::make_q(centres[b], kinematics::Quaternion::identity()), Vector6::Zero()});
  }
  world.detect(scene.states, 0.01 * radius, scene.contacts);
  std::vector<Vector6> u_free(centres.size(), Vector6::Zero());
  for (Vector6& u : u_free) u[2] = -g_h;
  scene.problem =
      contact::assemble_problem(scene.contacts, scene.bodies, scene.states, u_free, material);
  return scene;
}

/// A vertical column of k touching spheres on the ground, sphere j (from the bottom) centred at
/// z = r (2j + 1). Statics of one step: the contact below the j-th sphere from the top carries
/// λ_N = j m g h, and every end velocity is zero.
inline SphereScene sphere_column(int k, double radius, double mass, double g_h,
                                 const contact::ContactMaterial& material) {
  std::vector<Vector3> centres;
  for (int j = 0; j < k; ++j) centres.emplace_back(0.0, 0.0, radius * (2.0 * j + 1.0));
  return sphere_scene(centres, radius, mass, g_h, material);
}

/// One sphere resting on an inclined ground through the origin with unit normal n (centre r n):
/// under the gravity impulse −g h e_z its contact sticks (rolls) exactly when
/// μ ≥ (2/7) tan θ, θ = the angle between n and e_z (a solid sphere, G_TT = 7/(2m)).
inline SphereScene sphere_on_incline(const Vector3& n, double radius, double mass, double g_h,
                                     const contact::ContactMaterial& material) {
  return sphere_scene({radius * n}, radius, mass, g_h, material, n);
}

/// A square pyramid of spheres on the ground: layer l (from the bottom, l < layers) holds
/// (layers − l)² spheres at x, y = r (2i + l), z = r (1 + √2 l), each resting on four spheres of
/// the layer below; neighbours in a layer touch. Hyperstatic: Λ is not unique, the velocities are.
inline SphereScene sphere_pyramid(int layers, double radius, double mass, double g_h,
                                  const contact::ContactMaterial& material) {
  std::vector<Vector3> centres;
  for (int l = 0; l < layers; ++l) {
    for (int i = 0; i < layers - l; ++i) {
      for (int j = 0; j < layers - l; ++j) {
        centres.emplace_back(radius * (2.0 * i + l), radius * (2.0 * j + l),
                             radius * (1.0 + std::sqrt(2.0) * l));
      }
    }
  }
  return sphere_scene(centres, radius, mass, g_h, material);
}

}  // namespace grbd::test
