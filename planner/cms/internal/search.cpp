#include "spar/planner/cms/internal/search.hpp"

#include <utility>

namespace spar::planner::cms::internal {

ForwardChecking::ForwardChecking(BitsetArray domains, std::vector<std::vector<Neighbor>> neighbors,
                                 Order order)
    : order_{order},
      neighbors_{std::move(neighbors)},
      domains_{std::move(domains)},
      assigned_(static_cast<std::size_t>(domains_.count()), 0),
      frames_(static_cast<std::size_t>(domains_.count())),
      assignment_(static_cast<std::size_t>(domains_.count()), -1) {}

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
    descend = true;
    for (const Neighbor& neighbor : neighbors_[variable]) {
      const auto other = static_cast<std::size_t>(neighbor.variable);
      if (assigned_[other] != 0) continue;
      const auto width = static_cast<std::size_t>(neighbor.row_words);
      domains_[neighbor.variable].intersect_with(
          pool.subspan(neighbor.rows + static_cast<std::size_t>(label) * width, width));
      if (domains_[neighbor.variable].none()) {
        descend = false;  // wiped out: try the next label at this level
        break;
      }
    }
  }
}

}  // namespace spar::planner::cms::internal
