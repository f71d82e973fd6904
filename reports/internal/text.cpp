#include "spar/reports/internal/text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace spar::reports::internal {

std::string fixed(double value, int decimals) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[400];  // DBL_MAX has 309 integer digits; decimals are at most 15
  std::snprintf(buffer, sizeof buffer, "%.*f", std::clamp(decimals, 0, 15), value);
  std::string out = buffer;
  if (out.find('.') != std::string::npos) {
    out.erase(out.find_last_not_of('0') + 1);
    if (out.back() == '.') out.pop_back();
  }
  return out == "-0" ? "0" : out;
}

std::string rounded(double value, int digits) {
  if (!std::isfinite(value) || value == 0.0) return fixed(value, 0);
  // Decimals so that `digits` significant digits show; none for large values, and from 1e7 on
  // scientific notation (fixed notation would print up to 309 digits).
  const int magnitude = static_cast<int>(std::floor(std::log10(std::fabs(value))));
  if (magnitude >= 7) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.*g", std::max(digits, 1), value);
    return buffer;
  }
  return fixed(value, std::clamp(digits - 1 - magnitude, 0, 15));
}

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string cell_escape(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

double to_length_unit(const Units& units, double metres) {
  return metres / units.metres_per_length;
}

double to_angle_unit(const Units& units, double radians) {
  return radians / units.radians_per_angle;
}

std::string half_width_text(const UncertaintyVariable& variable) {
  const RangeDisplay& display = variable.display;
  if (display.lo == -display.hi) return "±" + rounded(display.hi) + " " + display.unit;
  return "[" + rounded(display.lo) + ", " + rounded(display.hi) + "] " + display.unit;
}

std::string step_title(const Step& step) {
  std::string title = step.action + " " + step.object.value_or("");
  if (step.fixed_object) title += " into " + *step.fixed_object;
  return title;
}

std::string family_step_label(const Report& report, const FamilyStep& step) {
  if (step.action == "start") return "initial state";
  if (step.action == "finish") return "goal";
  if (report.chosen)
    if (const auto position = step_position(*report.chosen, step.id))
      return step_label(*report.chosen, *position);
  return "step " + std::to_string(step.id);
}

std::string variable_users(const Report& report, const std::string& name) {
  std::string out;
  for (const FamilyStep& step : report.family.steps)
    if (std::find(step.args.begin(), step.args.end(), name) != step.args.end())
      out += (out.empty() ? "" : ", ") + family_step_label(report, step);
  return out;
}

std::string allocated_by(const Chosen& chosen, const UncertaintyVariable& variable) {
  if (!variable.step || *variable.step < 1 || std::size_t(*variable.step) > chosen.steps.size())
    return "initial";
  return step_label(chosen, std::size_t(*variable.step) - 1);
}

std::vector<std::optional<std::size_t>> repair_positions(const Chosen& chosen) {
  std::vector<std::optional<std::size_t>> out;
  std::vector<bool> used(chosen.steps.size(), false);
  for (const Repair& repair : chosen.repairs.value_or(std::vector<Repair>{})) {
    std::optional<std::size_t>& position = out.emplace_back();
    if (!repair.helped) continue;
    for (std::size_t k = 0; k < chosen.steps.size() && !position; ++k) {
      const Step& step = chosen.steps[k];
      if (!used[k] && step.inserted.value_or(false) && step.action == repair.action &&
          step.object.value_or("") == repair.object)
        used[k] = true, position = k;
    }
  }
  return out;
}

namespace {

// "for #8 assemble peg": the step a repair was tried for.
std::string repair_target(const Chosen& chosen, const Repair& repair) {
  const auto target = step_position(chosen, repair.for_step);
  return "for " +
         (target ? step_label(chosen, *target) : "step " + std::to_string(repair.for_step));
}

}  // namespace

std::string repair_title(const Chosen& chosen, const Repair& repair,
                         std::optional<std::size_t> position) {
  if (position) {
    std::string title = step_label(chosen, *position) + ", " + repair_target(chosen, repair);
    // A reading that corrects only some components says which (the others are known better).
    const std::optional<std::vector<std::string>>& corrects = chosen.steps[*position].corrects;
    if (corrects && corrects->size() < 4) {
      std::string list;
      for (const std::string& component : *corrects) list += (list.empty() ? "" : ", ") + component;
      title += list.empty() ? " (corrects nothing)" : " (corrects " + list + " only)";
    }
    return title;
  }
  return repair.action + " " + repair.object + " " + repair_target(chosen, repair);
}

std::string dropped_repairs(const Chosen& chosen) {
  std::string out;
  for (const RepairSearch& search : chosen.repair_searches.value_or(std::vector<RepairSearch>{})) {
    std::string kinds;
    for (const auto& [kind, count] : search.dropped)
      if (count > 0) kinds += (kinds.empty() ? "" : " and ") + std::to_string(count) + " " + kind;
    if (kinds.empty()) continue;
    const auto target = step_position(chosen, search.for_step);
    out += (out.empty() ? "" : "; ") + kinds + " for " +
           (target ? step_label(chosen, *target) : "step " + std::to_string(search.for_step)) +
           " (" + std::to_string(search.sets_tried) + " sets of " +
           std::to_string(search.candidates) + " candidates tried)";
  }
  return out;
}

namespace {

std::string unit_suffix(const std::string& unit) {
  if (unit == "1") return " (cosine)";
  return unit.empty() ? "" : " " + unit;
}

}  // namespace

std::string step_details(const Units& units, const Step& step) {
  const std::string& length = units.length;
  std::string out;
  const auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
  if (step.grasp) {
    const Grasp& grasp = *step.grasp;
    add("grasp " + grasp.label + " (faces " + std::to_string(grasp.faces[0]) + "/" +
        std::to_string(grasp.faces[1]) + ", width " + rounded(grasp.width) + " " + length + ")");
  }
  const auto position = [&](const Matrix& pose) {
    return "(" + fixed(pose[0][3]) + ", " + fixed(pose[1][3]) + ", " + fixed(pose[2][3]) + ") " +
           length;
  };
  if (step.fixed_object) {
    add(*step.fixed_object + " at " + position(*step.fixed_pose));
    add(step.object.value_or("") + " to " + position(*step.held_pose));
  } else if (step.object_pose) {
    add(std::string(step.action == "putdown" ? "to " : "at ") + position(*step.object_pose));
  }
  if (step.stable_pose && *step.stable_pose) add("stable pose " + **step.stable_pose);
  if (step.configuration && *step.configuration) add("arm " + **step.configuration);
  if (step.sensing)
    add(step.sensing->sensor + " at " + step.sensing->viewpoint + " (aspect " +
        (step.sensing->aspect.empty() ? "-" : step.sensing->aspect) + "), at most " +
        rounded(step.sensing->predicted_max_ambiguity) + " bits left");
  if (step.vision)
    add("camera " + step.vision->camera + " sees " + std::to_string(step.vision->edges.size()) +
        " of its edges");
  return out;
}

std::string requirement_text(const Precondition& precondition) {
  return precondition.relation + " " + rounded(precondition.display.threshold, 6) +
         unit_suffix(precondition.display.unit);
}

std::string bound_text(const Precondition& precondition, bool inner) {
  const DisplayBounds& display = precondition.display;
  if (inner && !display.inner_lo)
    return "none (" + precondition.no_inner_range.value_or("no witness") + ")";
  const double lo = inner ? *display.inner_lo : display.lo;
  const double hi = inner ? *display.inner_hi : display.hi;
  return "[" + rounded(lo) + ", " + rounded(hi) + "]" + unit_suffix(display.unit);
}

std::string margin_text(const Units& units, const Precondition& precondition) {
  if (!precondition.holds_up_to_scale) return "";
  const Margin& margin = *precondition.margin;
  // A component the precondition does not depend on (no such variable scaled) is left out:
  // "±0 deg" would read as "no rotation allowed".
  std::vector<std::string> parts;
  if (margin.displacement > 0)
    parts.push_back("±" + rounded(margin.displacement, 2) + " " + units.length);
  if (margin.rotation > 0) parts.push_back("±" + rounded(margin.rotation, 2) + " " + units.angle);
  std::string out = "x" + rounded(*precondition.holds_up_to_scale, 2);
  if (precondition.holds_up_to_capped.value_or(false)) out = "≥ " + out + ", search cap";
  for (std::size_t i = 0; i < parts.size(); ++i) out.append(i == 0 ? " (" : ", ").append(parts[i]);
  if (!parts.empty()) out.append(")");
  return out;
}

std::string repair_bound_text(const Units& units, const RepairBound& entry) {
  const bool length = entry.unit && *entry.unit == "m";
  const auto shown = [&](double v) { return rounded(length ? to_length_unit(units, v) : v); };
  return "[" + shown(entry.lo) + ", " + shown(entry.hi) + "]" +
         (length ? " " + units.length : std::string());
}

std::string sensor_residual_text(const Units& units, const SensorResidual& needed) {
  const double largest = std::max({needed.dx, needed.dy, needed.dz});
  return "a range-scan with a residual of ±" + rounded(largest, 2) + " " + units.length + ", ±" +
         rounded(needed.dtheta, 2) + " " + units.angle + " (x" + rounded(needed.scale, 2) +
         (needed.capped ? " of the scenario's sensor, the search cap, or coarser"
                        : " of the scenario's sensor") +
         ") would make this step hold";
}

std::string vision_text(const VisionCheck& vision) {
  std::string edges;
  for (const std::string& edge : vision.edges) edges += (edges.empty() ? "" : ", ") + edge;
  return "camera " + vision.camera + " must see " + edges +
         " (PSEIKI accepts at scene belief >= " + rounded(vision.acceptance, 2) + ")";
}

std::string vision_view_text(const VisionCheck& vision) {
  const VisionView& view = *vision.view;
  std::size_t own = 0;
  for (const VisionViewEdge& edge : view.edges) own += edge.object == vision.object;
  return "the expected scene as camera " + vision.camera + " renders it at this step, " +
         std::to_string(view.width) + " x " + std::to_string(view.height) +
         " px: " + std::to_string(own) + " edges of " + vision.object + ", " +
         std::to_string(view.edges.size() - own) +
         " of the other objects and the gripper, which hide what lies behind them";
}

std::pair<int, int> holding(const Step& step) {
  int holds = 0, total = 0;
  if (step.preconditions)
    for (const Precondition& precondition : *step.preconditions) {
      ++total;
      holds += precondition.verdict == "satisfied" ? 1 : 0;
    }
  return {holds, total};
}

VerdictCounts verdict_counts(const Report& report) {
  VerdictCounts counts;
  if (!report.chosen) return counts;
  for (const Step& step : report.chosen->steps)
    if (step.preconditions)
      for (const Precondition& precondition : *step.preconditions) {
        const std::string& verdict = precondition.verdict;
        (verdict == "satisfied"  ? counts.satisfied
         : verdict == "violated" ? counts.violated
                                 : counts.undecided)++;
      }
  return counts;
}

// ---- chosen.probability ----

const Precondition& probability_precondition(const Chosen& chosen,
                                             const PreconditionProbability& entry) {
  return chosen.steps.at(entry.step).preconditions.value().at(entry.index);
}

double precondition_display(const Report& report, const PreconditionProbability& entry, double si) {
  return probability_precondition(*report.chosen, entry).unit == "m"
             ? to_length_unit(report.units, si)
             : si;
}

std::string sigma_text(const Report& report, const PreconditionProbability& entry) {
  const bool length = probability_precondition(*report.chosen, entry).unit == "m";
  return "σ " + rounded(precondition_display(report, entry, entry.sigma)) +
         (length ? " " + report.units.length : std::string());
}

std::string tolerance_text(double half_width, const std::string& unit) {
  if (half_width == 0) return "must be exact";
  return rounded(half_width) + " " + unit;
}

std::string probability_text(double probability, bool proved) {
  if (proved) return "0 (proved)";
  if (probability == 0) return "0";
  return rounded(100 * probability) + "%";
}

std::string monte_carlo_text(double p, const std::array<double, 2>& ci, bool proved) {
  return probability_text(p, proved) + " [" + probability_text(ci[0], false) + ", " +
         probability_text(ci[1], false) + "]";
}

std::string plan_probability_text(const Probability& probability) {
  const auto& rows = probability.preconditions;
  const bool all_proved = !rows.empty() && std::all_of(rows.begin(), rows.end(),
                                                       [](const auto& row) { return row.proved; });
  if (all_proved && probability.plan.p_monte_carlo == 0)
    return "0 (every precondition proved; none of the " + std::to_string(probability.samples) +
           " Monte Carlo points violates one)";
  return monte_carlo_text(probability.plan.p_monte_carlo, probability.plan.ci, false) +
         " (Monte Carlo)";
}

std::string monte_carlo_points_text(const Probability& probability) {
  const std::string out =
      "Monte Carlo draws " + std::to_string(probability.samples) + " points (95% Wilson interval";
  for (const auto& row : probability.preconditions)
    if (row.proved && row.samples && *row.samples < probability.samples)
      return out + "; a proved precondition is checked on the first " +
             std::to_string(*row.samples) + " of them).";
  return out + ").";
}

std::string allocation_text(const Tolerances& tolerances) {
  const std::string& status = tolerances.status;
  if (status == "not_needed")
    return "not needed: every precondition is proved over the scenario's box";
  if (status == "infeasible")
    return "infeasible: some precondition fails at the nominal point, whatever the tolerances";
  const std::string rounds = std::to_string(tolerances.rounds);
  return (status == "proved" ? "proved by the sound bounds"
                             : "NOT proved by the sound bounds (see the misses)") +
         std::string(" after ") + rounds + " round" + (rounds == "1" ? "" : "s") + ", cost " +
         rounded(tolerances.cost);
}

}  // namespace spar::reports::internal
