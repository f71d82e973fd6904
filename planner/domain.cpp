#include "spar/planner/domain.hpp"

#include <algorithm>

#include "spar/planner/error.hpp"
#include "planner/internal/builtin_domain_text.hpp"

namespace spar::planner {
namespace {

std::string join_arguments(std::string_view name, const std::vector<std::string>& args) {
  std::string text(name);
  if (args.empty()) return text;
  text += '(';
  for (std::size_t i = 0; i < args.size(); ++i) text += (i ? ", " : "") + args[i];
  return text + ')';
}

// The template called `name` in `list`, else DomainError listing the known names.
template <class Template>
const Template& find_named(const std::vector<Template>& list, std::string_view name,
                           std::string_view what, const std::string& source) {
  const auto found =
      std::find_if(list.begin(), list.end(), [&](const Template& t) { return t.name == name; });
  if (found != list.end()) return *found;
  std::string known;
  for (const Template& t : list) known += (known.empty() ? "" : ", ") + t.name;
  throw DomainError(source + ": no " + std::string(what) + " '" + std::string(name) +
                    "' (known: " + known + ")");
}

}  // namespace

std::string Atom::str() const { return join_arguments(predicate, args); }

std::string GeometricPrecondition::str() const {
  switch (kind) {
    case GeometricConstraintKind::kReachable:
      return join_arguments("reachable", args);
    case GeometricConstraintKind::kMateReachable:
      return join_arguments("mate_reachable", args);
    case GeometricConstraintKind::kMemberMatingFree:
      return join_arguments("member", {args.at(0), "grasps_leaving_mating_faces_free"});
    case GeometricConstraintKind::kMatingPoses:
      return join_arguments("in_position_class", {args.at(0), "mating_poses"});
  }
  return {};
}

int ActionTemplate::parameter_index(std::string_view name) const {
  for (std::size_t i = 0; i < parameters.size(); ++i)
    if (parameters[i].name == name) return static_cast<int>(i);
  return -1;
}

const ActionTemplate& Domain::action(std::string_view name) const {
  return find_named(actions, name, "action", source);
}
const VerificationTemplate& Domain::verification(std::string_view name) const {
  return find_named(verifications, name, "verification", source);
}
const RecoveryTemplate& Domain::recovery(std::string_view name) const {
  return find_named(recoveries, name, "recovery", source);
}

const Domain& builtin_domain() {
  static const Domain domain = parse_domain(internal::kBuiltinDomainText, "<built-in domain>");
  return domain;
}

}  // namespace spar::planner
