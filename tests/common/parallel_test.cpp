// run_tasks (common/parallel.hpp): every task runs once on any number of threads, progress is
// reported on the calling thread only, the first error comes back to the caller and stops new
// tasks, workers run under the caller's deadline, and caller_first runs on the caller meanwhile.
#include "spar/common/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <latch>
#include <string>
#include <thread>
#include <vector>

#include "spar/common/deadline.hpp"
#include "tests/common/expect_message.hpp"

namespace spar {
namespace {

using namespace std::chrono_literals;

TEST(RunTasks, EveryTaskRunsOnceWhateverTheThreads) {
  for (const unsigned threads : {0u, 1u, 2u, 3u, 8u})
    for (const std::size_t count : {0u, 1u, 2u, 7u, 500u}) {
      std::vector<std::atomic<int>> runs(count);
      run_tasks(count, threads, [&](std::size_t i) { ++runs[i]; });
      for (std::size_t i = 0; i < count; ++i)
        EXPECT_EQ(runs[i], 1) << "task " << i << " of " << count << ", " << threads << " threads";
    }
}

TEST(RunTasks, OneThreadRunsThemInOrderOnTheCaller) {
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<std::size_t> order;
  std::vector<std::size_t> reported;
  run_tasks(
      5, 1,
      [&](std::size_t i) {
        EXPECT_EQ(std::this_thread::get_id(), caller);
        order.push_back(i);
      },
      [&](std::size_t finished) { reported.push_back(finished); });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(reported, (std::vector<std::size_t>{1, 2, 3, 4, 5}));
}

TEST(RunTasks, ProgressComesOnTheCallingThreadOnly) {
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<bool> elsewhere{false};
  std::size_t last = 0;
  bool increasing = true;
  run_tasks(
      200, 4, [](std::size_t) { std::this_thread::sleep_for(10us); },
      [&](std::size_t finished) {
        elsewhere = elsewhere || std::this_thread::get_id() != caller;
        increasing = increasing && finished > last;
        last = finished;
      });
  EXPECT_FALSE(elsewhere);
  EXPECT_TRUE(increasing);
  EXPECT_LE(last, 200u);
}

TEST(RunTasks, TheFirstErrorReachesTheCallerAndNoTaskStartsAfterIt) {
  std::vector<std::size_t> ran;
  EXPECT_THROW_MESSAGE(run_tasks(10, 1,
                                 [&](std::size_t i) {
                                   ran.push_back(i);
                                   if (i == 3) throw Error("task 3 failed");
                                 }),
                       "task 3 failed");
  EXPECT_EQ(ran, (std::vector<std::size_t>{0, 1, 2, 3}));
  // On several threads too (the others stop taking tasks; the ones running finish).
  std::atomic<int> started{0};
  EXPECT_THROW_MESSAGE(run_tasks(1000, 3,
                                 [&](std::size_t i) {
                                   ++started;
                                   if (i == 0) throw Error("the first task failed");
                                   std::this_thread::sleep_for(100us);
                                 }),
                       "the first task failed");
  EXPECT_LT(started, 1000);
}

// A progress report that throws (plan()'s checks the time limit) stops the work like a task's
// error: the workers take no new task.
TEST(RunTasks, AProgressReportThatThrowsStopsTheWork) {
  std::atomic<int> started{0};
  EXPECT_THROW_MESSAGE(run_tasks(
                           1000, 2,
                           [&](std::size_t) {
                             ++started;
                             std::this_thread::sleep_for(200us);
                           },
                           [](std::size_t) { throw Error("time limit of 1 s reached"); }),
                       "time limit of 1 s reached");
  EXPECT_LT(started, 100);
}

TEST(RunTasks, WorkersRunUnderTheCallersDeadline) {
  const std::thread::id caller = std::this_thread::get_id();
  const ScopedDeadline limit(1ms);
  std::this_thread::sleep_for(5ms);
  std::atomic<bool> worker_checked{false};
  // The caller's own task only waits, so the error can come only from a worker's check.
  EXPECT_THROW_MESSAGE(run_tasks(2, 2,
                                 [&](std::size_t) {
                                   if (std::this_thread::get_id() == caller) {
                                     std::this_thread::sleep_for(50ms);
                                     return;
                                   }
                                   worker_checked = true;
                                   for (int i = 0; i < 200; ++i) check_deadline();
                                 }),
                       "time limit of 0.001 s reached");
  EXPECT_TRUE(worker_checked);
}

// caller_first runs once, on the caller, before its first task, while the workers already take
// tasks; with one thread it runs before every task.
TEST(RunTasks, CallerFirstRunsOnTheCallerWhileTheWorkersStart) {
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<std::string> order;
  run_tasks(
      3, 1, [&](std::size_t i) { order.push_back("task " + std::to_string(i)); }, {},
      [&] {
        EXPECT_EQ(std::this_thread::get_id(), caller);
        order.push_back("first");
      });
  EXPECT_EQ(order, (std::vector<std::string>{"first", "task 0", "task 1", "task 2"}));
  // Two threads: the worker finishes task 0 while the caller is still in caller_first (it waits
  // for that task), and the task needing caller_first's result waits for it.
  std::latch task_zero_done(1), built(1);
  std::atomic<bool> first_ran{false};
  std::atomic<int> runs{0};
  run_tasks(
      2, 2,
      [&](std::size_t i) {
        if (i == 0) {
          EXPECT_NE(std::this_thread::get_id(), caller);
          task_zero_done.count_down();
        } else {
          built.wait();
          EXPECT_TRUE(first_ran);
        }
        ++runs;
      },
      {},
      [&] {
        task_zero_done.wait();  // task 0 ran meanwhile, on the worker
        first_ran = true;
        built.count_down();
      });
  EXPECT_EQ(runs, 2);
}

TEST(RunTasks, AnErrorInCallerFirstReachesTheCaller) {
  for (const unsigned threads : {1u, 2u}) {
    std::atomic<int> started{0};
    EXPECT_THROW_MESSAGE(run_tasks(
                             1000, threads,
                             [&](std::size_t) {
                               ++started;
                               std::this_thread::sleep_for(100us);
                             },
                             {}, [] { throw Error("building failed"); }),
                         "building failed");
    EXPECT_LT(started, 1000) << threads << " threads";
  }
}

}  // namespace
}  // namespace spar
