#include "spar/common/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "spar/common/deadline.hpp"

namespace spar {

void run_tasks(std::size_t count, unsigned threads, const std::function<void(std::size_t)>& task,
               const std::function<void(std::size_t finished)>& on_caller_done,
               const std::function<void()>& caller_first) {
  std::atomic<std::size_t> next{0}, finished{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  // Remembers the first error and stops the others from taking tasks.
  const auto fail = [&] {
    const std::lock_guard lock(error_mutex);
    if (!first_error) first_error = std::current_exception();
    failed = true;
  };
  // Takes tasks until none is left or a task (or the caller's progress report: a time limit
  // checked there) has thrown.
  const auto work = [&](bool on_caller) {
    if (on_caller && caller_first) {
      try {
        caller_first();
      } catch (...) {
        fail();
        return;
      }
    }
    for (std::size_t i = next++; i < count && !failed; i = next++) {
      try {
        task(i);
        const std::size_t done = ++finished;
        if (on_caller && on_caller_done) on_caller_done(done);
      } catch (...) {
        fail();
        return;
      }
    }
  };
  const std::size_t workers =
      std::min<std::size_t>(threads > 1 ? threads - 1 : 0, count > 1 ? count - 1 : 0);
  {
    const std::optional<Deadline> deadline = current_deadline();
    std::vector<std::jthread> pool;
    for (std::size_t w = 0; w < workers; ++w)
      pool.emplace_back([&] {
        std::optional<ScopedDeadline> inherited;
        if (deadline) inherited.emplace(*deadline);
        work(false);
      });
    work(true);
  }  // joins the workers
  if (first_error) std::rethrow_exception(first_error);
}

unsigned default_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

}  // namespace spar
