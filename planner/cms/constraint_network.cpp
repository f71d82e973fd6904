#include "planner/cms/constraint_network.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "planner/cms/error.hpp"

namespace spar::planner::cms {

namespace {

using internal::Arc;
using internal::Bitset;
using internal::ForwardChecking;

[[nodiscard]] int other_end(const Arc& arc, int variable) {
  return arc.first == variable ? arc.second : arc.first;
}

// Keeps in `matrix` only rows of labels in `rows` and, within them, columns in `columns`.
void keep_current_pairs(internal::BitMatrix& matrix, const Bitset& rows, const Bitset& columns) {
  for (int row = 0; row < matrix.rows(); ++row) {
    const std::span<std::uint64_t> words = matrix.row(row);
    const bool live = rows.test(row);
    for (std::size_t i = 0; i < words.size(); ++i)
      words[i] = live ? words[i] & columns.words()[i] : 0;
  }
}

}  // namespace

AllowedPairs::AllowedPairs(int rows, int columns) : bits_(rows, columns) {
  if (rows < 1 || columns < 1) {
    throw CmsError("allowed pairs: a " + std::to_string(rows) + " x " + std::to_string(columns) +
                   " matrix has no pairs (domains have at least one label)");
  }
}

void AllowedPairs::allow(int row_label, int column_label) {
  if (row_label < 0 || row_label >= rows() || column_label < 0 || column_label >= columns()) {
    throw CmsError("allowed pairs: (" + std::to_string(row_label) + ", " +
                   std::to_string(column_label) + ") is outside the " + std::to_string(rows()) +
                   " x " + std::to_string(columns()) + " matrix");
  }
  bits_.set(row_label, column_label);
}

bool AllowedPairs::allowed(int row_label, int column_label) const {
  return row_label >= 0 && row_label < rows() && column_label >= 0 && column_label < columns() &&
         bits_.test(row_label, column_label);
}

int ConstraintNetwork::add_variable(std::string name, int domain_size,
                                    const std::vector<int>& initial_labels) {
  if (domain_size < 1) {
    throw CmsError("variable " + name + ": domain size " + std::to_string(domain_size) +
                   " (a domain has at least one label)");
  }
  Bitset labels(domain_size);
  for (const int label : initial_labels) {
    if (label < 0 || label >= domain_size) {
      throw CmsError("variable " + name + ": initial label " + std::to_string(label) +
                     " is outside its domain 0.." + std::to_string(domain_size - 1));
    }
    labels.set(label);
  }
  if (labels.none()) throw CmsError("variable " + name + ": empty initial label set");
  const int id = variable_count();
  witness_.push_back(labels.find_first());
  variables_.push_back({std::move(name), domain_size, id});
  labels_.push_back(std::move(labels));
  incident_.emplace_back();
  return id;
}

void ConstraintNetwork::check_variable(int var) const {
  if (var < 0 || var >= variable_count()) {
    throw CmsError("constraint network: variable " + std::to_string(var) +
                   " does not exist (the network has " + std::to_string(variable_count()) +
                   " variables)");
  }
}

const std::string& ConstraintNetwork::name(int var) const {
  check_variable(var);
  return variables_[static_cast<std::size_t>(var)].name;
}

int ConstraintNetwork::domain_size(int var) const {
  check_variable(var);
  return variables_[static_cast<std::size_t>(var)].domain_size;
}

int ConstraintNetwork::representative(int var) const {
  check_variable(var);
  return variables_[static_cast<std::size_t>(var)].representative;
}

std::vector<int> ConstraintNetwork::labels(int var) const {
  const Bitset& set = labels_[static_cast<std::size_t>(representative(var))];
  std::vector<int> result;
  for (int label = set.find_first(); label >= 0; label = set.find_next(label + 1)) {
    result.push_back(label);
  }
  return result;
}

bool ConstraintNetwork::has_label(int var, int label) const {
  const Bitset& set = labels_[static_cast<std::size_t>(representative(var))];
  return label >= 0 && label < set.size() && set.test(label);
}

bool ConstraintNetwork::could_unify(int a, int b) const {
  const int first = representative(a);
  const int second = representative(b);
  return first == second ||
         (domain_size(a) == domain_size(b) && labels_[static_cast<std::size_t>(first)].intersects(
                                                  labels_[static_cast<std::size_t>(second)]));
}

std::vector<ArcPairs> ConstraintNetwork::arcs() const {
  std::vector<ArcPairs> result;
  for (const Arc& arc : arcs_) {
    ArcPairs printed{arc.first, arc.second, {}};
    for (int row = 0; row < arc.forward.rows(); ++row) {
      const auto words = arc.forward.row(row);
      for (int column = internal::span_find_next(words, arc.forward.columns(), 0); column >= 0;
           column = internal::span_find_next(words, arc.forward.columns(), column + 1)) {
        printed.pairs.emplace_back(row, column);
      }
    }
    result.push_back(std::move(printed));
  }
  std::sort(result.begin(), result.end(), [](const ArcPairs& x, const ArcPairs& y) {
    return std::pair{x.first, x.second} < std::pair{y.first, y.second};
  });
  return result;
}

std::vector<int> ConstraintNetwork::representatives() const {
  std::vector<int> result;
  for (int var = 0; var < variable_count(); ++var) {
    if (variables_[static_cast<std::size_t>(var)].representative == var) result.push_back(var);
  }
  return result;
}

int ConstraintNetwork::find_arc(int first, int second) const {
  for (const int index : incident_[static_cast<std::size_t>(first)]) {
    if (other_end(arcs_[static_cast<std::size_t>(index)], first) == second) return index;
  }
  return -1;
}

// AC-3's revise: drops the labels of revision.variable that no current label at the arc's other
// end supports. Returns true if it dropped any.
bool ConstraintNetwork::revise(LabelSets& labels, Revision revision) const {
  const Arc& arc = arcs_[static_cast<std::size_t>(revision.arc)];
  const bool from_first = arc.first == revision.variable;
  Bitset& own = labels[static_cast<std::size_t>(revision.variable)];
  const Bitset& other = labels[static_cast<std::size_t>(from_first ? arc.second : arc.first)];
  bool changed = false;
  for (int label = own.find_first(); label >= 0; label = own.find_next(label + 1)) {
    if (!other.intersects(arc.row(from_first, label))) {
      own.reset(label);
      changed = true;
    }
  }
  return changed;
}

// AC-3 from the given revisions: false as soon as a label set empties.
bool ConstraintNetwork::propagate(LabelSets& labels, std::vector<Revision> queue) const {
  const auto key = [this](Revision revision) {
    const bool from_first =
        arcs_[static_cast<std::size_t>(revision.arc)].first == revision.variable;
    return static_cast<std::size_t>(revision.arc) * 2 + (from_first ? 0 : 1);
  };
  std::vector<char> queued(arcs_.size() * 2, 0);
  for (const Revision revision : queue) queued[key(revision)] = 1;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const Revision revision = queue[head];
    queued[key(revision)] = 0;
    if (!revise(labels, revision)) continue;
    if (labels[static_cast<std::size_t>(revision.variable)].none()) return false;
    for (const int index : incident_[static_cast<std::size_t>(revision.variable)]) {
      if (index == revision.arc) continue;
      const Revision next{other_end(arcs_[static_cast<std::size_t>(index)], revision.variable),
                          index};
      if (queued[key(next)] == 0) {
        queued[key(next)] = 1;
        queue.push_back(next);
      }
    }
  }
  return true;
}

