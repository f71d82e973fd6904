// ConstraintNetwork: SPAR's geometric binary constraint network (seed 001, "The Geometric Binary
// Constraint Network"; Dechter & Pearl 1987). Nodes are plan variables (a grasp, a position),
// each with a label set drawn from its domain 0..domain_size-1 (the planner maps labels to grasp
// or stable-pose names; the network knows nothing of robots). Arcs are binary constraints: the
// set of allowed label pairs between two variables. Several constraints between the same two
// variables intersect into one arc.
//
// Every operation that adds a constraint (restrict = SPAR's member / in_position_class, post =
// reachable / mate_reachable, unify = codesignation) first prunes the label sets to arc
// consistency (AC-3), then makes sure a consistent full labeling still exists: the network keeps
// one such labeling (its witness); where the change breaks it, it first tries to repair it one
// variable at a time (no backtracking). If that fails, each connected component concerned gets a
// new labeling: read off without backtracking if the component is a tree (arc consistency alone
// decides trees, Freuder 1982), else found by search (backtracking with forward checking and
// arc consistency maintained after every assignment, within the explicit SearchBudget).
// Tree-structured networks, SPAR's usual grasp-position pairs, are therefore never refused for lack
// of budget. The operation returns kConsistent and keeps the change, or returns kInconsistent /
// kBudgetExhausted and leaves the network exactly as it was (operator== holds). Hence every network
// a caller can observe is arc consistent and has a consistent labeling.
//
// Costs (n variables, e arcs, d labels per domain): an operation costs O(n + e) for the witness
// check plus AC-3 on bit rows (a revision is O(d²/64); O(e·d³/64) at worst, a few revisions
// usually; unify also copies the network once); the search runs only when the witness cannot be
// repaired. Copying is O(n + e·d²/64) in a fixed handful of allocations: 0.2 µs for 32 variables
// and 31 arcs of 24 x 8 labels.
//
// Codesignated variables (unify) share one representative, the smallest id of their class;
// every query answers for the representative. The network is a plain copyable value: vectors
// and bitsets, no pointers (the planner copies it for every branch of its search).
//
// Example:
//   ConstraintNetwork network;
//   const int grasp = network.add_variable("?grasp", 4, {0, 1, 2, 3});
//   const int pose = network.add_variable("?pose", 3, {0, 1, 2});
//   AllowedPairs reachable(4, 3);  reachable.allow(1, 2);  reachable.allow(3, 2);
//   assert(network.post(grasp, pose, reachable) == Consistency::kConsistent);
//   // network.labels(grasp) == {1, 3}, network.labels(pose) == {2}
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "spar/planner/cms/internal/bitset.hpp"
#include "spar/planner/cms/internal/search.hpp"

namespace spar::planner::cms {

// The verdict of an operation (or of a full consistency check).
enum class Consistency {
  kConsistent,       // a consistent full labeling exists (the change was kept)
  kInconsistent,     // none exists (the change was refused)
  kBudgetExhausted,  // the search ran out of nodes before deciding (the change was refused)
};

// How much backtracking search an operation may spend: every label the search tries costs one
// node. Arc consistency and the witness check are not counted (they are polynomial).
struct SearchBudget {
  std::uint64_t nodes{100'000};
};

// The allowed label pairs of a binary constraint between variables a and b: a bit matrix of
// domain_size(a) rows by domain_size(b) columns, nothing allowed at first.
class AllowedPairs {
 public:
  AllowedPairs(int rows, int columns);
  [[nodiscard]] int rows() const { return bits_.rows(); }
  [[nodiscard]] int columns() const { return bits_.columns(); }
  // Throws CmsError for a label outside the matrix.
  void allow(int row_label, int column_label);
  [[nodiscard]] bool allowed(int row_label, int column_label) const;

