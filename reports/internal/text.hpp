// Reading a report's JSON and formatting its values for people (reports/ only).
//
// Numbers in a report are JSON numbers or the strings "inf", "-inf" and "nan" (json_values.hpp);
// value() reads either. Rounding is for reading only: rounded() keeps `digits` significant digits
// (never fewer than the integer part needs) and drops trailing zeros, so 0.0023999 -> "0.0024".
//
// Example:
//   const double hi = value(step["preconditions"][0]["hi"]);        // inf for "inf"
//   std::string text = rounded(hi * 39.37) + " in";                  // "0.047 in"
//   out << html_escape(step["action"].get<std::string>());
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace spar::reports::internal {

using Json = nlohmann::ordered_json;

// A report number: a JSON number, or "inf", "-inf", "nan"; NaN for anything else (null).
[[nodiscard]] double value(const Json& number);
// `value` rounded to `digits` significant digits for reading ("inf", "-inf", "nan" as words).
[[nodiscard]] std::string rounded(double value, int digits = 3);
// `value` with at most `decimals` decimals, trailing zeros dropped: 3e-15 -> "0", 12.4 -> "12.4".
[[nodiscard]] std::string fixed(double value, int decimals = 3);
// A string member, or `fallback` when it is absent or null.
[[nodiscard]] std::string text(const Json& object, std::string_view key,
                               std::string_view fallback = "");
// Escapes & < > " ' for HTML text and attribute values.
[[nodiscard]] std::string html_escape(std::string_view text);
// Escapes | and newlines for a Markdown table cell.
[[nodiscard]] std::string cell_escape(std::string_view text);
// A length in the report's length unit: SI metres times 1 / units.metres_per_length.
[[nodiscard]] double to_length_unit(const Json& report, double metres);
// An angle in the report's angle unit.
[[nodiscard]] double to_angle_unit(const Json& report, double radians);
// "+-0.11 in" for a variable of report["chosen"]["uncertainty_variables"].
[[nodiscard]] std::string half_width_text(const Json& variable);
// The step of report["chosen"]["steps"] with this id, or nullptr.
[[nodiscard]] const Json* step_by_id(const Json& report, int id);
// "pickup block" / "assemble peg into block": what a chosen step does, in words.
[[nodiscard]] std::string step_title(const Json& step);

// "grasp G4 (faces 3/5, width 3 in), object at (20, 0, 1.5) in, stable pose P6, arm lun".
[[nodiscard]] std::string step_details(const Json& report, const Json& step);
// A precondition's requirement in display units: "< 0 in", ">= 0.999 (cosine)".
[[nodiscard]] std::string requirement_text(const Json& precondition);
// "[lo, hi] unit" from a precondition's display values (`inner` picks inner_lo, inner_hi).
[[nodiscard]] std::string bound_text(const Json& precondition, bool inner = false);
// The reverse-analysis margin: "x2.3 (+-0.25 in, +-13 deg)", or "" when not computed.
[[nodiscard]] std::string margin_text(const Json& report, const Json& precondition);
// "+-0.25 in" range of a repair's before/after entry, converted to the report's units.
[[nodiscard]] std::string repair_bound_text(const Json& report, const Json& entry);
// "a range-scan with residual +-0.018 in, +-0.9 deg (x0.9 of the sensor's) would make it hold".
[[nodiscard]] std::string sensor_residual_text(const Json& report, const Json& needed);

// ---- chosen.probability (issue 15) ----
// The chosen step's precondition an entry of chosen.probability.preconditions describes.
[[nodiscard]] const Json& probability_precondition(const Json& report, const Json& entry);
// A value of that precondition (SI) in display units: lengths in the report's unit.
[[nodiscard]] double precondition_display(const Json& report, const Json& entry, double si);
// "σ 0.012 in" / "σ 0.0021" for an entry.
[[nodiscard]] std::string sigma_text(const Json& report, const Json& entry);
// "0 (proved)", "12.3%", "0.0041%".
[[nodiscard]] std::string probability_text(double probability, bool proved);
// "0.12% [0.1%, 0.14%]" from an entry's p_monte_carlo and ci (or the plan's).
[[nodiscard]] std::string monte_carlo_text(const Json& entry, bool proved);
// "not needed: ..." / "proved in 2 rounds (cost 0.38)" for chosen.probability.tolerances.
[[nodiscard]] std::string allocation_text(const Json& tolerances);

struct VerdictCounts {
  int satisfied{0}, violated{0}, undecided{0};
  [[nodiscard]] int total() const { return satisfied + violated + undecided; }
};
[[nodiscard]] VerdictCounts verdict_counts(const Json& report);  // over the chosen steps

}  // namespace spar::reports::internal
