#pragma once
/// \file
/// \brief MPI for a program (chapter 8): the environment that starts and ends it, the communicator
/// of all processes, and the one way an error ends a parallel run. MPI's own types stay in the
/// implementation; what the rest of grbd sees is a grbd::Communicator.

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "grbd/core/communicator.hpp"

namespace grbd::parallel {

/// True when this process was started by an MPI launcher (mpirun, mpiexec, srun with PMIx): the
/// launcher's environment variables are set. A program started alone then runs the serial path
/// and never initialises MPI.
bool launched_by_mpi();

/// This process's rank as the MPI launcher's environment gives it (0 when not launched by MPI),
/// known before MPI is initialised: the commands that run no MPI of their own speak on rank 0
/// only, one message per job.
int launcher_rank();

/// The communicator of every process of the run, MPI_COMM_WORLD (or a duplicate of a given
/// communicator). Collective operations as grbd::Communicator promises; a failing MPI call ends
/// every process through abort_run().
class MpiCommunicator final : public Communicator {
 public:
  /// A duplicate of MPI_COMM_WORLD, so that grbd's messages never meet a caller's.
  MpiCommunicator();
  ~MpiCommunicator() override;
  MpiCommunicator(const MpiCommunicator&) = delete;
  MpiCommunicator& operator=(const MpiCommunicator&) = delete;

  int rank() const override;
  int size() const override;
  void sum(std::span<double> values) const override;
  void sum(std::span<std::uint64_t> values) const override;
  void max(std::span<double> values) const override;
  void min(std::span<double> values) const override;
  bool all(bool value) const override;
  /// A non-blocking reduction (MPI_Iallreduce) that a process with `ok` false tests until
  /// `patience` has passed, then ends every process through abort_run(error, 1).
  bool agree(bool ok, const std::string& error, double patience) const override;
  void broadcast(std::vector<std::byte>& bytes, int root) const override;
  void all_gather(std::span<const std::byte> mine,
                  std::vector<std::vector<std::byte>>& all) const override;
  void gather(std::span<const std::byte> mine, std::vector<std::vector<std::byte>>& all,
              int root) const override;
  void exchange(std::span<const int> neighbours, std::span<const std::vector<std::byte>> send,
                std::vector<std::vector<std::byte>>& received) const override;
  void barrier() const override;
  const void* mpi_comm() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int rank_ = 0;
  int size_ = 1;
};

/// MPI for the lifetime of a program: initialised by the constructor when the program was
/// launched by MPI (launched_by_mpi()) or when `force` is set, finalised by the destructor. Only
/// one may exist. Without MPI, world() is the one-process communicator.
class MpiEnvironment {
 public:
  /// Initialises MPI (thread level MPI_THREAD_FUNNELED) if launched by MPI or `force`.
  explicit MpiEnvironment(bool force = false);
  ~MpiEnvironment();
  MpiEnvironment(const MpiEnvironment&) = delete;
  MpiEnvironment& operator=(const MpiEnvironment&) = delete;

  /// True when MPI is initialised.
  bool active() const { return world_ != nullptr; }
  /// All processes of the run (the one-process communicator without MPI).
  const Communicator& world() const;
  /// Ends this process now with `exit_code`, its output streams flushed, without finalizing MPI
  /// or closing HDF5: what every process of a run does after a collective write failed
  /// (io::AbandonedFiles), where HDF5's collective clean-up inside MPI_Finalize would hang or
  /// crash. The files hold what their last flush wrote. With several processes each first waits
  /// (at most 10 s) until all have come here, so that none ends before rank 0 said why.
  [[noreturn]] void end_now(int exit_code) const;

 private:
  std::unique_ptr<MpiCommunicator> world_;
};

/// Ends a parallel run from any rank: prints "grbd: rank R: <message>" once on stderr and ends
/// every process with `exit_code` (MPI_Abort); without MPI, prints "grbd: <message>" and exits.
/// The way an error that only some ranks see ends all of them, never a hang.
[[noreturn]] void abort_run(const std::string& message, int exit_code);

}  // namespace grbd::parallel
