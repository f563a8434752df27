/// \file
/// \brief The one-process communicator.

#include "grbd/core/communicator.hpp"

#include <string>

#include "grbd/core/error.hpp"

namespace grbd {

void SelfCommunicator::broadcast(std::vector<std::byte>&, int root) const {
  if (root != 0) {
    throw InvalidArgument("SelfCommunicator::broadcast: expected root 0, found " +
                          std::to_string(root));
  }
}

void SelfCommunicator::all_gather(std::span<const std::byte> mine,
                                  std::vector<std::vector<std::byte>>& all) const {
  all.resize(1);
  all[0].assign(mine.begin(), mine.end());
}

void SelfCommunicator::gather(std::span<const std::byte> mine,
                              std::vector<std::vector<std::byte>>& all, int root) const {
  if (root != 0) {
    throw InvalidArgument("Communicator::gather: expected root 0 of 1 process, found " +
                          std::to_string(root));
  }
  all_gather(mine, all);
}

void require_exchange(std::span<const int> neighbours,
                      std::span<const std::vector<std::byte>> send, int size) {
  if (send.size() != neighbours.size()) {
    throw InvalidArgument("Communicator::exchange: expected one message per neighbour, found " +
                          std::to_string(send.size()) + " for " +
                          std::to_string(neighbours.size()));
  }
  for (const int peer : neighbours) {
    if (peer < 0 || peer >= size) {
      throw InvalidArgument("Communicator::exchange: expected neighbours in [0, " +
                            std::to_string(size) + "), found " + std::to_string(peer));
    }
  }
}

void SelfCommunicator::exchange(std::span<const int> neighbours,
                                std::span<const std::vector<std::byte>> send,
                                std::vector<std::vector<std::byte>>& received) const {
  require_exchange(neighbours, send, 1);
  received.assign(send.begin(), send.end());  // every neighbour is this rank
}

const Communicator& self_communicator() {
  static const SelfCommunicator self;
  return self;
}

}  // namespace grbd
