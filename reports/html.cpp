#include "spar/reports/html.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "spar/reports/internal/check.hpp"
#include "spar/reports/internal/layout.hpp"
#include "spar/reports/internal/text.hpp"
#include "spar/reports/markdown.hpp"

namespace spar::reports {
namespace {

using internal::html_escape;
using internal::Json;
using internal::rounded;
using internal::text;
using internal::value;

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

void summary_section(const Json& report, std::ostringstream& out) {
  const Json& units = report.at("units");
  out << "<h1>spar plan report: " << html_escape(text(report, "scenario")) << "</h1>\n";
  if (!text(report, "description").empty())
    out << "<p>" << html_escape(text(report, "description")) << "</p>\n";
  out << "<p class=\"note\">Report " << html_escape(text(report, "schema")) << ". Lengths in "
      << html_escape(text(units, "length")) << ", angles in " << html_escape(text(units, "angle"))
      << "; numbers are rounded for reading, the JSON report keeps the exact values.</p>\n"
      << "<section id=\"summary\"><div class=\"summary\">" << html_escape(summary(report))
      << "</div></section>\n";
}

// The chosen plan as boxes in execution order, six to a row.
void timeline_section(const Json& report, std::ostringstream& out) {
  const Json& steps = report.at("chosen").at("steps");
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
    const Json& step = steps[i];
    const int x = 10 + (i % kPerRow) * (kWidth + kGap), y = 10 + (i / kPerRow) * kRowHeight;
    const bool inserted = step.value("inserted", false), failed = step.value("failed", false);
    int holding = 0, total = 0;
    for (const Json& precondition : step.value("preconditions", Json::array())) {
      ++total;
      holding += precondition.at("verdict") == "satisfied" ? 1 : 0;
    }
    out << "<g class=\"step" << (inserted ? " inserted" : "") << "\"><title>"
        << html_escape(internal::step_title(step) + ": " + internal::step_details(report, step))
        << "</title><rect x=\"" << x << "\" y=\"" << y << "\" width=\"" << kWidth << "\" height=\""
        << kHeight << "\" rx=\"6\" fill=\"" << action_colour(text(step, "action")) << "\" stroke=\""
        << (failed ? "#b3261e" : "#55606e") << "\" stroke-width=\"" << (failed ? 2.5 : 1.2) << "\""
        << (inserted ? " stroke-dasharray=\"5,3\"" : "") << "/>\n"
        << "<text x=\"" << x + 8 << "\" y=\"" << y + 18
        << "\" font-size=\"12\" font-weight=\"bold\">" << i + 1 << ". "
        << html_escape(text(step, "action")) << "</text>\n"
        << "<text x=\"" << x + 8 << "\" y=\"" << y + 35 << "\" font-size=\"12\">"
        << html_escape(text(step, "object"))
        << (step.contains("fixed_object") ? " into " + html_escape(text(step, "fixed_object")) : "")
        << "</text>\n<text x=\"" << x + 8 << "\" y=\"" << y + 53 << "\" font-size=\"11\" fill=\""
        << (holding == total ? "#17723a" : "#b3261e") << "\">"
        << (total == 0
                ? std::string("no uncertainty checks")
                : std::to_string(holding) + "/" + std::to_string(total) + " preconditions hold")
        << "</text>\n";
    if (inserted)
      out << "<text x=\"" << x + kWidth - 6 << "\" y=\"" << y + 18
          << "\" font-size=\"10\" text-anchor=\"end\" fill=\"#a05a00\">inserted</text>\n";
    if (step.contains("verification"))
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
std::string bound_bar(const Json& precondition) {
  const Json& display = precondition.at("display");
  const double lo = value(display.at("lo")), hi = value(display.at("hi"));
  const double inner_lo = value(display.at("inner_lo")), inner_hi = value(display.at("inner_hi"));
  const double threshold = value(display.at("threshold"));
  const std::string relation = text(precondition, "relation");
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
  const std::string verdict = text(precondition, "verdict");
  const char* fill = verdict == "satisfied"  ? "#9fd8b0"
                     : verdict == "violated" ? "#f2aaa4"
                                             : "#f7cf91";
  const char* inner = verdict == "satisfied"  ? "#2e8b57"
                      : verdict == "violated" ? "#b3261e"
                                              : "#a05a00";
  std::string unit;
  if (text(display, "unit") != "1") unit.append(" ").append(text(display, "unit"));
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
std::string distribution_plot(const Json& report, const Json& entry) {
  const Json& precondition = internal::probability_precondition(report, entry);
  const Json& display = precondition.at("display");
  const double lo = value(display.at("lo")), hi = value(display.at("hi"));
  const double threshold = value(display.at("threshold"));
  const double mean = internal::precondition_display(report, entry, value(entry.at("mean")));
  const double sigma = internal::precondition_display(report, entry, value(entry.at("sigma")));
  const std::string relation = text(precondition, "relation");
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

void probability_section(const Json& report, std::ostringstream& out) {
  const Json& probability = report.at("chosen").at("probability");
  out << "<section id=\"probability\"><h2>Failure probability and tolerances</h2>\n<p "
         "class=\"note\">"
         "Beyond the worst case: each uncertainty variable is distributed in its box as the "
         "scenario says (uniform unless <code>distribution: gaussian</code>). σ is first order "
         "(J Σ Jᵀ); P first order is the linearised precondition's Gaussian truncated to the sound "
         "bound; Monte Carlo draws "
      << probability.at("samples").get<std::size_t>()
      << " points (95% Wilson interval). The plot: that Gaussian over the worst-case interval "
         "(the bar), the threshold dashed, the failing side tinted. A proved precondition fails "
         "with probability 0.</p>\n<p>P(some precondition fails) = "
      << html_escape(internal::monte_carlo_text(probability.at("plan"), false))
      << " (Monte Carlo).</p>\n<table id=\"probability-table\"><tr><th>step</th>"
         "<th>precondition</th><th>σ</th><th>P first order</th><th>P Monte Carlo</th>"
         "<th>distribution vs worst case</th><th>note</th></tr>\n";
  for (const Json& entry : probability.at("preconditions")) {
    const Json& step = report.at("chosen").at("steps").at(entry.at("step").get<std::size_t>());
    const bool proved = entry.at("proved").get<bool>();
    out << "<tr class=\"probability\"><td>" << step.at("id").get<int>() << " "
        << html_escape(internal::step_title(step)) << "</td><td><code>"
        << html_escape(text(entry, "name")) << "</code></td><td class=\"num\">"
        << html_escape(internal::sigma_text(report, entry)) << "</td><td class=\"num\">"
        << html_escape(internal::probability_text(value(entry.at("p_first_order")), proved))
        << "</td><td class=\"num\">" << html_escape(internal::monte_carlo_text(entry, proved))
        << "</td><td>" << distribution_plot(report, entry) << "</td><td class=\"note\">"
        << html_escape(text(entry, "note")) << "</td></tr>\n";
  }
  out << "</table>\n";
  const Json& tolerances = probability.at("tolerances");
  out << "<p>Tolerance allocation: " << html_escape(internal::allocation_text(tolerances))
      << ".</p>\n";
  if (text(tolerances, "status") != "not_needed") {
    out << "<table id=\"tolerance-table\"><tr><th>parameter</th><th>half-width</th>"
           "<th>allocated</th><th>cost</th></tr>\n";
    for (const Json& parameter : tolerances.at("parameters")) {
      const Json& display = parameter.at("display");
      const std::string unit = " " + text(display, "unit");
      out << "<tr><td>" << html_escape(text(parameter, "name")) << "</td><td class=\"num\">"
          << rounded(value(display.at("half_width"))) << html_escape(unit)
          << "</td><td class=\"num\">" << rounded(value(display.at("allocated")))
          << html_escape(unit) << "</td><td class=\"num\">" << rounded(value(parameter.at("cost")))
          << "</td></tr>\n";
    }
    out << "</table>\n";
  }
  out << "</section>\n";
}

// Up to six variables' shares of the bound's width, largest first.
std::string blame_bars(const Json& precondition) {
  if (!precondition.contains("blame")) return "<span class=\"note\">not computed</span>";
  const Json& blame = precondition.at("blame");
  const std::size_t shown = std::min<std::size_t>(blame.size(), 6);
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"blame\" width=\"250\" height=\""
      << 4 + 14 * shown << "\">";
  for (std::size_t i = 0; i < shown; ++i) {
    const double share = std::clamp(value(blame[i].at("share")), 0.0, 1.0);
    const double y = 2 + 14.0 * static_cast<double>(i);
    svg << "<g><title>" << html_escape(text(blame[i], "variable")) << ": "
        << rounded(100 * share, 3) << "% of the bound's width</title><text x=\"0\" y=\""
        << px(y + 10) << "\" font-size=\"10\">" << html_escape(text(blame[i], "variable"))
        << "</text><rect x=\"120\" y=\"" << px(y + 2) << "\" width=\""
        << px(std::max(0.5, 95 * share)) << "\" height=\"9\" fill=\"#5b7fb8\"/><text x=\""
        << px(122 + 95 * share) << "\" y=\"" << px(y + 10) << "\" font-size=\"9\">"
        << rounded(100 * share, 2) << "%</text></g>";
  }
  svg << "</svg>";
  return svg.str();
}

// The witness (the worst point found) in the variables' display units.
std::string witness_table(const Json& report, const Json& precondition,
                          const std::map<std::string, std::string>& variable_units) {
  const Json& witness = precondition.at("witness");
  if (witness.empty()) return "<span class=\"note\">none</span>";
  std::ostringstream out;
  out << "<details><summary>" << witness.size() << " values</summary><table class=\"witness\">";
  for (const auto& [name, number] : witness.items()) {
    const auto unit = variable_units.find(name);
    const bool angle = unit != variable_units.end() && unit->second == "rad";
    const double shown = angle ? internal::to_angle_unit(report, value(number))
                               : internal::to_length_unit(report, value(number));
    out << "<tr><td>" << html_escape(name) << "</td><td class=\"num\">" << rounded(shown, 4) << " "
        << html_escape(text(report.at("units"), angle ? "angle" : "length")) << "</td></tr>";
  }
  out << "</table></details>";
  return out.str();
}

void preconditions_section(const Json& report, std::ostringstream& out) {
  std::map<std::string, std::string> variable_units;
  for (const Json& variable : report.at("chosen").value("uncertainty_variables", Json::array()))
    variable_units[text(variable, "name")] = text(variable, "unit");
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
  for (const Json& step : report.at("chosen").at("steps")) {
    ++number;
    for (const Json& precondition : step.value("preconditions", Json::array())) {
      const std::string verdict = text(precondition, "verdict");
      out << "<tr class=\"precondition\" data-verdict=\"" << html_escape(verdict) << "\"><td>"
          << number << ". " << html_escape(internal::step_title(step)) << "</td><td><code title=\""
          << html_escape(text(precondition, "expression")) << "\">"
          << html_escape(text(precondition, "name")) << "</code></td><td>" << verdict_span(verdict)
          << "</td><td>" << html_escape(internal::requirement_text(precondition)) << "</td><td>"
          << html_escape(internal::bound_text(precondition)) << "<br><span class=\"note\">inner "
          << html_escape(internal::bound_text(precondition, true)) << "</span></td><td>"
          << bound_bar(precondition) << "</td><td>"
          << html_escape(internal::margin_text(report, precondition)) << "</td><td>"
          << witness_table(report, precondition, variable_units) << "</td><td>"
          << blame_bars(precondition) << "</td><td class=\"num\">"
          << (precondition.contains("monte_carlo_violation")
                  ? rounded(100 * value(precondition.at("monte_carlo_violation")), 3) + "%"
                  : std::string("-"))
          << "</td></tr>\n";
    }
  }
  out << "</table></section>\n";
}

void repairs_section(const Json& report, std::ostringstream& out) {
  out << "<section id=\"repairs\"><h2>Inserted sensing and squeeze</h2>\n";
  const Json& repairs = report.at("chosen").value("repairs", Json::array());
  if (repairs.empty()) {
    out << "<p>None tried: no precondition failed before repair.</p></section>\n";
    return;
  }
  out << "<table><tr><th>insertion</th><th>for step</th><th>outcome</th><th>precondition</th>"
         "<th>before</th><th>after</th></tr>\n";
  for (const Json& repair : repairs) {
    const Json& before = repair.at("before");
    const Json& after = repair.at("after");
    const Json* target = internal::step_by_id(report, repair.at("for_step").get<int>());
    for (std::size_t i = 0; i < before.size() && i < after.size(); ++i)
      out << "<tr><td>" << html_escape(text(repair, "action") + " " + text(repair, "object"))
          << "</td><td>" << repair.at("for_step").get<int>() << " "
          << (target != nullptr ? html_escape(internal::step_title(*target)) : "") << "</td><td>"
          << (repair.at("helped").get<bool>() ? "kept" : "dropped") << "</td><td><code>"
          << html_escape(text(before[i], "name")) << "</code></td><td>"
          << html_escape(internal::repair_bound_text(report, before[i])) << " "
          << verdict_span(text(before[i], "verdict")) << "</td><td>"
          << html_escape(internal::repair_bound_text(report, after[i])) << " "
          << verdict_span(text(after[i], "verdict")) << "</td></tr>\n";
  }
  out << "</table></section>\n";
}

void verification_section(const Json& report, std::ostringstream& out) {
  out << "<section id=\"verification\"><h2>Verification and recovery</h2>\n";
  bool any = false;
  for (const Json& step : report.at("chosen").at("steps")) {
    if (!step.contains("verification")) continue;
    any = true;
    out << "<h3>Step " << step.at("id").get<int>() << ": "
        << html_escape(internal::step_title(step)) << "</h3><ul>";
    if (step.contains("sensor_residual_needed"))
      out << "<li>"
          << html_escape(internal::sensor_residual_text(report, step.at("sensor_residual_needed")))
          << "</li>";
    for (const Json& plan : step.at("verification")) {
      out << "<li>verify: " << html_escape(text(plan, "sense")) << " (expect "
          << html_escape(text(plan, "expect")) << ")<ul>";
      for (const Json& outcome : plan.at("outcomes"))
        out << "<li>if " << html_escape(text(outcome, "when")) << ": "
            << html_escape(text(outcome, "error")) << ", recover by <b>"
            << html_escape(text(outcome, "recovery")) << "</b></li>";
      out << "</ul></li>";
    }
    for (const Json& recovery : step.value("recovery", Json::array())) {
      out << "<li>recovery <b>" << html_escape(text(recovery, "plan")) << "</b> for "
          << html_escape(text(recovery, "error")) << ": <ol>";
      for (const Json& action : recovery.at("steps"))
        out << "<li>" << html_escape(action.get<std::string>()) << "</li>";
      out << "</ol></li>";
    }
    out << "</ul>\n";
  }
  if (!any)
    out << "<p>Every precondition of the chosen plan holds: nothing to verify at execution.</p>";
  out << "</section>\n";
}

void uncertainty_section(const Json& report, std::ostringstream& out) {
  const Json& variables = report.at("chosen").value("uncertainty_variables", Json::array());
  if (variables.empty()) return;
  out << "<section id=\"uncertainty\"><h2>Uncertainty variables</h2>\n<table><tr><th>variable</th>"
         "<th>source</th><th>object</th><th>step</th><th>range</th></tr>\n";
  for (const Json& variable : variables)
    out << "<tr><td>" << html_escape(text(variable, "name")) << "</td><td>"
        << html_escape(text(variable, "source")) << "</td><td>"
        << html_escape(text(variable, "object", "(arm)")) << "</td><td class=\"num\">"
        << (variable.at("step").is_number() ? std::to_string(variable.at("step").get<int>()) : "")
        << "</td><td class=\"num\">" << html_escape(internal::half_width_text(variable))
        << "</td></tr>\n";
  out << "</table></section>\n";
}

// The family's ordering graph (transitive reduction), layered top-down by longest path.
void ordering_section(const Json& report, std::ostringstream& out) {
  const Json& family = report.at("family");
  const Json& steps = family.at("steps");
  std::map<int, int> node_of;  // step id -> node
  for (std::size_t i = 0; i < steps.size(); ++i)
    node_of[steps[i].at("id").get<int>()] = static_cast<int>(i);
  std::vector<std::pair<int, int>> edges;
  for (const Json& pair : family.at("ordering")) {
    const auto from = node_of.find(pair.at(0).get<int>()), to = node_of.find(pair.at(1).get<int>());
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
    std::string label = text(steps[i], "text");
    if (label.size() > 40) label = label.substr(0, 38) + "...";
    out << "<g><title>" << html_escape(text(steps[i], "text")) << "</title><rect x=\""
        << centre_x(node) - kWidth / 2 << "\" y=\"" << top(node) << "\" width=\"" << kWidth
        << "\" height=\"" << kHeight << "\" rx=\"5\" fill=\""
        << action_colour(text(steps[i], "action")) << "\" stroke=\"#55606e\"/><text x=\""
        << centre_x(node) << "\" y=\"" << top(node) + 19
        << "\" font-size=\"11\" text-anchor=\"middle\">" << steps[i].at("id").get<int>() << ": "
        << html_escape(label) << "</text></g>\n";
  }
  out << "</svg></div></section>\n";
}

// The geometric constraint network: variables on a circle, arcs labelled with their pair counts.
void network_section(const Json& report, std::ostringstream& out) {
  const Json& family = report.at("family");
  const Json& variables = family.at("variables");
  const int count = static_cast<int>(variables.size());
  std::map<std::string, int> node_of;
  for (int i = 0; i < count; ++i) node_of[text(variables[i], "name")] = i;
  std::vector<std::pair<int, int>> edges;
  for (const Json& arc : family.at("arcs")) {
    const auto first = node_of.find(arc.at("variables").at(0).get<std::string>());
    const auto second = node_of.find(arc.at("variables").at(1).get<std::string>());
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
      << family.at("arcs").size()
      << " binary constraints, each labelled with its number of allowed label pairs.</p>\n"
      << "<div class=\"scroll\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << px(size)
      << "\" height=\"" << px(size) << "\" role=\"img\" aria-label=\"constraint network\">\n";
  for (const Json& arc : family.at("arcs")) {
    const auto first = node_of.find(arc.at("variables").at(0).get<std::string>());
    const auto second = node_of.find(arc.at("variables").at(1).get<std::string>());
    if (first == node_of.end() || second == node_of.end()) continue;
    const int p = first->second, q = second->second;
    out << "<g><title>" << html_escape(arc.at("variables").at(0).get<std::string>()) << " - "
        << html_escape(arc.at("variables").at(1).get<std::string>()) << ": "
        << arc.at("pairs").size() << " allowed pairs</title><line x1=\"" << px(x(p)) << "\" y1=\""
        << px(y(p)) << "\" x2=\"" << px(x(q)) << "\" y2=\"" << px(y(q))
        << "\" stroke=\"#8893a2\" stroke-width=\"1.3\"/><text x=\"" << px((x(p) + x(q)) / 2)
        << "\" y=\"" << px((y(p) + y(q)) / 2 - 3) << "\" font-size=\"10\" fill=\"#2b5fad\" "
        << "text-anchor=\"middle\">" << arc.at("pairs").size() << "</text></g>\n";
  }
  for (int i = 0; i < count; ++i) {
    const Json& variable = variables[i];
    std::string labels;
    for (const Json& label : variable.at("labels"))
      labels.append(labels.empty() ? "" : " ").append(label.get<std::string>());
    out << "<g><title>" << html_escape(text(variable, "name")) << " ("
        << html_escape(text(variable, "type")) << " of " << html_escape(text(variable, "object"))
        << "): " << html_escape(labels) << "</title><rect x=\"" << px(x(i) - 60) << "\" y=\""
        << px(y(i) - 16) << "\" width=\"120\" height=\"32\" rx=\"14\" fill=\""
        << (text(variable, "type") == "grasp" ? "#cfe0fb" : "#cdeee6")
        << "\" stroke=\"#55606e\"/><text x=\"" << px(x(i)) << "\" y=\"" << px(y(i) - 2)
        << "\" font-size=\"11\" text-anchor=\"middle\">" << html_escape(text(variable, "name"))
        << "</text><text x=\"" << px(x(i)) << "\" y=\"" << px(y(i) + 11)
        << "\" font-size=\"9\" text-anchor=\"middle\" fill=\"#55606e\">"
        << variable.at("labels").size() << " label"
        << (variable.at("labels").size() == 1 ? "" : "s") << "</text></g>\n";
  }
  out << "</svg></div></section>\n";
}

void instances_section(const Json& report, std::ostringstream& out) {
  const Json& instances = report.at("instances");
  out << "<section id=\"instances\"><h2>Instances considered</h2>\n<p>"
      << instances.at("count").get<std::size_t>()
      << (instances.at("count") == 1 ? " plan instance enumerated" : " plan instances enumerated")
      << (instances.at("limit_reached").get<bool>() ? " (the limit was reached: more exist)" : "")
      << "; phase 2 examines them in order until one has no error.</p>\n"
      << "<table id=\"instance-table\"><tr><th>instance</th><th>errors</th><th>steps</th>"
         "<th>inserted</th><th>failed preconditions</th><th></th></tr>\n";
  const Json& chosen = report.at("chosen");
  for (const Json& examined : instances.at("examined")) {
    const std::size_t index = examined.at("index").get<std::size_t>();
    out << "<tr class=\"instance\"><td class=\"num\">#" << index + 1 << "</td><td class=\"num\">"
        << examined.at("errors").get<int>() << "</td><td class=\"num\">"
        << examined.at("steps").get<std::size_t>() << "</td><td class=\"num\">"
        << examined.at("inserted").get<std::size_t>() << "</td><td class=\"num\">"
        << examined.at("failed_preconditions").get<std::size_t>() << " / "
        << examined.at("preconditions").get<std::size_t>() << "</td><td>"
        << (chosen.is_object() && chosen.at("index") == index ? "chosen" : "") << "</td></tr>\n";
  }
  out << "</table></section>\n";
}

std::string html(const Json& report) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>spar "
         "report: "
      << html_escape(text(report, "scenario")) << "</title>\n<style>" << kStyle
      << "</style>\n</head>\n<body>\n";
  summary_section(report, out);
  if (report.at("chosen").is_object()) {
    timeline_section(report, out);
    preconditions_section(report, out);
    repairs_section(report, out);
    verification_section(report, out);
    if (report.at("chosen").contains("probability")) probability_section(report, out);
    uncertainty_section(report, out);
  }
  if (report.at("status") == "planned") {
    ordering_section(report, out);
    network_section(report, out);
  }
  instances_section(report, out);
  out << "</body>\n</html>\n";
  return out.str();
}

}  // namespace

std::string render_html(const nlohmann::ordered_json& report) {
  return internal::guarded("HTML", report, [&] { return html(report); });
}

}  // namespace spar::reports
