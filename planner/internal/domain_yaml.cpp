// Reads a domain file (planner/domain.yaml's format) into a Domain; every mistake is a DomainError
// with `file:line:col`.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "spar/common/input_file.hpp"
#include "spar/common/text.hpp"
#include "spar/planner/domain.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/internal/yaml_syntax.hpp"

namespace spar::planner {
namespace {

// Constants an atom may use besides parameter names.
const std::set<std::string, std::less<>> kConstants = {"empty"};

// The predicates the planner states itself (the initial state, goals and phase 2's effects) and
// their arities: gripper(empty), at(object, position), holding(object, grasp), assembled(held,
// fixed).
const std::map<std::string, std::size_t, std::less<>> kPlannerPredicates = {
    {"gripper", 1}, {"at", 2}, {"holding", 2}, {"assembled", 2}};

class DomainReader {
 public:
  // `source` may come from the file system: it is kept printable (common/text.hpp).
  explicit DomainReader(const std::string& source) : source_(printable(source)) {}

  // What a message echoes from the file passes through printable() (control characters that
  // YAML escapes produce).
  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& what) const {
    throw DomainError(internal::yaml_where(source_, mark) + ": " + printable(what));
  }

  // Checks that `node` is a map whose keys are all in `allowed`.
  void expect_map(const YAML::Node& node, const std::string& what,
                  std::initializer_list<std::string_view> allowed) const {
    if (!node.IsMap()) fail(node.Mark(), what + " must be a map");
    for (const auto& entry : node) {
      const std::string key = scalar(entry.first, "a key of " + what);
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string known;
        for (std::string_view k : allowed) known += (known.empty() ? "" : ", ") + std::string(k);
        fail(entry.first.Mark(),
             "unknown key '" + key + "' in " + what + " (known: " + known + ")");
      }
    }
  }

