// Relation: how an expression compares with a threshold in an inequality (<, <=, >, >=), with its
// one name table. bounds/ decides inequalities with it (bounds::Relation is this type); the
// planner's preconditions, the CLI's and Python's inequality parsers and the reports name a
// relation through this table.
//
// Invariant: kRelationNames lists every enumerator once, in declaration order.
//
// Example:
//   const std::optional<Relation> r = relation_from_name("<=");
//   assert(r == Relation::kLessEqual && upper_limit(*r) && to_string(*r) ==
//   std::string_view("<="));
#pragma once

#include <algorithm>
#include <array>
#include <optional>
#include <string_view>

namespace spar {

enum class Relation { kLess, kLessEqual, kGreater, kGreaterEqual };

inline constexpr std::array<std::string_view, 4> kRelationNames = {"<", "<=", ">", ">="};

[[nodiscard]] constexpr std::string_view relation_name(Relation relation) {
  return kRelationNames[static_cast<int>(relation)];
}
[[nodiscard]] inline std::optional<Relation> relation_from_name(std::string_view name) {
  const auto found = std::find(kRelationNames.begin(), kRelationNames.end(), name);
  if (found == kRelationNames.end()) return std::nullopt;
  return static_cast<Relation>(found - kRelationNames.begin());
}
// `f < t` or `f <= t`: the expression is bounded from above, violations lie above t.
[[nodiscard]] constexpr bool upper_limit(Relation relation) {
  return relation == Relation::kLess || relation == Relation::kLessEqual;
}
// `<` or `>`: proof needs a strict inequality.
[[nodiscard]] constexpr bool strict(Relation relation) {
  return relation == Relation::kLess || relation == Relation::kGreater;
}
// Whether `value relation threshold` is true; false for a NaN value (undefined there).
[[nodiscard]] constexpr bool holds(double value, Relation relation, double threshold) {
  switch (relation) {
    case Relation::kLess:
      return value < threshold;
    case Relation::kLessEqual:
      return value <= threshold;
    case Relation::kGreater:
      return value > threshold;
    case Relation::kGreaterEqual:
      return value >= threshold;
  }
  return false;
}

}  // namespace spar
