// Cooperative time limits (common/deadline.hpp, issue 22): nothing happens without a deadline, a
// loop that checks is stopped soon after its deadline, the earlier of two nested deadlines holds,
// and leaving a scope restores the one before.
#include "spar/common/deadline.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tests/common/expect_message.hpp"

namespace spar {
namespace {

using namespace std::chrono_literals;

// Calls check_deadline() until it throws; how long that took, and the message.
std::pair<std::chrono::duration<double>, std::string> run_until_stopped() {
  const auto start = std::chrono::steady_clock::now();
  try {
    for (int i = 0; i < 10'000'000; ++i) {
      check_deadline();
      if (i % 64 == 0) std::this_thread::sleep_for(100us);
    }
  } catch (const TimeLimitError& error) {
    return {std::chrono::steady_clock::now() - start, error.what()};
  }
  return {std::chrono::steady_clock::now() - start, ""};
}

TEST(Deadline, NoneMeansNoStop) {
  for (int i = 0; i < 1000; ++i) EXPECT_NO_THROW(check_deadline());
}

TEST(Deadline, ALoopThatChecksStopsSoonAfterIt) {
  const ScopedDeadline limit(20ms);
  const auto [took, message] = run_until_stopped();
  EXPECT_EQ(message, "time limit of 0.02 s reached");
  EXPECT_GE(took, 20ms);
  EXPECT_LT(took, 2s);  // generous: a shared machine
}

TEST(Deadline, TheEarlierOfNestedDeadlinesHoldsAndTheOuterComesBack) {
  const ScopedDeadline outer(30ms);
  {
    const ScopedDeadline inner(10s);  // later: the outer one still holds
    EXPECT_EQ(run_until_stopped().second, "time limit of 0.03 s reached");
  }
  EXPECT_THROW_MESSAGE(check_deadline(), "time limit of 0.03 s reached");
}

TEST(Deadline, LeavingTheScopeLiftsIt) {
  { const ScopedDeadline limit(1ms); }
  std::this_thread::sleep_for(5ms);
  for (int i = 0; i < 200; ++i) EXPECT_NO_THROW(check_deadline());
}

TEST(Deadline, EachThreadHasItsOwn) {
  const ScopedDeadline limit(1ms);
  std::this_thread::sleep_for(5ms);
  std::thread other([] {
    for (int i = 0; i < 200; ++i) EXPECT_NO_THROW(check_deadline());
  });
  other.join();
  EXPECT_THROW_MESSAGE(
      [] {
        for (int i = 0; i < 200; ++i) check_deadline();
      }(),
      "time limit of 0.001 s reached");
}

}  // namespace
}  // namespace spar