ForwardChecking ConstraintNetwork::make_search(const std::vector<int>& component,
                                               const LabelSets& labels,
                                               ForwardChecking::Order order) const {
  std::vector<int> local(variables_.size(), -1);
  for (std::size_t i = 0; i < component.size(); ++i) {
    local[static_cast<std::size_t>(component[i])] = static_cast<int>(i);
  }
  std::vector<Bitset> domains;
  std::vector<std::vector<ForwardChecking::Neighbor>> neighbors(component.size());
  for (std::size_t i = 0; i < component.size(); ++i) {
    const int var = component[i];
    domains.push_back(labels[static_cast<std::size_t>(var)]);
    for (const int index : incident_[static_cast<std::size_t>(var)]) {
      const Arc& arc = arcs_[static_cast<std::size_t>(index)];
      const int other = local[static_cast<std::size_t>(other_end(arc, var))];
      if (other < 0) throw std::logic_error("constraint network: component is not closed");
      neighbors[i].push_back({other, index, arc.first == var});
    }
  }
  return ForwardChecking(std::move(domains), std::move(neighbors), order);
}

// The connected components (over arcs) holding the seeds, each ascending, each once.
std::vector<std::vector<int>> ConstraintNetwork::components_of(std::vector<int> seeds) const {
  std::vector<char> seen(variables_.size(), 0);
  std::vector<std::vector<int>> components;
  for (const int seed : seeds) {
    if (seen[static_cast<std::size_t>(seed)] != 0) continue;
    std::vector<int> component{seed};
    seen[static_cast<std::size_t>(seed)] = 1;
    for (std::size_t head = 0; head < component.size(); ++head) {
      for (const int index : incident_[static_cast<std::size_t>(component[head])]) {
        const int other = other_end(arcs_[static_cast<std::size_t>(index)], component[head]);
        if (seen[static_cast<std::size_t>(other)] == 0) {
          seen[static_cast<std::size_t>(other)] = 1;
          component.push_back(other);
        }
      }
    }
    std::sort(component.begin(), component.end());
    components.push_back(std::move(component));
  }
  return components;
}

