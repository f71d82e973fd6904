#include "spar/planner/uncertainty/space.hpp"

#include <algorithm>
#include <cmath>

#include "spar/planner/error.hpp"

namespace spar::planner {

const char* to_string(UncertaintySource source) {
  switch (source) {
    case UncertaintySource::kInitial:
      return "initial";
    case UncertaintySource::kManipulator:
      return "manipulator";
    case UncertaintySource::kSensor:
      return "sensor";
    case UncertaintySource::kJoint:
      return "joint";
  }
  return "?";
}

namespace {

std::string name_of(const VariableSpec& spec) {
  if (!spec.name.empty()) return std::string(spec.name);
  return std::string(to_string(spec.component)) + "_" + std::string(spec.tag);
}

void check_spec(const VariableSpec& spec) {
  const std::string name = name_of(spec);
  if (!std::isfinite(spec.half_width) || spec.half_width < 0)
    throw PlanError("uncertainty half-width of " + name + " must be finite and >= 0");
  if (!std::isfinite(spec.sigma) || spec.sigma < 0)
    throw PlanError("sigma of " + name + " must be finite and >= 0");
}

// Where expression id `key` is or belongs in the sorted by_symbol_ list.
template <typename Entries>
auto slot_of(Entries& entries, std::uint32_t key) {
  return std::lower_bound(entries.begin(), entries.end(), key,
                          [](const auto& entry, std::uint32_t k) { return entry.first < k; });
}

}  // namespace

VariableId UncertaintySpace::allocate(const VariableSpec& spec) {
  check_spec(spec);
  const std::string base = name_of(spec);
  std::string name = base;
  symbolic::Expr symbol = pool_->variable(name);
  for (int suffix = 2; id_of(symbol); ++suffix) {  // taken: the next suffix
    name = base + "_" + std::to_string(suffix);
    symbol = pool_->variable(name);
  }
  const VariableId id{static_cast<std::uint32_t>(variables_.size())};
  variables_.push_back({.name = std::move(name),
                        .component = spec.component,
                        .lower = -spec.half_width,
                        .upper = spec.half_width,
                        .sigma = spec.sigma,
                        .provenance = spec.provenance});
  symbols_.push_back(symbol);
  by_symbol_.insert(slot_of(by_symbol_, symbol.id()), {symbol.id(), id});
  return id;
}

kinematics::PoseError UncertaintySpace::allocate_pose(
    const kinematics::PoseUncertainty& half_widths, const Provenance& provenance,
    std::string_view tag, const kinematics::PoseUncertainty& sigmas) {
  const double widths[4] = {half_widths.dx, half_widths.dy, half_widths.dz, half_widths.dtheta};
  const double sigma[4] = {sigmas.dx, sigmas.dy, sigmas.dz, sigmas.dtheta};
  VariableSpec specs[4];
  for (const PoseComponent component : kPoseComponents) {
    const int i = index_of(component);
    specs[i] = {.component = component,
                .half_width = widths[i],
                .sigma = sigma[i],
                .provenance = provenance,
                .tag = tag};
    check_spec(specs[i]);  // all checked first: a refused allocation adds nothing
  }
  symbolic::Expr symbols[4];
  for (int i = 0; i < 4; ++i) symbols[i] = symbol(allocate(specs[i]));
  return {symbols[0], symbols[1], symbols[2], symbols[3]};
}

std::optional<VariableId> UncertaintySpace::id_of(symbolic::Expr symbol) const {
  if (symbol.is_null() || &symbol.pool() != pool_) return std::nullopt;
  const auto found = slot_of(by_symbol_, symbol.id());
  if (found == by_symbol_.end() || found->first != symbol.id()) return std::nullopt;
  return found->second;
}

void UncertaintySpace::set_range(VariableId id, double lower, double upper) {
  if (!(std::isfinite(lower) && std::isfinite(upper) && lower <= upper))
    throw PlanError("uncertainty range of " + variable(id).name +
                    " must be finite with lower <= upper");
  variables_.at(id.index).lower = lower;
  variables_.at(id.index).upper = upper;
}

bounds::Interval UncertaintySpace::range(VariableId id) const {
  const SpaceVariable& v = variable(id);
  return bounds::Interval(v.lower, v.upper);
}

std::vector<bounds::Interval> UncertaintySpace::ranges(std::span<const VariableId> ids) const {
  std::vector<bounds::Interval> box;
  box.reserve(ids.size());
  for (const VariableId id : ids) box.push_back(range(id));
  return box;
}

}  // namespace spar::planner
