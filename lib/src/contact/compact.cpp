/// \file
/// \brief The compact (world-frame) contact problem: inverse masses, validation, Delassus blocks
/// and the kernels of its model. The SOR sweep lives beside chapter 5's in
/// solutions/05-contact-laws/prox.cpp, where the prox updates it repeats can be inlined.

#include "grbd/contact/compact.hpp"

#include <cmath>
#include <string>

#include "grbd/contact/detail/compact_kernels.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::contact {

namespace {

[[noreturn]] void refuse(const std::string& what) {
  throw InvalidArgument("compact contact problem: " + what);
}

std::string contact_name(std::size_t i) { return "contact " + std::to_string(i); }

}  // namespace

WorldInverseMass world_inverse_mass(const InverseMass& M_inv, const Matrix3& A_IK) {
  WorldInverseMass w;
  w.inv_m = M_inv.inv_m;
  const Vector3& d = M_inv.K_Theta_inv;
  if (d(0) == d(1) && d(1) == d(2)) {
    w.I_Theta_inv = d(0) * Matrix3::Identity();
  } else {
    w.I_Theta_inv = A_IK * d.asDiagonal() * A_IK.transpose();
    // Symmetric to the last bit, so that G_ii is.
    w.I_Theta_inv = 0.5 * (w.I_Theta_inv + w.I_Theta_inv.transpose()).eval();
  }
  return w;
}

void validate(const CompactProblem& problem) {
  const std::size_t bodies = problem.M_inv.size();
  if (problem.u_free.size() != bodies) {
    refuse("M_inv has " + std::to_string(bodies) + " bodies but u_free has " +
           std::to_string(problem.u_free.size()));
  }
  for (std::size_t b = 0; b < bodies; ++b) {
    const WorldInverseMass& M = problem.M_inv[b];
    if (!(M.inv_m > 0.0) || !std::isfinite(M.inv_m)) {
      refuse("body " + std::to_string(b) + ": expected a finite 1/m > 0, found " +
             format_number(M.inv_m));
    }
    if (!M.I_Theta_inv.allFinite() || !(M.I_Theta_inv.diagonal().minCoeff() > 0.0) ||
        !M.I_Theta_inv.isApprox(M.I_Theta_inv.transpose(), 1e-12)) {
      refuse("body " + std::to_string(b) +
             ": expected a finite symmetric I_Theta_inv with a positive diagonal");
    }
    if (problem.isotropic && M.I_Theta_inv != M.I_Theta_inv(0, 0) * Matrix3::Identity()) {
      refuse("body " + std::to_string(b) +
             ": the problem is marked isotropic but I_Theta_inv is not a multiple of I");
    }
    if (!problem.u_free[b].allFinite())
      refuse("body " + std::to_string(b) + ": u_free is not finite");
  }
  for (std::size_t i = 0; i < problem.contacts.size(); ++i) {
    const CompactContact& c = problem.contacts[i];
    const auto check = [&](BodyIndex body, const char* side) {
      if (body != kStatic && (body < 0 || static_cast<std::size_t>(body) >= bodies)) {
        refuse(contact_name(i) + ": body_" + side + " = " + std::to_string(body) +
               " is neither kStatic (-1) nor a body index in [0, " + std::to_string(bodies) + ")");
      }
    };
    check(c.body_a, "a");
    check(c.body_b, "b");
    if (c.body_a == kStatic && c.body_b == kStatic)
      refuse(contact_name(i) + ": both sides are static");
    if (c.body_a == c.body_b) {
      refuse(contact_name(i) + ": body " + std::to_string(c.body_a) + " touches itself");
    }
    if (!c.n.allFinite() || !c.t1.allFinite() || !c.r_a.allFinite() || !c.r_b.allFinite() ||
        !c.xi_A.allFinite()) {
      refuse(contact_name(i) + ": n, t1, r_a, r_b and xi_A must be finite");
    }
    if (std::abs(c.n.norm() - 1.0) > 1e-9 || std::abs(c.t1.norm() - 1.0) > 1e-9 ||
        std::abs(c.n.dot(c.t1)) > 1e-9) {
      refuse(contact_name(i) +
             ": expected a unit normal n and a unit tangent t1 ⟂ n, found |n| = " +
             format_number(c.n.norm()) + ", |t1| = " + format_number(c.t1.norm()) +
             ", n·t1 = " + format_number(c.n.dot(c.t1)));
    }
    if (!(c.mu >= 0.0) || !std::isfinite(c.mu)) {
      refuse(contact_name(i) + ": expected a finite friction coefficient mu >= 0, found " +
             format_number(c.mu));
    }
  }
}

