#pragma once
/// \file
/// \brief The agreement on an error that only some processes meet (chapter 8): every phase of a
/// run that can fail on one process — reading the scene and the options, checking the files, a
/// step, a record, a checkpoint, the close — runs inside run_agreed(), and then every process throws
/// the same error or none does. One process is the serial case: the work runs and its error, if
/// any, propagates untouched.

#include <cstdint>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/core/error.hpp"

namespace grbd {

/// What run_agreed() uses to carry an error's kind from one process to the others.
namespace agreement_detail {

/// The position of the first of `Kinds` that `e` is (its dynamic type), or sizeof...(Kinds).
template <class... Kinds>
std::uint8_t kind_of(const std::exception& e) {
  std::uint8_t k = 0;
  const bool found = ((dynamic_cast<const Kinds*>(&e) != nullptr ? true : (++k, false)) || ...);
  static_cast<void>(found);
  return k;
}

/// Throws the `kind`-th of `Kinds` with `message`; past the list, grbd::Error(message).
template <class... Kinds>
[[noreturn]] void raise(std::uint8_t kind, const std::string& message) {
  std::uint8_t k = 0;
  ((kind == k++ ? throw Kinds(message) : void()), ...);
  throw Error(message);
}

}  // namespace agreement_detail

// [agree]
/// Runs `work` on every process of `comm`; when it throws on some, every process throws the error
/// of the lowest rank that failed, as the same kind (collective). `Kinds` are the error types the
/// caller tells apart — most derived first, each constructible from its message — because the
/// kind decides what happens next (the command line's exit code); any other grbd::Error or
/// std::exception arrives as grbd::Error, std::bad_alloc as std::bad_alloc. A message that not
/// every process met alike names its rank ("rank 2: …") unless that is rank 0, which speaks for
/// the run (and alone does the work that only one process does: checking the files).
///
/// A process that failed inside a collective operation that the others still wait in — a
/// collective write of parallel HDF5, an exchange of a step — cannot agree with them: after
/// kAgreementPatience seconds it ends every process with its message (Communicator::agree),
/// instead of a hang. At one process the work simply runs, and its exception propagates as
/// thrown.
template <class... Kinds, class Work>
void run_agreed(const Communicator& comm, Work&& work) {
  if (comm.size() == 1) {
    std::forward<Work>(work)();
    return;
  }
  constexpr auto kMemory = static_cast<std::uint8_t>(sizeof...(Kinds) + 1);
  std::vector<std::byte> mine;  // empty: no error here; else the kind, then the message
  const auto report = [&](std::uint8_t kind, const std::string& message) {
    mine.resize(1 + message.size());
    mine[0] = static_cast<std::byte>(kind);
    std::memcpy(mine.data() + 1, message.data(), message.size());
  };
  try {
    std::forward<Work>(work)();
  } catch (const std::bad_alloc&) {
    report(kMemory, "out of memory");
  } catch (const std::exception& e) {
    report(agreement_detail::kind_of<Kinds...>(e), e.what());
  }
  const std::string error =
      mine.empty() ? std::string()
                   : std::string(reinterpret_cast<const char*>(mine.data()) + 1, mine.size() - 1);
  if (comm.agree(mine.empty(), error, kAgreementPatience)) return;
  std::vector<std::vector<std::byte>> all;
  comm.all_gather(mine, all);
  bool alike = true;
  for (const std::vector<std::byte>& other : all) alike = alike && other == all.front();
  for (std::size_t r = 0; r < all.size(); ++r) {
    if (all[r].empty()) continue;
    const auto kind = static_cast<std::uint8_t>(all[r][0]);
    std::string message(reinterpret_cast<const char*>(all[r].data()) + 1, all[r].size() - 1);
    if (kind == kMemory) throw std::bad_alloc();
    if (!alike && r > 0) message = "rank " + std::to_string(r) + ": " + message;
    agreement_detail::raise<Kinds...>(kind, message);
  }
}
// [agree]

}  // namespace grbd
