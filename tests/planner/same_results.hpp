// Two results the tests expect to be equal bit for bit (the same work on one thread and on
// several, or split into parts): every field compared exactly, with where it differs.
#pragma once

#include <gtest/gtest.h>

#include "spar/planner/uncertainty/probability.hpp"

namespace spar::planner::testing {

inline void expect_same_allocation(const ToleranceAllocation& a, const ToleranceAllocation& b) {
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.rounds, b.rounds);
  EXPECT_EQ(a.cost, b.cost);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  for (std::size_t q = 0; q < a.parameters.size(); ++q)
    EXPECT_EQ(a.parameters[q].allocated, b.parameters[q].allocated) << a.parameters[q].name;
  ASSERT_EQ(a.misses.size(), b.misses.size());
  for (std::size_t k = 0; k < a.misses.size(); ++k) EXPECT_EQ(a.misses[k].by, b.misses[k].by);
}

}  // namespace spar::planner::testing