Matrix3 delassus_block(const CompactContact& c, std::span<const WorldInverseMass> M_inv) {
  const Vector3 t2 = c.t2();
  Matrix3 G = Matrix3::Zero();
  const auto add = [&](BodyIndex body, const Vector3& r) {
    if (body == kStatic) return;
    const WorldInverseMass& M = M_inv[static_cast<std::size_t>(body)];
    Matrix3 C;
    C.col(0) = r.cross(c.n);
    C.col(1) = r.cross(c.t1);
    C.col(2) = r.cross(t2);
    G += M.inv_m * Matrix3::Identity() + C.transpose() * M.I_Theta_inv * C;
  };
  add(c.body_a, c.r_a);
  add(c.body_b, c.r_b);
  return G;
}

Vector3 delassus_diagonal(const CompactContact& c, std::span<const WorldInverseMass> M_inv) {
  return detail::delassus_diagonal<false>(c, M_inv.data());
}

Vector3 contact_velocity(const CompactContact& c, std::span<const Vector6> u) {
  Vector3 w = Vector3::Zero();
  if (c.body_a != kStatic) {
    const Vector6& ua = u[static_cast<std::size_t>(c.body_a)];
    w += ua.head<3>() + ua.tail<3>().cross(c.r_a);
  }
  if (c.body_b != kStatic) {
    const Vector6& ub = u[static_cast<std::size_t>(c.body_b)];
    w -= ub.head<3>() + ub.tail<3>().cross(c.r_b);
  }
  return {c.n.dot(w), c.t1.dot(w), c.t2().dot(w)};
}

Vector6 side_percussion(const CompactContact& c, const Vector3& r_side, const Vector3& lambda) {
  const Vector3 P = c.n * lambda(0) + c.t1 * lambda(1) + c.t2() * lambda(2);
  Vector6 out;
  out << P, r_side.cross(P);
  return out;
}

void add_percussion(const CompactContact& c, const Vector3& lambda,
                    std::span<const WorldInverseMass> M_inv, std::span<Vector6> v) {
  const auto apply = [&](BodyIndex body, const Vector3& r, double sign) {
    if (body == kStatic) return;
    const WorldInverseMass& M = M_inv[static_cast<std::size_t>(body)];
    const Vector6 p = side_percussion(c, r, lambda);
    Vector6& vb = v[static_cast<std::size_t>(body)];
    vb.head<3>() += sign * M.inv_m * p.head<3>();
    vb.tail<3>() += sign * (M.I_Theta_inv * p.tail<3>());
  };
  apply(c.body_a, c.r_a, 1.0);
  apply(c.body_b, c.r_b, -1.0);
}

void velocities_from_percussions(const CompactProblem& problem, std::span<const Vector3> lambda,
                                 std::vector<Vector6>& u) {
  u.assign(problem.u_free.begin(), problem.u_free.end());
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    add_percussion(problem.contacts[i], lambda[i], problem.M_inv, u);
  }
}