// Finds a consistent labeling of each component (they share no arc, so each is independent) and
// writes it into `witness`; the first component without one decides the verdict.
Consistency ConstraintNetwork::search_components(const std::vector<std::vector<int>>& components,
                                                 const LabelSets& labels, SearchBudget budget,
                                                 std::vector<int>& witness) const {
  std::uint64_t nodes_left = budget.nodes;
  for (const std::vector<int>& component : components) {
    ForwardChecking search =
        make_search(component, labels, ForwardChecking::Order::kFewestLabelsFirst);
    switch (search.next(arcs_, nodes_left)) {
      case ForwardChecking::Outcome::kFound:
        for (std::size_t i = 0; i < component.size(); ++i) {
          witness[static_cast<std::size_t>(component[i])] = search.assignment()[i];
        }
        break;
      case ForwardChecking::Outcome::kNoMore:
        return Consistency::kInconsistent;
      case ForwardChecking::Outcome::kOutOfBudget:
        return Consistency::kBudgetExhausted;
    }
  }
  return Consistency::kConsistent;
}

// The cheap first try when the witness no longer fits: gives each misfit, in turn, the first
// current label (its old one first) that every arc at it allows with the neighbours' witness
// labels (neighbours still to be repaired are skipped; they check against it in their turn).
// True if every misfit got one: the witness is then consistent again. False says nothing about
// consistency; settle() then searches.
bool ConstraintNetwork::repair(const LabelSets& labels, const std::vector<int>& misfits,
                               std::vector<int>& witness) const {
  const auto fits = [&](int var, int label) {
    for (const int index : incident_[static_cast<std::size_t>(var)]) {
      const Arc& arc = arcs_[static_cast<std::size_t>(index)];
      const int other = other_end(arc, var);
      const int other_label = witness[static_cast<std::size_t>(other)];
      if (other_label < 0 || !labels[static_cast<std::size_t>(other)].test(other_label)) continue;
      const auto row = arc.row(arc.first == var, label);
      if (((row[static_cast<std::size_t>(other_label / internal::kWordBits)] >>
            (other_label % internal::kWordBits)) &
           1U) == 0) {
        return false;
      }
    }
    return true;
  };
  for (const int var : misfits) {
    const Bitset& own = labels[static_cast<std::size_t>(var)];
    int& label = witness[static_cast<std::size_t>(var)];
    if (label >= 0 && own.test(label) && fits(var, label)) continue;
    label = -1;
    for (int candidate = own.find_first(); candidate >= 0;
         candidate = own.find_next(candidate + 1)) {
      if (fits(var, candidate)) {
        label = candidate;
        break;
      }
    }
    if (label < 0) return false;
  }
  return true;
}

bool ConstraintNetwork::is_tree(const std::vector<int>& component) const {
  std::size_t incidences = 0;
  for (const int var : component) incidences += incident_[static_cast<std::size_t>(var)].size();
  return incidences / 2 + 1 == component.size();  // connected with n - 1 arcs
}

