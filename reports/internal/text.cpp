#include "spar/reports/internal/text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace spar::reports::internal {

double value(const Json& number) {
  if (number.is_number()) return number.get<double>();
  if (number.is_string()) {
    const std::string& word = number.get_ref<const std::string&>();
    if (word == "inf") return HUGE_VAL;
    if (word == "-inf") return -HUGE_VAL;
  }
  return std::nan("");
}

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

std::string text(const Json& object, std::string_view key, std::string_view fallback) {
  const auto found = object.find(key);
  if (found == object.end() || !found->is_string()) return std::string(fallback);
  return found->get<std::string>();
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

double to_length_unit(const Json& report, double metres) {
  return metres / value(report.at("units").at("metres_per_length"));
}

double to_angle_unit(const Json& report, double radians) {
  return radians / value(report.at("units").at("radians_per_angle"));
}

std::string half_width_text(const Json& variable) {
  const Json& display = variable.at("display");
  const double lo = value(display.at("lo")), hi = value(display.at("hi"));
  const std::string unit = text(display, "unit");
  if (lo == -hi) return "±" + rounded(hi) + " " + unit;
  return "[" + rounded(lo) + ", " + rounded(hi) + "] " + unit;
}

const Json* step_by_id(const Json& report, int id) {
  const Json& chosen = report.at("chosen");
  if (!chosen.is_object()) return nullptr;
  for (const Json& step : chosen.at("steps"))
    if (step.at("id") == id) return &step;
  return nullptr;
}

std::string step_title(const Json& step) {
  std::string title = text(step, "action") + " " + text(step, "object");
  if (step.contains("fixed_object")) title += " into " + text(step, "fixed_object");
  return title;
}

namespace {

std::string unit_suffix(const std::string& unit) {
  if (unit == "1") return " (cosine)";
  return unit.empty() ? "" : " " + unit;
}

}  // namespace

std::string step_details(const Json& report, const Json& step) {
  const std::string length = report.at("units").at("length").get<std::string>();
  std::string out;
  const auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
  if (step.contains("grasp")) {
    const Json& grasp = step.at("grasp");
    add("grasp " + text(grasp, "label") + " (faces " + grasp.at("faces").at(0).dump() + "/" +
        grasp.at("faces").at(1).dump() + ", width " + rounded(value(grasp.at("width"))) + " " +
        length + ")");
  }
  const auto position = [&](const Json& pose) {
    return "(" + fixed(value(pose.at(0).at(3))) + ", " + fixed(value(pose.at(1).at(3))) + ", " +
           fixed(value(pose.at(2).at(3))) + ") " + length;
  };
  if (step.contains("fixed_object")) {
    add(text(step, "fixed_object") + " at " + position(step.at("fixed_pose")));
    add(text(step, "object") + " to " + position(step.at("held_pose")));
  } else if (step.contains("object_pose")) {
    add(std::string(text(step, "action") == "putdown" ? "to " : "at ") +
        position(step.at("object_pose")));
  }
  if (step.contains("stable_pose") && step.at("stable_pose").is_string())
    add("stable pose " + text(step, "stable_pose"));
  if (step.contains("configuration") && step.at("configuration").is_string())
    add("arm " + text(step, "configuration"));
  return out;
}

std::string requirement_text(const Json& precondition) {
  const Json& display = precondition.at("display");
  return text(precondition, "relation") + " " + rounded(value(display.at("threshold")), 6) +
         unit_suffix(text(display, "unit"));
}

std::string bound_text(const Json& precondition, bool inner) {
  const Json& display = precondition.at("display");
  const double lo = value(display.at(inner ? "inner_lo" : "lo"));
  const double hi = value(display.at(inner ? "inner_hi" : "hi"));
  return "[" + rounded(lo) + ", " + rounded(hi) + "]" + unit_suffix(text(display, "unit"));
}

std::string margin_text(const Json& report, const Json& precondition) {
  if (!precondition.contains("holds_up_to_scale")) return "";
  const Json& margin = precondition.at("margin");
  const Json& units = report.at("units");
  // A component the precondition does not depend on (no such variable scaled) is left out:
  // "±0 deg" would read as "no rotation allowed".
  std::vector<std::string> parts;
  for (const auto& [key, unit] : {std::pair{"displacement", "length"}, {"rotation", "angle"}}) {
    const double half_width = value(margin.at(key));
    if (half_width > 0) parts.push_back("±" + rounded(half_width, 2) + " " + text(units, unit));
  }
  std::string out = "x" + rounded(value(precondition.at("holds_up_to_scale")), 2);
  for (std::size_t i = 0; i < parts.size(); ++i) out.append(i == 0 ? " (" : ", ").append(parts[i]);
  if (!parts.empty()) out.append(")");
  return out;
}

std::string repair_bound_text(const Json& report, const Json& entry) {
  const bool length = entry.at("unit") == "m";
  const auto shown = [&](const char* key) {
    const double v = value(entry.at(key));
    return rounded(length ? to_length_unit(report, v) : v);
  };
  return "[" + shown("lo") + ", " + shown("hi") + "]" +
         (length ? " " + report.at("units").at("length").get<std::string>() : std::string());
}

std::string sensor_residual_text(const Json& report, const Json& needed) {
  const Json& units = report.at("units");
  const double largest =
      std::max({value(needed.at("dx")), value(needed.at("dy")), value(needed.at("dz"))});
  return "a range-scan with a residual of ±" + rounded(largest, 2) + " " + text(units, "length") +
         ", ±" + rounded(value(needed.at("dtheta")), 2) + " " + text(units, "angle") + " (x" +
         rounded(value(needed.at("scale")), 2) +
         " of the scenario's sensor) would make this step hold";
}

VerdictCounts verdict_counts(const Json& report) {
  VerdictCounts counts;
  const Json& chosen = report.at("chosen");
  if (!chosen.is_object()) return counts;
  for (const Json& step : chosen.at("steps"))
    for (const Json& precondition : step.value("preconditions", Json::array())) {
      const std::string verdict = text(precondition, "verdict");
      (verdict == "satisfied"  ? counts.satisfied
       : verdict == "violated" ? counts.violated
                               : counts.undecided)++;
    }
  return counts;
}

// ---- chosen.probability (issue 15) ----

const Json& probability_precondition(const Json& report, const Json& entry) {
  return report.at("chosen")
      .at("steps")
      .at(entry.at("step").get<std::size_t>())
      .at("preconditions")
      .at(entry.at("index").get<std::size_t>());
}

double precondition_display(const Json& report, const Json& entry, double si) {
  return text(probability_precondition(report, entry), "unit") == "m" ? to_length_unit(report, si)
                                                                      : si;
}

std::string sigma_text(const Json& report, const Json& entry) {
  const bool length = text(probability_precondition(report, entry), "unit") == "m";
  return "σ " + rounded(precondition_display(report, entry, value(entry.at("sigma")))) +
         (length ? " " + report.at("units").at("length").get<std::string>() : std::string());
}

std::string probability_text(double probability, bool proved) {
  if (proved) return "0 (proved)";
  if (probability == 0) return "0";
  return rounded(100 * probability) + "%";
}

std::string monte_carlo_text(const Json& entry, bool proved) {
  const Json& ci = entry.at("ci");
  return probability_text(value(entry.at("p_monte_carlo")), proved) + " [" +
         probability_text(value(ci.at(0)), false) + ", " +
         probability_text(value(ci.at(1)), false) + "]";
}

std::string allocation_text(const Json& tolerances) {
  const std::string status = text(tolerances, "status");
  if (status == "not_needed")
    return "not needed: every precondition is proved over the scenario's box";
  if (status == "infeasible")
    return "infeasible: some precondition fails at the nominal point, whatever the tolerances";
  const std::string rounds = std::to_string(tolerances.at("rounds").get<int>());
  return (status == "proved" ? "proved by the sound bounds"
                             : "NOT proved by the sound bounds (see the misses)") +
         std::string(" after ") + rounds + " round" + (rounds == "1" ? "" : "s") + ", cost " +
         rounded(value(tolerances.at("cost")));
}

}  // namespace spar::reports::internal