namespace {

template <bool Isotropic>
double start_solve_kernel(const CompactProblem& problem, std::span<const Vector3> lambda,
                          double alpha, std::span<RFactors> r, std::vector<Vector6>& u) {
  const std::size_t n = problem.contacts.size();
  u.assign(problem.u_free.begin(), problem.u_free.end());
  const CompactContact* contacts = problem.contacts.data();
  const Vector6* u_free = problem.u_free.data();
  const WorldInverseMass* M_inv = problem.M_inv.data();
  Vector6* U = u.data();
  constexpr std::size_t kAhead = 8;  // contacts; the records themselves stream in order
  const auto prefetch = [&](BodyIndex b) {
    if (b == kStatic) return;
    const auto k = static_cast<std::size_t>(b);
    __builtin_prefetch(&U[k], 1);
    __builtin_prefetch(reinterpret_cast<const char*>(&U[k] + 1) - 1, 1);
    __builtin_prefetch(&u_free[k]);
    __builtin_prefetch(reinterpret_cast<const char*>(&u_free[k] + 1) - 1);
    __builtin_prefetch(&M_inv[k]);
    __builtin_prefetch(reinterpret_cast<const char*>(&M_inv[k] + 1) - 1);
  };
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kAhead < n) {
      prefetch(contacts[i + kAhead].body_a);
      prefetch(contacts[i + kAhead].body_b);
    }
    const CompactContact& c = contacts[i];
    const Vector3 f[3] = {c.n, c.t1, c.t2()};
    // r_factors() reads the diagonal of G_ii only.
    if (!r.empty()) {
      r[i] = r_factors(Matrix3(detail::delassus_diagonal<Isotropic>(c, M_inv).asDiagonal()), alpha);
    }
    // c_i = Fᵀ(v_a + ω_a × r_a − v_b − ω_b × r_b) + xi_A from the free velocities.
    double w[3] = {0.0, 0.0, 0.0};
    if (c.body_a != kStatic) detail::add_point_velocity(1.0, u_free[c.body_a].data(), c.r_a, w);
    if (c.body_b != kStatic) detail::add_point_velocity(-1.0, u_free[c.body_b].data(), c.r_b, w);
    for (int k = 0; k < 3; ++k) {
      const double ck = f[k](0) * w[0] + f[k](1) * w[1] + f[k](2) * w[2] + c.xi_A(k);
      sum += ck * ck;
    }
    const Vector3& l = lambda[i];
    if (l.isZero(0.0)) continue;
    double P[3];
    detail::world_percussion(c, f[2], l, P);
    if (c.body_a != kStatic)
      detail::apply_percussion<Isotropic>(1.0, M_inv[c.body_a], c.r_a, P, U[c.body_a].data());
    if (c.body_b != kStatic)
      detail::apply_percussion<Isotropic>(-1.0, M_inv[c.body_b], c.r_b, P, U[c.body_b].data());
  }
  return sum;
}

}  // namespace

double start_solve(const CompactProblem& problem, std::span<const Vector3> lambda, double alpha,
                   std::span<RFactors> r, std::vector<Vector6>& u) {
  return problem.isotropic ? start_solve_kernel<true>(problem, lambda, alpha, r, u)
                           : start_solve_kernel<false>(problem, lambda, alpha, r, u);
}

ContactProblem body_form(const CompactProblem& problem, std::span<const InverseMass> M_inv,
                         std::span<const Matrix3> A_IK) {
  const std::size_t n = problem.M_inv.size();
  if (M_inv.size() != n || A_IK.size() != n || problem.u_free.size() != n) {
    throw InvalidArgument("body_form: expected " + std::to_string(n) +
                          " inverse masses, orientations and free velocities (one per body), "
                          "found " +
                          std::to_string(M_inv.size()) + ", " + std::to_string(A_IK.size()) +
                          " and " + std::to_string(problem.u_free.size()));
  }
  ContactProblem out;
  out.M_inv.assign(M_inv.begin(), M_inv.end());
  out.u_free.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.u_free[i] << problem.u_free[i].head<3>(), A_IK[i].transpose() * problem.u_free[i].tail<3>();
  }
  out.contacts.resize(problem.contacts.size());
  for (std::size_t k = 0; k < problem.contacts.size(); ++k) {
    const CompactContact& c = problem.contacts[k];
    ContactConstraint& cc = out.contacts[k];
    cc.body_a = c.body_a;
    cc.body_b = c.body_b;
    const Vector3 d[3] = {c.n, c.t1, c.t2()};
    const auto jacobian = [&](BodyIndex body, const Vector3& r, collision::ContactJacobian& W) {
      W.setZero();
      if (body == kStatic) return;
      if (body < 0 || static_cast<std::size_t>(body) >= n) {
        throw InvalidArgument("body_form: contact " + std::to_string(k) + ": body index " +
                              std::to_string(body) + " out of range");
      }
      for (int j = 0; j < 3; ++j) {
        W.col(j) << d[j], A_IK[static_cast<std::size_t>(body)].transpose() * r.cross(d[j]);
      }
    };
    jacobian(c.body_a, c.r_a, cc.W_a);
    jacobian(c.body_b, c.r_b, cc.W_b);
    cc.gamma_A = c.xi_A;
    cc.mu = c.mu;
    cc.eps_N = 1.0;
    cc.eps_T = 1.0;
  }
  return out;
}

}  // namespace grbd::contact
