// Domain: SPAR's action templates as data (seed 001 fig. 2, survey fig. 1), with the verification
// and local-recovery templates of seed 001 figs. 11-12.
//
// An action template has parameters (plan variables), operational preconditions (atoms), geometric
// preconditions (a constraint on plan variables plus the operational goal it constrains), its
// effect on uncertainty and the uncertainty-precondition builders phase 2 calls (typed at load:
// planner/uncertainty/effects.hpp; phase 2 uses exactly these and never reads predicate names),
// and add and delete lists. The built-in domain is planner/domain.yaml, compiled into spar;
// load_domain() reads another file so an action can be added or changed without recompiling
// (format: docs/domain.md and the comments at the top of planner/domain.yaml).
//
// Grammar of the text forms:
//   atom        predicate(arg, ...)          args are parameter names or constants (e.g. `empty`)
//   type        object | grasp(P) | position(P) | placement(P)    P names an object parameter
//   constraint  reachable(G, X) | mate_reachable(G, X) | member(G,
//   grasps_leaving_mating_faces_free)
//               | in_position_class(X, mating_poses)
// Invariants (checked by the loader, DomainError with file:line:col otherwise): parameter names are
// unique; every atom/constraint argument is a parameter or a known constant; typed parameters name
// an object parameter; constraint arguments have the types the constraint needs; every verification
// an action names exists, and every recovery a verification names exists; every action has an
// effect, its builders are known, listed once and fit the effect, and its parameters give what the
// effect and builders need (requirements_of); `kind`, when given, agrees with the effect.
//
// Example:
//   const Domain domain = builtin_domain();
//   const ActionTemplate& pickup = domain.action("pickup");
//   pickup.add[0].predicate;          // "holding"
//   pickup.geometric[0].kind;         // GeometricConstraintKind::kReachable
//   pickup.effect;                    // Effect::kGrasp
//   pickup.uncertainty[0];            // Builder::kPickup
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "spar/planner/uncertainty/effects.hpp"

namespace spar::planner {

struct Atom {
  std::string predicate;
  std::vector<std::string> args;          // parameter names or constants
  [[nodiscard]] std::string str() const;  // "at(object, position)"
  friend bool operator==(const Atom&, const Atom&) = default;
};

enum class ParameterType { kObject, kGrasp, kPosition, kPlacement };

struct Parameter {
  std::string name;
  ParameterType type{ParameterType::kObject};
  std::string of;  // the object parameter a grasp/position/placement belongs to ("" for objects)
};

enum class GeometricConstraintKind {
  kReachable,         // reachable(grasp, position): usable grasp, IK within limits, gripper down
  kMateReachable,     // mate_reachable(grasp, position): the held object at T_fixed Ta reachable
  kMemberMatingFree,  // member(grasp, grasps_leaving_mating_faces_free)
  kMatingPoses,       // in_position_class(position, mating_poses)
};

struct GeometricPrecondition {
  GeometricConstraintKind kind{GeometricConstraintKind::kReachable};
  std::vector<std::string> args;  // parameter names (the label-set name is implied by `kind`)
  Atom establishes;               // SPAR's operational goal the constraint is attached to
  [[nodiscard]] std::string str() const;  // "reachable(grasp, position)"
};

// The action's role in phase 1, implied by its effect (a `kind:` key may repeat it).
enum class ActionKind {
  kManipulation,  // used by phase 1 to reach goals
  kSensing,       // effect sense: phase 2 splices it in to replace an object's uncertainty
  kReduction,     // effect reduce: phase 2 splices it in before a pickup
};

struct ActionTemplate {
  std::string name;
  ActionKind kind{ActionKind::kManipulation};
  std::vector<Parameter> parameters;
  std::vector<Atom> operational;
  std::vector<GeometricPrecondition> geometric;
  Effect effect{Effect::kNone};  // the domain's `effect:` (required)
  // Effect sense only, the domain's `sensor:`: a fixed camera's verification (`camera`: phase 2
  // splices it in where a camera with a residual sees the object) or a range-scan (`range_scan`,
  // the default).
  bool camera{false};
  std::vector<Builder> uncertainty;  // the domain's `uncertainty:` builders, in its order
  std::vector<Atom> add;
  std::vector<Atom> del;
  std::vector<std::string> verification;  // VerificationTemplate names

  // Index of the parameter called `name`, or -1.
  [[nodiscard]] int parameter_index(std::string_view name) const;
};

// One possible outcome of a verification and the error it means.
struct VerificationOutcome {
  std::string when;      // text with {placeholders}
  std::string error;     // e.g. missed_object
  std::string recovery;  // RecoveryTemplate name
};

struct VerificationTemplate {
  std::string name;
  std::string sense;   // what is measured, with {placeholders}
  std::string expect;  // the expected reading
  std::vector<VerificationOutcome> outcomes;
};

struct RecoveryTemplate {
  std::string name;
  std::vector<std::string> steps;  // with {placeholders}
};

struct Domain {
  std::string source;  // file name, or "<built-in domain>"
  std::vector<ActionTemplate> actions;
  std::vector<VerificationTemplate> verifications;
  std::vector<RecoveryTemplate> recoveries;

  // Each throws DomainError naming the known ones when there is no such template.
  [[nodiscard]] const ActionTemplate& action(std::string_view name) const;
  [[nodiscard]] const VerificationTemplate& verification(std::string_view name) const;
  [[nodiscard]] const RecoveryTemplate& recovery(std::string_view name) const;
};

[[nodiscard]] const Domain& builtin_domain();
[[nodiscard]] Domain load_domain(const std::filesystem::path& path);
// `source` names the text in messages.
[[nodiscard]] Domain parse_domain(std::string_view text, const std::string& source);

}  // namespace spar::planner
