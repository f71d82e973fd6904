#include "spar/reports/html.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "spar/reports/internal/check.hpp"
#include "spar/reports/internal/layout.hpp"
#include "spar/reports/internal/text.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/markdown.hpp"
#include "spar/reports/sensing.hpp"

namespace spar::reports {
namespace {

using internal::html_escape;
using internal::rounded;

// An SVG coordinate: one decimal is plenty and keeps the file small and stable.
std::string px(double coordinate) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f", coordinate);
  std::string out = buffer;
  if (out.size() > 2 && out.compare(out.size() - 2, 2, ".0") == 0) out.resize(out.size() - 2);
  return out == "-0" ? "0" : out;
}

const char* kStyle = R"(
body{font-family:sans-serif;margin:24px auto;max-width:1180px;color:#1d2430;line-height:1.4}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.15em;margin-top:1.8em;border-bottom:1px solid #d4d9e1}
table{border-collapse:collapse;font-size:13px;margin:.5em 0}
th,td{border:1px solid #d4d9e1;padding:3px 6px;vertical-align:top;text-align:left}
th{background:#eef1f5}td.num{text-align:right;font-variant-numeric:tabular-nums}
.satisfied{color:#17723a;font-weight:bold}.violated{color:#b3261e;font-weight:bold}
.undecided{color:#a05a00;font-weight:bold}
.summary{background:#f5f7fa;border:1px solid #d4d9e1;padding:8px 12px;white-space:pre-wrap;font-family:monospace;font-size:13px}
code{font-size:12px}details summary{cursor:pointer;color:#2b5fad}
.scroll{overflow-x:auto}svg text{font-family:sans-serif}
.note{color:#5a6472;font-size:13px}
)";

std::string verdict_span(const std::string& verdict) {
  return "<span class=\"" + html_escape(verdict) + "\">" + html_escape(verdict) + "</span>";
}

const char* action_colour(const std::string& action) {
  static const std::map<std::string, const char*> colours = {{"pickup", "#cfe0fb"},
                                                             {"putdown", "#cdeee6"},
                                                             {"assemble", "#e4d7f6"},
                                                             {"range-scan", "#ffe1bf"},
                                                             {"squeeze", "#fff2a8"}};
  const auto found = colours.find(action);
  return found == colours.end() ? "#e6e8ec" : found->second;
}

void summary_section(const Report& report, std::ostringstream& out) {
  const Units& units = report.units;
  out << "<h1>spar plan report: " << html_escape(report.scenario) << "</h1>\n";
  if (!report.description.empty()) out << "<p>" << html_escape(report.description) << "</p>\n";
  out << "<p class=\"note\">Report " << html_escape(report.schema) << ". Lengths in "
      << html_escape(units.length) << ", angles in " << html_escape(units.angle)
      << "; numbers are rounded for reading, the JSON report keeps the exact values.</p>\n"
      << "<section id=\"summary\"><div class=\"summary\">" << html_escape(summary(report))
      << "</div></section>\n";
}

// The chosen plan as boxes in execution order, six to a row.
void timeline_section(const Report& report, std::ostringstream& out) {
  const std::vector<Step>& steps = report.chosen->steps;
  constexpr int kPerRow = 6, kWidth = 160, kHeight = 64, kGap = 28, kRowHeight = 112;
  const int count = static_cast<int>(steps.size());
  const int rows = std::max(1, (count + kPerRow - 1) / kPerRow);
  const int width = std::min(count, kPerRow) * (kWidth + kGap) + 20;
  out << "<section id=\"timeline\"><h2>Chosen plan, in execution order</h2>\n"
      << "<p class=\"note\">Dashed: inserted by phase 2 (sensing or squeeze). Red: a precondition "
         "fails. A \"verify\" badge: verification sensing and recovery are posted.</p>\n"
      << "<div class=\"scroll\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width
      << "\" height=\"" << rows * kRowHeight + 10
      << "\" role=\"img\" aria-label=\"plan timeline\">\n"
      << "<defs><marker id=\"arrow\" viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"7\" "
         "markerHeight=\"7\" orient=\"auto\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\"#6b7480\"/>"
         "</marker></defs>\n";
  for (int i = 0; i < count; ++i) {
    const Step& step = steps[i];
    const int x = 10 + (i % kPerRow) * (kWidth + kGap), y = 10 + (i / kPerRow) * kRowHeight;
    const bool inserted = step.inserted.value_or(false), failed = step.failed.value_or(false);
    const auto [holding, total] = internal::holding(step);
    out << "<g class=\"step" << (inserted ? " inserted" : "") << "\"><title>"
        << html_escape(internal::step_title(step) + ": " +
                       internal::step_details(report.units, step))
        << "</title><rect x=\"" << x << "\" y=\"" << y << "\" width=\"" << kWidth << "\" height=\""
        << kHeight << "\" rx=\"6\" fill=\"" << action_colour(step.action) << "\" stroke=\""
        << (failed ? "#b3261e" : "#55606e") << "\" stroke-width=\"" << (failed ? 2.5 : 1.2) << "\""
        << (inserted ? " stroke-dasharray=\"5,3\"" : "") << "/>\n"
        << "<text x=\"" << x + 8 << "\" y=\"" << y + 18
        << "\" font-size=\"12\" font-weight=\"bold\">" << i + 1 << ". " << html_escape(step.action)
        << "</text>\n"
        << "<text x=\"" << x + 8 << "\" y=\"" << y + 35 << "\" font-size=\"12\">"
        << html_escape(step.object.value_or(""))
        << (step.fixed_object ? " into " + html_escape(*step.fixed_object) : "")
        << "</text>\n<text x=\"" << x + 8 << "\" y=\"" << y + 53 << "\" font-size=\"11\" fill=\""
        << (holding == total ? "#17723a" : "#b3261e") << "\">"
        << (total == 0
                ? std::string("no uncertainty checks")
                : std::to_string(holding) + "/" + std::to_string(total) + " preconditions hold")
        << "</text>\n";
    if (inserted)
      out << "<text x=\"" << x + kWidth - 6 << "\" y=\"" << y + 18
          << "\" font-size=\"10\" text-anchor=\"end\" fill=\"#a05a00\">inserted</text>\n";
    if (step.verification)
      out << "<rect x=\"" << x + 8 << "\" y=\"" << y + kHeight + 6
          << "\" width=\"52\" height=\"18\" rx=\"9\" fill=\"#b3261e\"/><text x=\"" << x + 34
          << "\" y=\"" << y + kHeight + 19
          << "\" font-size=\"11\" fill=\"#fff\" text-anchor=\"middle\">verify</text>\n";
    if (i + 1 < count && (i + 1) % kPerRow != 0)
      out << "<line x1=\"" << x + kWidth << "\" y1=\"" << y + kHeight / 2 << "\" x2=\""
          << x + kWidth + kGap - 2 << "\" y2=\"" << y + kHeight / 2
          << "\" stroke=\"#6b7480\" stroke-width=\"1.5\" marker-end=\"url(#arrow)\"/>\n";
    out << "</g>\n";
  }
  out << "</svg></div></section>\n";
}

// A bar of the sound bound [lo, hi] (light), the inner bound inside it (dark) and the threshold
// (a dashed line); the side of the threshold where the precondition fails is tinted.
std::string bound_bar(const Precondition& precondition) {
  const DisplayBounds& display = precondition.display;
  const double lo = display.lo, hi = display.hi;
  const double inner_lo = display.inner_lo, inner_hi = display.inner_hi;
  const double threshold = display.threshold;
  const std::string& relation = precondition.relation;
  const bool below_ok = relation == "<" || relation == "<=";
  // The axis spans every finite value shown, padded by 8% each side.
  double axis_lo = threshold, axis_hi = threshold;
  for (const double v : {lo, hi, inner_lo, inner_hi})
    if (std::isfinite(v)) axis_lo = std::min(axis_lo, v), axis_hi = std::max(axis_hi, v);
  const double span =
      axis_hi - axis_lo > 0 ? axis_hi - axis_lo : std::max(1e-12, std::fabs(axis_hi));
  axis_lo -= 0.08 * span;
  axis_hi += 0.08 * span;
  constexpr double kWidth = 260, kLeft = 6, kRight = 6;
  const auto at = [&](double v) {
    const double clamped = std::isfinite(v) ? v : (v > 0 ? axis_hi : axis_lo);
    return kLeft + (clamped - axis_lo) / (axis_hi - axis_lo) * (kWidth - kLeft - kRight);
  };
  const std::string& verdict = precondition.verdict;
  const char* fill = verdict == "satisfied"  ? "#9fd8b0"
                     : verdict == "violated" ? "#f2aaa4"
                                             : "#f7cf91";
  const char* inner = verdict == "satisfied"  ? "#2e8b57"
                      : verdict == "violated" ? "#b3261e"
                                              : "#a05a00";
  std::string unit;
  if (display.unit != "1") unit.append(" ").append(display.unit);
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"bound-bar\" width=\"" << kWidth
      << "\" height=\"40\"><title>sound bound [" << rounded(lo, 8) << ", " << rounded(hi, 8) << "]"
      << unit << "; inner bound [" << rounded(inner_lo, 8) << ", " << rounded(inner_hi, 8) << "]"
      << unit << "; requirement " << html_escape(relation) << " " << rounded(threshold, 8) << unit
      << "</title>\n";
  const double t = at(threshold);
  if (below_ok)
    svg << "<rect x=\"" << px(t) << "\" y=\"4\" width=\"" << px(kWidth - kRight - t)
        << "\" height=\"22\" fill=\"#fbe9e7\"/>";
  else
    svg << "<rect x=\"" << kLeft << "\" y=\"4\" width=\"" << px(t - kLeft)
        << "\" height=\"22\" fill=\"#fbe9e7\"/>";
  svg << "<rect x=\"" << px(at(lo)) << "\" y=\"7\" width=\"" << px(std::max(1.0, at(hi) - at(lo)))
      << "\" height=\"16\" fill=\"" << fill << "\" stroke=\"" << inner
      << "\" stroke-width=\"0.8\"/>"
      << "<rect x=\"" << px(at(inner_lo)) << "\" y=\"11\" width=\""
      << px(std::max(1.0, at(inner_hi) - at(inner_lo))) << "\" height=\"8\" fill=\"" << inner
      << "\"/><line x1=\"" << px(t) << "\" y1=\"1\" x2=\"" << px(t)
      << "\" y2=\"29\" stroke=\"#1d2430\" stroke-width=\"1.5\" stroke-dasharray=\"3,2\"/>";
  // The ends' values under the bar, or one "lo .. hi" label where the bar is too short for two.
  if (at(hi) - at(lo) >= 60)
    svg << "<text x=\"" << px(at(lo)) << "\" y=\"38\" font-size=\"9\">" << rounded(lo)
        << "</text><text x=\"" << px(at(hi)) << "\" y=\"38\" font-size=\"9\" "
        << "text-anchor=\"end\">" << rounded(hi) << "</text>";
  else
    svg << "<text x=\"" << px(std::clamp((at(lo) + at(hi)) / 2, 40.0, kWidth - 40.0))
        << "\" y=\"38\" font-size=\"9\" text-anchor=\"middle\">" << rounded(lo) << " .. "
        << rounded(hi) << "</text>";
  svg << "</svg>";
  return svg.str();
}

// chosen.probability (issue 15): the first-order Gaussian of a precondition (density, truncated
// to the sound bound) over its worst-case interval [lo, hi] (the bar), with the threshold dashed
// and the failing side tinted, in display units.
std::string distribution_plot(const Report& report, const PreconditionProbability& entry) {
  const Precondition& precondition = internal::probability_precondition(*report.chosen, entry);
  const DisplayBounds& display = precondition.display;
  const double lo = display.lo, hi = display.hi;
  const double threshold = display.threshold;
  const double mean = internal::precondition_display(report, entry, entry.mean);
  const double sigma = internal::precondition_display(report, entry, entry.sigma);
  const std::string& relation = precondition.relation;
  const bool below_ok = relation == "<" || relation == "<=";
  double axis_lo = threshold, axis_hi = threshold;
  for (const double v : {lo, hi, mean})
    if (std::isfinite(v)) axis_lo = std::min(axis_lo, v), axis_hi = std::max(axis_hi, v);
  const double span =
      axis_hi - axis_lo > 0 ? axis_hi - axis_lo : std::max(1e-12, std::fabs(axis_hi));
  axis_lo -= 0.08 * span;
  axis_hi += 0.08 * span;
  constexpr double kWidth = 200, kLeft = 4, kRight = 4, kBase = 30, kHeight = 24;
  const auto at = [&](double v) {
    const double clamped =
        std::isfinite(v) ? std::clamp(v, axis_lo, axis_hi) : (v > 0 ? axis_hi : axis_lo);
    return kLeft + (clamped - axis_lo) / (axis_hi - axis_lo) * (kWidth - kLeft - kRight);
  };
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"distribution\" width=\"" << kWidth
      << "\" height=\"36\"><title>first-order mean " << rounded(mean) << ", sigma "
      << rounded(sigma) << "; worst case [" << rounded(lo) << ", " << rounded(hi)
      << "]; requirement " << html_escape(relation) << " " << rounded(threshold) << "</title>";
  const double t = at(threshold);
  svg << "<rect x=\"" << px(below_ok ? t : kLeft) << "\" y=\"2\" width=\""
      << px(below_ok ? kWidth - kRight - t : t - kLeft) << "\" height=\"" << kBase
      << "\" fill=\"#fbe9e7\"/><rect x=\"" << px(at(lo)) << "\" y=\"" << kBase << "\" width=\""
      << px(std::max(1.0, at(hi) - at(lo))) << "\" height=\"4\" fill=\"#8aa0bd\"/>";
  if (sigma > 0 && std::isfinite(sigma) && std::isfinite(lo) && std::isfinite(hi)) {
    svg << "<polyline fill=\"none\" stroke=\"#2b5fad\" stroke-width=\"1.2\" points=\"";
    constexpr int kPoints = 48;
    for (int i = 0; i <= kPoints; ++i) {
      const double x = lo + (hi - lo) * i / kPoints, z = (x - mean) / sigma;
      svg << (i ? " " : "") << px(at(x)) << "," << px(kBase - kHeight * std::exp(-0.5 * z * z));
    }
    svg << "\"/>";
  } else {
    svg << "<line x1=\"" << px(at(mean)) << "\" y1=\"" << kBase - kHeight << "\" x2=\""
        << px(at(mean)) << "\" y2=\"" << kBase << "\" stroke=\"#2b5fad\" stroke-width=\"1.5\"/>";
  }
  svg << "<line x1=\"" << px(t) << "\" y1=\"1\" x2=\"" << px(t)
      << "\" y2=\"35\" stroke=\"#1d2430\" "
      << "stroke-width=\"1.5\" stroke-dasharray=\"3,2\"/></svg>";
  return svg.str();
}

void probability_section(const Report& report, std::ostringstream& out) {
  const Probability& probability = *report.chosen->probability;
  out << "<section id=\"probability\"><h2>Failure probability and tolerances</h2>\n<p "
         "class=\"note\">"
         "Beyond the worst case: each uncertainty variable is distributed in its box as the "
         "scenario says (uniform unless <code>distribution: gaussian</code>). σ is first order "
         "(J Σ Jᵀ); P first order is the linearised precondition's Gaussian truncated to the sound "
         "bound; Monte Carlo draws "
      << probability.samples
      << " points (95% Wilson interval). The plot: that Gaussian over the worst-case interval "
         "(the bar), the threshold dashed, the failing side tinted. A proved precondition fails "
         "with probability 0.</p>\n<p>P(some precondition fails) = "
      << html_escape(
             internal::monte_carlo_text(probability.plan.p_monte_carlo, probability.plan.ci, false))
      << " (Monte Carlo).</p>\n<table id=\"probability-table\"><tr><th>step</th>"
         "<th>precondition</th><th>σ</th><th>P first order</th><th>P Monte Carlo</th>"
         "<th>distribution vs worst case</th><th>note</th></tr>\n";
  for (const PreconditionProbability& entry : probability.preconditions) {
    const Step& step = report.chosen->steps.at(entry.step);
    const bool proved = entry.proved;
    out << "<tr class=\"probability\"><td>" << step.id << " "
        << html_escape(internal::step_title(step)) << "</td><td><code>" << html_escape(entry.name)
        << "</code></td><td class=\"num\">" << html_escape(internal::sigma_text(report, entry))
        << "</td><td class=\"num\">"
        << html_escape(internal::probability_text(entry.p_first_order, proved))
        << "</td><td class=\"num\">"
        << html_escape(internal::monte_carlo_text(entry.p_monte_carlo, entry.ci, proved))
        << "</td><td>" << distribution_plot(report, entry) << "</td><td class=\"note\">"
        << html_escape(entry.note) << "</td></tr>\n";
  }
  out << "</table>\n";
  const Tolerances& tolerances = probability.tolerances;
  out << "<p>Tolerance allocation: " << html_escape(internal::allocation_text(tolerances))
      << ".</p>\n";
  if (tolerances.status != "not_needed") {
    out << "<table id=\"tolerance-table\"><tr><th>parameter</th><th>half-width</th>"
           "<th>allocated</th><th>cost</th></tr>\n";
    for (const ToleranceParameter& parameter : tolerances.parameters) {
      const ToleranceDisplay& display = parameter.display;
      const std::string unit = " " + display.unit;
      out << "<tr><td>" << html_escape(parameter.name) << "</td><td class=\"num\">"
          << rounded(display.half_width) << html_escape(unit) << "</td><td class=\"num\">"
          << rounded(display.allocated) << html_escape(unit) << "</td><td class=\"num\">"
          << rounded(parameter.cost) << "</td></tr>\n";
    }
    out << "</table>\n";
  }
  out << "</section>\n";
}

// Up to six variables' shares of the bound's width, largest first.
std::string blame_bars(const Precondition& precondition) {
  if (!precondition.blame) return "<span class=\"note\">not computed</span>";
  const std::vector<Blame>& blame = *precondition.blame;
  const std::size_t shown = std::min<std::size_t>(blame.size(), 6);
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"blame\" width=\"250\" height=\""
      << 4 + 14 * shown << "\">";
  for (std::size_t i = 0; i < shown; ++i) {
    const double share = std::clamp(blame[i].share, 0.0, 1.0);
    const double y = 2 + 14.0 * static_cast<double>(i);
    svg << "<g><title>" << html_escape(blame[i].variable) << ": " << rounded(100 * share, 3)
        << "% of the bound's width</title><text x=\"0\" y=\"" << px(y + 10)
        << "\" font-size=\"10\">" << html_escape(blame[i].variable) << "</text><rect x=\"120\" y=\""
        << px(y + 2) << "\" width=\"" << px(std::max(0.5, 95 * share))
        << "\" height=\"9\" fill=\"#5b7fb8\"/><text x=\"" << px(122 + 95 * share) << "\" y=\""
        << px(y + 10) << "\" font-size=\"9\">" << rounded(100 * share, 2) << "%</text></g>";
  }
  svg << "</svg>";
  return svg.str();
}

// The witness (the worst point found) in the variables' display units.
std::string witness_table(const Report& report, const Precondition& precondition,
                          const std::map<std::string, std::string>& variable_units) {
  const NamedValues<double>& witness = precondition.witness;
  if (witness.empty()) return "<span class=\"note\">none</span>";
  std::ostringstream out;
  out << "<details><summary>" << witness.size() << " values</summary><table class=\"witness\">";
  for (const auto& [name, number] : witness) {
    const auto unit = variable_units.find(name);
    const bool angle = unit != variable_units.end() && unit->second == "rad";
    const double shown = angle ? internal::to_angle_unit(report.units, number)
                               : internal::to_length_unit(report.units, number);
    out << "<tr><td>" << html_escape(name) << "</td><td class=\"num\">" << rounded(shown, 4) << " "
        << html_escape(angle ? report.units.angle : report.units.length) << "</td></tr>";
  }
  out << "</table></details>";
  return out.str();
}

void preconditions_section(const Report& report, std::ostringstream& out) {
  std::map<std::string, std::string> variable_units;
  if (report.chosen->uncertainty_variables)
    for (const UncertaintyVariable& variable : *report.chosen->uncertainty_variables)
      variable_units[variable.name] = variable.unit;
  out << "<section id=\"preconditions\"><h2>Preconditions</h2>\n<p class=\"note\">The bar: the "
         "sound bound [lo, hi] (light) holds for every uncertainty value in the box; the inner "
         "bound (dark) is attained at witness points, so the true range lies between them; the "
         "dashed line is the threshold and the tinted side is where the precondition fails. "
         "Blame: each variable's share of the bound's width. Holds up to: the largest scale of "
         "the objects' uncertainty for which the precondition is still proved.</p>\n"
      << "<table id=\"precondition-table\"><tr><th># step</th><th>precondition</th><th>verdict</th>"
         "<th>requirement</th><th>bound</th><th>bound vs threshold</th><th>holds up to</th>"
         "<th>witness</th><th>blame</th><th>sampled violations</th></tr>\n";
  int number = 0;  // execution position, as in the timeline
  for (const Step& step : report.chosen->steps) {
    ++number;
    if (!step.preconditions) continue;
    for (const Precondition& precondition : *step.preconditions) {
      const std::string& verdict = precondition.verdict;
      out << "<tr class=\"precondition\" data-verdict=\"" << html_escape(verdict) << "\"><td>"
          << number << ". " << html_escape(internal::step_title(step)) << "</td><td><code title=\""
          << html_escape(precondition.expression) << "\">" << html_escape(precondition.name)
          << "</code></td><td>" << verdict_span(verdict) << "</td><td>"
          << html_escape(internal::requirement_text(precondition)) << "</td><td>"
          << html_escape(internal::bound_text(precondition)) << "<br><span class=\"note\">inner "
          << html_escape(internal::bound_text(precondition, true)) << "</span></td><td>"
          << bound_bar(precondition) << "</td><td>"
          << html_escape(internal::margin_text(report.units, precondition)) << "</td><td>"
          << witness_table(report, precondition, variable_units) << "</td><td>"
          << blame_bars(precondition) << "</td><td class=\"num\">"
          << (precondition.monte_carlo_violation
                  ? rounded(100 * *precondition.monte_carlo_violation, 3) + "%"
                  : std::string("-"))
          << "</td></tr>\n";
    }
  }
  out << "</table></section>\n";
}

void repairs_section(const Report& report, std::ostringstream& out) {
  out << "<section id=\"repairs\"><h2>Inserted sensing and squeeze</h2>\n";
  const Chosen& chosen = *report.chosen;
  if (!chosen.repairs || chosen.repairs->empty()) {
    out << "<p>None tried: no precondition failed before repair.</p></section>\n";
    return;
  }
  out << "<table><tr><th>insertion</th><th>for step</th><th>outcome</th><th>precondition</th>"
         "<th>before</th><th>after</th></tr>\n";
  for (const Repair& repair : *chosen.repairs) {
    const std::vector<RepairBound>& before = repair.before;
    const std::vector<RepairBound>& after = repair.after;
    const auto target = step_position(chosen, repair.for_step);
    for (std::size_t i = 0; i < before.size() && i < after.size(); ++i)
      out << "<tr><td>" << html_escape(repair.action + " " + repair.object) << "</td><td>"
          << repair.for_step << " "
          << (target ? html_escape(internal::step_title(chosen.steps[*target])) : "") << "</td><td>"
          << (repair.helped ? "kept" : "dropped") << "</td><td><code>"
          << html_escape(before[i].name.value_or("")) << "</code></td><td>"
          << html_escape(internal::repair_bound_text(report.units, before[i])) << " "
          << verdict_span(before[i].verdict) << "</td><td>"
          << html_escape(internal::repair_bound_text(report.units, after[i])) << " "
          << verdict_span(after[i].verdict) << "</td></tr>\n";
  }
  out << "</table></section>\n";
}

void verification_section(const Report& report, std::ostringstream& out) {
  out << "<section id=\"verification\"><h2>Verification and recovery</h2>\n";
  bool any = false;
  for (const Step& step : report.chosen->steps) {
    if (!step.verification) continue;
    any = true;
    out << "<h3>Step " << step.id << ": " << html_escape(internal::step_title(step)) << "</h3><ul>";
    if (step.sensor_residual_needed)
      out << "<li>"
          << html_escape(internal::sensor_residual_text(report.units, *step.sensor_residual_needed))
          << "</li>";
    for (const Verification& plan : *step.verification) {
      out << "<li>verify: " << html_escape(plan.sense) << " (expect " << html_escape(plan.expect)
          << ")<ul>";
      for (const Outcome& outcome : plan.outcomes)
        out << "<li>if " << html_escape(outcome.when) << ": " << html_escape(outcome.error)
            << ", recover by <b>" << html_escape(outcome.recovery) << "</b></li>";
      out << "</ul></li>";
    }
    for (const Recovery& recovery : step.recovery.value_or(std::vector<Recovery>{})) {
      out << "<li>recovery <b>" << html_escape(recovery.plan) << "</b> for "
          << html_escape(recovery.error) << ": <ol>";
      for (const std::string& action : recovery.steps)
        out << "<li>" << html_escape(action) << "</li>";
      out << "</ol></li>";
    }
    out << "</ul>\n";
  }
  if (!any)
    out << "<p>Every precondition of the chosen plan holds: nothing to verify at execution.</p>";
  out << "</section>\n";
}

void uncertainty_section(const Report& report, std::ostringstream& out) {
  if (!report.chosen->uncertainty_variables || report.chosen->uncertainty_variables->empty())
    return;
  const std::vector<UncertaintyVariable>& variables = *report.chosen->uncertainty_variables;
  out << "<section id=\"uncertainty\"><h2>Uncertainty variables</h2>\n<table><tr><th>variable</th>"
         "<th>source</th><th>object</th><th>step</th><th>range</th></tr>\n";
  for (const UncertaintyVariable& variable : variables)
    out << "<tr><td>" << html_escape(variable.name) << "</td><td>" << html_escape(variable.source)
        << "</td><td>" << html_escape(variable.object.value_or("(arm)"))
        << "</td><td class=\"num\">" << (variable.step ? std::to_string(*variable.step) : "")
        << "</td><td class=\"num\">" << html_escape(internal::half_width_text(variable))
        << "</td></tr>\n";
  out << "</table></section>\n";
}

// The family's ordering graph (transitive reduction), layered top-down by longest path.
void ordering_section(const Report& report, std::ostringstream& out) {
  const Family& family = report.family;
  const std::vector<FamilyStep>& steps = family.steps;
  std::map<int, int> node_of;  // step id -> node
  for (std::size_t i = 0; i < steps.size(); ++i) node_of[steps[i].id] = static_cast<int>(i);
  std::vector<std::pair<int, int>> edges;
  for (const std::array<int, 2>& pair : family.ordering) {
    const auto from = node_of.find(pair[0]), to = node_of.find(pair[1]);
    if (from != node_of.end() && to != node_of.end()) edges.emplace_back(from->second, to->second);
  }
  const internal::LayeredLayout layout =
      internal::layered_layout(static_cast<int>(steps.size()), edges);
  constexpr int kWidth = 250, kHeight = 30, kColumn = 270, kRow = 62;
  const auto centre_x = [&](int node) { return 10 + layout.position[node] * kColumn + kWidth / 2; };
  const auto top = [&](int node) { return 10 + layout.layer[node] * kRow; };
  out << "<section id=\"ordering\"><h2>Ordering graph of the plan family</h2>\n<p class=\"note\">"
      << steps.size() << " steps, " << edges.size()
      << " ordering constraints (prior_to, transitive reduction); layers by longest path from the "
         "initial state.</p>\n<div class=\"scroll\"><svg xmlns=\"http://www.w3.org/2000/svg\" "
         "width=\""
      << std::max(1, layout.widest) * kColumn + 20 << "\" height=\"" << layout.layers * kRow + 20
      << "\" role=\"img\" aria-label=\"ordering graph\"><defs><marker id=\"arrow-ordering\" "
         "viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" "
         "orient=\"auto\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\"#6b7480\"/></marker></defs>\n";
  for (const auto& [from, to] : edges)
    out << "<line x1=\"" << centre_x(from) << "\" y1=\"" << top(from) + kHeight << "\" x2=\""
        << centre_x(to) << "\" y2=\"" << top(to) - 2
        << "\" stroke=\"#6b7480\" stroke-width=\"1.3\" marker-end=\"url(#arrow-ordering)\"/>\n";
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const int node = static_cast<int>(i);
    std::string label = steps[i].text;
    if (label.size() > 40) label = label.substr(0, 38) + "...";
    out << "<g><title>" << html_escape(steps[i].text) << "</title><rect x=\""
        << centre_x(node) - kWidth / 2 << "\" y=\"" << top(node) << "\" width=\"" << kWidth
        << "\" height=\"" << kHeight << "\" rx=\"5\" fill=\"" << action_colour(steps[i].action)
        << "\" stroke=\"#55606e\"/><text x=\"" << centre_x(node) << "\" y=\"" << top(node) + 19
        << "\" font-size=\"11\" text-anchor=\"middle\">" << steps[i].id << ": "
        << html_escape(label) << "</text></g>\n";
  }
  out << "</svg></div></section>\n";
}

// The geometric constraint network: variables on a circle, arcs labelled with their pair counts.
void network_section(const Report& report, std::ostringstream& out) {
  const Family& family = report.family;
  const std::vector<PlanVariable>& variables = family.variables;
  const int count = static_cast<int>(variables.size());
  std::map<std::string, int> node_of;
  for (int i = 0; i < count; ++i) node_of[variables[i].name] = i;
  std::vector<std::pair<int, int>> edges;
  for (const Arc& arc : family.arcs) {
    const auto first = node_of.find(arc.variables[0]);
    const auto second = node_of.find(arc.variables[1]);
    if (first != node_of.end() && second != node_of.end())
      edges.emplace_back(first->second, second->second);
  }
  const std::vector<internal::Point> ring = internal::circular_layout(count);
  const std::vector<int> slot = internal::circle_order(count, edges);
  // Nodes 120 wide: the circle's circumference gives each about 170 px.
  const double radius = std::max(110.0, 170.0 * count / (2 * 3.14159265358979));
  const double size = 2 * radius + 200;
  const auto x = [&](int node) { return size / 2 + radius * ring[slot[node]].x; };
  const auto y = [&](int node) { return size / 2 + radius * ring[slot[node]].y; };
  out << "<section id=\"network\"><h2>Geometric constraint network</h2>\n<p class=\"note\">"
      << count << " plan variables (grasps, positions) with their label sets; "
      << family.arcs.size()
      << " binary constraints, each labelled with its number of allowed label pairs.</p>\n"
      << "<div class=\"scroll\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << px(size)
      << "\" height=\"" << px(size) << "\" role=\"img\" aria-label=\"constraint network\">\n";
  for (const Arc& arc : family.arcs) {
    const auto first = node_of.find(arc.variables[0]);
    const auto second = node_of.find(arc.variables[1]);
    if (first == node_of.end() || second == node_of.end()) continue;
    const int p = first->second, q = second->second;
    out << "<g><title>" << html_escape(arc.variables[0]) << " - " << html_escape(arc.variables[1])
        << ": " << arc.pairs.size() << " allowed pairs</title><line x1=\"" << px(x(p)) << "\" y1=\""
        << px(y(p)) << "\" x2=\"" << px(x(q)) << "\" y2=\"" << px(y(q))
        << "\" stroke=\"#8893a2\" stroke-width=\"1.3\"/><text x=\"" << px((x(p) + x(q)) / 2)
        << "\" y=\"" << px((y(p) + y(q)) / 2 - 3) << "\" font-size=\"10\" fill=\"#2b5fad\" "
        << "text-anchor=\"middle\">" << arc.pairs.size() << "</text></g>\n";
  }
  for (int i = 0; i < count; ++i) {
    const PlanVariable& variable = variables[i];
    std::string labels;
    for (const std::string& label : variable.labels)
      labels.append(labels.empty() ? "" : " ").append(label);
    out << "<g><title>" << html_escape(variable.name) << " (" << html_escape(variable.type)
        << " of " << html_escape(variable.object) << "): " << html_escape(labels)
        << "</title><rect x=\"" << px(x(i) - 60) << "\" y=\"" << px(y(i) - 16)
        << "\" width=\"120\" height=\"32\" rx=\"14\" fill=\""
        << (variable.type == "grasp" ? "#cfe0fb" : "#cdeee6") << "\" stroke=\"#55606e\"/><text x=\""
        << px(x(i)) << "\" y=\"" << px(y(i) - 2) << "\" font-size=\"11\" text-anchor=\"middle\">"
        << html_escape(variable.name) << "</text><text x=\"" << px(x(i)) << "\" y=\""
        << px(y(i) + 11) << "\" font-size=\"9\" text-anchor=\"middle\" fill=\"#55606e\">"
        << variable.labels.size() << " label" << (variable.labels.size() == 1 ? "" : "s")
        << "</text></g>\n";
  }
  out << "</svg></div></section>\n";
}

void instances_section(const Report& report, std::ostringstream& out) {
  const Instances& instances = report.instances;
  out << "<section id=\"instances\"><h2>Instances considered</h2>\n<p>" << instances.count
      << (instances.count == 1 ? " plan instance enumerated" : " plan instances enumerated")
      << (instances.limit_reached ? " (the limit was reached: more exist)" : "")
      << "; phase 2 examines them in order until one has no error.</p>\n"
      << "<table id=\"instance-table\"><tr><th>instance</th><th>errors</th><th>steps</th>"
         "<th>inserted</th><th>failed preconditions</th><th></th></tr>\n";
  for (const ExaminedInstance& examined : instances.examined) {
    out << "<tr class=\"instance\"><td class=\"num\">#" << examined.index + 1
        << "</td><td class=\"num\">" << examined.errors << "</td><td class=\"num\">"
        << examined.steps << "</td><td class=\"num\">" << examined.inserted
        << "</td><td class=\"num\">" << examined.failed_preconditions << " / "
        << examined.preconditions << "</td><td>"
        << (report.chosen && report.chosen->index == examined.index ? "chosen" : "")
        << "</td></tr>\n";
  }
  out << "</table></section>\n";
}

// One section per outcome of sensing: the branch's steps and preconditions, as a plan's.
void branches_section(const Report& report, std::ostringstream& out) {
  out << "<section><h2>Branches: one plan per outcome of sensing</h2></section>\n";
  for (const Branch& branch : *report.branches) {
    out << "<section><h3>Branch " << html_escape(branch.outcome) << " ("
        << html_escape(branch.object) << " is " << html_escape(branch.outcome)
        << "): " << html_escape(branch.status) << "</h3></section>\n";
    if (branch.steps.empty()) continue;
    const Report view = branch_as_plan(report, branch);
    timeline_section(view, out);
    preconditions_section(view, out);
  }
}

std::string html(const Report& report) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>spar "
         "report: "
      << html_escape(report.scenario) << "</title>\n<style>" << kStyle
      << "</style>\n</head>\n<body>\n";
  summary_section(report, out);
  if (report.sensing) out << sensing_html(*report.sensing);
  if (report.branches) {
    if (report.chosen) timeline_section(report, out);
    branches_section(report, out);
  } else if (report.chosen) {
    timeline_section(report, out);
    preconditions_section(report, out);
    repairs_section(report, out);
    verification_section(report, out);
    if (report.chosen->probability) probability_section(report, out);
    uncertainty_section(report, out);
  }
  if (report.status == "planned" && !report.branches) {
    ordering_section(report, out);
    network_section(report, out);
  }
  if (!report.branches) instances_section(report, out);
  out << "</body>\n</html>\n";
  return out.str();
}

}  // namespace

std::string render_html(const Report& report) {
  return internal::guarded("HTML", [&] { return html(report); });
}

std::string render_html(const nlohmann::ordered_json& report) {
  return internal::guarded("HTML", [&] { return html(report_from_json(report)); });
}

}  // namespace spar::reports
