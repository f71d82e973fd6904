// The one table of numeric limits: every length, angle and count a scenario file or a command-line
// option can set has a row here, so the scenario loader, `spar object` and any later reader refuse
// the same values with the same words. The limits keep values physically meaningful (1e308 is not
// a gripper opening) and keep the work they set bounded (an approach step of 1e-9 rad would make
// six billion grasps).
//
// A row: the key (the scenario's key path, e.g. "grasping.approach_step"; a key used in many
// places names its kind, e.g. "pose.position"), the quantity (length in metres, angle in radians,
// a count, or a plain number), the closed or half-open range in those SI units, and why the limit
// is there (printed with the refusal). To add a key: add a row to kNumericLimits in limits.cpp
// (tests/common/limits_test.cpp checks every row), then call limit_problem where the value is
// read, and list the range in docs/scenario.md.
//
// Messages show the range in the unit the value was given in:
//   "must be a length > 0 and <= 78.74 in (2 m: the widest parallel gripper spar models), got
//    3.9e306 in"
//
// Example:
//   const NumericLimit& opening = numeric_limit("robot.gripper.max_opening");
//   opening.contains(0.1016);                                   // true: 4 in, in metres
//   limit_problem(opening, 1e308 * units::kInch, {units::kInch, "in"});
//       // "must be a length > 0 and <= 78.74 in (...), got 1e+308 in"
//   limit_problem(numeric_limit("grasping.positions_per_axis"), 5, {});   // nothing: allowed
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace spar {

enum class Quantity { kLength, kAngle, kCount, kNumber };

struct NumericLimit {
  std::string_view key;
  Quantity quantity{Quantity::kNumber};
  double low{0};  // in metres, radians or units of one
  double high{0};
  bool low_exclusive{false};
  std::string_view reason;  // why: "the widest parallel gripper spar models"

  [[nodiscard]] bool contains(double value) const;
};

// A length or angle unit as the value was given: SI per unit and its name ("in", "deg").
// Default: metres or radians (name chosen by the quantity) and plain numbers.
struct GivenUnit {
  double si_per_unit{1};
  std::string_view name;
};

// Every row, in the table's order.
[[nodiscard]] std::span<const NumericLimit> numeric_limits();
// The row for `key`; throws std::logic_error for a key the table lacks (a programming error).
[[nodiscard]] const NumericLimit& numeric_limit(std::string_view key);

// Nothing when `value` is inside the limit, else what is wrong in `unit`: "must be ..., got
// <given_text>" (the value as the user wrote it; without it, the value in `unit`).
[[nodiscard]] std::optional<std::string> limit_problem(const NumericLimit& limit, double value,
                                                       GivenUnit unit = {},
                                                       std::string_view given_text = {});
// The range in `unit`: "a length > 0 and <= 78.74 in".
[[nodiscard]] std::string describe_limit(const NumericLimit& limit, GivenUnit unit = {});

}  // namespace spar
