/// \file
/// \brief The body-form contact problem: validation, velocities, assembly from collision contacts.

#include "grbd/contact/problem.hpp"

#include <cmath>
#include <string>

#include "grbd/collision/contact.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

namespace {

std::string contact_name(std::size_t i) { return "contact " + std::to_string(i); }

/// "<where>: contact i" or "<where>" for kNoIndex.
std::string contact_context(std::string_view where, std::size_t i) {
  return i == kNoIndex ? std::string(where) : std::string(where) + ": " + contact_name(i);
}

[[noreturn]] void refuse(const std::string& what) {
  throw InvalidArgument("contact problem: " + what);
}

bool all_finite(const auto& matrix) { return matrix.allFinite(); }

}  // namespace

void require_body_indices(const ContactConstraint& contact, std::size_t bodies,
                          std::string_view where, std::size_t index) {
  const auto check = [&](BodyIndex body, const char* side) {
    if (body != kStatic && (body < 0 || static_cast<std::size_t>(body) >= bodies)) {
      throw InvalidArgument(contact_context(where, index) + ": body_" + side +
                            " = " + std::to_string(body) +
                            " is neither kStatic (-1) nor a body index in [0, " +
                            std::to_string(bodies) + ")");
    }
  };
  check(contact.body_a, "a");
  check(contact.body_b, "b");
  if (contact.body_a == kStatic && contact.body_b == kStatic) {
    throw InvalidArgument(contact_context(where, index) + ": both sides are static");
  }
}

InverseMass inverse_mass(const body::RigidBody& body) {
  body::require_valid(body, "inverse_mass");
  InverseMass M_inv;
  M_inv.inv_m = 1.0 / body.m;
  M_inv.K_Theta_inv = body.K_Theta.cwiseInverse();
  return M_inv;
}

void validate(const ContactProblem& problem) {
  const std::size_t bodies = problem.M_inv.size();
  if (problem.u_free.size() != bodies) {
    refuse("M_inv has " + std::to_string(bodies) + " bodies but u_free has " +
           std::to_string(problem.u_free.size()));
  }
  for (std::size_t b = 0; b < bodies; ++b) {
    const InverseMass& M = problem.M_inv[b];
    if (!(M.inv_m > 0.0) || !std::isfinite(M.inv_m)) {
      refuse("body " + std::to_string(b) + ": expected a finite 1/m > 0, found " +
             format_number(M.inv_m));
    }
    for (int k = 0; k < 3; ++k) {
      if (!(M.K_Theta_inv(k) > 0.0) || !std::isfinite(M.K_Theta_inv(k))) {
        refuse("body " + std::to_string(b) + ": expected finite inverse principal moments "
               "K_Theta_inv > 0, found K_Theta_inv(" + std::to_string(k) + ") = " +
               format_number(M.K_Theta_inv(k)));
      }
    }
    if (!all_finite(problem.u_free[b])) {
      refuse("body " + std::to_string(b) + ": u_free is not finite");
    }
  }
  if (!problem.keys.empty() && problem.keys.size() != problem.contacts.size()) {
    refuse("keys must be empty or have one entry per contact; found " +
           std::to_string(problem.keys.size()) + " keys for " +
           std::to_string(problem.contacts.size()) + " contacts");
  }
  for (std::size_t i = 0; i < problem.contacts.size(); ++i) {
    const ContactConstraint& c = problem.contacts[i];
    require_body_indices(c, bodies, "contact problem", i);
    if (c.body_a == c.body_b) {
      refuse(contact_name(i) + ": body " + std::to_string(c.body_a) + " touches itself");
    }
    if (!all_finite(c.W_a) || !all_finite(c.W_b) || !all_finite(c.gamma_A)) {
      refuse(contact_name(i) + ": W_a, W_b and gamma_A must be finite");
    }
    if (!(c.mu >= 0.0) || !std::isfinite(c.mu)) {
      refuse(contact_name(i) + ": expected a finite friction coefficient mu >= 0, found " +
             format_number(c.mu));
    }
    if (!(c.eps_N >= 0.0 && c.eps_N <= 1.0)) {
      refuse(contact_name(i) + ": expected a normal restitution eps_N in [0, 1], found " +
             format_number(c.eps_N));
    }
    if (!(c.eps_T >= -1.0 && c.eps_T <= 1.0)) {
      refuse(contact_name(i) + ": expected a tangential restitution eps_T in [-1, 1], found " +
             format_number(c.eps_T));
    }
    const Matrix3 G = delassus_block(c, problem.M_inv);
    for (int k = 0; k < 3; ++k) {
      if (!(G(k, k) > 0.0) || !std::isfinite(G(k, k))) {
        refuse(contact_name(i) + ": the Delassus block G_ii needs a positive, finite diagonal, "
               "found G(" +
               std::to_string(k) + "," + std::to_string(k) + ") = " + format_number(G(k, k)) +
               " (are its force directions W zero?)");
      }
    }
  }
}

