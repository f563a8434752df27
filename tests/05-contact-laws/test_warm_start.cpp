// Chapter 5: warm starts — the percussions of one step, stored by contact identity
// (collision::ContactKey), as the initial guess of the next solve.
//
// Independent references: the stored values themselves (a warm start copies numbers, so every
// comparison is exact), keys built member by member, and for the solve a column of three spheres
// resting on the ground, whose percussions (3, 2, 1) m g h are known in closed form: started
// from them, SOR has nothing left to do.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "grbd/collision/contact.hpp"
#include "grbd/contact/problem.hpp"
#include "grbd/contact/solver.hpp"
#include "grbd/contact/warm_start.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/random.hpp"

namespace {

using grbd::Vector3;
using grbd::Vector6;
using grbd::collision::ContactJacobian;
using grbd::collision::ContactKey;
using grbd::contact::ContactConstraint;
using grbd::contact::ContactProblem;
using grbd::contact::ContactSolution;
using grbd::contact::kStatic;
using grbd::contact::SolverOptions;
using grbd::contact::WarmStart;
using grbd::test::Random;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// `count` distinct keys: colliders i and i + 1000, a face of a and a vertex of b.
std::vector<ContactKey> distinct_keys(int count, int first = 0) {
  std::vector<ContactKey> keys;
  for (int i = first; i < first + count; ++i) {
    keys.push_back({i, i + 1000, grbd::collision::face_feature(static_cast<std::uint64_t>(i % 6)),
                    grbd::collision::vertex_feature(static_cast<std::uint64_t>(i))});
  }
  return keys;
}

std::vector<Vector3> random_percussions(Random& rng, std::size_t count) {
  std::vector<Vector3> lambda;
  for (std::size_t i = 0; i < count; ++i) lambda.push_back(rng.vector3(-1.0, 2.0));
  return lambda;
}

// The contact Jacobian at the identity orientation for the lever arm ρ and the frame
// (e_z, e_x, e_y): columns (d, ρ × d).
ContactJacobian upright_jacobian(const Vector3& rho) {
  ContactJacobian W;
  for (int k = 0; k < 3; ++k) {
    const Vector3 d = Vector3::Unit((k + 2) % 3);  // e_z, e_x, e_y
    W.col(k) << d, rho.cross(d);
  }
  return W;
}

// A column of three spheres (mass m, radius R) on the ground with the gravity impulse g h in
// u_free: contact 0 ground–sphere 0, contact i sphere i on sphere i − 1; μ = 0.5. With
// `reversed` the contacts (and keys) are listed in the opposite order.
ContactProblem sphere_column(double m, double R, double gh, bool reversed) {
  ContactProblem p;
  for (int b = 0; b < 3; ++b) {
    p.M_inv.push_back({1.0 / m, grbd::Vector3::Constant(1.0 / (0.4 * m * R * R))});
    Vector6 u = Vector6::Zero();
    u(2) = -gh;
    p.u_free.push_back(u);
  }
  for (int i = 0; i < 3; ++i) {
    ContactConstraint c;
    c.body_a = i;
    c.body_b = i == 0 ? kStatic : i - 1;
    c.W_a = upright_jacobian(Vector3(0.0, 0.0, -R));
    if (i > 0) c.W_b = upright_jacobian(Vector3(0.0, 0.0, R));
    c.mu = 0.5;
    p.contacts.push_back(c);
    p.keys.push_back({i + 1, i, 0, 0});
  }
  if (reversed) {
    std::reverse(p.contacts.begin(), p.contacts.end());
    std::reverse(p.keys.begin(), p.keys.end());
  }
  return p;
}

}  // namespace

