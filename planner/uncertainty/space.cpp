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
  }
  return "?";
}

kinematics::PoseError UncertaintySpace::allocate(const kinematics::PoseUncertainty& half_widths,
                                                 const Provenance& provenance, std::string_view tag,
                                                 const kinematics::PoseUncertainty& sigmas) {
  const double widths[4] = {half_widths.dx, half_widths.dy, half_widths.dz, half_widths.dtheta};
  const double sigma[4] = {sigmas.dx, sigmas.dy, sigmas.dz, sigmas.dtheta};
  const char* const prefixes[4] = {"dx_", "dy_", "dz_", "dtheta_"};
  const char components[4] = {'x', 'y', 'z', 't'};
  for (int i = 0; i < 4; ++i)  // all checked first: a refused allocation adds nothing
    if (!std::isfinite(widths[i]) || widths[i] < 0)
      throw PlanError("uncertainty half-width of " + std::string(prefixes[i]) + std::string(tag) +
                      " must be finite and >= 0");
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(sigma[i]) || sigma[i] < 0)
      throw PlanError("sigma of " + std::string(prefixes[i]) + std::string(tag) +
                      " must be finite and >= 0");
  symbolic::Expr symbols[4];
  for (int i = 0; i < 4; ++i) {
    std::string name = prefixes[i] + std::string(tag);
    for (int suffix = 2; std::any_of(variables_.begin(), variables_.end(),
                                     [&](const SpaceVariable& v) { return v.name == name; });
         ++suffix)
      name = prefixes[i] + std::string(tag) + "_" + std::to_string(suffix);
    symbols[i] = pool_->variable(name);
    variables_.push_back({name, components[i], -widths[i], widths[i], sigma[i], provenance});
    symbols_.push_back(symbols[i]);
  }
  return {symbols[0], symbols[1], symbols[2], symbols[3]};
}

int UncertaintySpace::index_of(symbolic::Expr symbol) const {
  const auto found = std::find(symbols_.begin(), symbols_.end(), symbol);
  return found == symbols_.end() ? -1 : static_cast<int>(found - symbols_.begin());
}

void UncertaintySpace::set_range(int index, double lower, double upper) {
  if (!(std::isfinite(lower) && std::isfinite(upper) && lower <= upper))
    throw PlanError("uncertainty range of " + variables_.at(index).name +
                    " must be finite with "
                    "lower <= upper");
  variables_.at(index).lower = lower;
  variables_.at(index).upper = upper;
}

std::vector<bounds::Interval> UncertaintySpace::ranges(
    std::span<const symbolic::Expr> symbols) const {
  std::vector<bounds::Interval> box;
  box.reserve(symbols.size());
  for (const symbolic::Expr symbol : symbols) {
    const int index = index_of(symbol);
    if (index < 0) throw PlanError("internal: a variable outside the uncertainty space");
    box.push_back(bounds::Interval(variables_[index].lower, variables_[index].upper));
  }
  return box;
}

}  // namespace spar::planner
