#pragma once
/// \file
/// \brief Collective operations over rows (chapter 8), built on the Communicator: where each
/// process's rows lie in a global order (an exclusive scan), one message to every process, the rows
/// of received messages, and a sample sort across the processes — what the output, the
/// checkpoints and the parallel engine need to write and move rows among many processes.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>
#include <vector>

#include "grbd/core/communicator.hpp"

namespace grbd::collective {

/// Appends a trivially copyable row to a message.
template <class Row>
void put(std::vector<std::byte>& out, const Row& row) {
  static_assert(std::is_trivially_copyable_v<Row>);
  const std::size_t at = out.size();
  out.resize(at + sizeof(Row));
  std::memcpy(out.data() + at, &row, sizeof(Row));
}

/// Where this process's rows lie in the global order: rows [offset, offset + n) of `total`.
struct Block {
  std::uint64_t offset = 0;  ///< the global row of this process's first row
  std::uint64_t total = 0;   ///< rows of every process
};

/// The blocks of `count` rows on each process, in rank order (collective).
inline Block block_of(const Communicator& comm, std::uint64_t count) {
  if (comm.size() == 1) return {0, count};
  std::vector<std::vector<std::byte>> all;
  comm.all_gather(std::as_bytes(std::span(&count, 1)), all);
  Block block;
  for (int r = 0; r < comm.size(); ++r) {
    std::uint64_t n = 0;
    std::memcpy(&n, all[static_cast<std::size_t>(r)].data(), sizeof n);
    if (r < comm.rank()) block.offset += n;
    block.total += n;
  }
  return block;
}

/// One message to every process, this one included, and one from each (collective): `send[r]`
/// goes to rank r, `received[r]` comes from it.
inline void exchange_with_all(const Communicator& comm,
                              std::span<const std::vector<std::byte>> send,
                              std::vector<std::vector<std::byte>>& received) {
  std::vector<int> everyone(static_cast<std::size_t>(comm.size()));
  for (int r = 0; r < comm.size(); ++r) everyone[static_cast<std::size_t>(r)] = r;
  comm.exchange(everyone, send, received);
}

/// The rows of messages of trivially copyable rows, in the order of the messages and of the rows
/// in each.
template <class Row>
std::vector<Row> rows_of(const std::vector<std::vector<std::byte>>& messages) {
  static_assert(std::is_trivially_copyable_v<Row>);
  std::vector<Row> rows;
  for (const std::vector<std::byte>& part : messages) {
    const std::size_t at = rows.size();
    rows.resize(at + part.size() / sizeof(Row));
    if (!part.empty()) std::memcpy(rows.data() + at, part.data(), part.size());
  }
  return rows;
}

// [sort across]
/// Sorts `rows` by key_of(row) across the processes (collective): afterwards the rows of rank 0,
/// then rank 1, … are the global sorted order, each process holding a block of about the
/// average size, and the result tells where its block lies. A sample sort: every process sends
/// up to 32 evenly spaced keys of its sorted rows, each weighted by the rows it stands for; the
/// splitters are the weighted quantiles of all samples, the same on every process; one exchange
/// among all processes moves each row to the process of its key's interval. Rows with equal keys
/// go to the same process. At P = 1 only the sort.
template <class Row, class KeyOf>
Block sort_across(const Communicator& comm, std::vector<Row>& rows, KeyOf key_of) {
  static_assert(std::is_trivially_copyable_v<Row>);
  using Key = std::decay_t<decltype(key_of(rows.front()))>;
  static_assert(std::is_trivially_copyable_v<Key>);
  const auto less = [&](const Row& a, const Row& b) { return key_of(a) < key_of(b); };
  std::sort(rows.begin(), rows.end(), less);
  const int P = comm.size();
  if (P == 1) return {0, rows.size()};

  struct Sample {
    Key key;
    double weight;
  };
  const std::size_t n = rows.size();
  const std::size_t s = std::min<std::size_t>(n, 32);
  std::vector<Sample> mine(s);
  for (std::size_t j = 0; j < s; ++j) {
    mine[j] = {key_of(rows[(2 * j + 1) * n / (2 * s)]), static_cast<double>(n) / double(s)};
  }
  std::vector<std::vector<std::byte>> all;
  comm.all_gather(std::as_bytes(std::span(mine)), all);
  std::vector<Sample> samples = rows_of<Sample>(all);
  std::sort(samples.begin(), samples.end(),
            [](const Sample& a, const Sample& b) { return a.key < b.key; });
  double weight = 0.0;
  for (const Sample& x : samples) weight += x.weight;
  // splitter[k − 1] starts the keys of rank k: the sample at which the cumulated weight passes
  // k / P of the whole.
  std::vector<Key> splitters;
  double cumulated = 0.0;
  std::size_t at = 0;
  for (int k = 1; k < P && !samples.empty(); ++k) {
    const double target = weight * k / P;
    while (at + 1 < samples.size() && cumulated + samples[at].weight < target) {
      cumulated += samples[at++].weight;
    }
    splitters.push_back(samples[at].key);
  }
  std::vector<std::vector<std::byte>> send(static_cast<std::size_t>(P));
  std::size_t first = 0;
  for (int r = 0; r < P; ++r) {
    // Rows [first, last) have keys below splitter r (rank r's upper end; the last rank's: none).
    std::size_t last = n;
    if (r < static_cast<int>(splitters.size())) {
      const Key& upper = splitters[static_cast<std::size_t>(r)];
      last = static_cast<std::size_t>(
          std::partition_point(rows.begin() + static_cast<std::ptrdiff_t>(first), rows.end(),
                               [&](const Row& row) { return key_of(row) < upper; }) -
          rows.begin());
    }
    std::vector<std::byte>& out = send[static_cast<std::size_t>(r)];
    out.resize((last - first) * sizeof(Row));
    if (last > first) std::memcpy(out.data(), rows.data() + first, out.size());
    first = last;
  }
  std::vector<std::vector<std::byte>> received;
  exchange_with_all(comm, send, received);
  rows = rows_of<Row>(received);
  std::sort(rows.begin(), rows.end(), less);
  return block_of(comm, rows.size());
}
// [sort across]

}  // namespace grbd::collective
