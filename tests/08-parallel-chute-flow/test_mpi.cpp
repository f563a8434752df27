// Chapter 8: the communicator under mpiexec (run with 1, 2 and 3 processes). References: what
// each rank contributes is a known function of its rank, so every collective result has a closed
// form; a sum of doubles must equal, bit for bit, the sum formed in rank order.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/parallel/mpi.hpp"

namespace grbd::parallel {
namespace {

const Communicator* world = nullptr;

std::vector<std::byte> bytes_of(const std::string& text) {
  std::vector<std::byte> b(text.size());
  std::memcpy(b.data(), text.data(), text.size());
  return b;
}

std::string text_of(const std::vector<std::byte>& b) {
  return std::string(reinterpret_cast<const char*>(b.data()), b.size());
}

// What rank r contributes at position k: values whose sum depends on the order of addition.
double contribution(int r, std::size_t k) { return std::pow(10.0, 8 * (r % 3)) / (3.0 + k + r); }

TEST(Communicator, SumsAreFormedInRankOrderAndAgreeToTheBit) {
  const int p = world->size();
  std::vector<double> values(5);
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = contribution(world->rank(), k);
  world->sum(values);
  for (std::size_t k = 0; k < values.size(); ++k) {
    double expected = 0.0;
    for (int r = 0; r < p; ++r) expected += contribution(r, k);
    EXPECT_EQ(values[k], expected) << "k = " << k;
  }
  std::vector<std::uint64_t> counts{static_cast<std::uint64_t>(world->rank()) + 1, 1};
  world->sum(counts);
  EXPECT_EQ(counts[0], static_cast<std::uint64_t>(p * (p + 1) / 2));
  EXPECT_EQ(counts[1], static_cast<std::uint64_t>(p));
}

TEST(Communicator, MaxMinAllAny) {
  const int p = world->size();
  std::vector<double> hi{double(world->rank()), -double(world->rank())};
  std::vector<double> lo = hi;
  world->max(hi);
  world->min(lo);
  EXPECT_EQ(hi[0], p - 1.0);
  EXPECT_EQ(hi[1], 0.0);
  EXPECT_EQ(lo[0], 0.0);
  EXPECT_EQ(lo[1], 1.0 - p);
  EXPECT_TRUE(world->all(true));
  EXPECT_EQ(world->all(world->rank() != 0), false);
  EXPECT_EQ(world->any(world->rank() == p - 1), true);
  EXPECT_FALSE(world->any(false));
}

TEST(Communicator, BroadcastAndAllGatherHandEveryoneTheSameBytes) {
  const int p = world->size();
  std::vector<std::byte> b = bytes_of(world->rank() == p - 1 ? "from the last rank" : "x");
  world->broadcast(b, p - 1);
  EXPECT_EQ(text_of(b), "from the last rank");
  std::vector<std::vector<std::byte>> all;
  const std::string mine(static_cast<std::size_t>(world->rank()), 'a');  // rank 0 sends nothing
  world->all_gather(bytes_of(mine), all);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(p));
  for (int r = 0; r < p; ++r) EXPECT_EQ(text_of(all[r]), std::string(r, 'a'));
  EXPECT_THROW(world->broadcast(b, p), InvalidArgument);
}

TEST(Communicator, ExchangeWithNeighboursOnARing) {
  // Each rank's neighbours on a ring of p: itself at p = 1, the other at p = 2, both sides else.
  const int p = world->size();
  const int me = world->rank();
  std::vector<int> neighbours;
  for (const int n : {(me + p - 1) % p, (me + 1) % p}) {
    if (std::find(neighbours.begin(), neighbours.end(), n) == neighbours.end()) {
      neighbours.push_back(n);
    }
  }
  std::vector<std::vector<std::byte>> send;
  for (const int n : neighbours) {
    send.push_back(bytes_of(std::to_string(me) + "->" + std::to_string(n) +
                            std::string(1000 * static_cast<std::size_t>(me), '.')));
  }
  std::vector<std::vector<std::byte>> received;
  for (int round = 0; round < 3; ++round) {  // reused buffers, repeated rounds
    world->exchange(neighbours, send, received);
    ASSERT_EQ(received.size(), neighbours.size());
    for (std::size_t k = 0; k < neighbours.size(); ++k) {
      EXPECT_EQ(text_of(received[k]),
                std::to_string(neighbours[k]) + "->" + std::to_string(me) +
                    std::string(1000 * static_cast<std::size_t>(neighbours[k]), '.'));
    }
  }
  const int outside[] = {p};
  EXPECT_THROW(world->exchange(outside, std::span(send).first(1), received), InvalidArgument);
}

}  // namespace
}  // namespace grbd::parallel

// gtest under mpiexec: every rank runs every test; rank 0 prints the report, the others their
// failures only; the program fails on every rank when a test failed on any.
int main(int argc, char** argv) {
  grbd::parallel::MpiEnvironment mpi(true);
  grbd::parallel::world = &mpi.world();
  ::testing::InitGoogleTest(&argc, argv);
  if (mpi.world().rank() != 0) {
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  const int failed = RUN_ALL_TESTS();
  const bool everywhere = mpi.world().all(failed == 0);
  if (!everywhere && mpi.world().rank() == 0) {
    std::fprintf(stderr, "a test failed on some rank (its failures are printed above)\n");
  }
  return everywhere ? 0 : 1;
}
