#include "spar/reports/markdown.hpp"

#include <sstream>

#include "spar/reports/internal/check.hpp"
#include "spar/reports/internal/text.hpp"

namespace spar::reports {
namespace {

using internal::Json;
using internal::rounded;
using internal::text;
using internal::value;

std::string plural(std::size_t count, const char* noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

// Inserted steps as "range-scan block, range-scan peg".
std::string inserted_list(const Json& steps) {
  std::string out;
  for (const Json& step : steps)
    if (step.value("inserted", false))
      out += (out.empty() ? "" : ", ") + internal::step_title(step);
  return out;
}

std::string summary_lines(const Json& report) {
  std::ostringstream out;
  const Json& chosen = report.at("chosen");
  const Json& instances = report.at("instances");
  out << "plan " << text(report, "scenario") << ": " << text(report, "status");
  if (!chosen.is_object()) {
    out << " (" << text(report, "reason") << ")\n";
    return out.str();
  }
  const Json& steps = chosen.at("steps");
  const std::string inserted = inserted_list(steps);
  out << ", " << plural(steps.size(), "step")
      << (inserted.empty() ? "" : " (inserted by phase 2: " + inserted + ")") << '\n';
  const internal::VerdictCounts counts = internal::verdict_counts(report);
  out << "  preconditions: " << counts.total() << " decided, " << counts.satisfied << " satisfied, "
      << counts.violated << " violated, " << counts.undecided << " undecided\n";
  if (chosen.contains("errors"))
    out << "  errors: " << chosen.at("errors").get<int>()
        << (chosen.at("errors").get<int>() == 0 ? " (nothing to verify at execution)"
                                                : " (verification and recovery posted)")
        << '\n';
  out << "  instances: " << instances.at("count").get<std::size_t>() << " enumerated"
      << (instances.at("limit_reached").get<bool>() ? " (limit reached)" : "") << ", "
      << instances.at("examined").size() << " examined, chosen #"
      << chosen.at("index").get<std::size_t>() + 1 << '\n';
  return out.str();
}

void plan_section(const Json& report, std::ostringstream& out) {
  out << "\n## Chosen plan, in execution order\n\n"
      << "| # | step | action | details | preconditions |\n"
      << "|--:|--:|---|---|---|\n";
  int number = 0;
  for (const Json& step : report.at("chosen").at("steps")) {
    int holding = 0, total = 0;
    for (const Json& precondition : step.value("preconditions", Json::array())) {
      ++total;
      holding += precondition.at("verdict") == "satisfied" ? 1 : 0;
    }
    out << "| " << ++number << " | " << step.at("id").get<int>() << " | "
        << internal::step_title(step) << (step.value("inserted", false) ? " *(inserted)*" : "")
        << " | " << internal::cell_escape(internal::step_details(report, step)) << " | "
        << (total == 0 ? std::string("none")
                       : std::to_string(holding) + "/" + std::to_string(total) + " hold")
        << (step.value("failed", false) ? " **(failed)**" : "") << " |\n";
  }
}

void preconditions_section(const Json& report, std::ostringstream& out) {
  out << "\n## Preconditions\n\n"
      << "Sound bounds [lo, hi] hold for every uncertainty value in the box; the inner bound is "
         "attained at witness points (the true range lies between the two). Lengths in "
      << text(report.at("units"), "length")
      << "; exact values, expressions (SI) and witnesses are in the JSON report.\n\n"
      << "| # step | precondition | verdict | requirement | bound | inner bound | holds up to |\n"
      << "|---|---|---|---|---|---|---|\n";
  int number = 0;  // execution position, as in the plan table
  for (const Json& step : report.at("chosen").at("steps")) {
    ++number;
    for (const Json& precondition : step.value("preconditions", Json::array())) {
      const std::string verdict = text(precondition, "verdict");
      out << "| " << number << ". " << internal::step_title(step) << " | `"
          << internal::cell_escape(text(precondition, "name")) << "` | "
          << (verdict == "satisfied" ? verdict : "**" + verdict + "**") << " | "
          << internal::requirement_text(precondition) << " | " << internal::bound_text(precondition)
          << " | " << internal::bound_text(precondition, true) << " | "
          << internal::margin_text(report, precondition) << " |\n";
    }
  }
}

void repairs_section(const Json& report, std::ostringstream& out) {
  out << "\n## Inserted sensing and squeeze\n\n";
  const Json& repairs = report.at("chosen").value("repairs", Json::array());
  if (repairs.empty()) {
    out << "None tried: no precondition failed before repair.\n";
    return;
  }
  for (const Json& repair : repairs) {
    const Json* target = internal::step_by_id(report, repair.at("for_step").get<int>());
    out << "- " << text(repair, "action") << " " << text(repair, "object") << " for step "
        << repair.at("for_step").get<int>()
        << (target != nullptr ? " (" + internal::step_title(*target) + ")" : "") << ": "
        << (repair.at("helped").get<bool>() ? "kept" : "did not help, dropped") << '\n';
    const Json& before = repair.at("before");
    const Json& after = repair.at("after");
    for (std::size_t i = 0; i < before.size() && i < after.size(); ++i) {
      if (before[i].at("verdict") == "satisfied" && after[i].at("verdict") == "satisfied")
        continue;  // unchanged and holding: not what the insertion was for
      out << "  - `" << text(before[i], "name", "precondition " + std::to_string(i + 1))
          << "`: " << internal::repair_bound_text(report, before[i]) << " "
          << text(before[i], "verdict") << " -> " << internal::repair_bound_text(report, after[i])
          << " " << text(after[i], "verdict") << '\n';
    }
  }
}

void verification_section(const Json& report, std::ostringstream& out) {
  out << "\n## Verification and recovery\n\n";
  bool any = false;
  for (const Json& step : report.at("chosen").at("steps")) {
    if (!step.contains("verification")) continue;
    any = true;
    out << "- step " << step.at("id").get<int>() << " (" << internal::step_title(step) << ")\n";
    if (step.contains("sensor_residual_needed"))
      out << "  - " << internal::sensor_residual_text(report, step.at("sensor_residual_needed"))
          << '\n';
    for (const Json& plan : step.at("verification")) {
      out << "  - verify: " << text(plan, "sense") << " (expect " << text(plan, "expect") << ")\n";
      for (const Json& outcome : plan.at("outcomes"))
        out << "    - if " << text(outcome, "when") << ": " << text(outcome, "error")
            << ", recover by " << text(outcome, "recovery") << '\n';
    }
    for (const Json& recovery : step.value("recovery", Json::array())) {
      out << "  - recovery `" << text(recovery, "plan") << "` for " << text(recovery, "error")
          << ":";
      for (const Json& action : recovery.at("steps"))
        out << " " << action.get<std::string>() << ";";
      out << '\n';
    }
  }
  if (!any) out << "Every precondition of the chosen plan holds: nothing to verify at execution.\n";
}

// chosen.probability (issue 15): σ and P(violation) per precondition, the tolerance allocation.
void probability_section(const Json& report, std::ostringstream& out) {
  const Json& probability = report.at("chosen").at("probability");
  const Json& jacobian = probability.at("jacobian");
  out << "\n## Failure probability and tolerances\n\n"
      << "Beyond the worst case: each uncertainty variable is distributed in its box as the "
         "scenario says (uniform unless `distribution: gaussian`). σ is first order (J Σ Jᵀ; J is "
      << jacobian.at("rows").get<std::size_t>() << " × " << jacobian.at("cols").get<std::size_t>()
      << ", " << jacobian.at("nonzeros").get<std::size_t>()
      << " nonzeros); P first order is the "
         "linearised precondition's Gaussian truncated to the sound bound; Monte Carlo draws "
      << probability.at("samples").get<std::size_t>()
      << " points (95% Wilson interval). A proved precondition fails with probability 0.\n\n"
      << "P(some precondition fails) = "
      << internal::monte_carlo_text(probability.at("plan"), false) << " (Monte Carlo).\n\n"
      << "| step | precondition | σ | P first order | P Monte Carlo | note |\n"
      << "|---|---|---|---|---|---|\n";
  for (const Json& entry : probability.at("preconditions")) {
    const Json& step = report.at("chosen").at("steps").at(entry.at("step").get<std::size_t>());
    const bool proved = entry.at("proved").get<bool>();
    out << "| " << step.at("id").get<int>() << " " << internal::step_title(step) << " | `"
        << internal::cell_escape(text(entry, "name")) << "` | "
        << internal::sigma_text(report, entry) << " | "
        << internal::probability_text(value(entry.at("p_first_order")), proved) << " | "
        << internal::monte_carlo_text(entry, proved) << " | "
        << internal::cell_escape(text(entry, "note")) << " |\n";
  }
  const Json& tolerances = probability.at("tolerances");
  out << "\nTolerance allocation: " << internal::allocation_text(tolerances) << ".\n";
  if (text(tolerances, "status") == "not_needed") return;
  out << "\n| parameter | half-width | allocated | cost |\n|---|---|---|---|\n";
  for (const Json& parameter : tolerances.at("parameters")) {
    const Json& display = parameter.at("display");
    out << "| " << text(parameter, "name") << " | " << rounded(value(display.at("half_width")))
        << " " << text(display, "unit") << " | " << rounded(value(display.at("allocated"))) << " "
        << text(display, "unit") << " | " << rounded(value(parameter.at("cost"))) << " |\n";
  }
}

void instances_section(const Json& report, std::ostringstream& out) {
  const Json& instances = report.at("instances");
  out << "\n## Instances considered\n\n"
      << instances.at("count").get<std::size_t>()
      << (instances.at("count") == 1 ? " plan instance enumerated" : " plan instances enumerated")
      << (instances.at("limit_reached").get<bool>() ? " (the limit was reached: more exist)" : "")
      << "; phase 2 examines them in order until one has no error.\n\n"
      << "| instance | errors | steps | inserted | failed preconditions | |\n"
      << "|--:|--:|--:|--:|--:|---|\n";
  const Json& chosen = report.at("chosen");
  for (const Json& examined : instances.at("examined")) {
    const std::size_t index = examined.at("index").get<std::size_t>();
    out << "| #" << index + 1 << " | " << examined.at("errors").get<int>() << " | "
        << examined.at("steps").get<std::size_t>() << " | "
        << examined.at("inserted").get<std::size_t>() << " | "
        << examined.at("failed_preconditions").get<std::size_t>() << " / "
        << examined.at("preconditions").get<std::size_t>() << " | "
        << (chosen.is_object() && chosen.at("index") == index ? "chosen" : "") << " |\n";
  }
}

std::string markdown(const Json& report) {
  std::ostringstream out;
  const Json& units = report.at("units");
  out << "# spar plan report: " << text(report, "scenario") << "\n\n";
  if (!text(report, "description").empty()) out << text(report, "description") << "\n\n";
  out << "Report " << text(report, "schema") << "; lengths in " << text(units, "length")
      << ", angles in " << text(units, "angle") << ".\n\n```\n"
      << summary_lines(report) << "```\n";
  if (!report.at("chosen").is_object()) return out.str();
  plan_section(report, out);
  preconditions_section(report, out);
  repairs_section(report, out);
  verification_section(report, out);
  if (report.at("chosen").contains("probability")) probability_section(report, out);
  instances_section(report, out);
  return out.str();
}

}  // namespace

std::string render_markdown(const nlohmann::ordered_json& report) {
  return internal::guarded("Markdown", report, [&] { return markdown(report); });
}

std::string summary(const nlohmann::ordered_json& report) {
  return internal::guarded("a summary", report, [&] { return summary_lines(report); });
}

}  // namespace spar::reports
