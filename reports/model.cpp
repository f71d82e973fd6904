#include "spar/reports/model.hpp"

namespace spar::reports {

Report branch_as_plan(const Report& report, const Branch& branch) {
  Report view = report;
  view.branches.reset();
  Chosen& chosen = view.chosen.emplace();
  chosen.steps = branch.steps;
  chosen.errors = branch.errors;
  return view;
}

std::string step_label(const Chosen& chosen, std::size_t position) {
  const Step& step = chosen.steps.at(position);
  std::string label = "#" + std::to_string(position + 1) + " " + step.action;
  if (step.object) label += " " + *step.object;
  return label;
}

std::optional<std::size_t> step_position(const Chosen& chosen, int id) {
  for (std::size_t i = 0; i < chosen.steps.size(); ++i)
    if (chosen.steps[i].id == id) return i;
  return std::nullopt;
}

}  // namespace spar::reports