// Reference: the stored percussions, exactly, for the same 50 keys asked in another order; all
// 50 are found.
TEST(WarmStart, InitializeReturnsWhatWasStored) {
  Random rng(5951);
  const std::vector<ContactKey> keys = distinct_keys(50);
  const std::vector<Vector3> lambda = random_percussions(rng, keys.size());
  WarmStart warm;
  warm.store(keys, lambda);
  EXPECT_EQ(warm.size(), 50U);
  std::vector<std::size_t> order(keys.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = (7 * i + 3) % order.size();
  std::vector<ContactKey> asked;
  for (const std::size_t i : order) asked.push_back(keys[i]);
  std::vector<Vector3> initial;
  EXPECT_EQ(warm.initialize(asked, initial), 50U);
  ASSERT_EQ(initial.size(), 50U);
  for (std::size_t j = 0; j < order.size(); ++j) {
    EXPECT_EQ(initial[j], lambda[order[j]]) << "key " << order[j];
  }
}

// Reference: of 30 stored keys 20 are asked, interleaved with 15 new ones: 20 are found and the
// new ones start at exactly zero; the output is resized and what it held before (NaN) is
// overwritten.
TEST(WarmStart, NewContactsStartAtZero) {
  Random rng(5952);
  const std::vector<ContactKey> stored = distinct_keys(30);
  const std::vector<Vector3> lambda = random_percussions(rng, stored.size());
  WarmStart warm;
  warm.store(stored, lambda);
  const std::vector<ContactKey> fresh = distinct_keys(15, 100);
  std::vector<ContactKey> asked;
  std::vector<int> source;  // index into `stored`, or −1 for a new key
  std::size_t next_stored = 0, next_fresh = 0;
  for (int i = 0; i < 35; ++i) {
    if (i % 7 < 4) {
      source.push_back(static_cast<int>(next_stored));
      asked.push_back(stored[next_stored++]);
    } else {
      source.push_back(-1);
      asked.push_back(fresh[next_fresh++]);
    }
  }
  ASSERT_EQ(std::count(source.begin(), source.end(), -1), 15);
  std::vector<Vector3> initial(100, Vector3::Constant(kNaN));
  EXPECT_EQ(warm.initialize(asked, initial), 20U);
  ASSERT_EQ(initial.size(), asked.size());
  for (std::size_t i = 0; i < asked.size(); ++i) {
    const Vector3 expected =
        source[i] >= 0 ? lambda[static_cast<std::size_t>(source[i])] : Vector3::Zero();
    EXPECT_EQ(initial[i], expected) << "contact " << i;
  }
}

// Reference: keys that differ from a stored one in a single member — either collider, either
// feature, or with the colliders swapped — are different contacts.
TEST(WarmStart, KeysDifferInEveryMember) {
  const ContactKey key{3, 7, grbd::collision::face_feature(2),
                       grbd::collision::edge_feature(grbd::collision::mesh_edge_index(4, 9))};
  WarmStart warm;
  warm.store(std::vector<ContactKey>{key}, std::vector<Vector3>{Vector3(1.0, 0.25, -0.5)});
  std::vector<ContactKey> others(5, key);
  others[0].collider_a = 4;
  others[1].collider_b = 8;
  others[2].feature_a = grbd::collision::face_feature(3);
  others[3].feature_b = grbd::collision::vertex_feature(grbd::collision::mesh_edge_index(4, 9));
  std::swap(others[4].collider_a, others[4].collider_b);
  std::vector<Vector3> initial;
  EXPECT_EQ(warm.initialize(others, initial), 0U);
  for (const Vector3& l : initial) EXPECT_EQ(l, Vector3::Zero());
  ContactKey same = key;
  same.feature_b = grbd::collision::edge_feature(grbd::collision::mesh_edge_index(9, 4));
  EXPECT_EQ(warm.initialize(std::vector<ContactKey>{same}, initial), 1U);
  EXPECT_EQ(initial[0], Vector3(1.0, 0.25, -0.5));
}

// Reference: store() replaces: after a second store, the keys of the first step that are not in
// the second are gone, and the shared ones hold the second step's percussions.
TEST(WarmStart, StoreReplacesThePreviousStep) {
  Random rng(5953);
  const std::vector<ContactKey> first = distinct_keys(10);
  const std::vector<ContactKey> second = distinct_keys(6, 5);  // keys 5 … 10
  const std::vector<Vector3> lambda1 = random_percussions(rng, first.size());
  const std::vector<Vector3> lambda2 = random_percussions(rng, second.size());
  WarmStart warm;
  warm.store(first, lambda1);
  warm.store(second, lambda2);
  EXPECT_EQ(warm.size(), 6U);
  std::vector<Vector3> initial;
  EXPECT_EQ(warm.initialize(first, initial), 5U);
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(initial[i], i < 5 ? Vector3::Zero() : lambda2[i - 5]) << "key " << i;
  }
}