 private:
  friend class ConstraintNetwork;
  internal::BitMatrix bits_;
};

// A full labeling: the label of every variable id (codesignated ids have the same label).
using Labeling = std::vector<int>;

// One arc for printing: its two variables (representatives, first < second) and the allowed
// pairs (label of first, label of second) that remain, sorted.
struct ArcPairs {
  int first{0};
  int second{0};
  std::vector<std::pair<int, int>> pairs;
  friend bool operator==(const ArcPairs&, const ArcPairs&) = default;
};

class ConstraintNetwork {
 public:
  // Adds a variable with labels 0..domain_size-1, of which `initial_labels` are possible, and
  // returns its id (0, 1, 2, ...). Throws CmsError if domain_size < 1, a label is outside the
  // domain or the initial set is empty.
  int add_variable(std::string name, int domain_size, const std::vector<int>& initial_labels);

  // SPAR's member / in_position_class: intersects the label set of `var` with `labels`.
  [[nodiscard]] Consistency restrict(int var, const std::vector<int>& labels,
                                     SearchBudget budget = {});
  // A binary constraint: only the pairs in `allowed` (domain_size(a) × domain_size(b)) may be
  // taken by (a, b). If a and b are codesignated, it restricts their label to {l : (l, l)}.
  [[nodiscard]] Consistency post(int a, int b, const AllowedPairs& allowed,
                                 SearchBudget budget = {});
  // The same with allowed pairs given by a predicate, called once for each pair of current labels
  // of a and b (pairs of labels already ruled out are not asked).
  [[nodiscard]] Consistency post(int a, int b, const std::function<bool(int, int)>& allowed,
                                 SearchBudget budget = {});
  // Codesignation: from now on a and b are one plan variable (label sets intersect, arcs merge).
  // Throws CmsError if their domains differ in size.
  [[nodiscard]] Consistency unify(int a, int b, SearchBudget budget = {});

  [[nodiscard]] int variable_count() const { return static_cast<int>(variables_.size()); }
  [[nodiscard]] const std::string& name(int var) const;
  [[nodiscard]] int domain_size(int var) const;
  // The smallest id codesignated with var (var itself if never unified).
  [[nodiscard]] int representative(int var) const;
  // The current label set of var (of its representative), ascending.
  [[nodiscard]] std::vector<int> labels(int var) const;
  [[nodiscard]] bool has_label(int var, int label) const;
  // A cheap necessary (not sufficient) condition for unify(a, b) to succeed: a and b are
  // codesignated, or have the same domain and share a current label. Only unify decides.
  [[nodiscard]] bool could_unify(int a, int b) const;
  // The arcs between representatives, sorted by (first, second).
  [[nodiscard]] std::vector<ArcPairs> arcs() const;

  // Proves again, by search from scratch (ignoring the witness), that a consistent full labeling
  // exists. The operations keep that true, so the answer is kConsistent unless the budget runs
  // out; tests use it against brute force.
  [[nodiscard]] Consistency consistent(SearchBudget budget = {}) const;

  // Checks the invariants written at the members below; throws std::logic_error naming the first
  // broken one. For tests.
  void check_invariants() const;

  friend bool operator==(const ConstraintNetwork&, const ConstraintNetwork&) = default;

 private:
  friend class Labelings;
  struct Variable {
    std::string name;
    int domain_size{0};
    int representative{0};
    friend bool operator==(const Variable&, const Variable&) = default;
  };
  // Label sets indexed by variable id (the layout of labels_).
  using LabelSets = internal::BitsetArray;
  // A directed revision request for AC-3: prune `variable` against arc `arc`.
  struct Revision {
    int variable{0};
    int arc{0};
  };