// A consistent labeling of a tree-structured component whose labels are arc consistent, without
// backtracking (Freuder 1982): the first variable takes its smallest label, and every other
// variable, reached from the one before it in breadth-first order, the smallest label the arc
// from there allows (arc consistency guarantees one).
void ConstraintNetwork::label_tree(const std::vector<int>& component, const LabelSets& labels,
                                   std::vector<int>& witness) const {
  std::vector<char> labeled(variables_.size(), 0);
  std::vector<int> order{component.front()};
  witness[static_cast<std::size_t>(order.front())] =
      labels[static_cast<std::size_t>(order.front())].find_first();
  labeled[static_cast<std::size_t>(order.front())] = 1;
  for (std::size_t head = 0; head < order.size(); ++head) {
    const int parent = order[head];
    const int parent_label = witness[static_cast<std::size_t>(parent)];
    for (const int index : incident_[static_cast<std::size_t>(parent)]) {
      const Arc& arc = arcs_[static_cast<std::size_t>(index)];
      const int child = other_end(arc, parent);
      if (labeled[static_cast<std::size_t>(child)] != 0) continue;
      Bitset allowed = labels[static_cast<std::size_t>(child)];
      allowed.intersect_with(arc.row(arc.first == parent, parent_label));
      const int label = allowed.find_first();
      if (label < 0)
        throw std::logic_error("constraint network: tree labeling met a wiped-out arc");
      witness[static_cast<std::size_t>(child)] = label;
      labeled[static_cast<std::size_t>(child)] = 1;
      order.push_back(child);
    }
  }
}

void ConstraintNetwork::mask_arc(Arc& arc) const {
  const Bitset& first = labels_[static_cast<std::size_t>(arc.first)];
  const Bitset& second = labels_[static_cast<std::size_t>(arc.second)];
  keep_current_pairs(arc.forward, first, second);
  keep_current_pairs(arc.backward, second, first);
}

// Arc consistency from `queue`, then a consistent labeling: the witness where it still fits,
// else the witness repaired, else, in each connected component where it does not fit, a
// labeling read off the tree (arc consistency decides a tree-structured component) or found by
// search. On kConsistent
// commits the labels and the witness and drops pruned pairs from the arcs at changed variables and
// from `touched_arcs`; otherwise changes nothing.
Consistency ConstraintNetwork::settle(LabelSets labels, std::vector<Revision> queue,
                                      SearchBudget budget, const std::vector<int>& touched_arcs) {
  if (!propagate(labels, std::move(queue))) return Consistency::kInconsistent;
  std::vector<int> misfits;
  for (const int var : representatives()) {
    const int label = witness_[static_cast<std::size_t>(var)];
    if (label < 0 || !labels[static_cast<std::size_t>(var)].test(label)) misfits.push_back(var);
  }
  for (const Arc& arc : arcs_) {
    const int first = witness_[static_cast<std::size_t>(arc.first)];
    const int second = witness_[static_cast<std::size_t>(arc.second)];
    if (first >= 0 && second >= 0 && !arc.forward.test(first, second)) {
      misfits.push_back(arc.first);
      misfits.push_back(arc.second);
    }
  }
  std::sort(misfits.begin(), misfits.end());
  misfits.erase(std::unique(misfits.begin(), misfits.end()), misfits.end());
  std::vector<int> witness = witness_;
  if (!misfits.empty() && !repair(labels, misfits, witness)) {
    std::vector<std::vector<int>> cyclic;
    for (std::vector<int>& component : components_of(misfits)) {
      if (is_tree(component)) {
        label_tree(component, labels, witness);
      } else {
        cyclic.push_back(std::move(component));
      }
    }
    const Consistency verdict = search_components(cyclic, labels, budget, witness);
    if (verdict != Consistency::kConsistent) return verdict;
  }
  std::vector<char> changed(variables_.size(), 0);
  for (std::size_t var = 0; var < labels.size(); ++var) changed[var] = labels[var] != labels_[var];
  labels_ = std::move(labels);
  witness_ = std::move(witness);
  for (Arc& arc : arcs_) {
    if (changed[static_cast<std::size_t>(arc.first)] != 0 ||
        changed[static_cast<std::size_t>(arc.second)] != 0) {
      mask_arc(arc);
    }
  }
  for (const int index : touched_arcs) mask_arc(arcs_[static_cast<std::size_t>(index)]);
  return Consistency::kConsistent;
}

