#pragma once
/// \file
/// \brief A time limit for a call that might block or loop forever: the test program aborts with
/// a message instead of hanging the suite.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <string>
#include <utility>

namespace grbd::test {

/// Runs `f` on another thread and returns what it returns (or throws what it throws), but aborts
/// the whole test program, naming `what`, if `f` has not finished after `limit`: a thread that
/// blocks or loops cannot be stopped, and a hang must fail the suite rather than stall it.
template <class F>
auto within(std::chrono::seconds limit, const std::string& what, F&& f) {
  auto future = std::async(std::launch::async, std::forward<F>(f));
  if (future.wait_for(limit) != std::future_status::ready) {
    std::fprintf(stderr, "FATAL: %s has not finished after %lld s: it blocks or loops\n",
                 what.c_str(), static_cast<long long>(limit.count()));
    std::fflush(stderr);
    std::abort();
  }
  return future.get();
}

}  // namespace grbd::test
