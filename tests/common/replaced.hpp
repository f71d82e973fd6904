// replaced(text, from, to): `text` with the first `from` replaced by `to`, how tests derive a
// variant of a scenario or domain text from a valid one. A `from` that is not there is a test
// failure (the variant would silently be the original, and the test would check nothing).
//
// Example:
//   const Scenario s = parse_scenario(replaced(kValid, "dx: 0.1", "dx: -1"), "cell.yaml", ".");
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <string>

namespace spar::test_support {

inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

}  // namespace spar::test_support