Consistency ConstraintNetwork::restrict(int var, const std::vector<int>& labels,
                                        SearchBudget budget) {
  const int rep = representative(var);
  Bitset allowed(domain_size(var));
  for (const int label : labels) {
    if (label < 0 || label >= allowed.size()) {
      throw CmsError("restrict " + name(var) + ": label " + std::to_string(label) +
                     " is outside its domain 0.." + std::to_string(allowed.size() - 1));
    }
    allowed.set(label);
  }
  LabelSets next = labels_;
  next[static_cast<std::size_t>(rep)].intersect_with(allowed);
  if (next[static_cast<std::size_t>(rep)].none()) return Consistency::kInconsistent;
  std::vector<Revision> queue;
  for (const int index : incident_[static_cast<std::size_t>(rep)]) {
    queue.push_back({other_end(arcs_[static_cast<std::size_t>(index)], rep), index});
  }
  return settle(std::move(next), std::move(queue), budget, {});
}

Consistency ConstraintNetwork::post(int a, int b, const AllowedPairs& allowed,
                                    SearchBudget budget) {
  if (allowed.rows() != domain_size(a) || allowed.columns() != domain_size(b)) {
    throw CmsError("post " + name(a) + ", " + name(b) + ": allowed pairs are " +
                   std::to_string(allowed.rows()) + " x " + std::to_string(allowed.columns()) +
                   ", the domains are " + std::to_string(domain_size(a)) + " x " +
                   std::to_string(domain_size(b)));
  }
  int first = representative(a);
  int second = representative(b);
  if (first == second) {  // codesignated: a unary constraint on the diagonal
    std::vector<int> diagonal;
    for (int label = 0; label < allowed.rows(); ++label) {
      if (allowed.allowed(label, label)) diagonal.push_back(label);
    }
    return restrict(first, diagonal, budget);
  }
  internal::BitMatrix forward = allowed.bits_;
  internal::BitMatrix backward = forward.transposed();
  if (first > second) {
    std::swap(first, second);
    std::swap(forward, backward);
  }
  // Install the arc (intersected with an existing one), settle, and take it out on refusal.
  const int existing = find_arc(first, second);
  std::optional<Arc> saved;
  int index = existing;
  if (existing >= 0) {
    Arc& arc = arcs_[static_cast<std::size_t>(existing)];
    saved = arc;
    arc.forward.intersect_with(forward);
    arc.backward.intersect_with(backward);
  } else {
    index = static_cast<int>(arcs_.size());
    arcs_.push_back({first, second, std::move(forward), std::move(backward)});
    incident_[static_cast<std::size_t>(first)].push_back(index);
    incident_[static_cast<std::size_t>(second)].push_back(index);
  }
  const Consistency verdict = settle(labels_, {{first, index}, {second, index}}, budget, {index});
  if (verdict != Consistency::kConsistent) {
    if (saved) {
      arcs_[static_cast<std::size_t>(index)] = std::move(*saved);
    } else {
      arcs_.pop_back();
      incident_[static_cast<std::size_t>(first)].pop_back();
      incident_[static_cast<std::size_t>(second)].pop_back();
    }
  }
  return verdict;
}

Consistency ConstraintNetwork::post(int a, int b, const std::function<bool(int, int)>& allowed,
                                    SearchBudget budget) {
  AllowedPairs pairs(domain_size(a), domain_size(b));
  const bool codesignated = representative(a) == representative(b);
  for (const int label_a : labels(a)) {
    if (codesignated) {
      if (allowed(label_a, label_a)) pairs.allow(label_a, label_a);
      continue;
    }
    for (const int label_b : labels(b)) {
      if (allowed(label_a, label_b)) pairs.allow(label_a, label_b);
    }
  }
  return post(a, b, pairs, budget);
}

void ConstraintNetwork::rebuild_incidence() {
  for (std::vector<int>& list : incident_) list.clear();
  for (std::size_t index = 0; index < arcs_.size(); ++index) {
    incident_[static_cast<std::size_t>(arcs_[index].first)].push_back(static_cast<int>(index));
    incident_[static_cast<std::size_t>(arcs_[index].second)].push_back(static_cast<int>(index));
  }
}

