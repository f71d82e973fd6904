#include "spar/reports/markdown.hpp"

#include <sstream>

#include "spar/reports/internal/cell_svg.hpp"
#include "spar/reports/internal/check.hpp"
#include "spar/reports/internal/text.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/sensing.hpp"

namespace spar::reports {
namespace {

using internal::cell_escape;
using internal::rounded;

std::string plural(std::size_t count, const char* noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

// Inserted steps as "#5 range-scan block, #6 range-scan peg".
std::string inserted_list(const Chosen& chosen) {
  std::string out;
  for (std::size_t k = 0; k < chosen.steps.size(); ++k)
    if (chosen.steps[k].inserted.value_or(false))
      out += (out.empty() ? "" : ", ") + step_label(chosen, k);
  return out;
}

std::string summary_lines(const Report& report) {
  std::ostringstream out;
  out << "plan " << report.scenario << ": " << report.status;
  if (!report.chosen) {
    out << " (" << report.reason.value_or("") << ")\n";
    return out.str();
  }
  const Chosen& chosen = *report.chosen;
  const std::string inserted = inserted_list(chosen);
  out << ", " << plural(chosen.steps.size(), "step")
      << (inserted.empty() ? "" : " (inserted by phase 2: " + inserted + ")") << '\n';
  const internal::VerdictCounts counts = internal::verdict_counts(report);
  out << "  preconditions: " << counts.total() << " decided, " << counts.satisfied << " satisfied, "
      << counts.violated << " violated, " << counts.undecided << " undecided\n";
  if (chosen.errors)
    out << "  errors: " << *chosen.errors
        << (*chosen.errors == 0 ? " (nothing to verify at execution)"
                                : " (verification and recovery posted)")
        << '\n';
  if (report.branches) {
    for (const Branch& branch : *report.branches)
      out << "  branch " << branch.outcome << ": " << branch.status << ", "
          << plural(branch.steps.size(), "step")
          << (branch.errors ? ", " + plural(static_cast<std::size_t>(*branch.errors), "error") : "")
          << '\n';
    return out.str();
  }
  out << "  instances: " << report.instances.count << " enumerated"
      << (report.instances.limit_reached ? " (limit reached)" : "") << ", "
      << report.instances.examined.size() << " examined, instance " << chosen.index + 1
      << " chosen\n";
  return out.str();
}

void markdown_plan(const Report& report, std::ostringstream& out) {
  const Chosen& chosen = *report.chosen;
  out << "\n## Chosen plan, in execution order\n\n"
      << "| step | details | preconditions |\n"
      << "|---|---|---|\n";
  for (std::size_t k = 0; k < chosen.steps.size(); ++k) {
    const Step& step = chosen.steps[k];
    const auto [holds, total] = internal::holding(step);
    out << "| " << step_label(chosen, k) << (step.inserted.value_or(false) ? " *(inserted)*" : "")
        << " | " << cell_escape(internal::step_details(report.units, step)) << " | "
        << (total == 0 ? std::string("none")
                       : std::to_string(holds) + "/" + std::to_string(total) + " hold")
        << (step.failed.value_or(false) ? " **(failed)**" : "") << " |\n";
  }
}

void markdown_preconditions(const Report& report, std::ostringstream& out) {
  out << "\n## Preconditions\n\n"
      << "Sound bounds [lo, hi] hold for every uncertainty value in the box; the inner bound is "
         "attained at witness points (the true range lies between the two). Lengths in "
      << report.units.length
      << "; exact values, expressions (SI) and witnesses are in the JSON report.\n\n"
      << "| step | precondition | verdict | requirement | bound | inner bound | holds up to |\n"
      << "|---|---|---|---|---|---|---|\n";
  const Chosen& chosen = *report.chosen;
  for (std::size_t k = 0; k < chosen.steps.size(); ++k) {
    const Step& step = chosen.steps[k];
    if (!step.preconditions) continue;
    for (const Precondition& precondition : *step.preconditions) {
      const std::string& verdict = precondition.verdict;
      out << "| " << step_label(chosen, k) << " | `" << cell_escape(precondition.name) << "` | "
          << (verdict == "satisfied" ? verdict : "**" + verdict + "**") << " | "
          << internal::requirement_text(precondition) << " | " << internal::bound_text(precondition)
          << " | " << internal::bound_text(precondition, true) << " | "
          << internal::margin_text(report.units, precondition) << " |\n";
    }
  }
}

void markdown_repairs(const Report& report, std::ostringstream& out) {
  out << "\n## Inserted sensing and squeeze\n\n";
  const Chosen& chosen = *report.chosen;
  if (!chosen.repairs || chosen.repairs->empty()) {
    out << "None tried: no precondition failed before repair.\n";
    return;
  }
  const std::vector<std::optional<std::size_t>> positions = internal::repair_positions(chosen);
  for (std::size_t r = 0; r < chosen.repairs->size(); ++r) {
    const Repair& repair = (*chosen.repairs)[r];
    if (!repair.helped) continue;  // the dropped ones: one line below
    out << "- " << internal::repair_title(chosen, repair, positions[r]) << ": kept\n";
    if (positions[r] && chosen.steps[*positions[r]].vision)
      out << "  - " << internal::vision_text(*chosen.steps[*positions[r]].vision)
          << "; the scene it expects is drawn in the HTML report\n";
    for (std::size_t i = 0; i < repair.before.size() && i < repair.after.size(); ++i) {
      const RepairBound &before = repair.before[i], &after = repair.after[i];
      if (before.verdict == "satisfied" && after.verdict == "satisfied")
        continue;  // unchanged and holding: not what the insertion was for
      out << "  - `" << before.name.value_or("precondition " + std::to_string(i + 1))
          << "`: " << internal::repair_bound_text(report.units, before) << " " << before.verdict
          << " -> " << internal::repair_bound_text(report.units, after) << " " << after.verdict
          << '\n';
    }
  }
  const std::string dropped = internal::dropped_repairs(chosen);
  if (!dropped.empty())
    out << "- Not kept (the search keeps the smallest set that does best): " << dropped << ".\n";
}

void markdown_verification(const Report& report, std::ostringstream& out) {
  out << "\n## Verification and recovery\n\n";
  bool any = false;
  const Chosen& chosen = *report.chosen;
  for (std::size_t k = 0; k < chosen.steps.size(); ++k) {
    const Step& step = chosen.steps[k];
    if (!step.verification) continue;
    any = true;
    out << "- " << step_label(chosen, k) << "\n";
    if (step.sensor_residual_needed)
      out << "  - " << internal::sensor_residual_text(report.units, *step.sensor_residual_needed)
          << '\n';
    for (const Verification& plan : *step.verification) {
      out << "  - verify: " << plan.sense << " (expect " << plan.expect << ")\n";
      if (plan.vision) {
        out << "    - " << internal::vision_text(*plan.vision) << '\n';
        if (plan.vision->view)
          out << "    - " << internal::vision_view_text(*plan.vision)
              << " (drawn in the HTML report)\n";
      }
      for (const Outcome& outcome : plan.outcomes)
        out << "    - if " << outcome.when << ": " << outcome.error << ", recover by "
            << outcome.recovery << '\n';
    }
    for (const Recovery& recovery : step.recovery.value_or(std::vector<Recovery>{})) {
      out << "  - recovery `" << recovery.plan << "` for " << recovery.error << ":";
      for (const std::string& action : recovery.steps) out << " " << action << ";";
      out << '\n';
    }
  }
  if (!any) out << "Every precondition of the chosen plan holds: nothing to verify at execution.\n";
}

// chosen.probability: σ and P(violation) per precondition, the tolerance allocation.
void markdown_probability(const Report& report, std::ostringstream& out) {
  const Probability& probability = *report.chosen->probability;
  const Jacobian& jacobian = probability.jacobian;
  out << "\n## Failure probability and tolerances\n\n"
      << "Beyond the worst case: each uncertainty variable is distributed in its box as the "
         "scenario says (uniform unless `distribution: gaussian`). σ is first order (J Σ Jᵀ; J is "
      << jacobian.rows << " × " << jacobian.cols << ", " << jacobian.nonzeros
      << " nonzeros); P first order is the "
         "linearised precondition's Gaussian truncated to the sound bound; "
      << internal::monte_carlo_points_text(probability)
      << " A proved precondition fails with probability 0.\n\n"
      << "P(some precondition fails) = " << internal::plan_probability_text(probability) << ".\n\n"
      << "| step | precondition | σ | P first order | P Monte Carlo | note |\n"
      << "|---|---|---|---|---|---|\n";
  for (const PreconditionProbability& entry : probability.preconditions) {
    out << "| " << step_label(*report.chosen, entry.step) << " | `" << cell_escape(entry.name)
        << "` | " << internal::sigma_text(report, entry) << " | "
        << internal::probability_text(entry.p_first_order, entry.proved) << " | "
        << internal::monte_carlo_text(entry.p_monte_carlo, entry.ci, entry.proved) << " | "
        << cell_escape(entry.note) << " |\n";
  }
  const Tolerances& tolerances = probability.tolerances;
  out << "\nTolerance allocation: " << internal::allocation_text(tolerances) << ".\n";
  if (tolerances.status == "not_needed") return;
  out << "\n| parameter | half-width | allocated | cost |\n|---|---|---|---|\n";
  for (const ToleranceParameter& parameter : tolerances.parameters) {
    const ToleranceDisplay& display = parameter.display;
    out << "| " << parameter.name << " | "
        << internal::tolerance_text(display.half_width, display.unit) << " | "
        << internal::tolerance_text(display.allocated, display.unit) << " | "
        << rounded(parameter.cost) << " |\n";
  }
}

// The cell's views, written beside the report as SVG files (write.hpp).
void markdown_cell(const Report& report, std::ostringstream& out) {
  out << "\n## The work cell\n\n"
      << "From above and from the front (lengths in " << report.units.length
      << "): the table, the robot's base and reach, the places, each object's outline (held: "
         "orange), the gripper, the box of positions the handled object may occupy (red) and "
         "inserted sensing (dashed rings).\n\n";
  for (std::size_t v = 0; v < report.cell->views.size(); ++v)
    out << "![" << report.cell->views[v].title << "](" << internal::cell_view_file(v) << ")\n";
}

void markdown_instances(const Report& report, std::ostringstream& out) {
  const Instances& instances = report.instances;
  out << "\n## Instances considered\n\n"
      << instances.count
      << (instances.count == 1 ? " plan instance enumerated" : " plan instances enumerated")
      << (instances.limit_reached ? " (the limit was reached: more exist)" : "")
      << "; phase 2 examines them in order until one has no error.\n\n"
      << "| instance | errors | steps | inserted | failed preconditions | |\n"
      << "|--:|--:|--:|--:|--:|---|\n";
  for (const ExaminedInstance& examined : instances.examined)
    out << "| " << examined.index + 1 << " | " << examined.errors << " | " << examined.steps
        << " | " << examined.inserted << " | " << examined.failed_preconditions << " / "
        << examined.preconditions << " | "
        << (report.chosen && report.chosen->index == examined.index ? "chosen" : "") << " |\n";
}

// One section per outcome of sensing: the branch's steps and preconditions, as a plan's.
void markdown_branches(const Report& report, std::ostringstream& out) {
  out << "\n## Branches: one plan per outcome of sensing\n";
  for (const Branch& branch : *report.branches) {
    out << "\n### Branch " << branch.outcome << " (" << branch.object << " is " << branch.outcome
        << "): " << branch.status << "\n";
    if (branch.steps.empty()) continue;
    const Report view = branch_as_plan(report, branch);
    markdown_plan(view, out);
    markdown_preconditions(view, out);
  }
}

std::string markdown(const Report& report) {
  std::ostringstream out;
  out << "# spar plan report: " << report.scenario << "\n\n";
  if (!report.description.empty()) out << report.description << "\n\n";
  out << "Report " << report.schema << "; lengths in " << report.units.length << ", angles in "
      << report.units.angle << ".\n\n```\n"
      << summary_lines(report) << "```\n";
  if (report.sensing) out << sensing_markdown(*report.sensing);
  if (!report.chosen) return out.str();
  markdown_plan(report, out);
  if (report.branches) {
    markdown_branches(report, out);
    return out.str();
  }
  if (report.cell) markdown_cell(report, out);
  markdown_preconditions(report, out);
  markdown_repairs(report, out);
  markdown_verification(report, out);
  if (report.chosen->probability) markdown_probability(report, out);
  markdown_instances(report, out);
  return out.str();
}

}  // namespace

std::string render_markdown(const Report& report) {
  return internal::guarded("Markdown", [&] { return markdown(report); });
}

std::string render_markdown(const nlohmann::ordered_json& report) {
  return internal::guarded("Markdown", [&] { return markdown(report_from_json(report)); });
}

std::string summary(const Report& report) {
  return internal::guarded("a summary", [&] { return summary_lines(report); });
}

}  // namespace spar::reports
