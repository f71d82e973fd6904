// Formatting the report model's values for people (reports/ only).
//
// Rounding is for reading only: rounded() keeps `digits` significant digits (never fewer than the
// integer part needs) and drops trailing zeros, so 0.0023999 -> "0.0024".
//
// Example:
//   std::string text = rounded(precondition.display.hi) + " in";   // "0.047 in"
//   out << html_escape(step.action);
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "spar/reports/model.hpp"

namespace spar::reports::internal {

// `value` rounded to `digits` significant digits for reading ("inf", "-inf", "nan" as words).
[[nodiscard]] std::string rounded(double value, int digits = 3);
// `value` with at most `decimals` decimals, trailing zeros dropped: 3e-15 -> "0", 12.4 -> "12.4".
[[nodiscard]] std::string fixed(double value, int decimals = 3);
// Escapes & < > " ' for HTML text and attribute values.
[[nodiscard]] std::string html_escape(std::string_view text);
// Escapes | and newlines for a Markdown table cell.
[[nodiscard]] std::string cell_escape(std::string_view text);
// A length in the report's length unit: SI metres times 1 / units.metres_per_length.
[[nodiscard]] double to_length_unit(const Units& units, double metres);
// An angle in the report's angle unit.
[[nodiscard]] double to_angle_unit(const Units& units, double radians);
// "+-0.11 in" for an uncertainty variable.
[[nodiscard]] std::string half_width_text(const UncertaintyVariable& variable);
// "pickup block" / "assemble peg into block": what a chosen step does, in words.
[[nodiscard]] std::string step_title(const Step& step);

// ---- one numbering: a chosen step is "#k action object" (model.hpp's step_label) ----
// A family step by its place in the chosen plan: "#3 pickup block"; "initial state" and "goal"
// for the start and finish; "step <id>" for one the plan does not execute.
[[nodiscard]] std::string family_step_label(const Report& report, const FamilyStep& step);
// The chosen steps whose arguments name plan variable `name`: "#2 pickup peg, #8 assemble peg".
[[nodiscard]] std::string variable_users(const Report& report, const std::string& name);
// The step that allocated an uncertainty variable: "#3 pickup block", or "initial".
[[nodiscard]] std::string allocated_by(const Chosen& chosen, const UncertaintyVariable& variable);
// Per repair of chosen.repairs: the position of the inserted step it became (kept repairs: the
// inserted steps with its action and object, in order), nullopt for a dropped one.
[[nodiscard]] std::vector<std::optional<std::size_t>> repair_positions(const Chosen& chosen);
// "#5 range-scan block, for #8 assemble peg" (kept; "... (corrects dy, dz only)" when its
// reading corrects some components only) / "range-scan block for #8 assemble peg".
[[nodiscard]] std::string repair_title(const Chosen& chosen, const Repair& repair,
                                       std::optional<std::size_t> position);
// The repair candidates phase 2 searched and dropped (chosen.repair_searches), in one line:
// "1 range-scan and 4 squeeze for #5 assemble peg (11 sets of 6 candidates tried)"; "" when none
// was dropped.
[[nodiscard]] std::string dropped_repairs(const Chosen& chosen);

// "grasp G4 (faces 3/5, width 3 in), object at (20, 0, 1.5) in, stable pose P6, arm lun".
[[nodiscard]] std::string step_details(const Units& units, const Step& step);
// A precondition's requirement in display units: "< 0 in", ">= 0.999 (cosine)".
[[nodiscard]] std::string requirement_text(const Precondition& precondition);
// "[lo, hi] unit" from a precondition's display values (`inner` picks inner_lo, inner_hi; without
// an attained range "none (why)", never the swapped [hi, lo]).
[[nodiscard]] std::string bound_text(const Precondition& precondition, bool inner = false);
// The reverse-analysis margin: "x2.3 (+-0.25 in, +-13 deg)", "≥ x8, search cap (...)" when the
// search stopped at its cap, or "" when not computed.
[[nodiscard]] std::string margin_text(const Units& units, const Precondition& precondition);
// "[lo, hi] in" range of a repair's before/after entry, converted to the report's units.
[[nodiscard]] std::string repair_bound_text(const Units& units, const RepairBound& entry);
// "a range-scan with residual +-0.018 in, +-0.9 deg (x0.9 of the sensor's) would make it hold".
[[nodiscard]] std::string sensor_residual_text(const Units& units, const SensorResidual& needed);
// "camera overhead must see peg/e1, peg/e4 (PSEIKI accepts at scene belief >= 0.5)".
[[nodiscard]] std::string vision_text(const VisionCheck& vision);
// "the expected scene as camera overhead renders it at this step, 640 x 480 px: 7 edges of peg,
// 25 of the other objects and the gripper, which hide what lies behind them" (vision.view set).
[[nodiscard]] std::string vision_view_text(const VisionCheck& vision);

// ---- chosen.probability ----
// The chosen step's precondition an entry of chosen.probability.preconditions describes.
[[nodiscard]] const Precondition& probability_precondition(const Chosen& chosen,
                                                           const PreconditionProbability& entry);
// A value of that precondition (SI) in display units: lengths in the report's unit.
[[nodiscard]] double precondition_display(const Report& report,
                                          const PreconditionProbability& entry, double si);
// A tolerance in display units, a zero one as the requirement it is: "0.05 in", "must be exact".
[[nodiscard]] std::string tolerance_text(double half_width, const std::string& unit);
// "σ 0.012 in" / "σ 0.0021" for an entry.
[[nodiscard]] std::string sigma_text(const Report& report, const PreconditionProbability& entry);
// "0 (proved)", "12.3%", "0.0041%".
[[nodiscard]] std::string probability_text(double probability, bool proved);
// "0.12% [0.1%, 0.14%]" from a Monte Carlo estimate and its interval.
[[nodiscard]] std::string monte_carlo_text(double p, const std::array<double, 2>& ci, bool proved);
// The plan's P(some precondition fails): "0 (every precondition proved; none of the 20000 Monte
// Carlo points violates one)" when the sound bounds proved them all, else the sampled share with
// its Wilson interval and " (Monte Carlo)".
[[nodiscard]] std::string plan_probability_text(const Probability& probability);
// "Monte Carlo draws 20000 points (95% Wilson interval; a proved precondition is checked on the
// first 2000 of them)." (the second part when some are proved and some are not).
[[nodiscard]] std::string monte_carlo_points_text(const Probability& probability);
// "not needed: ..." / "proved in 2 rounds (cost 0.38)" for chosen.probability.tolerances.
[[nodiscard]] std::string allocation_text(const Tolerances& tolerances);

struct VerdictCounts {
  int satisfied{0}, violated{0}, undecided{0};
  [[nodiscard]] int total() const { return satisfied + violated + undecided; }
};
[[nodiscard]] VerdictCounts verdict_counts(const Report& report);  // over the chosen steps
// Preconditions of a step that hold, and all of them (0/0 when phase 2 did not run).
[[nodiscard]] std::pair<int, int> holding(const Step& step);

}  // namespace spar::reports::internal
