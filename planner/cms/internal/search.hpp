// The binary constraint network's arcs and its backtracking search with forward checking and
// maintained arc consistency (Dechter & Pearl 1987; Sabin & Freuder 1994), over a subset of the
// network's variables renumbered 0..k-1. Private to planner/cms/: ConstraintNetwork and Labelings
// drive it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "spar/planner/cms/internal/bitset.hpp"

namespace spar::planner::cms::internal {

// One arc of the network: the allowed label pairs between two representative variables, as two
// bit matrices kept in a flat word pool that the network owns (so copying all arcs is one
// memcpy): `forward` has a row per label of first, bit m of row l set iff (l, m) is allowed;
// `backward` is its transpose, so both directions read rows.
struct Arc {
  int first{0};             // the smaller variable id
  int second{0};            // the larger variable id
  int first_domain{0};      // domain size of first: rows of forward, columns of backward
  int second_domain{0};     // domain size of second
  std::size_t forward{0};   // offset of forward in the pool
  std::size_t backward{0};  // offset of backward in the pool

  [[nodiscard]] int row_words(bool from_first) const {
    return words_for(from_first ? second_domain : first_domain);
  }
  [[nodiscard]] std::size_t words(bool from_first) const {
    return static_cast<std::size_t>(from_first ? first_domain : second_domain) *
           static_cast<std::size_t>(row_words(from_first));
  }
  // The labels of the other end allowed with `label` at end `from_first ? first : second`.
  template <class Word>
  [[nodiscard]] std::span<Word> row(std::span<Word> pool, bool from_first, int label) const {
    const auto width = static_cast<std::size_t>(row_words(from_first));
    return pool.subspan((from_first ? forward : backward) + static_cast<std::size_t>(label) * width,
                        width);
  }
  friend bool operator==(const Arc&, const Arc&) = default;
};

// Resumable depth-first search over label assignments with forward checking and maintained arc
// consistency (MAC, Sabin & Freuder 1994): assigning a label removes, from every unassigned
// neighbour's domain, the labels the arc does not allow with it, and then every unassigned
// variable whose domain shrank has its unassigned neighbours revised in turn (a label stays only
// while some label of each neighbour supports it), until nothing changes; a domain left empty
// rejects the label. Removed labels belong to no solution extending the current assignment, so
// the solutions and their order are those of plain backtracking; only dead ends are cut earlier.
// Labels are tried in ascending order; the variable order is fixed (the order given: solutions come
// out lexicographically) or dynamic (fewest remaining labels first, for a quick yes/no). Every
// label tried costs one node of the budget.
class ForwardChecking {
 public:
  struct Neighbor {
    int variable{0};      // local index of the other end
    std::size_t rows{0};  // offset in the word pool of the arc's matrix read from this end
    int row_words{0};     // words per row of that matrix
  };
  enum class Order { kAsGiven, kFewestLabelsFirst };
  enum class Outcome { kFound, kNoMore, kOutOfBudget };

  ForwardChecking(BitsetArray domains, std::vector<std::vector<Neighbor>> neighbors, Order order);

  // Advances to the next solution. kFound: assignment() holds it (a label per local variable);
  // kNoMore: all solutions have been produced; kOutOfBudget: nodes_left reached zero (every
  // later call says so too). `pool` holds the arcs' matrices; the same on every call.
  [[nodiscard]] Outcome next(std::span<const std::uint64_t> pool, std::uint64_t& nodes_left);
  [[nodiscard]] const std::vector<int>& assignment() const { return assignment_; }

 private:
  struct Frame {
    int variable{0};
    int label{-1};      // the label tried last at this level (-1: none yet)
    BitsetArray saved;  // the domains before this level's assignment
  };
  [[nodiscard]] int choose_variable(int depth) const;
  // Forward checks `variable`'s new label, then restores arc consistency among the unassigned
  // variables; false when some domain is wiped out.
  [[nodiscard]] bool propagate(std::span<const std::uint64_t> pool, int variable, int label);
  // D(u) := its labels that some label of D(v) (`supports`) allows; true when it shrank. By rows:
  // `back` is u's end of the arc (a row per label of u). By union: `forward` is v's end.
  static bool revise_by_rows(std::span<const std::uint64_t> pool, const Neighbor& back,
                             ConstBitsRef supports, BitsRef domain);
  bool revise_by_union(std::span<const std::uint64_t> pool, const Neighbor& forward,
                       ConstBitsRef supports, BitsRef domain);

  Order order_;
  std::vector<std::vector<Neighbor>> neighbors_;
  // reverse_[v][k]: the index, in the list of v's k-th neighbour u, of u's entry for v.
  std::vector<std::vector<int>> reverse_;
  std::vector<int> queue_;  // variables whose domain shrank, to revise their neighbours
  std::vector<char> queued_;
  std::vector<std::uint64_t> union_;  // revise_by_union's scratch
  BitsetArray domains_;               // current domains; an assigned variable's holds its one label
  std::vector<char> assigned_;
  std::vector<Frame> frames_;  // one per variable; the first depth_ are the active levels
  int depth_{0};
  std::vector<int> assignment_;
  enum class State { kFresh, kRunning, kNoMore, kOutOfBudget } state_{State::kFresh};
};

}  // namespace spar::planner::cms::internal
