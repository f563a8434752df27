#pragma once
// What the output and the checkpoints need to be written by many processes at once (chapter 8;
// private to the library): rows put into one global order across the processes (a sample sort),
// so that each process writes one contiguous block of a dataset, and the agreement on an error
// that only some processes meet while they read or write a file.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <exception>
#include <new>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/io/output.hpp"
#include "grbd/timestep/contacts.hpp"

namespace grbd::io::collective {

/// A warm start as a row of a checkpoint or of a message: its contact's key and percussion.
struct WarmRow {
  timestep::ContactKey key;  ///< the contact
  double lambda[3];          ///< its percussion Λ [N s]
};

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

/// Runs `work` on every process; when it throws on some, every process throws IoError with the
/// message of the lowest rank that failed (collective): what a file read or written by every
/// process needs, where one process may find a damaged row that the others never see. Without
/// an error, every process returns.
template <class Work>
void agree(const Communicator& comm, Work&& work) {
  if (comm.size() == 1) {
    work();
    return;
  }
  std::string message;
  bool failed = false;
  try {
    work();
  } catch (const std::bad_alloc&) {
    failed = true;
    message = "out of memory";
  } catch (const std::exception& e) {
    failed = true;
    message = e.what();
  }
  // A process that failed inside a collective call of parallel HDF5 has left the others waiting
  // in it: after kAgreementPatience it ends the run with its message rather than wait forever.
  if (comm.agree(!failed, message, kAgreementPatience)) return;
  std::vector<std::vector<std::byte>> all;
  std::vector<std::byte> mine(failed ? message.size() + 1 : 0);
  if (failed) std::memcpy(mine.data(), message.data(), message.size());
  comm.all_gather(mine, all);
  for (const std::vector<std::byte>& part : all) {
    if (part.empty()) continue;
    throw IoError(std::string(reinterpret_cast<const char*>(part.data()), part.size() - 1));
  }
}

}  // namespace grbd::io::collective
