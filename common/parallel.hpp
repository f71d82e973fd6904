// run_tasks: independent tasks on a few threads, for work that splits into parts which share
// nothing mutable (phase 2's margins: each part bounds its own copy of a precondition).
//
// Rules:
//   - task(0) ... task(count - 1) each run exactly once, on the calling thread and up to
//     threads - 1 workers started for the call; threads <= 1 (or a single task) runs them all on
//     the caller, in order, with no thread started. Which thread runs which task varies from run
//     to run, so a task must write only what is its own: results do not depend on the schedule.
//   - Tasks are taken in index order (put the long ones first for a short makespan).
//   - Workers run under the caller's deadline (common/deadline.hpp): check_deadline() in a task
//     throws there as it would on the caller.
//   - The first exception a task (or on_caller_done) throws is rethrown on the caller once every
//     thread has stopped; no task starts after it is thrown (the ones running finish).
//   - `on_caller_done(finished)`, if set, is called on the calling thread only, after each task
//     it ran, with the number of tasks finished so far on every thread: progress reports stay on
//     the thread that asked for the work.
//   - `caller_first`, if set, runs once on the calling thread after the workers have started and
//     before it takes a task: work only that thread may do (reading an expression pool it owns)
//     overlaps the workers' first tasks. A task that needs its result waits for it (a std::latch
//     it counts down when it ends, thrown or not); if it throws, that is rethrown like a task's.
// Cost: threads - 1 thread starts per call, one atomic increment per task.
//
// Example:
//   std::vector<double> squares(100);
//   spar::run_tasks(squares.size(), 2, [&](std::size_t i) { squares[i] = double(i) * i; });
#pragma once

#include <cstddef>
#include <functional>

namespace spar {

void run_tasks(std::size_t count, unsigned threads, const std::function<void(std::size_t)>& task,
               const std::function<void(std::size_t finished)>& on_caller_done = {},
               const std::function<void()>& caller_first = {});

// The threads a command line uses by default: one per hardware thread (at least 1).
[[nodiscard]] unsigned default_threads();

}  // namespace spar