// Makes `gone` a member of `keep`'s class (keep < gone, both representatives): intersects the
// label sets, turns an arc between them into a restriction of keep to its diagonal, and moves
// gone's other arcs to keep, intersecting with keep's arc to the same variable. Arc consistency
// and the witness are left for settle().
void ConstraintNetwork::merge_into(int keep, int gone) {
  for (Variable& variable : variables_) {
    if (variable.representative == gone) variable.representative = keep;
  }
  Bitset& kept = labels_[static_cast<std::size_t>(keep)];
  kept.intersect_with(labels_[static_cast<std::size_t>(gone)]);
  labels_[static_cast<std::size_t>(gone)] = Bitset();
  witness_[static_cast<std::size_t>(gone)] = -1;
  std::vector<char> removed(arcs_.size(), 0);
  for (const int index : incident_[static_cast<std::size_t>(gone)]) {
    Arc& arc = arcs_[static_cast<std::size_t>(index)];
    const bool gone_first = arc.first == gone;
    const int other = other_end(arc, gone);
    if (other == keep) {
      Bitset diagonal(kept.size());
      for (int label = 0; label < diagonal.size(); ++label) {
        if (arc.forward.test(label, label)) diagonal.set(label);
      }
      kept.intersect_with(diagonal);
      removed[static_cast<std::size_t>(index)] = 1;
      continue;
    }
    (gone_first ? arc.first : arc.second) = keep;
    if (arc.first > arc.second) {
      std::swap(arc.first, arc.second);
      std::swap(arc.forward, arc.backward);
    }
    const int existing = find_arc(keep, other);  // keep's incidence is not yet rebuilt
    if (existing >= 0) {
      arcs_[static_cast<std::size_t>(existing)].forward.intersect_with(arc.forward);
      arcs_[static_cast<std::size_t>(existing)].backward.intersect_with(arc.backward);
      removed[static_cast<std::size_t>(index)] = 1;
    }
  }
  std::vector<Arc> remaining;
  for (std::size_t index = 0; index < arcs_.size(); ++index) {
    if (removed[index] == 0) remaining.push_back(std::move(arcs_[index]));
  }
  arcs_ = std::move(remaining);
  rebuild_incidence();
}

Consistency ConstraintNetwork::unify(int a, int b, SearchBudget budget) {
  if (domain_size(a) != domain_size(b)) {
    throw CmsError("unify " + name(a) + " with " + name(b) + ": their domains differ (" +
                   std::to_string(domain_size(a)) + " and " + std::to_string(domain_size(b)) +
                   " labels)");
  }
  const int keep = std::min(representative(a), representative(b));
  const int gone = std::max(representative(a), representative(b));
  if (keep == gone) return Consistency::kConsistent;
  ConstraintNetwork next = *this;
  next.merge_into(keep, gone);
  if (next.labels_[static_cast<std::size_t>(keep)].none()) return Consistency::kInconsistent;
  std::vector<Revision> queue;
  const std::vector<int> touched = next.incident_[static_cast<std::size_t>(keep)];
  for (const int index : touched) {
    queue.push_back({keep, index});
    queue.push_back({other_end(next.arcs_[static_cast<std::size_t>(index)], keep), index});
  }
  const Consistency verdict = next.settle(next.labels_, std::move(queue), budget, touched);
  if (verdict == Consistency::kConsistent) *this = std::move(next);
  return verdict;
}

Consistency ConstraintNetwork::consistent(SearchBudget budget) const {
  std::vector<int> witness(variables_.size(), -1);
  return search_components(components_of(representatives()), labels_, budget, witness);
}

