// Effects: what a step does to the uncertainty of the objects it handles, and which precondition
// builders phase 2 calls for it. The domain file says both for every action template (its
// `effect:` and `uncertainty:` keys, planner/domain.yaml); the loader resolves the names once into
// these enums (ActionTemplate::effect, ActionTemplate::uncertainty), so phase 2 never looks at
// names or predicates. An unknown name is a DomainError with file:line:col.
//
// Effects (the state changes are SPAR's, planner/uncertainty/propagation.hpp gives the algebra):
//   grasp    the handled object leaves the table and is held (pickup);
//   release  the held object is put on the table at the step's position (putdown);
//   insert   the held object joins the fixed one and is no longer tracked (assemble);
//   sense    the object's pose error is replaced by the sensor's residual where it is not already
//            inside it (range-scan);
//   reduce   a grasp and a release in place with the same arm error (squeeze);
//   none     no change (an action phase 2 has nothing to say about).
// Builders (planner/uncertainty/builders.hpp), called in the order the domain lists them, before
// the effect is applied:
//   pickup    SPAR's four finger/contact inequalities of the handled object on the table;
//   squeeze   the same four, reported as the squeeze's own;
//   assemble  the insertion's clearance inequalities (needs effect insert).
// What an effect or builder needs of the action's parameters is checked at load
// (requirements_of); what it needs of the state (the object on the table, or held) when a step is
// propagated.
//
// Invariant: kEffectNames / kBuilderNames list every enumerator once, in declaration order.
//
// Example:
//   const std::optional<Effect> effect = effect_from_name("grasp");   // Effect::kGrasp
//   assert(to_string(*effect) == std::string_view("grasp"));
//   assert(!builder_from_name("weld"));
//   std::string known = known_effects();                              // "grasp, release, ..."
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace spar::planner {

enum class Effect { kGrasp, kRelease, kInsert, kSense, kReduce, kNone };
enum class Builder { kPickup, kSqueeze, kAssemble };

inline constexpr std::array<std::string_view, 6> kEffectNames = {"grasp", "release", "insert",
                                                                 "sense", "reduce",  "none"};
inline constexpr std::array<std::string_view, 3> kBuilderNames = {"pickup", "squeeze", "assemble"};

[[nodiscard]] std::string_view to_string(Effect effect);
[[nodiscard]] std::string_view to_string(Builder builder);
[[nodiscard]] std::optional<Effect> effect_from_name(std::string_view name);
[[nodiscard]] std::optional<Builder> builder_from_name(std::string_view name);
[[nodiscard]] std::string known_effects();   // "grasp, release, insert, sense, reduce, none"
[[nodiscard]] std::string known_builders();  // "pickup, squeeze, assemble"

// Whether the effect moves the arm (a fresh arm error is allocated for the step).
[[nodiscard]] bool moves_arm(Effect effect);
// Whether the step changes where its object is (grasp, release, insert, reduce).
[[nodiscard]] bool moves_object(Effect effect);

// What an action's parameters must provide for an effect or a builder (checked by the loader).
struct Requirements {
  bool grasp{false};           // a grasp parameter (of the handled object)
  bool own_position{false};    // a position/placement of the handled object
  bool other_position{false};  // a position of another object (the fixed one of an insertion)
  bool object{false};          // an object parameter
  bool on_table{false};        // the builder reads the handled object's table state
};
[[nodiscard]] Requirements requirements_of(Effect effect);
[[nodiscard]] Requirements requirements_of(Builder builder);
// Whether `builder` can be called before a step with `effect` (pickup and squeeze need the object
// on the table, so not release or insert; assemble needs insert). Empty when it can, else why not.
[[nodiscard]] std::string builder_conflict(Builder builder, Effect effect);

}  // namespace spar::planner