  // One line of text: no control characters (a NUL or a backspace from a YAML escape would print
  // as something else in every report).
  std::string scalar(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar()) fail(node.Mark(), what + " must be a text");
    if (find_control_character(node.Scalar()))
      fail(node.Mark(), what + " " + single_quoted(node.Scalar()) +
                            " holds a control character: texts must be printable");
    return node.Scalar();
  }

  std::vector<std::string> scalars(const YAML::Node& node, const std::string& what) const {
    std::vector<std::string> out;
    if (!node) return out;
    if (!node.IsSequence()) fail(node.Mark(), what + " must be a list");
    for (const auto& item : node) out.push_back(scalar(item, what + " entry"));
    return out;
  }

  // "name(a, b)" -> {name, {a, b}}; `name` alone has no arguments.
  Atom parse_atom(const YAML::Node& node, const std::string& what) const {
    const std::string text = scalar(node, what);
    Atom atom;
    const auto open = text.find('(');
    auto trim = [](std::string s) {
      const auto first = s.find_first_not_of(" \t");
      if (first == std::string::npos) return std::string();
      return s.substr(first, s.find_last_not_of(" \t") - first + 1);
    };
    atom.predicate = trim(text.substr(0, open));
    if (open != std::string::npos) {
      if (text.back() != ')')
        fail(node.Mark(), what + " '" + text +
                              "' lacks its closing ')' (in a [...] list, quote "
                              "atoms that contain commas: \"at(object, position)\")");
      std::stringstream args(text.substr(open + 1, text.size() - open - 2));
      std::string arg;
      while (std::getline(args, arg, ',')) atom.args.push_back(trim(arg));
    }
    const auto is_name = [](const std::string& s) {
      return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
      });
    };
    if (!is_name(atom.predicate)) fail(node.Mark(), what + " '" + text + "' is not name(args)");
    for (const std::string& arg : atom.args)
      if (!is_name(arg)) fail(node.Mark(), what + " '" + text + "' has an empty or bad argument");
    return atom;
  }

  Parameter parse_parameter(const std::string& name, const YAML::Node& type_node) const {
    const Atom type = parse_atom(type_node, "parameter type");
    Parameter parameter{.name = name, .type = ParameterType::kObject, .of = {}};
    if (type.predicate == "object" && type.args.empty()) return parameter;
    static const std::pair<std::string_view, ParameterType> kTyped[] = {
        {"grasp", ParameterType::kGrasp},
        {"position", ParameterType::kPosition},
        {"placement", ParameterType::kPlacement}};
    for (const auto& [type_name, type_kind] : kTyped) {
      if (type.predicate == type_name && type.args.size() == 1) {
        parameter.type = type_kind;
        parameter.of = type.args[0];
        return parameter;
      }
    }
    fail(type_node.Mark(), "parameter '" + name + "' has unknown type '" + type.str() +
                               "' (known: object, grasp(P), position(P), placement(P))");
  }

  // Every argument of `atom` must be a parameter or a constant.
  void check_arguments(const ActionTemplate& action, const Atom& atom,
                       const YAML::Node& node) const {
    for (const std::string& arg : atom.args)
      if (action.parameter_index(arg) < 0 && !kConstants.contains(arg))
        fail(node.Mark(), "'" + arg + "' in " + atom.str() + " is not a parameter of action '" +
                              action.name + "'");
  }

  void check_type(const ActionTemplate& action, const std::string& arg, ParameterType wanted,
                  const std::string& constraint, const YAML::Node& node) const {
    const int index = action.parameter_index(arg);
    if (index < 0) fail(node.Mark(), "'" + arg + "' in " + constraint + " is not a parameter");
    const ParameterType type = action.parameters[index].type;
    const bool position_like =
        type == ParameterType::kPosition || type == ParameterType::kPlacement;
    const bool ok = wanted == ParameterType::kPosition ? position_like : type == wanted;
    if (!ok)
      fail(node.Mark(), "'" + arg + "' in " + constraint + " must be a " +
                            (wanted == ParameterType::kGrasp ? "grasp" : "position"));
  }

  GeometricPrecondition parse_geometric(const ActionTemplate& action,
                                        const YAML::Node& node) const {
    expect_map(node, "geometric precondition", {"constraint", "for"});
    if (!node["constraint"] || !node["for"])
      fail(node.Mark(), "a geometric precondition needs 'constraint' and 'for'");
    const Atom constraint = parse_atom(node["constraint"], "constraint");
    GeometricPrecondition geometric;
    geometric.establishes = parse_atom(node["for"], "'for' goal");
    check_arguments(action, geometric.establishes, node["for"]);
    check_arity(geometric.establishes, node["for"]);
    const std::string text = constraint.str();
    const auto expect_arguments = [&](std::size_t count) {
      if (constraint.args.size() != count)
        fail(node["constraint"].Mark(), text + " takes " + std::to_string(count) + " arguments");
    };
    if (constraint.predicate == "reachable" || constraint.predicate == "mate_reachable") {
      expect_arguments(2);
      geometric.kind = constraint.predicate == "reachable"
                           ? GeometricConstraintKind::kReachable
                           : GeometricConstraintKind::kMateReachable;
      check_type(action, constraint.args[0], ParameterType::kGrasp, text, node["constraint"]);
      check_type(action, constraint.args[1], ParameterType::kPosition, text, node["constraint"]);
      geometric.args = constraint.args;
    } else if (constraint.predicate == "member") {
      expect_arguments(2);
      if (constraint.args[1] != "grasps_leaving_mating_faces_free")
        fail(node["constraint"].Mark(),
             "member() knows the label set grasps_leaving_mating_faces_free, not '" +
                 constraint.args[1] + "'");
      check_type(action, constraint.args[0], ParameterType::kGrasp, text, node["constraint"]);
      geometric.kind = GeometricConstraintKind::kMemberMatingFree;
      geometric.args = {constraint.args[0]};
    } else if (constraint.predicate == "in_position_class") {
      expect_arguments(2);
      if (constraint.args[1] != "mating_poses")
        fail(node["constraint"].Mark(),
             "in_position_class() knows the pose class mating_poses, not '" + constraint.args[1] +
                 "'");
      check_type(action, constraint.args[0], ParameterType::kPosition, text, node["constraint"]);
      geometric.kind = GeometricConstraintKind::kMatingPoses;
      geometric.args = {constraint.args[0]};
    } else {
      fail(node["constraint"].Mark(),
           "unknown constraint '" + constraint.predicate +
               "' (known: reachable, mate_reachable, member, in_position_class)");
    }
    return geometric;
  }

  std::vector<Atom> parse_atoms(const ActionTemplate& action, const YAML::Node& node,
                                const std::string& what) const {
    std::vector<Atom> atoms;
    if (!node) return atoms;
    if (!node.IsSequence()) fail(node.Mark(), what + " must be a list of atoms");
    for (const auto& item : node) {
      atoms.push_back(parse_atom(item, what + " atom"));
      check_arguments(action, atoms.back(), item);
      check_arity(atoms.back(), item);
    }
    return atoms;
  }

  // A predicate the planner states itself has its arity (kPlannerPredicates); any other keeps the
  // arity of its first use in the file, so at(object) cannot silently never match at(o, p).
  void check_arity(const Atom& atom, const YAML::Node& node) const {
    std::size_t expected = atom.args.size();
    std::string where = "the planner's " + atom.predicate + "(...)";
    if (const auto known = kPlannerPredicates.find(atom.predicate);
        known != kPlannerPredicates.end()) {
      expected = known->second;
    } else if (const auto [first, inserted] =
                   arities_.try_emplace(atom.predicate, atom.args.size(), node.Mark());
               !inserted) {
      expected = first->second.first;
      where = "its first use at " + internal::yaml_where(source_, first->second.second);
    }
    if (atom.args.size() != expected)
      fail(node.Mark(), single_quoted(atom.str()) + " has " + std::to_string(atom.args.size()) +
                            " argument(s), but " + atom.predicate + " takes " +
                            std::to_string(expected) + " (" + where + ")");
  }

  // The first parameter of `type` (position also finds a placement), or nullptr: the instance
  // steps read the handled object and its position from these (planner/instances.cpp).
  static const Parameter* first_of(const ActionTemplate& action, ParameterType type) {
    for (const Parameter& parameter : action.parameters)
      if (parameter.type == type ||
          (type == ParameterType::kPosition && parameter.type == ParameterType::kPlacement))
        return &parameter;
    return nullptr;
  }

  // What an effect or builder (`what`) needs of the action's parameters.
  void check_requirements(const ActionTemplate& action, const Requirements& needs,
                          const std::string& what, const YAML::Mark& mark) const {
    const Parameter* grasp = first_of(action, ParameterType::kGrasp);
    const Parameter* position = first_of(action, ParameterType::kPosition);
    const std::string where = " (action '" + action.name + "')";
    if (needs.object && !first_of(action, ParameterType::kObject))
      fail(mark, what + " needs an object parameter" + where);
    if ((needs.grasp || needs.own_position || needs.other_position) && grasp == nullptr)
      fail(mark, what + " needs a grasp parameter, grasp(<object>)" + where);
    if (needs.own_position && (position == nullptr || position->of != grasp->of))
      fail(mark, what + " needs a position or placement of the grasped object '" + grasp->of + "'" +
                     where);
    if (needs.other_position && (position == nullptr || position->of == grasp->of))
      fail(mark, what + " needs a position of the fixed object (another object than the grasped '" +
                     grasp->of + "')" + where);
  }

  // `effect:` (required) and the `kind:` it implies (a given kind must agree).
  void parse_effect(ActionTemplate& action, const YAML::Node& node) const {
    const YAML::Node effect = node["effect"];
    if (!effect)
      fail(node.Mark(),
           "action '" + action.name + "' needs 'effect' (one of " + known_effects() + ")");
    const std::string name = scalar(effect, "effect");
    const std::optional<Effect> parsed = effect_from_name(name);
    if (!parsed)
      fail(effect.Mark(), "unknown effect '" + name + "' (known: " + known_effects() + ")");
    action.effect = *parsed;
    action.kind = action.effect == Effect::kSense    ? ActionKind::kSensing
                  : action.effect == Effect::kReduce ? ActionKind::kReduction
                                                     : ActionKind::kManipulation;
    check_requirements(action, requirements_of(action.effect), "effect " + name, effect.Mark());
    if (const YAML::Node sensor = node["sensor"]) {
      if (action.effect != Effect::kSense)
        fail(sensor.Mark(), "'sensor' is for actions with effect sense (action '" + action.name +
                                "' has effect " + name + ")");
      const std::string text = scalar(sensor, "sensor");
      if (text != "range_scan" && text != "camera")
        fail(sensor.Mark(), "unknown sensor '" + text + "' (known: range_scan, camera)");
      action.camera = text == "camera";
    }
    if (const YAML::Node kind = node["kind"]) {
      static const std::pair<std::string_view, ActionKind> kKinds[] = {
          {"manipulation", ActionKind::kManipulation},
          {"sensing", ActionKind::kSensing},
          {"reduction", ActionKind::kReduction}};
      const std::string text = scalar(kind, "kind");
      const auto found = std::find_if(std::begin(kKinds), std::end(kKinds),
                                      [&](const auto& entry) { return entry.first == text; });
      if (found == std::end(kKinds))
        fail(kind.Mark(), "unknown kind '" + text + "' (known: manipulation, sensing, reduction)");
      if (found->second != action.kind)
        fail(kind.Mark(), "kind '" + text + "' disagrees with effect " + name +
                              " (effect sense is kind sensing, reduce is reduction, the others "
                              "manipulation; the kind may be left out)");
    }
  }

  // `uncertainty:` builders, in order: known, listed once, fitting the effect and the parameters.
  void parse_builders(ActionTemplate& action, const YAML::Node& list) const {
    const std::vector<std::string> names = scalars(list, "uncertainty");
    for (std::size_t i = 0; i < names.size(); ++i) {
      const YAML::Mark mark = list[i].Mark();
      const std::optional<Builder> builder = builder_from_name(names[i]);
      if (!builder)
        fail(mark,
             "unknown uncertainty builder '" + names[i] + "' (known: " + known_builders() + ")");
      if (std::find(action.uncertainty.begin(), action.uncertainty.end(), *builder) !=
          action.uncertainty.end())
        fail(mark, "uncertainty builder '" + names[i] + "' is listed twice");
      if (const std::string conflict = builder_conflict(*builder, action.effect); !conflict.empty())
        fail(mark, conflict + " (action '" + action.name + "')");
      check_requirements(action, requirements_of(*builder), "builder " + names[i], mark);
      action.uncertainty.push_back(*builder);
    }
  }

  ActionTemplate parse_action(const YAML::Node& node) const {
    expect_map(node, "action",
               {"name", "kind", "effect", "sensor", "parameters", "operational", "geometric",
                "uncertainty", "add", "delete", "verification"});
    if (!node["name"]) fail(node.Mark(), "an action needs a 'name'");
    ActionTemplate action;
    action.name = scalar(node["name"], "action name");
    const YAML::Node parameters = node["parameters"];
    if (!parameters || !parameters.IsMap())
      fail(parameters ? parameters.Mark() : node.Mark(),
           "action '" + action.name + "' needs 'parameters' as a map name: type");
    for (const auto& entry : parameters) {
      const std::string name = scalar(entry.first, "parameter name");
      if (action.parameter_index(name) >= 0)
        fail(entry.first.Mark(), "parameter '" + name + "' appears twice");
      action.parameters.push_back(parse_parameter(name, entry.second));
    }
    for (const auto& entry : parameters) {
      const Parameter& parameter = action.parameters[action.parameter_index(entry.first.Scalar())];
      if (parameter.type == ParameterType::kObject) continue;
      const int owner = action.parameter_index(parameter.of);
      if (owner < 0 || action.parameters[owner].type != ParameterType::kObject)
        fail(entry.second.Mark(), "'" + parameter.of + "' in the type of '" + parameter.name +
                                      "' is not an object parameter");
    }
    action.operational = parse_atoms(action, node["operational"], "operational");
    if (const YAML::Node geometric = node["geometric"]) {
      if (!geometric.IsSequence()) fail(geometric.Mark(), "'geometric' must be a list");
      for (const auto& item : geometric) action.geometric.push_back(parse_geometric(action, item));
    }
    parse_effect(action, node);
    parse_builders(action, node["uncertainty"]);
    action.add = parse_atoms(action, node["add"], "add");
    action.del = parse_atoms(action, node["delete"], "delete");
    action.verification = scalars(node["verification"], "verification");
    return action;
  }

  VerificationTemplate parse_verification(const YAML::Node& node) const {
    expect_map(node, "verification", {"name", "sense", "expect", "outcomes"});
    VerificationTemplate verification;
    if (!node["name"] || !node["sense"])
      fail(node.Mark(), "a verification needs 'name' and 'sense'");
    verification.name = scalar(node["name"], "verification name");
    verification.sense = scalar(node["sense"], "sense");
    if (node["expect"]) verification.expect = scalar(node["expect"], "expect");
    if (const YAML::Node outcomes = node["outcomes"]) {
      if (!outcomes.IsSequence()) fail(outcomes.Mark(), "'outcomes' must be a list");
      for (const auto& item : outcomes) {
        expect_map(item, "outcome", {"when", "error", "recovery"});
        if (!item["when"] || !item["error"] || !item["recovery"])
          fail(item.Mark(), "an outcome needs 'when', 'error' and 'recovery'");
        verification.outcomes.push_back({scalar(item["when"], "when"),
                                         scalar(item["error"], "error"),
                                         scalar(item["recovery"], "recovery")});
      }
    }
    return verification;
  }

  Domain parse(std::string_view text) const {
    const YAML::Node root = internal::load_yaml_document<DomainError>(text, source_);
    Domain domain;
    domain.source = source_;
    expect_map(root, "the domain file", {"actions", "verifications", "recoveries"});
    const auto list = [&](const char* key) {
      const YAML::Node node = root[key];
      if (node && !node.IsSequence())
        fail(node.Mark(), std::string("'") + key + "' must be a list");
      return node;
    };
    std::map<std::string, YAML::Mark> verification_uses;
    for (const auto& item : list("actions")) {
      domain.actions.push_back(parse_action(item));
      for (std::size_t i = 0; i < domain.actions.back().verification.size(); ++i)
        verification_uses.emplace(domain.actions.back().verification[i],
                                  item["verification"][i].Mark());
      if (std::count_if(domain.actions.begin(), domain.actions.end(),
                        [&](const auto& a) { return a.name == domain.actions.back().name; }) > 1)
        fail(item.Mark(), "action '" + domain.actions.back().name + "' is defined twice");
    }
    if (domain.actions.empty()) fail(root.Mark(), "the domain has no actions");
    std::map<std::string, YAML::Mark> recovery_uses;
    for (const auto& item : list("verifications")) {
      domain.verifications.push_back(parse_verification(item));
      const auto& outcomes = domain.verifications.back().outcomes;
      for (std::size_t i = 0; i < outcomes.size(); ++i)
        recovery_uses.emplace(outcomes[i].recovery, item["outcomes"][i].Mark());
    }
    for (const auto& item : list("recoveries")) {
      expect_map(item, "recovery", {"name", "steps"});
      if (!item["name"]) fail(item.Mark(), "a recovery needs a 'name'");
      domain.recoveries.push_back(
          {scalar(item["name"], "recovery name"), scalars(item["steps"], "steps")});
    }
    // Every template named must exist (plain loops: clang 14 cannot capture structured bindings).
    const auto defined = [](const auto& templates, const std::string& name) {
      return std::any_of(templates.begin(), templates.end(),
                         [&name](const auto& t) { return t.name == name; });
    };
    for (const auto& use : verification_uses)
      if (!defined(domain.verifications, use.first))
        fail(use.second, "verification '" + use.first + "' is not defined under 'verifications'");
    for (const auto& use : recovery_uses)
      if (!defined(domain.recoveries, use.first))
        fail(use.second, "recovery '" + use.first + "' is not defined under 'recoveries'");
    return domain;
  }

 private:
  std::string source_;
  // Predicate -> arity and where it was first used (check_arity).
  mutable std::map<std::string, std::pair<std::size_t, YAML::Mark>> arities_;
};

}  // namespace

Domain parse_domain(std::string_view text, const std::string& source) {
  return DomainReader(source).parse(text);
}

Domain load_domain(const std::filesystem::path& path) {
  std::string text;
  try {
    text = read_input_file(path, "domain file", kMaxYamlFileBytes);
  } catch (const InputError& error) {
    throw DomainError(error.what());
  }
  return parse_domain(text, path.string());
}

}  // namespace spar::planner