void ConstraintNetwork::check_invariants() const {
  const auto fail = [](const std::string& what) {
    throw std::logic_error("constraint network: " + what);
  };
  const std::size_t n = variables_.size();
  if (labels_.size() != n || incident_.size() != n || witness_.size() != n) {
    fail("per-variable tables differ in size");
  }
  for (int var = 0; var < variable_count(); ++var) {
    const auto v = static_cast<std::size_t>(var);
    const int rep = variables_[v].representative;
    const std::string who = "variable " + std::to_string(var) + " (" + variables_[v].name + ")";
    if (rep < 0 || rep > var || variables_[static_cast<std::size_t>(rep)].representative != rep) {
      fail(who + ": representative " + std::to_string(rep) + " is not canonical");
    }
    if (variables_[static_cast<std::size_t>(rep)].domain_size != variables_[v].domain_size) {
      fail(who + ": domain differs from its representative's");
    }
    if (rep != var) {
      if (labels_[v].size() != 0 || !incident_[v].empty() || witness_[v] != -1) {
        fail(who + ": a codesignated id keeps labels, arcs or a witness");
      }
      continue;
    }
    if (labels_[v].size() != variables_[v].domain_size) fail(who + ": label set has wrong width");
    if (labels_[v].none()) fail(who + ": empty label set");
    if (witness_[v] < 0 || witness_[v] >= labels_[v].size() || !labels_[v].test(witness_[v])) {
      fail(who + ": witness label is not a current label");
    }
  }
  for (std::size_t index = 0; index < arcs_.size(); ++index) {
    const Arc& arc = arcs_[index];
    const std::string which = "arc " + std::to_string(arc.first) + "-" + std::to_string(arc.second);
    if (arc.first < 0 || arc.second >= variable_count() || arc.first >= arc.second) {
      fail(which + ": ends out of order or range");
    }
    const auto first = static_cast<std::size_t>(arc.first);
    const auto second = static_cast<std::size_t>(arc.second);
    if (variables_[first].representative != arc.first ||
        variables_[second].representative != arc.second) {
      fail(which + ": an end is not a representative");
    }
    if (arc.forward.rows() != variables_[first].domain_size ||
        arc.forward.columns() != variables_[second].domain_size ||
        !(arc.backward == arc.forward.transposed())) {
      fail(which + ": matrices have the wrong shape or are not transposes");
    }
    for (int label = 0; label < arc.forward.rows(); ++label) {
      const auto row = arc.forward.row(label);
      const bool live = labels_[first].test(label);
      if (!live && internal::spans_intersect(row, row)) fail(which + ": pairs of a pruned label");
      if (live && !labels_[second].intersects(row)) {
        fail(which + ": label " + std::to_string(label) + " has no support (not arc consistent)");
      }
      for (std::size_t i = 0; i < row.size(); ++i) {
        if ((row[i] & ~labels_[second].words()[i]) != 0) fail(which + ": pairs of a pruned label");
      }
    }
    for (int label = labels_[second].find_first(); label >= 0;
         label = labels_[second].find_next(label + 1)) {
      if (!labels_[first].intersects(arc.backward.row(label))) {
        fail(which + ": label " + std::to_string(label) + " has no support (not arc consistent)");
      }
    }
    if (find_arc(arc.first, arc.second) != static_cast<int>(index)) {
      fail(which + ": duplicate arc or missing incidence");
    }
    if (!arc.forward.test(witness_[first], witness_[second])) fail(which + ": witness violates it");
  }
  std::size_t incidences = 0;
  for (const std::vector<int>& list : incident_) {
    if (!std::is_sorted(list.begin(), list.end())) fail("incidence list not ascending");
    incidences += list.size();
  }
  if (incidences != 2 * arcs_.size()) fail("incidence lists do not match the arcs");
}

Labelings::Labelings(const ConstraintNetwork& network, SearchBudget budget)
    : network_{network},
      search_{network_.make_search(network_.representatives(), network_.labels_,
                                   ForwardChecking::Order::kAsGiven)},
      nodes_left_{budget.nodes} {
  int local = 0;
  for (int var = 0; var < network_.variable_count(); ++var) {
    local_of_.push_back(network_.representative(var) == var ? local++ : -1);
  }
}

std::optional<Labeling> Labelings::next() {
  switch (search_.next(network_.arcs_, nodes_left_)) {
    case ForwardChecking::Outcome::kFound: {
      Labeling labeling;
      for (int var = 0; var < network_.variable_count(); ++var) {
        const int local = local_of_[static_cast<std::size_t>(network_.representative(var))];
        labeling.push_back(search_.assignment()[static_cast<std::size_t>(local)]);
      }
      return labeling;
    }
    case ForwardChecking::Outcome::kNoMore:
      return std::nullopt;
    case ForwardChecking::Outcome::kOutOfBudget:
      budget_exhausted_ = true;
      return std::nullopt;
  }
  return std::nullopt;
}

LabelingBatch first_labelings(const ConstraintNetwork& network, std::size_t limit,
                              SearchBudget budget) {
  Labelings enumeration(network, budget);
  LabelingBatch batch;
  while (true) {
    std::optional<Labeling> labeling = enumeration.next();
    if (!labeling) {
      batch.stop = enumeration.budget_exhausted() ? LabelingBatch::Stop::kBudgetExhausted
                                                  : LabelingBatch::Stop::kAll;
      return batch;
    }
    if (batch.labelings.size() == limit) {
      batch.stop = LabelingBatch::Stop::kLimitReached;
      return batch;
    }
    batch.labelings.push_back(std::move(*labeling));
  }
}

}  // namespace spar::planner::cms
