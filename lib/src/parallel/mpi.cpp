/// \file
/// \brief MPI for a program: the environment, the communicator, abort_run().

#include "grbd/parallel/mpi.hpp"

// The C interface only: Open MPI's deprecated C++ bindings would need libmpi_cxx.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>
#include <thread>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::parallel {

namespace {

// Ends the run when an MPI call fails (MPI's default handler would abort without a word of ours).
void check(int status, const char* what) {
  if (status == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(status, text, &length);
  abort_run(std::string("MPI failed in ") + what + ": " + std::string(text, length), 1);
}

int int_count(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    abort_run(std::string(what) + ": a message of " + std::to_string(n) +
                  " bytes exceeds MPI's int count; split it",
              1);
  }
  return static_cast<int>(n);
}

MpiEnvironment* the_environment = nullptr;

}  // namespace

bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"}) {
    if (std::getenv(name) != nullptr) return true;
  }
  return false;
}

int launcher_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"}) {
    if (const char* value = std::getenv(name); value != nullptr) {
      char* end = nullptr;
      const long rank = std::strtol(value, &end, 10);
      if (end != value && *end == '\0' && rank >= 0) return static_cast<int>(rank);
    }
  }
  return 0;
}

struct MpiCommunicator::Impl {
  MPI_Comm comm = MPI_COMM_NULL;
  // The agreement's own communicator: a process that failed agrees there while the others may
  // still wait in a collective operation of `comm` (a step's reduction), which a reduction of the
  // agreement on `comm` would be matched with.
  MPI_Comm agreement = MPI_COMM_NULL;
};

MpiCommunicator::MpiCommunicator() : impl_(std::make_unique<Impl>()) {
  check(MPI_Comm_dup(MPI_COMM_WORLD, &impl_->comm), "MPI_Comm_dup");
  check(MPI_Comm_set_errhandler(impl_->comm, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
  check(MPI_Comm_dup(impl_->comm, &impl_->agreement), "MPI_Comm_dup");
  check(MPI_Comm_rank(impl_->comm, &rank_), "MPI_Comm_rank");
  check(MPI_Comm_size(impl_->comm, &size_), "MPI_Comm_size");
}

MpiCommunicator::~MpiCommunicator() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) return;
  if (impl_->agreement != MPI_COMM_NULL) MPI_Comm_free(&impl_->agreement);
  if (impl_->comm != MPI_COMM_NULL) MPI_Comm_free(&impl_->comm);
}

int MpiCommunicator::rank() const { return rank_; }
int MpiCommunicator::size() const { return size_; }

// [rank order sum]
void MpiCommunicator::sum(std::span<double> values) const {
  ++traffic_.collectives;
  // Every rank's values on every rank, then added in rank order: the same bits everywhere and on
  // every run, whatever reduction tree MPI would choose.
  const int n = int_count(values.size(), "Communicator::sum");
  std::vector<double> all(static_cast<std::size_t>(n) * static_cast<std::size_t>(size_));
  check(MPI_Allgather(values.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, impl_->comm),
        "MPI_Allgather (sum)");
  for (std::size_t k = 0; k < values.size(); ++k) {
    double total = 0.0;
    for (int r = 0; r < size_; ++r) total += all[static_cast<std::size_t>(r) * values.size() + k];
    values[k] = total;
  }
}
// [rank order sum]

void MpiCommunicator::sum(std::span<std::uint64_t> values) const {
  ++traffic_.collectives;
  check(MPI_Allreduce(MPI_IN_PLACE, values.data(), int_count(values.size(), "Communicator::sum"),
                      MPI_UINT64_T, MPI_SUM, impl_->comm),
        "MPI_Allreduce (sum)");
}

void MpiCommunicator::max(std::span<double> values) const {
  ++traffic_.collectives;
  check(MPI_Allreduce(MPI_IN_PLACE, values.data(), int_count(values.size(), "Communicator::max"),
                      MPI_DOUBLE, MPI_MAX, impl_->comm),
        "MPI_Allreduce (max)");
}

void MpiCommunicator::min(std::span<double> values) const {
  ++traffic_.collectives;
  check(MPI_Allreduce(MPI_IN_PLACE, values.data(), int_count(values.size(), "Communicator::min"),
                      MPI_DOUBLE, MPI_MIN, impl_->comm),
        "MPI_Allreduce (min)");
}

