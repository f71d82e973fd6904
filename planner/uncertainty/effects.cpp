#include "spar/planner/uncertainty/effects.hpp"

#include <algorithm>

namespace spar::planner {
namespace {

template <class Enum, std::size_t N>
std::optional<Enum> from_name(const std::array<std::string_view, N>& names, std::string_view name) {
  const auto found = std::find(names.begin(), names.end(), name);
  if (found == names.end()) return std::nullopt;
  return static_cast<Enum>(found - names.begin());
}

template <std::size_t N>
std::string joined(const std::array<std::string_view, N>& names) {
  std::string text;
  for (const std::string_view name : names) text += (text.empty() ? "" : ", ") + std::string(name);
  return text;
}

}  // namespace

std::string_view to_string(Effect effect) { return kEffectNames.at(static_cast<int>(effect)); }
std::string_view to_string(Builder builder) { return kBuilderNames.at(static_cast<int>(builder)); }

std::optional<Effect> effect_from_name(std::string_view name) {
  return from_name<Effect>(kEffectNames, name);
}
std::optional<Builder> builder_from_name(std::string_view name) {
  return from_name<Builder>(kBuilderNames, name);
}
std::string known_effects() { return joined(kEffectNames); }
std::string known_builders() { return joined(kBuilderNames); }

bool moves_arm(Effect effect) {
  return effect == Effect::kGrasp || effect == Effect::kRelease || effect == Effect::kInsert ||
         effect == Effect::kReduce;
}
bool moves_object(Effect effect) { return moves_arm(effect); }

Requirements requirements_of(Effect effect) {
  switch (effect) {
    case Effect::kGrasp:
      return {.grasp = true};
    case Effect::kRelease:
    case Effect::kReduce:
      return {.grasp = true, .own_position = true};
    case Effect::kInsert:
      return {.grasp = true, .other_position = true};
    case Effect::kSense:
      return {.object = true};
    case Effect::kNone:
      return {};
  }
  return {};
}

Requirements requirements_of(Builder builder) {
  switch (builder) {
    case Builder::kPickup:
    case Builder::kSqueeze:
      return {.grasp = true, .on_table = true};
    case Builder::kAssemble:
      return {.grasp = true, .other_position = true};
  }
  return {};
}

std::string builder_conflict(Builder builder, Effect effect) {
  if (builder == Builder::kAssemble && effect != Effect::kInsert)
    return "builder 'assemble' needs effect insert (it checks the held object against the fixed "
           "one)";
  if (requirements_of(builder).on_table &&
      (effect == Effect::kRelease || effect == Effect::kInsert))
    return "builder '" + std::string(to_string(builder)) +
           "' reads the object on the table, but before a step with effect " +
           std::string(to_string(effect)) + " it is held";
  return {};
}

}  // namespace spar::planner