  void check_variable(int var) const;
  [[nodiscard]] std::vector<int> representatives() const;
  [[nodiscard]] std::span<const int> incident(int var) const;
  [[nodiscard]] int find_arc(int first, int second) const;
  [[nodiscard]] std::span<const std::uint64_t> row(const internal::Arc& arc, bool from_first,
                                                   int label) const;
  [[nodiscard]] bool revise(LabelSets& labels, Revision revision) const;
  [[nodiscard]] bool propagate(LabelSets& labels, std::vector<Revision> queue) const;
  [[nodiscard]] internal::ForwardChecking make_search(const std::vector<int>& component,
                                                      const LabelSets& labels,
                                                      internal::ForwardChecking::Order order) const;
  [[nodiscard]] std::vector<std::vector<int>> components_of(std::vector<int> seeds) const;
  [[nodiscard]] Consistency search_components(const std::vector<std::vector<int>>& components,
                                              const LabelSets& labels, SearchBudget budget,
                                              std::vector<int>& witness) const;
  [[nodiscard]] bool is_tree(const std::vector<int>& component) const;
  void label_tree(const std::vector<int>& component, const LabelSets& labels,
                  std::vector<int>& witness) const;
  [[nodiscard]] bool repair(const LabelSets& labels, const std::vector<int>& misfits,
                            std::vector<int>& witness) const;
  [[nodiscard]] Consistency settle(LabelSets labels, std::vector<Revision> queue,
                                   SearchBudget budget, const std::vector<int>& touched_arcs);
  void add_arc(int first, int second, const internal::BitMatrix& forward,
               const internal::BitMatrix& backward);
  void intersect_arc(int index, std::span<const std::uint64_t> forward,
                     std::span<const std::uint64_t> backward);
  void mask_arc(const internal::Arc& arc);
  void merge_into(int keep, int gone);
  void rebuild_incidence();

  // The members are flat vectors, so a copy costs a handful of allocations whatever the size.
  //
  // variables_[v].representative is the smallest id codesignated with v, and the representative
  // of a representative is itself (canonical: one hop, no chains).
  std::vector<Variable> variables_;
  // labels_[v]: domain_size(v) bits. For a representative: a non-empty label set, arc consistent
  // with every arc at it. For any other id: empty.
  LabelSets labels_;
  // arcs_: at most one arc per pair of representatives, first < second, never a self-arc. Their
  // matrices live in arc_words_ (each arc's forward, then its backward, in arc order, nothing
  // else) and hold only pairs of current labels (rows and columns of pruned labels are zero).
  std::vector<internal::Arc> arcs_;
  std::vector<std::uint64_t> arc_words_;
  // The arcs at each variable, as offsets: incident_arcs_[incident_start_[v] ..
  // incident_start_[v + 1]) are the indices into arcs_ of the arcs at v, ascending (none for an
  // id that is not a representative). Rebuilt from arcs_ whenever arcs come or go.
  std::vector<int> incident_start_;
  std::vector<int> incident_arcs_;
  // witness_[r]: a consistent full labeling over the representatives (a current label of each,
  // every arc allowing every pair of it); -1 at other ids.
  std::vector<int> witness_;
};

// Lazy, deterministic enumeration of all consistent full labelings of a network,
// lexicographically (variables in id order, labels ascending), by backtracking with forward
// checking. Holds its own copy of the network: later changes to it are not seen.
class Labelings {
 public:
  // `budget` bounds the whole enumeration, not each labeling.
  explicit Labelings(const ConstraintNetwork& network, SearchBudget budget = {});

  // The next labeling, or std::nullopt when there are no more or the budget ran out.
  [[nodiscard]] std::optional<Labeling> next();
  // After next() returned std::nullopt: true if the budget ran out (labelings may remain).
  [[nodiscard]] bool budget_exhausted() const { return budget_exhausted_; }

 private:
  ConstraintNetwork network_;
  internal::ForwardChecking search_;  // over the representatives in ascending id order
  std::vector<int> local_of_;         // a representative's index in the search, -1 for others
  std::uint64_t nodes_left_;
  bool budget_exhausted_{false};
};

// Up to `limit` labelings in Labelings' order, and why the enumeration stopped.
struct LabelingBatch {
  enum class Stop { kAll, kLimitReached, kBudgetExhausted };
  std::vector<Labeling> labelings;
  Stop stop{Stop::kAll};
};
[[nodiscard]] LabelingBatch first_labelings(const ConstraintNetwork& network, std::size_t limit,
                                            SearchBudget budget = {});

}  // namespace spar::planner::cms
