#include "spar/qr/network.hpp"

namespace spar::qr {

std::string to_string(NodeKind kind) {
  switch (kind) {
    case NodeKind::kSum:
      return "sum";
    case NodeKind::kProduct:
      return "product";
    case NodeKind::kMonotonePlus:
      return "M+";
    case NodeKind::kNegative:
      return "negative";
    case NodeKind::kAbs:
      return "abs";
    case NodeKind::kConstant:
      return "constant";
    case NodeKind::kControl:
      return "control";
    case NodeKind::kThreshold:
      return "threshold";
  }
  return "?";
}

Relation relation_of(NodeKind kind) {
  switch (kind) {
    case NodeKind::kSum:
      return Relation::kSum;
    case NodeKind::kProduct:
      return Relation::kProduct;
    case NodeKind::kMonotonePlus:
      return Relation::kMonotonePlus;
    case NodeKind::kNegative:
      return Relation::kNegative;
    case NodeKind::kAbs:
      return Relation::kAbs;
    case NodeKind::kThreshold:
      return Relation::kThreshold;
    case NodeKind::kConstant:
    case NodeKind::kControl:
      break;
  }
  throw QrError(to_string(kind) + " nodes are ultimate causes and have no relation");
}

int Network::add(Node node) {
  for (const Node& existing : nodes_) {
    if (existing.name == node.name) throw QrError("duplicate node name '" + node.name + "'");
  }
  for (int cause : node.causes) {
    if (cause < 0 || cause >= size()) {
      throw QrError("node '" + node.name + "' names a cause that does not exist yet");
    }
  }
  nodes_.push_back(std::move(node));
  return size() - 1;
}

int Network::add_control(const std::string& name) {
  return add(Node{name, NodeKind::kControl, {}, Sign::kUnknown, std::nullopt});
}

int Network::add_constant(const std::string& name, Sign value) {
  return add(Node{name, NodeKind::kConstant, {}, value, std::nullopt});
}

int Network::add_relation(NodeKind kind, const std::string& name, const std::vector<int>& causes) {
  const Relation relation = relation_of(kind);
  if (static_cast<int>(causes.size()) != arity(relation)) {
    throw QrError("node '" + name + "': a " + to_string(kind) + " node takes " +
                  std::to_string(arity(relation)) + " cause(s), got " +
                  std::to_string(causes.size()));
  }
  return add(Node{name, kind, causes, Sign::kUnknown, std::nullopt});
}

int Network::add_threshold(const std::string& name, int cause) {
  return add(Node{name, NodeKind::kThreshold, {cause}, Sign::kUnknown, std::nullopt});
}

void Network::set_control_value(int control, double value) {
  Node& target = nodes_.at(control);
  if (target.kind != NodeKind::kControl) throw QrError("'" + target.name + "' is not a control");
  target.actual = value;
}

void Network::observe_threshold(int threshold, std::optional<bool> outcome) {
  Node& target = nodes_.at(threshold);
  if (target.kind != NodeKind::kThreshold) {
    throw QrError("'" + target.name + "' is not a threshold");
  }
  target.actual = outcome ? std::optional<double>(*outcome ? 1.0 : 0.0) : std::nullopt;
}

std::vector<Sign> Network::cause_values(const Node& node) const {
  std::vector<Sign> values;
  for (int cause : node.causes) values.push_back(nodes_[cause].value);
  return values;
}

void Network::propagate_values() {
  // Forward pass (topological order).
  for (Node& node : nodes_) {
    switch (node.kind) {
      case NodeKind::kConstant:
        break;
      case NodeKind::kControl:
        node.value = node.actual ? sign_of(*node.actual) : Sign::kUnknown;
        break;
      case NodeKind::kThreshold:
        if (node.actual) {
          node.value = *node.actual > 0.5 ? Sign::kPlus : Sign::kMinus;
          break;
        }
        [[fallthrough]];
      default:
        node.value = table_entry(value_table(relation_of(node.kind)), cause_values(node)).sign;
    }
  }
  // Backward refinement to a fixed point; each round makes at least one `?` definite, so at most
  // size() rounds.
  for (int round = 0; round < size(); ++round) {
    bool changed = false;
    for (int id = size() - 1; id >= 0; --id) {
      const Node& node = nodes_[id];
      if (node.causes.empty() || node.value == Sign::kUnknown) continue;
      const LikelyPotentials potentials =
          likely_potentials(value_table(relation_of(node.kind)), cause_values(node), node.value);
      for (std::size_t position = 0; position < node.causes.size(); ++position) {
        Node& cause = nodes_[node.causes[position]];
        const Sign refined = sign_of(potentials.inputs[position]);
        if (cause.value == Sign::kUnknown && refined != Sign::kUnknown) {
          cause.value = refined;
          changed = true;
        }
      }
    }
    if (!changed) break;
    for (Node& node : nodes_) {  // forward again so effects see the refined causes
      if (node.causes.empty() || node.value != Sign::kUnknown) continue;
      node.value = table_entry(value_table(relation_of(node.kind)), cause_values(node)).sign;
    }
  }
}

Potentials Network::node_change_potentials(int id, const std::vector<Sign>& changes) const {
  const Node& node = nodes_.at(id);
  std::vector<Sign> cause_changes;
  for (int cause : node.causes) cause_changes.push_back(changes[cause]);
  const LikelyPotentials potentials = likely_change_potentials(
      relation_of(node.kind), cause_values(node), node.value, cause_changes, Sign::kUnknown);
  return potentials.result;
}

std::vector<Sign> Network::propagate_changes(const std::map<int, Sign>& planned) const {
  std::vector<Sign> changes(nodes_.size(), Sign::kZero);
  for (int id = 0; id < size(); ++id) {
    if (const auto fixed = planned.find(id); fixed != planned.end()) {
      changes[id] = fixed->second;
    } else if (!nodes_[id].causes.empty()) {
      changes[id] = sign_of(node_change_potentials(id, changes));
    }
  }
  return changes;
}

Potentials Network::cause_change_potentials(int id, int cause_position, Sign desired,
                                            const std::vector<Sign>& changes) const {
  const Node& node = nodes_.at(id);
  std::vector<Sign> cause_changes;
  for (std::size_t position = 0; position < node.causes.size(); ++position) {
    cause_changes.push_back(static_cast<int>(position) == cause_position
                                ? Sign::kUnknown
                                : changes[node.causes[position]]);
  }
  const LikelyPotentials potentials = likely_change_potentials(
      relation_of(node.kind), cause_values(node), node.value, cause_changes, desired);
  return potentials.inputs[cause_position];
}

bool Network::is_ancestor(int ancestor, int id) const {
  if (ancestor > id) return false;  // causes precede effects
  std::vector<bool> reached(nodes_.size(), false);
  reached[id] = true;
  for (int current = id; current >= ancestor; --current) {
    if (!reached[current]) continue;
    if (current == ancestor) return true;
    for (int cause : nodes_[current].causes) reached[cause] = true;
  }
  return false;
}

int Network::find(const std::string& name) const {
  for (int id = 0; id < size(); ++id) {
    if (nodes_[id].name == name) return id;
  }
  throw QrError("no node named '" + name + "'");
}

}  // namespace spar::qr
