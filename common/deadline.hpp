// Cooperative time limits: a thread runs under at most one deadline (the earliest of the
// ScopedDeadlines alive on it), and the long loops of spar (grasp quantization, constraint
// posting, phase 2's instances, branch and bound, Monte Carlo) call check_deadline(), which
// throws TimeLimitError once the deadline has passed. `spar plan --batch --time-limit S` puts
// each scenario under one, so a scenario that would run for minutes gives a `time_limit` record
// and the batch goes on.
//
// Rules: check_deadline() is cheap without a deadline (one thread-local read) and reads the clock
// at most every 64th call with one, so a loop may call it once per iteration; it is never called
// where an exception cannot pass (inside an NLopt callback, a destructor). Code that catches
// spar::Error to turn a failure into a result must let TimeLimitError through (rethrow it).
//
// Example:
//   const ScopedDeadline limit(std::chrono::seconds(30));
//   for (const auto& pair : pairs) {
//     check_deadline();   // throws TimeLimitError "time limit of 30 s reached" after 30 s
//     work(pair);
//   }
#pragma once

#include <chrono>
#include <optional>

#include "spar/common/error.hpp"

namespace spar {

// The thread's deadline passed; the message says how long the limit was.
class TimeLimitError : public Error {
 public:
  using Error::Error;
};

// A point in time a thread must finish by, and the limit it came from (for the message).
struct Deadline {
  std::chrono::steady_clock::time_point at;
  double seconds;
};

// The calling thread's deadline, if it runs under one: threads that work for it take it along
// (ScopedDeadline(Deadline), as common/parallel.hpp's workers do).
[[nodiscard]] std::optional<Deadline> current_deadline();

// Puts the calling thread under `limit` from now, or under `deadline` (another thread's), or
// keeps an earlier deadline already set, until destroyed, when the previous deadline comes back.
// Not movable: it belongs to a scope.
class ScopedDeadline {
 public:
  explicit ScopedDeadline(std::chrono::duration<double> limit);
  explicit ScopedDeadline(const Deadline& deadline);
  ~ScopedDeadline();
  ScopedDeadline(const ScopedDeadline&) = delete;
  ScopedDeadline& operator=(const ScopedDeadline&) = delete;

 private:
  std::optional<Deadline> previous_;
};

// Throws TimeLimitError when the calling thread's deadline has passed.
void check_deadline();

}  // namespace spar