bool MpiCommunicator::all(bool value) const {
  ++traffic_.collectives;
  int flag = value ? 1 : 0;
  check(MPI_Allreduce(MPI_IN_PLACE, &flag, 1, MPI_INT, MPI_LAND, impl_->comm),
        "MPI_Allreduce (all)");
  return flag != 0;
}

// [agree]
bool MpiCommunicator::agree(bool ok, const std::string& error, double patience) const {
  ++traffic_.collectives;
  int flag = ok ? 1 : 0;
  int result = 0;
  MPI_Request request = MPI_REQUEST_NULL;
  check(MPI_Iallreduce(&flag, &result, 1, MPI_INT, MPI_LAND, impl_->agreement, &request),
        "MPI_Iallreduce (agree)");
  if (ok) {
    check(MPI_Wait(&request, MPI_STATUS_IGNORE), "MPI_Wait (agree)");
    return result != 0;
  }
  // This process failed: the others may be waiting inside a collective call it left.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(patience);
  int done = 0;
  while (true) {
    check(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "MPI_Test (agree)");
    if (done != 0) return result != 0;
    if (std::chrono::steady_clock::now() > deadline) {
      abort_run(error + " (the other processes did not answer within " + format_number(patience) +
                    " s: they wait inside an operation this process could not finish)",
                1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}
// [agree]

void MpiCommunicator::broadcast(std::vector<std::byte>& bytes, int root) const {
  ++traffic_.collectives;
  if (root < 0 || root >= size_) {
    throw InvalidArgument("Communicator::broadcast: expected a root in [0, " +
                          std::to_string(size_) + "), found " + std::to_string(root));
  }
  std::uint64_t n = bytes.size();
  check(MPI_Bcast(&n, 1, MPI_UINT64_T, root, impl_->comm), "MPI_Bcast (size)");
  bytes.resize(n);
  check(
      MPI_Bcast(bytes.data(), int_count(n, "Communicator::broadcast"), MPI_BYTE, root, impl_->comm),
      "MPI_Bcast");
}

void MpiCommunicator::all_gather(std::span<const std::byte> mine,
                                 std::vector<std::vector<std::byte>>& all) const {
  ++traffic_.collectives;
  const int n = int_count(mine.size(), "Communicator::all_gather");
  std::vector<int> counts(static_cast<std::size_t>(size_));
  check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, impl_->comm),
        "MPI_Allgather (sizes)");
  std::vector<int> offsets(static_cast<std::size_t>(size_));
  std::size_t total = 0;
  for (int r = 0; r < size_; ++r) {
    offsets[static_cast<std::size_t>(r)] = int_count(total, "Communicator::all_gather");
    total += static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]);
  }
  std::vector<std::byte> flat(total);
  check(MPI_Allgatherv(mine.data(), n, MPI_BYTE, flat.data(), counts.data(), offsets.data(),
                       MPI_BYTE, impl_->comm),
        "MPI_Allgatherv");
  all.resize(static_cast<std::size_t>(size_));
  for (int r = 0; r < size_; ++r) {
    const auto from = flat.begin() + offsets[static_cast<std::size_t>(r)];
    all[static_cast<std::size_t>(r)].assign(from, from + counts[static_cast<std::size_t>(r)]);
  }
}

void MpiCommunicator::gather(std::span<const std::byte> mine,
                             std::vector<std::vector<std::byte>>& all, int root) const {
  ++traffic_.collectives;
  if (root < 0 || root >= size_) {
    throw InvalidArgument("Communicator::gather: expected a root in [0, " + std::to_string(size_) +
                          "), found " + std::to_string(root));
  }
  const int n = int_count(mine.size(), "Communicator::gather");
  const bool at_root = rank_ == root;
  std::vector<int> counts(at_root ? static_cast<std::size_t>(size_) : 0);
  check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, impl_->comm),
        "MPI_Gather (sizes)");
  std::vector<int> offsets(counts.size());
  std::size_t total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    offsets[r] = int_count(total, "Communicator::gather");
    total += static_cast<std::size_t>(counts[r]);
  }
  std::vector<std::byte> flat(total);
  check(MPI_Gatherv(mine.data(), n, MPI_BYTE, flat.data(), counts.data(), offsets.data(), MPI_BYTE,
                    root, impl_->comm),
        "MPI_Gatherv");
  all.clear();
  if (!at_root) return;
  all.resize(counts.size());
  for (std::size_t r = 0; r < counts.size(); ++r) {
    const auto from = flat.begin() + offsets[r];
    all[r].assign(from, from + counts[r]);
  }
}

