// Wall-clock helpers the benchmark programs share: elapsed seconds, medians of repeated runs,
// and the machine's load average (printed next to every run: timings taken on a busy machine
// are compared as ratios within the run, never across runs).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace spar::bench {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The upper median (NaN for no values).
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? NAN : values[values.size() / 2];
}

// Wall time of each of `repeats` calls of `work`, in seconds.
inline std::vector<double> run_times(int repeats, const std::function<void()>& work) {
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    times.push_back(seconds_since(start));
  }
  return times;
}

// Median wall time of `repeats` calls of `work`, in seconds.
inline double time_median(int repeats, const std::function<void()>& work) {
  return median(run_times(repeats, work));
}

// "1 5 15"-minute load averages from /proc/loadavg.
inline std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

}  // namespace spar::bench