std::vector<Vector6> velocities_from_percussions(const ContactProblem& problem,
                                                 std::span<const Vector3> lambda) {
  if (lambda.size() != problem.contacts.size()) {
    refuse("expected one percussion per contact (" + std::to_string(problem.contacts.size()) +
           "), found " + std::to_string(lambda.size()));
  }
  if (problem.u_free.size() != problem.M_inv.size()) {
    refuse("M_inv has " + std::to_string(problem.M_inv.size()) + " bodies but u_free has " +
           std::to_string(problem.u_free.size()));
  }
  std::vector<Vector6> u = problem.u_free;
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    const ContactConstraint& c = problem.contacts[i];
    require_body_indices(c, u.size(), "velocities_from_percussions", i);
    if (c.body_a != kStatic) u[c.body_a] += problem.M_inv[c.body_a].apply(c.W_a * lambda[i]);
    if (c.body_b != kStatic) u[c.body_b] -= problem.M_inv[c.body_b].apply(c.W_b * lambda[i]);
  }
  return u;
}

std::vector<Vector3> contact_velocities(const ContactProblem& problem, std::span<const Vector6> u) {
  if (u.size() != problem.M_inv.size()) {
    refuse("expected one velocity per body (" + std::to_string(problem.M_inv.size()) + "), found " +
           std::to_string(u.size()));
  }
  std::vector<Vector3> xi(problem.contacts.size());
  for (std::size_t i = 0; i < xi.size(); ++i) {
    const ContactConstraint& c = problem.contacts[i];
    require_body_indices(c, u.size(), "contact_velocities", i);
    Vector3 gamma = Vector3::Zero();
    if (c.body_a != kStatic) gamma += c.W_a.transpose() * u[c.body_a];
    if (c.body_b != kStatic) gamma -= c.W_b.transpose() * u[c.body_b];
    xi[i] = impact_velocity(gamma, c.gamma_A, c.eps_N, c.eps_T);
  }
  return xi;
}

ContactProblem assemble_problem(std::span<const collision::Contact> contacts,
                                std::span<const body::RigidBody> bodies,
                                std::span<const body::State> states,
                                std::span<const Vector6> u_free, const ContactMaterial& material) {
  if (states.size() != bodies.size() || u_free.size() != bodies.size()) {
    throw InvalidArgument(
        "assemble_problem: bodies, states and u_free must have one entry per "
        "body; found " +
        std::to_string(bodies.size()) + ", " + std::to_string(states.size()) + " and " +
        std::to_string(u_free.size()));
  }
  // The states are checked here, once per body, and not again in the loop over the contacts:
  // a non-unit quaternion would scale every lever arm in W by |p|².
  for (std::size_t b = 0; b < states.size(); ++b) {
    body::require_valid(states[b], "assemble_problem", b);
  }
  ContactProblem problem;
  problem.M_inv.reserve(bodies.size());
  for (const body::RigidBody& b : bodies) problem.M_inv.push_back(inverse_mass(b));
  problem.u_free.assign(u_free.begin(), u_free.end());
  problem.contacts.reserve(contacts.size());
  problem.keys.reserve(contacts.size());
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const collision::Contact& k = contacts[i];
    ContactConstraint c;
    c.body_a = k.body_a;
    c.body_b = k.body_b;
    require_body_indices(c, bodies.size(), "assemble_problem", i);
    Vector3 gamma_A = Vector3::Zero();
    if (c.body_a != kStatic) {
      const body::State& s = states[c.body_a];
      c.W_a = collision::contact_jacobian(kinematics::Quaternion(Vector4(s.q.tail<4>())), k.K_rho_a,
                                          k.geometry.I_n, k.I_t1, k.I_t2);
      gamma_A += c.W_a.transpose() * s.u;
    }
    if (c.body_b != kStatic) {
      const body::State& s = states[c.body_b];
      c.W_b = collision::contact_jacobian(kinematics::Quaternion(Vector4(s.q.tail<4>())), k.K_rho_b,
                                          k.geometry.I_n, k.I_t1, k.I_t2);
      gamma_A -= c.W_b.transpose() * s.u;
    }
    c.gamma_A = gamma_A;
    c.mu = material.mu;
    c.eps_N = material.eps_N;
    c.eps_T = material.eps_T;
    problem.contacts.push_back(c);
    problem.keys.push_back(k.key());
  }
  return problem;
}

}  // namespace grbd::contact