// [exchange]
void MpiCommunicator::exchange(std::span<const int> neighbours,
                               std::span<const std::vector<std::byte>> send,
                               std::vector<std::vector<std::byte>>& received) const {
  require_exchange(neighbours, send, size_);
  const std::size_t m = neighbours.size();
  received.resize(m);
  // Sizes first, then the messages: every receive is posted before any wait, so no order of
  // neighbours can deadlock. A rank that is its own neighbour copies.
  constexpr int kSizeTag = 7101;
  constexpr int kDataTag = 7102;
  std::vector<std::uint64_t> sizes_out(m), sizes_in(m, 0);
  std::vector<MPI_Request> requests;
  requests.reserve(2 * m);
  for (std::size_t k = 0; k < m; ++k) {
    const int peer = neighbours[k];
    sizes_out[k] = send[k].size();
    if (peer == rank_) continue;
    requests.emplace_back();
    check(MPI_Irecv(&sizes_in[k], 1, MPI_UINT64_T, peer, kSizeTag, impl_->comm, &requests.back()),
          "MPI_Irecv (sizes)");
    requests.emplace_back();
    check(MPI_Isend(&sizes_out[k], 1, MPI_UINT64_T, peer, kSizeTag, impl_->comm, &requests.back()),
          "MPI_Isend (sizes)");
  }
  check(MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE),
        "MPI_Waitall (sizes)");
  requests.clear();
  for (std::size_t k = 0; k < m; ++k) {
    const int peer = neighbours[k];
    if (peer == rank_) {
      received[k] = send[k];
      continue;
    }
    received[k].resize(sizes_in[k]);
    traffic_.messages += 2;  // the size and the message
    traffic_.bytes += sizeof(std::uint64_t) + send[k].size();
    requests.emplace_back();
    check(MPI_Irecv(received[k].data(), int_count(sizes_in[k], "Communicator::exchange"), MPI_BYTE,
                    peer, kDataTag, impl_->comm, &requests.back()),
          "MPI_Irecv");
    requests.emplace_back();
    check(MPI_Isend(send[k].data(), int_count(send[k].size(), "Communicator::exchange"), MPI_BYTE,
                    peer, kDataTag, impl_->comm, &requests.back()),
          "MPI_Isend");
  }
  check(MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE),
        "MPI_Waitall");
}
// [exchange]

void MpiCommunicator::barrier() const {
  ++traffic_.collectives;
  check(MPI_Barrier(impl_->comm), "MPI_Barrier");
}

const void* MpiCommunicator::mpi_comm() const { return &impl_->comm; }

MpiEnvironment::MpiEnvironment(bool force) {
  if (the_environment != nullptr) {
    throw Error("MpiEnvironment: only one may exist in a program");
  }
  if (force || launched_by_mpi()) {
    int provided = 0;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    world_ = std::make_unique<MpiCommunicator>();
  }
  the_environment = this;
}

MpiEnvironment::~MpiEnvironment() {
  if (world_) {
    world_.reset();
    MPI_Finalize();
  }
  the_environment = nullptr;
}

void MpiEnvironment::end_now(int exit_code) const {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  // The processes leave together: a process that ended first would make mpiexec kill the others,
  // rank 0 among them before it wrote the job's one message. A non-blocking barrier, waited for
  // at most kEndWait: a process that never comes (it did not meet the failure) cannot hold the
  // others. MPI itself is intact; only HDF5's collective state is apart.
  if (world_ && world_->size() > 1) {
    constexpr auto kEndWait = std::chrono::seconds(10);
    MPI_Request request = MPI_REQUEST_NULL;
    if (MPI_Ibarrier(MPI_COMM_WORLD, &request) == MPI_SUCCESS) {
      const auto deadline = std::chrono::steady_clock::now() + kEndWait;
      int done = 0;
      while (MPI_Test(&request, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && done == 0 &&
             std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    }
  }
  std::_Exit(exit_code);
}

const Communicator& MpiEnvironment::world() const {
  return world_ ? static_cast<const Communicator&>(*world_) : self_communicator();
}

void abort_run(const std::string& message, int exit_code) {
  int initialized = 0;
  int finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  if (initialized && !finalized) {
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::fprintf(stderr, "grbd: rank %d: %s\n", rank, message.c_str());
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, exit_code);
  }
  std::fprintf(stderr, "grbd: %s\n", message.c_str());
  std::exit(exit_code);
}

}  // namespace grbd::parallel
