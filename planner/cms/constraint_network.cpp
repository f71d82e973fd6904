#include "spar/planner/cms/constraint_network.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "spar/planner/cms/error.hpp"

namespace spar::planner::cms {

namespace {

using internal::Arc;
using internal::Bitset;
using internal::ConstBitsRef;
using internal::ForwardChecking;

[[nodiscard]] int other_end(const Arc& arc, int variable) {
  return arc.first == variable ? arc.second : arc.first;
}

[[nodiscard]] std::vector<int> members(ConstBitsRef set) {
  std::vector<int> result;
  for (int bit = set.find_first(); bit >= 0; bit = set.find_next(bit + 1)) result.push_back(bit);
  return result;
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
  labels_[labels_.add(domain_size)].assign(labels);
  rebuild_incidence();
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
  return members(labels_[representative(var)]);
}

bool ConstraintNetwork::has_label(int var, int label) const {
  const ConstBitsRef set = labels_[representative(var)];
  return label >= 0 && label < set.size() && set.test(label);
}

bool ConstraintNetwork::could_unify(int a, int b) const {
  const int first = representative(a);
  const int second = representative(b);
  return first == second ||
         (domain_size(a) == domain_size(b) && labels_[first].intersects(labels_[second].words()));
}

std::vector<ArcPairs> ConstraintNetwork::arcs() const {
  std::vector<ArcPairs> result;
  for (const Arc& arc : arcs_) {
    ArcPairs printed{arc.first, arc.second, {}};
    for (int label = 0; label < arc.first_domain; ++label) {
      for (const int other :
           members(ConstBitsRef(row(arc, true, label).data(), arc.second_domain))) {
        printed.pairs.emplace_back(label, other);
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

std::span<const int> ConstraintNetwork::incident(int var) const {
  const auto begin = static_cast<std::size_t>(incident_start_[static_cast<std::size_t>(var)]);
  const auto end = static_cast<std::size_t>(incident_start_[static_cast<std::size_t>(var) + 1]);
  return std::span<const int>(incident_arcs_).subspan(begin, end - begin);
}

int ConstraintNetwork::find_arc(int first, int second) const {
  for (const int index : incident(first)) {
    if (other_end(arcs_[static_cast<std::size_t>(index)], first) == second) return index;
  }
  return -1;
}

std::span<const std::uint64_t> ConstraintNetwork::row(const Arc& arc, bool from_first,
                                                      int label) const {
  return arc.row(std::span<const std::uint64_t>(arc_words_), from_first, label);
}

void ConstraintNetwork::rebuild_incidence() {
  incident_start_.assign(variables_.size() + 1, 0);
  for (const Arc& arc : arcs_) {
    ++incident_start_[static_cast<std::size_t>(arc.first) + 1];
    ++incident_start_[static_cast<std::size_t>(arc.second) + 1];
  }
  for (std::size_t var = 0; var < variables_.size(); ++var) {
    incident_start_[var + 1] += incident_start_[var];
  }
  incident_arcs_.resize(2 * arcs_.size());
  std::vector<int> next(incident_start_.begin(), incident_start_.end() - 1);
  for (std::size_t index = 0; index < arcs_.size(); ++index) {
    for (const int end : {arcs_[index].first, arcs_[index].second}) {
      incident_arcs_[static_cast<std::size_t>(next[static_cast<std::size_t>(end)]++)] =
          static_cast<int>(index);
    }
  }
}

// AC-3's revise: drops the labels of revision.variable that no current label at the arc's other
// end supports. Returns true if it dropped any.
bool ConstraintNetwork::revise(LabelSets& labels, Revision revision) const {
  const Arc& arc = arcs_[static_cast<std::size_t>(revision.arc)];
  const bool from_first = arc.first == revision.variable;
  const internal::BitsRef own = labels[revision.variable];
  const ConstBitsRef other = labels[other_end(arc, revision.variable)];
  bool changed = false;
  for (int label = own.find_first(); label >= 0; label = own.find_next(label + 1)) {
    if (!other.intersects(row(arc, from_first, label))) {
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
    if (labels[revision.variable].none()) return false;
    for (const int index : incident(revision.variable)) {
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
  internal::BitsetArray domains;
  std::vector<std::vector<ForwardChecking::Neighbor>> neighbors(component.size());
  for (std::size_t i = 0; i < component.size(); ++i) {
    const int var = component[i];
    domains[domains.add(labels[var].size())].assign(labels[var]);
    for (const int index : incident(var)) {
      const Arc& arc = arcs_[static_cast<std::size_t>(index)];
      const int other = local[static_cast<std::size_t>(other_end(arc, var))];
      if (other < 0) throw std::logic_error("constraint network: component is not closed");
      const bool from_first = arc.first == var;
      neighbors[i].push_back(
          {other, from_first ? arc.forward : arc.backward, arc.row_words(from_first)});
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
      for (const int index : incident(component[head])) {
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
    switch (search.next(arc_words_, nodes_left)) {
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

bool ConstraintNetwork::is_tree(const std::vector<int>& component) const {
  std::size_t incidences = 0;
  for (const int var : component) incidences += incident(var).size();
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
  witness[static_cast<std::size_t>(order.front())] = labels[order.front()].find_first();
  labeled[static_cast<std::size_t>(order.front())] = 1;
  for (std::size_t head = 0; head < order.size(); ++head) {
    const int parent = order[head];
    const int parent_label = witness[static_cast<std::size_t>(parent)];
    for (const int index : incident(parent)) {
      const Arc& arc = arcs_[static_cast<std::size_t>(index)];
      const int child = other_end(arc, parent);
      if (labeled[static_cast<std::size_t>(child)] != 0) continue;
      Bitset allowed = labels[child].copy();
      allowed.intersect_with(row(arc, arc.first == parent, parent_label));
      const int label = allowed.find_first();
      if (label < 0)
        throw std::logic_error("constraint network: tree labeling met a wiped-out arc");
      witness[static_cast<std::size_t>(child)] = label;
      labeled[static_cast<std::size_t>(child)] = 1;
      order.push_back(child);
    }
  }
}

// The cheap first try when the witness no longer fits: gives each misfit, in turn, the first
// current label (its old one first) that every arc at it allows with the neighbours' witness
// labels (neighbours still to be repaired are skipped; they check against it in their turn).
// True if every misfit got one: the witness is then consistent again. False says nothing about
// consistency; settle() then labels the components concerned afresh.
bool ConstraintNetwork::repair(const LabelSets& labels, const std::vector<int>& misfits,
                               std::vector<int>& witness) const {
  const auto fits = [&](int var, int label) {
    for (const int index : incident(var)) {
      const Arc& arc = arcs_[static_cast<std::size_t>(index)];
      const int other = other_end(arc, var);
      const int other_label = witness[static_cast<std::size_t>(other)];
      if (other_label < 0 || !labels[other].test(other_label)) continue;
      if (!internal::span_test(row(arc, arc.first == var, label), other_label)) return false;
    }
    return true;
  };
  for (const int var : misfits) {
    const ConstBitsRef own = labels[var];
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

// Clears the pairs of labels no longer current from both matrices of `arc`.
void ConstraintNetwork::mask_arc(const Arc& arc) {
  const std::span<std::uint64_t> pool(arc_words_);
  for (const bool from_first : {true, false}) {
    const ConstBitsRef own = labels_[from_first ? arc.first : arc.second];
    const ConstBitsRef other = labels_[from_first ? arc.second : arc.first];
    for (int label = 0; label < own.size(); ++label) {
      const std::span<std::uint64_t> words = arc.row(pool, from_first, label);
      const bool live = own.test(label);
      for (std::size_t i = 0; i < words.size(); ++i) {
        words[i] = live ? words[i] & other.words()[i] : 0;
      }
    }
  }
}

// Arc consistency from `queue`, then a consistent labeling: the witness where it still fits,
// else the witness repaired, else, in each connected component where it does not fit, a
// labeling read off the tree (arc consistency decides a tree-structured component) or found by
// search. On kConsistent commits the labels and the witness and drops pruned pairs from the arcs
// at changed variables and from `touched_arcs`; otherwise changes nothing.
Consistency ConstraintNetwork::settle(LabelSets labels, std::vector<Revision> queue,
                                      SearchBudget budget, const std::vector<int>& touched_arcs) {
  if (!propagate(labels, std::move(queue))) return Consistency::kInconsistent;
  std::vector<int> misfits;
  for (const int var : representatives()) {
    const int label = witness_[static_cast<std::size_t>(var)];
    if (label < 0 || !labels[var].test(label)) misfits.push_back(var);
  }
  for (const Arc& arc : arcs_) {
    const int first = witness_[static_cast<std::size_t>(arc.first)];
    const int second = witness_[static_cast<std::size_t>(arc.second)];
    if (first >= 0 && second >= 0 && !internal::span_test(row(arc, true, first), second)) {
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
  for (int var = 0; var < variable_count(); ++var) {
    changed[static_cast<std::size_t>(var)] = !labels[var].equals(labels_[var]);
  }
  labels_ = std::move(labels);
  witness_ = std::move(witness);
  for (const Arc& arc : arcs_) {
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
  next[rep].intersect_with(allowed.words());
  if (next[rep].none()) return Consistency::kInconsistent;
  std::vector<Revision> queue;
  for (const int index : incident(rep)) {
    queue.push_back({other_end(arcs_[static_cast<std::size_t>(index)], rep), index});
  }
  return settle(std::move(next), std::move(queue), budget, {});
}

// Appends an arc first < second with the given matrices (forward: domain(first) rows).
void ConstraintNetwork::add_arc(int first, int second, const internal::BitMatrix& forward,
                                const internal::BitMatrix& backward) {
  const Arc arc{first,
                second,
                forward.rows(),
                backward.rows(),
                arc_words_.size(),
                arc_words_.size() + forward.words().size()};
  arc_words_.insert(arc_words_.end(), forward.words().begin(), forward.words().end());
  arc_words_.insert(arc_words_.end(), backward.words().begin(), backward.words().end());
  arcs_.push_back(arc);
}

// Intersects arc `index` with matrices of its shape, given as words (forward, then backward).
void ConstraintNetwork::intersect_arc(int index, std::span<const std::uint64_t> forward,
                                      std::span<const std::uint64_t> backward) {
  const Arc& arc = arcs_[static_cast<std::size_t>(index)];
  for (std::size_t i = 0; i < forward.size(); ++i) arc_words_[arc.forward + i] &= forward[i];
  for (std::size_t i = 0; i < backward.size(); ++i) arc_words_[arc.backward + i] &= backward[i];
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
  int index = find_arc(first, second);
  const bool existed = index >= 0;
  const std::size_t old_words = arc_words_.size();
  std::vector<std::uint64_t> saved;  // an existing arc's words before the intersection
  if (existed) {
    const Arc& arc = arcs_[static_cast<std::size_t>(index)];
    saved.assign(arc_words_.begin() + static_cast<std::ptrdiff_t>(arc.forward),
                 arc_words_.begin() + static_cast<std::ptrdiff_t>(arc.backward + arc.words(false)));
    intersect_arc(index, forward.words(), backward.words());
  } else {
    index = static_cast<int>(arcs_.size());
    add_arc(first, second, forward, backward);
    rebuild_incidence();
  }
  const Consistency verdict = settle(labels_, {{first, index}, {second, index}}, budget, {index});
  if (verdict != Consistency::kConsistent) {
    if (existed) {
      std::copy(saved.begin(), saved.end(),
                arc_words_.begin() +
                    static_cast<std::ptrdiff_t>(arcs_[static_cast<std::size_t>(index)].forward));
    } else {
      arcs_.pop_back();
      arc_words_.resize(old_words);
      rebuild_incidence();
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

// Makes `gone` a member of `keep`'s class (keep < gone, both representatives): intersects the
// label sets, turns an arc between them into a restriction of keep to its diagonal, and moves
// gone's other arcs to keep, intersecting with keep's arc to the same variable. Arc consistency
// and the witness are left for settle().
void ConstraintNetwork::merge_into(int keep, int gone) {
  for (Variable& variable : variables_) {
    if (variable.representative == gone) variable.representative = keep;
  }
  const internal::BitsRef kept = labels_[keep];
  kept.intersect_with(labels_[gone].words());
  labels_[gone].clear();
  witness_[static_cast<std::size_t>(gone)] = -1;
  std::vector<char> removed(arcs_.size(), 0);
  for (const int index : incident(gone)) {
    Arc& arc = arcs_[static_cast<std::size_t>(index)];
    const int other = other_end(arc, gone);
    if (other == keep) {
      for (int label = kept.find_first(); label >= 0; label = kept.find_next(label + 1)) {
        if (!internal::span_test(row(arc, true, label), label)) kept.reset(label);
      }
      removed[static_cast<std::size_t>(index)] = 1;
      continue;
    }
    (arc.first == gone ? arc.first : arc.second) = keep;
    if (arc.first > arc.second) {
      std::swap(arc.first, arc.second);
      std::swap(arc.first_domain, arc.second_domain);
      std::swap(arc.forward, arc.backward);
    }
    const int existing = find_arc(keep, other);  // the incidence still lists keep's old arcs
    if (existing >= 0) {                         // the two arcs' words do not overlap
      const std::span<const std::uint64_t> pool(arc_words_);
      intersect_arc(existing, pool.subspan(arc.forward, arc.words(true)),
                    pool.subspan(arc.backward, arc.words(false)));
      removed[static_cast<std::size_t>(index)] = 1;
    }
  }
  // Rebuild the arc list and its word pool without the removed arcs, forward before backward.
  std::vector<Arc> remaining;
  std::vector<std::uint64_t> words;
  const auto move_matrix = [&](std::size_t& offset, std::size_t count) {
    const auto begin = arc_words_.begin() + static_cast<std::ptrdiff_t>(offset);
    offset = words.size();
    words.insert(words.end(), begin, begin + static_cast<std::ptrdiff_t>(count));
  };
  for (std::size_t index = 0; index < arcs_.size(); ++index) {
    if (removed[index] != 0) continue;
    Arc arc = arcs_[index];
    move_matrix(arc.forward, arc.words(true));
    move_matrix(arc.backward, arc.words(false));
    remaining.push_back(arc);
  }
  arcs_ = std::move(remaining);
  arc_words_ = std::move(words);
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
  if (next.labels_[keep].none()) return Consistency::kInconsistent;
  std::vector<Revision> queue;
  const std::span<const int> at_keep = next.incident(keep);
  const std::vector<int> touched(at_keep.begin(), at_keep.end());
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
  if (labels_.count() != variable_count() || witness_.size() != n ||
      incident_start_.size() != n + 1 || incident_arcs_.size() != 2 * arcs_.size()) {
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
    if (labels_[var].size() != variables_[v].domain_size) fail(who + ": label set has wrong width");
    if (rep != var) {
      if (!labels_[var].none() || !incident(var).empty() || witness_[v] != -1) {
        fail(who + ": a codesignated id keeps labels, arcs or a witness");
      }
      continue;
    }
    if (labels_[var].none()) fail(who + ": empty label set");
    if (witness_[v] < 0 || witness_[v] >= labels_[var].size() || !labels_[var].test(witness_[v])) {
      fail(who + ": witness label is not a current label");
    }
  }
  std::size_t words = 0;
  for (std::size_t index = 0; index < arcs_.size(); ++index) {
    const Arc& arc = arcs_[index];
    const std::string which = "arc " + std::to_string(arc.first) + "-" + std::to_string(arc.second);
    if (arc.first < 0 || arc.second >= variable_count() || arc.first >= arc.second) {
      fail(which + ": ends out of order or range");
    }
    if (variables_[static_cast<std::size_t>(arc.first)].representative != arc.first ||
        variables_[static_cast<std::size_t>(arc.second)].representative != arc.second) {
      fail(which + ": an end is not a representative");
    }
    if (arc.first_domain != domain_size(arc.first) ||
        arc.second_domain != domain_size(arc.second) || arc.forward != words ||
        arc.backward != words + arc.words(true)) {
      fail(which + ": matrices have the wrong shape or place in the pool");
    }
    words += arc.words(true) + arc.words(false);
    for (const bool from_first : {true, false}) {
      const ConstBitsRef own = labels_[from_first ? arc.first : arc.second];
      const ConstBitsRef other = labels_[from_first ? arc.second : arc.first];
      for (int label = 0; label < own.size(); ++label) {
        const auto pairs = row(arc, from_first, label);
        for (int with = 0; with < other.size(); ++with) {
          if (internal::span_test(pairs, with) !=
              internal::span_test(from_first ? row(arc, false, with) : row(arc, true, with),
                                  label)) {
            fail(which + ": backward is not the transpose of forward");
          }
        }
        if (!own.test(label) && !ConstBitsRef(pairs.data(), other.size()).none()) {
          fail(which + ": pairs of a pruned label");
        }
        if (own.test(label) && !other.intersects(pairs)) {
          fail(which + ": label " + std::to_string(label) + " has no support (not arc consistent)");
        }
      }
    }
    if (find_arc(arc.first, arc.second) != static_cast<int>(index)) {
      fail(which + ": duplicate arc or missing incidence");
    }
    if (!internal::span_test(row(arc, true, witness_[static_cast<std::size_t>(arc.first)]),
                             witness_[static_cast<std::size_t>(arc.second)])) {
      fail(which + ": witness violates it");
    }
  }
  if (words != arc_words_.size()) fail("the arc word pool holds words of no arc");
  for (int var = 0; var < variable_count(); ++var) {
    const std::span<const int> list = incident(var);
    if (!std::is_sorted(list.begin(), list.end())) fail("incidence list not ascending");
    for (const int index : list) {
      const Arc& arc = arcs_[static_cast<std::size_t>(index)];
      if (arc.first != var && arc.second != var) fail("incidence lists an arc not at the variable");
    }
  }
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
  switch (search_.next(network_.arc_words_, nodes_left_)) {
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
