// PoseComponent: the four components of SPAR's pose error (seed 001 eqs. 1 and 2), dx, dy, dz (a
// displacement, metres) and dtheta (a rotation about z, radians), with their one name table. The
// planner's uncertainty variables, its tolerance parameters, reports and Python all name a
// component through this table.
//
// Invariant: kPoseComponentNames lists every enumerator once, in declaration order.
//
// Example:
//   const std::optional<PoseComponent> c = pose_component_from_name("dtheta");
//   assert(c && is_angle(*c) && to_string(*c) == std::string_view("dtheta"));
//   for (const PoseComponent component : kPoseComponents) std::cout << to_string(component);
#pragma once

#include <algorithm>
#include <array>
#include <optional>
#include <string_view>

namespace spar {

enum class PoseComponent { kDx, kDy, kDz, kDtheta };

inline constexpr std::array<PoseComponent, 4> kPoseComponents = {
    PoseComponent::kDx, PoseComponent::kDy, PoseComponent::kDz, PoseComponent::kDtheta};
inline constexpr std::array<std::string_view, 4> kPoseComponentNames = {"dx", "dy", "dz", "dtheta"};

[[nodiscard]] constexpr std::string_view to_string(PoseComponent component) {
  return kPoseComponentNames[static_cast<int>(component)];
}
[[nodiscard]] constexpr int index_of(PoseComponent component) {
  return static_cast<int>(component);
}
// An angle (radians) rather than a length (metres).
[[nodiscard]] constexpr bool is_angle(PoseComponent component) {
  return component == PoseComponent::kDtheta;
}
[[nodiscard]] inline std::optional<PoseComponent> pose_component_from_name(std::string_view name) {
  const auto found = std::find(kPoseComponentNames.begin(), kPoseComponentNames.end(), name);
  if (found == kPoseComponentNames.end()) return std::nullopt;
  return static_cast<PoseComponent>(found - kPoseComponentNames.begin());
}

}  // namespace spar
