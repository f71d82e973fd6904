#include "spar/reports/html.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "spar/reports/internal/cell_svg.hpp"
#include "spar/reports/internal/check.hpp"
#include "spar/reports/internal/layout.hpp"
#include "spar/reports/internal/text.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/markdown.hpp"
#include "spar/reports/sensing.hpp"
#include "spar/reports/vision_svg.hpp"

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

// Desktop first; below 700 px wide (a phone) the precondition table becomes one card per row so
// that every bar stays on screen, and every other table scrolls inside its own box.
const char* kStyle = R"(
body{font-family:sans-serif;margin:24px auto;max-width:1180px;padding:0 12px;color:#1d2430;line-height:1.4}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.15em;margin-top:1.8em;border-bottom:1px solid #d4d9e1}
table{border-collapse:collapse;font-size:13px;margin:.5em 0}
th,td{border:1px solid #d4d9e1;padding:3px 6px;vertical-align:top;text-align:left}
th{background:#eef1f5}td.num{text-align:right;font-variant-numeric:tabular-nums}
.satisfied{color:#17723a;font-weight:bold}.violated{color:#b3261e;font-weight:bold}
.undecided{color:#a05a00;font-weight:bold}
.summary{background:#f5f7fa;border:1px solid #d4d9e1;padding:8px 12px;white-space:pre-wrap;font-family:monospace;font-size:13px;overflow-x:auto}
code{font-size:12px;overflow-wrap:anywhere}details summary{cursor:pointer;color:#2b5fad}
.scroll{overflow-x:auto;max-width:100%}svg text{font-family:sans-serif}
section>.scroll>svg,.cell-views svg{max-width:100%;height:auto}
.note{color:#5a6472;font-size:13px}
ol.timeline{list-style:none;padding:0;display:flex;flex-wrap:wrap;gap:8px 22px}
ol.timeline li{position:relative;border:1.5px solid #55606e;border-radius:6px;padding:6px 9px;min-width:120px;max-width:220px;font-size:13px}
ol.timeline li:not(:last-child)::after{content:"\2192";position:absolute;right:-18px;top:40%;color:#6b7480}
ol.timeline li.inserted{border-style:dashed}ol.timeline li.failed{border-color:#b3261e;border-width:2.5px}
ol.timeline .label{font-weight:bold;display:block}ol.timeline .holds{font-size:11px;color:#17723a}
ol.timeline .fails{font-size:11px;color:#b3261e}ol.timeline .tag{font-size:10px;color:#a05a00}
ol.timeline .verify{display:inline-block;font-size:11px;color:#fff;background:#b3261e;border-radius:9px;padding:0 8px;margin-top:3px}
.cell-views{display:grid;grid-template-columns:repeat(auto-fill,minmax(300px,1fr));gap:12px}
.cell-views figure{margin:0;border:1px solid #d4d9e1;padding:4px}.cell-views svg{width:100%}
@media (max-width:700px){
body{margin:8px auto}
table.cards,table.cards tbody,table.cards tr,table.cards td{display:block;width:auto}
table.cards tr:first-child{display:none}table.cards tr{border:1px solid #d4d9e1;margin:0 0 10px;padding:4px}
table.cards td{border:none;padding:2px 4px}table.cards td::before{content:attr(data-label) ": ";color:#5a6472;font-size:12px}
}
)";

std::string verdict_span(const std::string& verdict) {
  return "<span class=\"" + html_escape(verdict) + "\">" + html_escape(verdict) + "</span>";
}

const char* action_colour(const std::string& action) {
  static const std::map<std::string, const char*> colours = {
      {"pickup", "#cfe0fb"},     {"putdown", "#cdeee6"},       {"assemble", "#e4d7f6"},
      {"range-scan", "#ffe1bf"}, {"camera-verify", "#ffe1bf"}, {"squeeze", "#fff2a8"}};
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

// The chosen plan as boxes in execution order: a list that wraps to the page's width.
void timeline_section(const Report& report, std::ostringstream& out) {
  const Chosen& chosen = *report.chosen;
  out << "<section id=\"timeline\"><h2>Chosen plan, in execution order</h2>\n"
      << "<p class=\"note\">Dashed: inserted by phase 2 (sensing or squeeze). Red: a precondition "
         "fails. A \"verify\" badge: verification sensing and recovery are posted.</p>\n"
      << "<ol class=\"timeline\">\n";
  for (std::size_t k = 0; k < chosen.steps.size(); ++k) {
    const Step& step = chosen.steps[k];
    const bool inserted = step.inserted.value_or(false), failed = step.failed.value_or(false);
    const auto [holding, total] = internal::holding(step);
    out << "<li class=\"step" << (inserted ? " inserted" : "") << (failed ? " failed" : "")
        << "\" style=\"background:" << action_colour(step.action) << "\" title=\""
        << html_escape(internal::step_details(report.units, step)) << "\"><span class=\"label\">"
        << html_escape(step_label(chosen, k)) << "</span>"
        << (step.fixed_object ? "<span>into " + html_escape(*step.fixed_object) + "</span><br>"
                              : "")
        << "<span class=\"" << (holding == total ? "holds" : "fails") << "\">"
        << (total == 0
                ? std::string("no uncertainty checks")
                : std::to_string(holding) + "/" + std::to_string(total) + " preconditions hold")
        << "</span>" << (inserted ? " <span class=\"tag\">inserted</span>" : "")
        << (step.verification ? "<br><span class=\"verify\">verify</span>" : "") << "</li>\n";
  }
  out << "</ol></section>\n";
}

// A bar of the sound bound [lo, hi] (light), the inner bound inside it (dark) and the threshold
// (a dashed line); the side of the threshold where the precondition fails is tinted.
std::string bound_bar(const Precondition& precondition) {
  const DisplayBounds& display = precondition.display;
  const double lo = display.lo, hi = display.hi;
  const bool attained = display.inner_lo.has_value();  // else no inner bar (nothing attained)
  const double inner_lo = display.inner_lo.value_or(lo), inner_hi = display.inner_hi.value_or(hi);
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
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"bound-bar\" viewBox=\"0 0 " << kWidth
      << " 40\" width=\"" << kWidth << "\" height=\"40\"><title>sound bound [" << rounded(lo, 8)
      << ", " << rounded(hi, 8) << "]" << unit << "; inner bound "
      << (attained ? "[" + rounded(inner_lo, 8) + ", " + rounded(inner_hi, 8) + "]" + unit
                   : html_escape(internal::bound_text(precondition, true)))
      << "; requirement " << html_escape(relation) << " " << rounded(threshold, 8) << unit
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
      << "\" stroke-width=\"0.8\"/>";
  if (attained)
    svg << "<rect x=\"" << px(at(inner_lo)) << "\" y=\"11\" width=\""
        << px(std::max(1.0, at(inner_hi) - at(inner_lo))) << "\" height=\"8\" fill=\"" << inner
        << "\"/>";
  svg << "<line x1=\"" << px(t) << "\" y1=\"1\" x2=\"" << px(t)
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
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"distribution\" viewBox=\"0 0 " << kWidth
      << " 36\" width=\"" << kWidth << "\" height=\"36\"><title>first-order mean " << rounded(mean)
      << ", sigma " << rounded(sigma) << "; worst case [" << rounded(lo) << ", " << rounded(hi)
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
         "bound; "
      << html_escape(internal::monte_carlo_points_text(probability))
      << " The plot: that Gaussian over the worst-case interval "
         "(the bar), the threshold dashed, the failing side tinted. A proved precondition fails "
         "with probability 0.</p>\n<p>P(some precondition fails) = "
      << html_escape(internal::plan_probability_text(probability))
      << ".</p>\n<div class=\"scroll\"><table "
         "id=\"probability-table\"><tr><th>step</th>"
         "<th>precondition</th><th>σ</th><th>P first order</th><th>P Monte Carlo</th>"
         "<th>distribution vs worst case</th><th>note</th></tr>\n";
  for (const PreconditionProbability& entry : probability.preconditions) {
    const bool proved = entry.proved;
    out << "<tr class=\"probability\"><td>" << html_escape(step_label(*report.chosen, entry.step))
        << "</td><td><code>" << html_escape(entry.name) << "</code></td><td class=\"num\">"
        << html_escape(internal::sigma_text(report, entry)) << "</td><td class=\"num\">"
        << html_escape(internal::probability_text(entry.p_first_order, proved))
        << "</td><td class=\"num\">"
        << html_escape(internal::monte_carlo_text(entry.p_monte_carlo, entry.ci, proved))
        << "</td><td>" << distribution_plot(report, entry) << "</td><td class=\"note\">"
        << html_escape(entry.note) << "</td></tr>\n";
  }
  out << "</table></div>\n";
  const Tolerances& tolerances = probability.tolerances;
  out << "<p>Tolerance allocation: " << html_escape(internal::allocation_text(tolerances))
      << ".</p>\n";
  if (tolerances.status != "not_needed") {
    out << "<div class=\"scroll\"><table "
           "id=\"tolerance-table\"><tr><th>parameter</th><th>half-width</th>"
           "<th>allocated</th><th>cost</th></tr>\n";
    for (const ToleranceParameter& parameter : tolerances.parameters) {
      const ToleranceDisplay& display = parameter.display;
      out << "<tr><td>" << html_escape(parameter.name) << "</td><td class=\"num\">"
          << html_escape(internal::tolerance_text(display.half_width, display.unit))
          << "</td><td class=\"num\">"
          << html_escape(internal::tolerance_text(display.allocated, display.unit))
          << "</td><td class=\"num\">" << rounded(parameter.cost) << "</td></tr>\n";
    }
    out << "</table></div>\n";
  }
  out << "</section>\n";
}

// Up to six variables' shares of the bound's width, largest first.
std::string blame_bars(const Precondition& precondition) {
  if (!precondition.blame) return "<span class=\"note\">not computed</span>";
  const std::vector<Blame>& blame = *precondition.blame;
  const std::size_t shown = std::min<std::size_t>(blame.size(), 6);
  std::ostringstream svg;
  // Names are never cut: the bars start after the longest one.
  std::size_t longest = 0;
  for (std::size_t i = 0; i < shown; ++i) longest = std::max(longest, blame[i].variable.size());
  const double bars = std::max(60.0, 6.0 * double(longest) + 8);
  const double width = bars + 130, height = 4 + 14.0 * double(shown);
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"blame\" viewBox=\"0 0 " << px(width)
      << " " << px(height) << "\" width=\"" << px(width) << "\" height=\"" << px(height) << "\">";
  for (std::size_t i = 0; i < shown; ++i) {
    const double share = std::clamp(blame[i].share, 0.0, 1.0);
    const double y = 2 + 14.0 * static_cast<double>(i);
    svg << "<g><title>" << html_escape(blame[i].variable) << ": " << rounded(100 * share, 3)
        << "% of the bound's width</title><text x=\"0\" y=\"" << px(y + 10)
        << "\" font-size=\"10\">" << html_escape(blame[i].variable) << "</text><rect x=\""
        << px(bars) << "\" y=\"" << px(y + 2) << "\" width=\"" << px(std::max(0.5, 95 * share))
        << "\" height=\"9\" fill=\"#5b7fb8\"/><text x=\"" << px(bars + 2 + 95 * share) << "\" y=\""
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

// A precondition's expression as its name's tooltip, cut after kTooltipCharacters: a chained
// arm's runs to megabytes (15 MB for a pickup of docs/scenario.md's UR5 task), which made the page
// as large and is more than any tooltip shows; report.json keeps every expression whole.
constexpr std::size_t kTooltipCharacters = 20000;
std::string expression_tooltip(const std::string& expression) {
  if (expression.empty())
    return "not printed: its tree form passes 10^7 nodes (its bound is still the expression's)";
  if (expression.size() <= kTooltipCharacters) return expression;
  // Cut before a character, not inside one: object names (hence variable names) may be UTF-8.
  std::size_t cut = kTooltipCharacters;
  while (cut > 0 && (static_cast<unsigned char>(expression[cut]) & 0xC0) == 0x80) --cut;
  return expression.substr(0, cut) + " ... (" + std::to_string(expression.size()) +
         " characters in all; report.json has the whole expression)";
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
         "Blame: each variable's (first-order) share of the bound's width. Holds up to: the "
         "largest scale of "
         "the objects' uncertainty for which the precondition is still proved.</p>\n"
      << "<div class=\"scroll\"><table id=\"precondition-table\" class=\"cards\"><tr>"
         "<th>step</th><th>precondition</th><th>verdict</th><th>requirement</th><th>bound</th>"
         "<th>bound vs threshold</th><th>holds up to</th><th>witness</th><th>blame</th>"
         "<th>sampled violations</th></tr>\n";
  const Chosen& chosen = *report.chosen;
  for (std::size_t k = 0; k < chosen.steps.size(); ++k) {
    const Step& step = chosen.steps[k];
    if (!step.preconditions) continue;
    for (const Precondition& precondition : *step.preconditions) {
      const std::string& verdict = precondition.verdict;
      out << "<tr class=\"precondition\" data-verdict=\"" << html_escape(verdict)
          << "\"><td data-label=\"step\">" << html_escape(step_label(chosen, k))
          << "</td><td data-label=\"precondition\"><code title=\""
          << html_escape(expression_tooltip(precondition.expression)) << "\">"
          << html_escape(precondition.name) << "</code></td><td data-label=\"verdict\">"
          << verdict_span(verdict) << "</td><td data-label=\"requirement\">"
          << html_escape(internal::requirement_text(precondition))
          << "</td><td data-label=\"bound\">" << html_escape(internal::bound_text(precondition))
          << "<br><span class=\"note\">inner "
          << html_escape(internal::bound_text(precondition, true))
          << "</span></td><td data-label=\"bound vs threshold\">" << bound_bar(precondition)
          << "</td><td data-label=\"holds up to\">"
          << html_escape(internal::margin_text(report.units, precondition))
          << "</td><td data-label=\"witness\">"
          << witness_table(report, precondition, variable_units) << "</td><td data-label=\"blame\">"
          << blame_bars(precondition) << "</td><td class=\"num\" data-label=\"sampled violations\">"
          << (precondition.monte_carlo_violation
                  ? rounded(100 * *precondition.monte_carlo_violation, 3) + "%"
                  : std::string("-"))
          << "</td></tr>\n";
    }
  }
  out << "</table></div></section>\n";
}

// What PSEIKI must see, and the expected scene as the camera renders it (reports of this version).
void vision_item(const VisionCheck& vision, std::ostringstream& out) {
  out << "<li>" << html_escape(internal::vision_text(vision));
  if (vision.view)
    out << "<figure class=\"vision\" style=\"margin:6px 0\">" << expected_scene_svg(vision)
        << "<figcaption class=\"note\">" << html_escape(internal::vision_view_text(vision))
        << "</figcaption></figure>";
  out << "</li>";
}

void repairs_section(const Report& report, std::ostringstream& out) {
  out << "<section id=\"repairs\"><h2>Inserted sensing and squeeze</h2>\n";
  const Chosen& chosen = *report.chosen;
  if (!chosen.repairs || chosen.repairs->empty()) {
    out << "<p>None tried: no precondition failed before repair.</p></section>\n";
    return;
  }
  // The kept insertions with the bounds they changed; the dropped ones in one line.
  const std::vector<std::optional<std::size_t>> positions = internal::repair_positions(chosen);
  bool any_kept = false;
  for (std::size_t r = 0; r < chosen.repairs->size(); ++r) {
    const Repair& repair = (*chosen.repairs)[r];
    if (!repair.helped) continue;
    if (!any_kept)
      out << "<div class=\"scroll\"><table id=\"repair-table\"><tr><th>insertion</th>"
             "<th>precondition</th><th>before</th><th>after</th></tr>\n";
    any_kept = true;
    for (std::size_t i = 0; i < repair.before.size() && i < repair.after.size(); ++i)
      out << "<tr><td>" << html_escape(internal::repair_title(chosen, repair, positions[r]))
          << "</td><td><code>" << html_escape(repair.before[i].name.value_or(""))
          << "</code></td><td>"
          << html_escape(internal::repair_bound_text(report.units, repair.before[i])) << " "
          << verdict_span(repair.before[i].verdict) << "</td><td>"
          << html_escape(internal::repair_bound_text(report.units, repair.after[i])) << " "
          << verdict_span(repair.after[i].verdict) << "</td></tr>\n";
  }
  if (any_kept) out << "</table></div>\n";
  // Kept camera verifications: what PSEIKI must see there, drawn as the camera renders it.
  for (std::size_t r = 0; r < chosen.repairs->size(); ++r) {
    if (!positions[r] || !chosen.steps[*positions[r]].vision) continue;
    out << "<h3>" << html_escape(step_label(chosen, *positions[r])) << "</h3><ul>";
    vision_item(*chosen.steps[*positions[r]].vision, out);
    out << "</ul>\n";
  }
  const std::string dropped = internal::dropped_repairs(chosen);
  if (!dropped.empty())
    out << "<p class=\"dropped\">Not kept (the search keeps the smallest set that does best): "
        << html_escape(dropped) << ".</p>\n";
  out << "</section>\n";
}

void verification_section(const Report& report, std::ostringstream& out) {
  out << "<section id=\"verification\"><h2>Verification and recovery</h2>\n";
  bool any = false;
  const Chosen& chosen = *report.chosen;
  for (std::size_t k = 0; k < chosen.steps.size(); ++k) {
    const Step& step = chosen.steps[k];
    if (!step.verification) continue;
    any = true;
    out << "<h3>" << html_escape(step_label(chosen, k)) << "</h3><ul>";
    if (step.sensor_residual_needed)
      out << "<li>"
          << html_escape(internal::sensor_residual_text(report.units, *step.sensor_residual_needed))
          << "</li>";
    for (const Verification& plan : *step.verification) {
      out << "<li>verify: " << html_escape(plan.sense) << " (expect " << html_escape(plan.expect)
          << ")<ul>";
      if (plan.vision) vision_item(*plan.vision, out);
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
  out << "<section id=\"uncertainty\"><h2>Uncertainty variables</h2>\n<div class=\"scroll\">"
         "<table><tr><th>variable</th><th>source</th><th>object</th><th>allocated by</th>"
         "<th>range</th></tr>\n";
  for (const UncertaintyVariable& variable : variables)
    out << "<tr><td>" << html_escape(variable.name) << "</td><td>" << html_escape(variable.source)
        << "</td><td>" << html_escape(variable.object.value_or("(arm)")) << "</td><td>"
        << html_escape(internal::allocated_by(*report.chosen, variable))
        << "</td><td class=\"num\">" << html_escape(internal::half_width_text(variable))
        << "</td></tr>\n";
  out << "</table></div></section>\n";
}

// About how wide `text` is at `font_size` in the report's sans-serif (for boxes that fit it).
double text_width(const std::string& text, double font_size) {
  return 0.58 * font_size * static_cast<double>(text.size());
}

// The family's ordering graph (transitive reduction), layered top-down by longest path. Each step
// is named as everywhere ("#3 pickup block"), with the family's text under it, never cut.
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
  std::vector<std::string> labels;
  double width = 120;
  for (const FamilyStep& step : steps) {
    labels.push_back(internal::family_step_label(report, step));
    width = std::max({width, text_width(labels.back(), 11) + 16, text_width(step.text, 10) + 16});
  }
  constexpr double kHeight = 38, kRow = 66;
  const double column = width + 20;
  const auto centre_x = [&](int node) { return 10 + layout.position[node] * column + width / 2; };
  const auto top = [&](int node) { return 10.0 + layout.layer[node] * kRow; };
  const double svg_width = std::max(1, layout.widest) * column + 20;
  const double svg_height = layout.layers * kRow + 20;
  out << "<section id=\"ordering\"><h2>Ordering graph of the plan family</h2>\n<p class=\"note\">"
      << steps.size() << " steps, " << edges.size()
      << " ordering constraints (prior_to, transitive reduction); layers by longest path from the "
         "initial state. Steps are numbered as in the chosen plan.</p>\n<div class=\"scroll\">"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 "
      << px(svg_width) << " " << px(svg_height) << "\" width=\"" << px(svg_width) << "\" height=\""
      << px(svg_height)
      << "\" role=\"img\" aria-label=\"ordering graph\"><defs><marker id=\"arrow-ordering\" "
         "viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" "
         "orient=\"auto\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\"#6b7480\"/></marker></defs>\n";
  for (const auto& [from, to] : edges)
    out << "<line x1=\"" << px(centre_x(from)) << "\" y1=\"" << px(top(from) + kHeight)
        << "\" x2=\"" << px(centre_x(to)) << "\" y2=\"" << px(top(to) - 2)
        << "\" stroke=\"#6b7480\" stroke-width=\"1.3\" marker-end=\"url(#arrow-ordering)\"/>\n";
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const int node = static_cast<int>(i);
    out << "<g><title>" << html_escape(labels[i] + ": " + steps[i].text) << "</title><rect x=\""
        << px(centre_x(node) - width / 2) << "\" y=\"" << px(top(node)) << "\" width=\""
        << px(width) << "\" height=\"" << px(kHeight) << "\" rx=\"5\" fill=\""
        << action_colour(steps[i].action) << "\" stroke=\"#55606e\"/><text x=\""
        << px(centre_x(node)) << "\" y=\"" << px(top(node) + 15)
        << "\" font-size=\"11\" font-weight=\"bold\" text-anchor=\"middle\">"
        << html_escape(labels[i]) << "</text><text x=\"" << px(centre_x(node)) << "\" y=\""
        << px(top(node) + 30) << "\" font-size=\"10\" text-anchor=\"middle\">"
        << html_escape(steps[i].text) << "</text></g>\n";
  }
  out << "</svg></div></section>\n";
}

// The geometric constraint network: variables on a circle, arcs labelled with their pair counts;
// each variable names the steps that use it ("#2 pickup peg").
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
  std::vector<std::string> users;
  double width = 120;
  for (const PlanVariable& variable : variables) {
    users.push_back(internal::variable_users(report, variable.name));
    width = std::max({width, text_width(variable.name, 11) + 20, text_width(users.back(), 9) + 20});
  }
  const std::vector<internal::Point> ring = internal::circular_layout(count);
  const std::vector<int> slot = internal::circle_order(count, edges);
  // The circle's circumference gives each node its width and a gap.
  const double radius = std::max(110.0, (width + 40) * count / (2 * 3.14159265358979));
  const double size = 2 * radius + width + 60;
  const auto x = [&](int node) { return size / 2 + radius * ring[slot[node]].x; };
  const auto y = [&](int node) { return size / 2 + radius * ring[slot[node]].y; };
  out << "<section id=\"network\"><h2>Geometric constraint network</h2>\n<p class=\"note\">"
      << count << " plan variables (grasps, positions) with their label sets and the steps that "
      << "use them; " << family.arcs.size()
      << " binary constraints, each labelled with its number of allowed label pairs.</p>\n"
      << "<div class=\"scroll\"><svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 "
      << px(size) << " " << px(size) << "\" width=\"" << px(size) << "\" height=\"" << px(size)
      << "\" role=\"img\" aria-label=\"constraint network\">\n";
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
        << " of " << html_escape(variable.object) << "; " << html_escape(users[i])
        << "): " << html_escape(labels) << "</title><rect x=\"" << px(x(i) - width / 2) << "\" y=\""
        << px(y(i) - 22) << "\" width=\"" << px(width) << "\" height=\"44\" rx=\"14\" fill=\""
        << (variable.type == "grasp" ? "#cfe0fb" : "#cdeee6") << "\" stroke=\"#55606e\"/><text x=\""
        << px(x(i)) << "\" y=\"" << px(y(i) - 8) << "\" font-size=\"11\" text-anchor=\"middle\">"
        << html_escape(variable.name) << "</text><text x=\"" << px(x(i)) << "\" y=\""
        << px(y(i) + 5) << "\" font-size=\"9\" text-anchor=\"middle\">" << html_escape(users[i])
        << "</text><text x=\"" << px(x(i)) << "\" y=\"" << px(y(i) + 17)
        << "\" font-size=\"9\" text-anchor=\"middle\" fill=\"#55606e\">" << variable.labels.size()
        << " label" << (variable.labels.size() == 1 ? "" : "s") << "</text></g>\n";
  }
  out << "</svg></div></section>\n";
}

// The work cell from above and from the front: the initial state, then after every pickup,
// putdown and assembly (internal/cell_svg.hpp).
void cell_section(const Report& report, std::ostringstream& out) {
  out << "<section id=\"cell\"><h2>The work cell</h2>\n<p class=\"note\">From above (x right, y "
         "up) and from the front (x right, z up), lengths in "
      << html_escape(report.units.length)
      << ": the table, the robot's base and its reach (dashed, an upper bound), the places "
         "(crosses), each object's outline (held: orange), the gripper (grey), the box of "
         "positions the handled object may occupy (red, true scale) and inserted sensing "
         "(dashed rings).</p>\n<div class=\"cell-views\">\n";
  for (std::size_t v = 0; v < report.cell->views.size(); ++v)
    out << "<figure>" << internal::cell_view_svg(report, v, false) << "</figure>\n";
  out << "</div></section>\n";
}

void instances_section(const Report& report, std::ostringstream& out) {
  const Instances& instances = report.instances;
  out << "<section id=\"instances\"><h2>Instances considered</h2>\n<p>" << instances.count
      << (instances.count == 1 ? " plan instance enumerated" : " plan instances enumerated")
      << (instances.limit_reached ? " (the limit was reached: more exist)" : "")
      << "; phase 2 examines them in order until one has no error.</p>\n"
      << "<div class=\"scroll\"><table "
         "id=\"instance-table\"><tr><th>instance</th><th>errors</th><th>steps</th>"
         "<th>inserted</th><th>failed preconditions</th><th></th></tr>\n";
  for (const ExaminedInstance& examined : instances.examined) {
    out << "<tr class=\"instance\"><td class=\"num\">" << examined.index + 1
        << "</td><td class=\"num\">" << examined.errors << "</td><td class=\"num\">"
        << examined.steps << "</td><td class=\"num\">" << examined.inserted
        << "</td><td class=\"num\">" << examined.failed_preconditions << " / "
        << examined.preconditions << "</td><td>"
        << (report.chosen && report.chosen->index == examined.index ? "chosen" : "")
        << "</td></tr>\n";
  }
  out << "</table></div></section>\n";
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
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>spar "
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
    if (report.cell) cell_section(report, out);
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
