// A qualitative network of a task's physics (seeds/000, sections 2-3).
//
// Eight node types: sum, product, M+, negative, absolute value (relations over their causes),
// constant and control (ultimate causes, no relation), and threshold (a boolean outcome of one
// cause). Every node holds a qualitative value (+ 0 - ?); control and threshold nodes also hold
// actual values (a control's number, a threshold's observed truth), and a control's qualitative
// value is the sign of its number. A node's relation to its causes is used in both directions:
// forward to propagate values and changes towards effects, backward (likely_potentials on the
// inputs) to refine unknown causes and to plan which cause to change.
//
// Invariant: nodes are stored in creation order and a node's causes are created before it, so the
// vector is a topological order (causes before effects). Loops over nodes are therefore plain
// forward / backward passes; nothing recurses over the network.
//
// Example:
//   Network net;
//   const int depth = net.add_control("digging depth");
//   const int force = net.add_relation(NodeKind::kMonotonePlus, "force", {depth});
//   net.set_control_value(depth, 8.0);
//   net.propagate_values();            // force is now +
//   auto changes = net.propagate_changes({{depth, Sign::kPlus}});   // force: +
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "spar/qr/qualitative.hpp"

namespace spar::qr {

enum class NodeKind : std::uint8_t {
  kSum,
  kProduct,
  kMonotonePlus,
  kNegative,
  kAbs,
  kConstant,
  kControl,
  kThreshold
};
[[nodiscard]] std::string to_string(NodeKind kind);
// The relation of a non-ultimate node kind; throws QrError for constant and control.
[[nodiscard]] Relation relation_of(NodeKind kind);

struct Node {
  std::string name;
  NodeKind kind{NodeKind::kControl};
  // Indices of the cause nodes, all smaller than this node's index: 2 for sum and product, 1 for
  // M+, negative, abs and threshold, none for constant and control.
  std::vector<int> causes;
  Sign value{Sign::kUnknown};
  // Control: the commanded number. Threshold: 1 (true) / 0 (false) when observed, empty otherwise.
  std::optional<double> actual;
};

class Network {
 public:
  int add_control(const std::string& name);
  // A landmark whose number is unknown to the planner but whose sign is known.
  int add_constant(const std::string& name, Sign value);
  int add_relation(NodeKind kind, const std::string& name, const std::vector<int>& causes);
  int add_threshold(const std::string& name, int cause);

  void set_control_value(int control, double value);
  // An observed outcome (true/false), or std::nullopt when it was not observed.
  void observe_threshold(int threshold, std::optional<bool> outcome);

  // Forward pass over values (controls: sign of their number; thresholds: the observation if any),
  // then backward refinement: an unknown cause becomes definite when likely_potentials() given the
  // effect's value leaves one possible sign. Repeats until nothing changes.
  void propagate_values();

  // Forward propagation of planned changes: `planned` fixes the changes of some nodes (controls,
  // usually); ultimate causes not in it are steady (0). Returns the change of every node; a node
  // whose change the tables cannot decide gets `?`.
  [[nodiscard]] std::vector<Sign> propagate_changes(const std::map<int, Sign>& planned) const;

  // Backward use of likely-change-potentials: the potentials of the changes (+, 0, -) of cause
  // number `cause_position` of `node` for the node to change by `desired`, the other causes
  // changing by `changes` (their entry, `?` meaning undecided).
  [[nodiscard]] Potentials cause_change_potentials(int node, int cause_position, Sign desired,
                                                   const std::vector<Sign>& changes) const;

  // Forward use: the potentials of the node's change given its causes' changes.
  [[nodiscard]] Potentials node_change_potentials(int node, const std::vector<Sign>& changes) const;

  // True when `ancestor` is `node` or one of its (transitive) causes.
  [[nodiscard]] bool is_ancestor(int ancestor, int node) const;

  [[nodiscard]] const Node& node(int id) const { return nodes_.at(id); }
  [[nodiscard]] int size() const { return static_cast<int>(nodes_.size()); }
  [[nodiscard]] int find(const std::string& name) const;  // throws QrError if absent

 private:
  int add(Node node);
  [[nodiscard]] std::vector<Sign> cause_values(const Node& node) const;

  std::vector<Node> nodes_;
};

}  // namespace spar::qr
