#include "spar/common/deadline.hpp"

#include <cstdio>

namespace spar {
namespace {

struct ThreadDeadline {
  std::chrono::steady_clock::time_point at;
  double seconds{0};
  bool active{false};
  unsigned calls{0};  // the clock is read every kClockEvery calls
};

thread_local ThreadDeadline current;

constexpr unsigned kClockEvery = 64;

}  // namespace

std::optional<Deadline> current_deadline() {
  if (!current.active) return std::nullopt;
  return Deadline{current.at, current.seconds};
}

ScopedDeadline::ScopedDeadline(std::chrono::duration<double> limit)
    : ScopedDeadline(
          Deadline{std::chrono::steady_clock::now() +
                       std::chrono::duration_cast<std::chrono::steady_clock::duration>(limit),
                   limit.count()}) {}

ScopedDeadline::ScopedDeadline(const Deadline& deadline) {
  if (current.active) previous_ = Deadline{current.at, current.seconds};
  if (!current.active || deadline.at < current.at) {
    current.at = deadline.at;
    current.seconds = deadline.seconds;
  }
  current.active = true;
  current.calls = 0;
}

ScopedDeadline::~ScopedDeadline() {
  current.active = previous_.has_value();
  current.calls = 0;  // the next check reads the clock
  if (previous_) {
    current.at = previous_->at;
    current.seconds = previous_->seconds;
  }
}

void check_deadline() {
  if (!current.active || ++current.calls % kClockEvery != 1) return;
  if (std::chrono::steady_clock::now() < current.at) return;
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", current.seconds);
  throw TimeLimitError(std::string("time limit of ") + seconds + " s reached");
}

}  // namespace spar
