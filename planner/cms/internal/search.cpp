#include "spar/planner/cms/internal/search.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace spar::planner::cms::internal {

ForwardChecking::ForwardChecking(BitsetArray domains, std::vector<std::vector<Neighbor>> neighbors,
                                 Order order)
    : order_{order},
      neighbors_{std::move(neighbors)},
      domains_{std::move(domains)},
      assigned_(static_cast<std::size_t>(domains_.count()), 0),
      frames_(static_cast<std::size_t>(domains_.count())),
      assignment_(static_cast<std::size_t>(domains_.count()), -1) {
  reverse_.resize(neighbors_.size());
  for (std::size_t v = 0; v < neighbors_.size(); ++v)
    for (const Neighbor& neighbor : neighbors_[v]) {
      const std::vector<Neighbor>& back = neighbors_[static_cast<std::size_t>(neighbor.variable)];
      const auto entry = std::find_if(back.begin(), back.end(), [&](const Neighbor& n) {
        return n.variable == static_cast<int>(v);
      });
      if (entry == back.end()) throw std::logic_error("forward checking: an arc has one end");
      reverse_[v].push_back(static_cast<int>(entry - back.begin()));
    }
  queued_.assign(neighbors_.size(), 0);
}

bool ForwardChecking::propagate(std::span<const std::uint64_t> pool, int variable, int label) {
  queue_.clear();
  const auto enqueue = [&](int v) {
    if (queued_[static_cast<std::size_t>(v)] != 0) return;
    queued_[static_cast<std::size_t>(v)] = 1;
    queue_.push_back(v);
  };
  bool wiped = false;
  for (const Neighbor& neighbor : neighbors_[static_cast<std::size_t>(variable)]) {
    if (assigned_[static_cast<std::size_t>(neighbor.variable)] != 0) continue;
    const auto width = static_cast<std::size_t>(neighbor.row_words);
    const BitsRef domain = domains_[neighbor.variable];
    if (!domain.intersect_with(
            pool.subspan(neighbor.rows + static_cast<std::size_t>(label) * width, width)))
      continue;
    if (domain.none()) {
      wiped = true;
      break;
    }
    enqueue(neighbor.variable);
  }
  // Revise the unassigned neighbours u of each shrunk v: u keeps label l only while some label m
  // of v allows it. Two equal ways to compute that, the cheaper one taken: per label l of u, does
  // the row of l (read from u's end of the arc) meet D(v)? (|D(u)| rows of v's width), or D(u) &=
  // the union of the rows of every m in D(v) read from v's end (|D(v)| rows of u's width): after
  // an assignment D(v) is often far smaller than D(u).
  for (std::size_t head = 0; !wiped && head < queue_.size(); ++head) {
    const int v = queue_[head];
    queued_[static_cast<std::size_t>(v)] = 0;
    const ConstBitsRef supports = domains_[v];
    const int support_count = supports.count();
    const std::vector<Neighbor>& around = neighbors_[static_cast<std::size_t>(v)];
    for (std::size_t k = 0; k < around.size() && !wiped; ++k) {
      const int u = around[k].variable;
      if (assigned_[static_cast<std::size_t>(u)] != 0) continue;
      const Neighbor& back =
          neighbors_[static_cast<std::size_t>(u)][static_cast<std::size_t>(reverse_[v][k])];
      const BitsRef domain = domains_[u];
      const bool shrank = support_count * around[k].row_words < domain.count() * back.row_words
                              ? revise_by_union(pool, around[k], supports, domain)
                              : revise_by_rows(pool, back, supports, domain);
      if (!shrank) continue;
      if (domain.none()) wiped = true;
      enqueue(u);
    }
  }
  for (const int v : queue_) queued_[static_cast<std::size_t>(v)] = 0;
  return !wiped;
}

bool ForwardChecking::revise_by_rows(std::span<const std::uint64_t> pool, const Neighbor& back,
                                     ConstBitsRef supports, BitsRef domain) {
  const auto width = static_cast<std::size_t>(back.row_words);
  bool shrank = false;
  for (int l = domain.find_first(); l >= 0; l = domain.find_next(l + 1))
    if (!supports.intersects(
            pool.subspan(back.rows + static_cast<std::size_t>(l) * width, width))) {
      domain.reset(l);
      shrank = true;
    }
  return shrank;
}

bool ForwardChecking::revise_by_union(std::span<const std::uint64_t> pool, const Neighbor& forward,
                                      ConstBitsRef supports, BitsRef domain) {
  const auto width = static_cast<std::size_t>(forward.row_words);
  union_.assign(width, 0);
  for (int m = supports.find_first(); m >= 0; m = supports.find_next(m + 1)) {
    span_unite(union_, pool.subspan(forward.rows + static_cast<std::size_t>(m) * width, width));
    if (span_is_subset(domain.words(), union_)) return false;  // every label of u is supported
  }
  return domain.intersect_with(union_);
}

int ForwardChecking::choose_variable(int depth) const {
  if (order_ == Order::kAsGiven) return depth;
  int best = -1;
  int best_count = 0;
  for (int variable = 0; variable < domains_.count(); ++variable) {
    if (assigned_[static_cast<std::size_t>(variable)] != 0) continue;
    const int count = domains_[variable].count();
    if (best < 0 || count < best_count) {
      best = variable;
      best_count = count;
    }
  }
  return best;
}

ForwardChecking::Outcome ForwardChecking::next(std::span<const std::uint64_t> pool,
                                               std::uint64_t& nodes_left) {
  if (state_ == State::kNoMore) return Outcome::kNoMore;
  if (state_ == State::kOutOfBudget) return Outcome::kOutOfBudget;
  // Fresh: open the first level. Running: the last call stopped at a solution; retry its
  // deepest level with the next label.
  bool descend = state_ == State::kFresh;
  state_ = State::kRunning;
  const int size = domains_.count();
  while (true) {
    if (descend) {
      if (depth_ == size) {
        for (int level = 0; level < size; ++level) {
          const Frame& frame = frames_[static_cast<std::size_t>(level)];
          assignment_[static_cast<std::size_t>(frame.variable)] = frame.label;
        }
        return Outcome::kFound;
      }
      Frame& frame = frames_[static_cast<std::size_t>(depth_)];
      frame.variable = choose_variable(depth_);
      frame.label = -1;
      frame.saved = domains_;
      ++depth_;
    }
    if (depth_ == 0) {
      state_ = State::kNoMore;
      return Outcome::kNoMore;
    }
    Frame& frame = frames_[static_cast<std::size_t>(depth_ - 1)];
    const auto variable = static_cast<std::size_t>(frame.variable);
    domains_ = frame.saved;
    assigned_[variable] = 0;
    const int label = frame.saved[frame.variable].find_next(frame.label + 1);
    if (label < 0) {  // level exhausted: back to the one above
      --depth_;
      descend = false;
      continue;
    }
    if (nodes_left == 0) {
      state_ = State::kOutOfBudget;
      return Outcome::kOutOfBudget;
    }
    --nodes_left;
    frame.label = label;
    assigned_[variable] = 1;
    const BitsRef own = domains_[frame.variable];
    own.clear();
    own.set(label);
    // Wiped out: try the next label at this level.
    descend = propagate(pool, frame.variable, label);
  }
}

}  // namespace spar::planner::cms::internal
