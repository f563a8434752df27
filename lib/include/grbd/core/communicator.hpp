#pragma once
/// \file
/// \brief The processes of a run and what they do together (chapter 8): a communicator with the
/// collective operations that the scene, the output and the parallel engine need. The one-process
/// communicator is here, in `core`, so that `scene` and `io` can be written collectively without
/// depending on MPI; `parallel::MpiCommunicator` is the one for `mpirun`. MPI's types never appear
/// in a public header.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace grbd {

/// How long a process that met an error waits for the others to agree on it [s]
/// (Communicator::agree): long enough for any process that is not stuck to finish its part of a
/// collective operation and arrive.
inline constexpr double kAgreementPatience = 20.0;

/// The processes of a run, numbered 0 … size() − 1, and their collective operations. Every
/// process of the communicator must make the same collective calls in the same order, with
/// arguments of the same length: a mismatch is a programming error that MPI may answer with a
/// hang, so the callers keep their calls in lock step. The operations do not throw on their own;
/// an implementation that cannot complete one ends the run (parallel::MpiCommunicator: one
/// message, every rank ends).
class Communicator {
 public:
  virtual ~Communicator() = default;

  /// This process's number.
  virtual int rank() const = 0;
  /// Number of processes.
  virtual int size() const = 0;

  /// \name Reductions, element by element, in place; every process gets the result. A sum of
  /// doubles is formed in rank order, so that every process gets the same bits and a repeated run
  /// the same result (MPI_Allreduce promises neither).
  ///@{
  virtual void sum(std::span<double> values) const = 0;         ///< Σ over processes
  virtual void sum(std::span<std::uint64_t> values) const = 0;  ///< Σ over processes
  virtual void max(std::span<double> values) const = 0;         ///< max over processes
  virtual void min(std::span<double> values) const = 0;         ///< min over processes
  ///@}
  /// True on every process when `value` is true on every process.
  virtual bool all(bool value) const = 0;
  /// True on every process when `value` is true on some process.
  bool any(bool value) const { return !all(!value); }
  /// The agreement after work that may have failed on some processes: true on every process when
  /// `ok` is true on every process. A process whose `ok` is false waits at most `patience` seconds
  /// for the others; when they do not all arrive — some wait inside a collective operation that
  /// this process left through its error, of parallel HDF5 for instance — no agreement can come,
  /// and this process ends the run with `error` (MpiCommunicator: abort_run(), exit code 1, one
  /// message, every process ends) instead of waiting forever. A process whose `ok` is true waits
  /// as long as it takes. The one-process communicator returns `ok`.
  virtual bool agree(bool ok, const std::string& error, double patience) const {
    static_cast<void>(error);
    static_cast<void>(patience);
    return all(ok);
  }

  /// Rank `root`'s bytes, given to every process (resized there).
  virtual void broadcast(std::vector<std::byte>& bytes, int root) const = 0;
  /// Every process's bytes, in rank order, on every process: `all[r]` is what rank r gave.
  virtual void all_gather(std::span<const std::byte> mine,
                          std::vector<std::vector<std::byte>>& all) const = 0;
  /// Every process's bytes, in rank order, on rank `root` only (`all[r]` is what rank r gave;
  /// `all` is emptied on the other ranks): what a record of the output needs, without a copy of
  /// every body on every process.
  virtual void gather(std::span<const std::byte> mine, std::vector<std::vector<std::byte>>& all,
                      int root) const = 0;
  /// One message to each neighbour and one from each: `send[k]` goes to rank `neighbours[k]`,
  /// `received[k]` (resized) comes from it. Neighbours are symmetric (if b is a's, a is b's; each
  /// lists the other once) and may include this rank itself (periodic images at P = 1). The
  /// messages are sent without waiting for each other (non-blocking), so that no order of calls
  /// can deadlock.
  virtual void exchange(std::span<const int> neighbours,
                        std::span<const std::vector<std::byte>> send,
                        std::vector<std::vector<std::byte>>& received) const = 0;
  /// Waits until every process has called it.
  virtual void barrier() const = 0;
  /// The address of the MPI communicator (an `MPI_Comm`) behind this one, for a library that
  /// works collectively over it (parallel HDF5); nullptr for a communicator without MPI.
  virtual const void* mpi_comm() const { return nullptr; }

  /// What this process has sent through the communicator so far: the point-to-point messages of
  /// exchange() (a size and a body for each neighbour that is not this process) with their bytes,
  /// and the collective operations it took part in (reductions, broadcasts, gathers, barriers).
  struct Traffic {
    std::uint64_t messages = 0;     ///< point-to-point messages sent
    std::uint64_t bytes = 0;        ///< their bytes
    std::uint64_t collectives = 0;  ///< collective operations
  };
  /// The traffic so far (zero for the one-process communicator).
  const Traffic& traffic() const { return traffic_; }

 protected:
  mutable Traffic traffic_;  ///< counted by the implementations
};

/// The communicator of a process that runs alone: rank 0 of 1, every collective operation the
/// identity (a reduction leaves its values, a broadcast its bytes, an exchange hands each message
/// to this rank itself).
class SelfCommunicator final : public Communicator {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void sum(std::span<double>) const override {}
  void sum(std::span<std::uint64_t>) const override {}
  void max(std::span<double>) const override {}
  void min(std::span<double>) const override {}
  bool all(bool value) const override { return value; }
  void broadcast(std::vector<std::byte>& bytes, int root) const override;
  void all_gather(std::span<const std::byte> mine,
                  std::vector<std::vector<std::byte>>& all) const override;
  void gather(std::span<const std::byte> mine, std::vector<std::vector<std::byte>>& all,
              int root) const override;
  void exchange(std::span<const int> neighbours, std::span<const std::vector<std::byte>> send,
                std::vector<std::vector<std::byte>>& received) const override;
  void barrier() const override {}
};

/// Throws InvalidArgument unless there is one message per neighbour and every neighbour is a rank
/// in [0, size): the check every Communicator::exchange() makes before it sends anything.
void require_exchange(std::span<const int> neighbours, std::span<const std::vector<std::byte>> send,
                      int size);

/// The one-process communicator (a process-wide instance).
const Communicator& self_communicator();

}  // namespace grbd
