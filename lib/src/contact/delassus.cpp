/// \file
/// \brief The assembled Delassus matrix W = Wᵀ M⁻¹ W of the body and compact forms.

#include "grbd/contact/delassus.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace grbd::contact {

namespace {

using Jacobian = Eigen::Matrix<double, 6, 3>;

/// One dynamic side of a contact: its body, σ W_s and M_s⁻¹ σ W_s.
struct Side {
  std::size_t body = 0;
  Jacobian W;
  Jacobian MW;
};

/// The assembly shared by both forms. `sides(i, out)` writes the dynamic sides of contact i to
/// out[0], out[1] and returns how many there are (1 or 2).
template <class Sides>
void assemble(std::size_t bodies, std::size_t n, Sides sides, BlockSparseMatrix& W) {
  std::vector<Side> side(2 * n);
  std::vector<int> count(n);
  // The contacts of each body, as compressed rows of (contact, side) entries 2 i + s.
  std::vector<std::int64_t> start(bodies + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    count[i] = sides(i, &side[2 * i]);
    for (int s = 0; s < count[i]; ++s) ++start[side[2 * i + s].body + 1];
  }
  for (std::size_t b = 0; b < bodies; ++b) start[b + 1] += start[b];
  std::vector<std::int64_t> entries(static_cast<std::size_t>(start[bodies]));
  std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    for (int s = 0; s < count[i]; ++s) {
      entries[static_cast<std::size_t>(fill[side[2 * i + s].body]++)] =
          static_cast<std::int64_t>(2 * i + s);
    }
  }

  W.row_start.assign(1, 0);
  W.column.clear();
  W.blocks.clear();
  W.diagonal.resize(n);
  std::vector<std::int64_t> mark(n, -1);   // the row that last listed contact j
  std::vector<std::int64_t> slot(n, 0);    // where block (i, j) of the current row is
  std::vector<std::int32_t> columns;
  for (std::size_t i = 0; i < n; ++i) {
    columns.clear();
    for (int s = 0; s < count[i]; ++s) {
      const std::size_t b = side[2 * i + s].body;
      for (std::int64_t e = start[b]; e < start[b + 1]; ++e) {
        const auto j = static_cast<std::size_t>(entries[static_cast<std::size_t>(e)] / 2);
        if (mark[j] == static_cast<std::int64_t>(i)) continue;
        mark[j] = static_cast<std::int64_t>(i);
        columns.push_back(static_cast<std::int32_t>(j));
      }
    }
    std::sort(columns.begin(), columns.end());
    const auto base = static_cast<std::int64_t>(W.blocks.size());
    for (std::size_t k = 0; k < columns.size(); ++k) {
      slot[static_cast<std::size_t>(columns[k])] = base + static_cast<std::int64_t>(k);
      W.column.push_back(columns[k]);
      W.blocks.push_back(Matrix3::Zero());
    }
    for (int s = 0; s < count[i]; ++s) {
      const Side& own = side[2 * i + s];
      for (std::int64_t e = start[own.body]; e < start[own.body + 1]; ++e) {
        const auto other = static_cast<std::size_t>(entries[static_cast<std::size_t>(e)]);
        W.blocks[static_cast<std::size_t>(slot[other / 2])].noalias() +=
            own.W.transpose() * side[other].MW;
      }
    }
    W.diagonal[i] = slot[i];
    W.row_start.push_back(static_cast<std::int64_t>(W.blocks.size()));
  }
}

}  // namespace

void assemble_delassus(const ContactProblem& problem, BlockSparseMatrix& W) {
  const auto sides = [&](std::size_t i, Side* out) {
    const ContactConstraint& c = problem.contacts[i];
    int k = 0;
    const auto add = [&](BodyIndex body, const Jacobian& Ws, double sign) {
      if (body == kStatic) return;
      Side& s = out[k++];
      s.body = static_cast<std::size_t>(body);
      s.W = sign * Ws;
      for (int a = 0; a < 3; ++a) s.MW.col(a) = problem.M_inv[s.body].apply(s.W.col(a));
    };
    add(c.body_a, c.W_a, 1.0);
    add(c.body_b, c.W_b, -1.0);
    return k;
  };
  assemble(problem.M_inv.size(), problem.contacts.size(), sides, W);
}

void assemble_delassus(const CompactProblem& problem, BlockSparseMatrix& W) {
  const auto sides = [&](std::size_t i, Side* out) {
    const CompactContact& c = problem.contacts[i];
    int k = 0;
    const auto add = [&](BodyIndex body, const Vector3& r, double sign) {
      if (body == kStatic) return;
      Side& s = out[k++];
      s.body = static_cast<std::size_t>(body);
      const WorldInverseMass& m = problem.M_inv[s.body];
      for (int a = 0; a < 3; ++a) {
        s.W.col(a) = sign * side_percussion(c, r, Vector3::Unit(a));
        s.MW.col(a) << m.inv_m * s.W.col(a).head<3>(), m.I_Theta_inv * s.W.col(a).tail<3>();
      }
    };
    add(c.body_a, c.r_a, 1.0);
    add(c.body_b, c.r_b, -1.0);
    return k;
  };
  assemble(problem.M_inv.size(), problem.contacts.size(), sides, W);
}

LocalProblem to_local(const ContactProblem& problem) {
  validate(problem);
  LocalProblem local;
  assemble_delassus(problem, local.W);
  local.q = contact_velocities(problem, problem.u_free);
  local.mu.reserve(problem.contacts.size());
  for (const ContactConstraint& c : problem.contacts) local.mu.push_back(c.mu);
  return local;
}

}  // namespace grbd::contact