// Reference: a key given twice keeps the last percussion.
TEST(WarmStart, ADuplicateKeyKeepsTheLastPercussion) {
  const std::vector<ContactKey> keys = distinct_keys(2);
  WarmStart warm;
  warm.store(
      std::vector<ContactKey>{keys[0], keys[1], keys[0]},
      std::vector<Vector3>{Vector3(1.0, 0.0, 0.0), Vector3(2.0, 0.0, 0.0), Vector3(3.0, 0.5, 0.0)});
  EXPECT_EQ(warm.size(), 2U);
  std::vector<Vector3> initial;
  EXPECT_EQ(warm.initialize(keys, initial), 2U);
  EXPECT_EQ(initial[0], Vector3(3.0, 0.5, 0.0));
  EXPECT_EQ(initial[1], Vector3(2.0, 0.0, 0.0));
}

// Reference: clear() forgets everything: size 0, no key found, all zero.
TEST(WarmStart, ClearForgetsEverything) {
  Random rng(5954);
  const std::vector<ContactKey> keys = distinct_keys(8);
  WarmStart warm;
  warm.store(keys, random_percussions(rng, keys.size()));
  ASSERT_EQ(warm.size(), 8U);
  warm.clear();
  EXPECT_EQ(warm.size(), 0U);
  std::vector<Vector3> initial;
  EXPECT_EQ(warm.initialize(keys, initial), 0U);
  ASSERT_EQ(initial.size(), 8U);
  for (const Vector3& l : initial) EXPECT_EQ(l, Vector3::Zero());
}

// Reference: no keys: nothing found and an empty initial guess; storing nothing stores nothing.
TEST(WarmStart, NoContacts) {
  Random rng(5955);
  WarmStart warm;
  warm.store(distinct_keys(3), random_percussions(rng, 3));
  std::vector<Vector3> initial(4, Vector3::Ones());
  EXPECT_EQ(warm.initialize(std::vector<ContactKey>{}, initial), 0U);
  EXPECT_TRUE(initial.empty());
  warm.store(std::vector<ContactKey>{}, std::vector<Vector3>{});
  EXPECT_EQ(warm.size(), 0U);
}

// Reference: 7 keys and 4 percussions are refused with InvalidArgument naming both counts.
TEST(WarmStart, RefusesKeysAndPercussionsOfDifferentLengths) {
  Random rng(5956);
  WarmStart warm;
  try {
    warm.store(distinct_keys(7), random_percussions(rng, 4));
    ADD_FAILURE() << "store() accepted 7 keys and 4 percussions";
  } catch (const grbd::InvalidArgument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find('7'), std::string::npos) << message;
    EXPECT_NE(message.find('4'), std::string::npos) << message;
  }
  EXPECT_THROW(warm.store(distinct_keys(0), random_percussions(rng, 1)), grbd::InvalidArgument);
}

// Reference: a column of three spheres on the ground carries (3, 2, 1) m g h. Solved cold, the
// percussions are stored by key; the next step lists the same contacts in the opposite order, the
// warm start finds all three in their new places, and SOR started from them converges in one
// iteration (cold: more) to the same percussions.
TEST(WarmStart, WarmStartedSorStartsAtTheSolution) {
  const double m = 1.5, R = 0.25, gh = 9.81e-2;
  const ContactProblem cold_problem = sphere_column(m, R, gh, false);
  SolverOptions options;
  options.max_iterations = 2000;
  ContactSolution cold;
  const auto cold_result = grbd::contact::solve_sor(cold_problem, cold, options);
  ASSERT_TRUE(cold_result.converged) << grbd::contact::describe(cold_result);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(cold.lambda[static_cast<std::size_t>(i)](0), (3 - i) * m * gh, 1e-5 * m * gh);
  }
  WarmStart warm;
  warm.store(cold_problem.keys, cold.lambda);

  const ContactProblem next = sphere_column(m, R, gh, true);
  ContactSolution started;
  ASSERT_EQ(warm.initialize(next.keys, started.lambda), 3U);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(started.lambda[i], cold.lambda[2 - i]);
  const auto warm_result = grbd::contact::solve_sor(next, started, options);
  ASSERT_TRUE(warm_result.converged) << grbd::contact::describe(warm_result);
  EXPECT_EQ(warm_result.iterations, 1);
  EXPECT_GT(cold_result.iterations, 2);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(started.lambda[i](0), static_cast<double>(i + 1) * m * gh, 1e-5 * m * gh);
  }
}
