#include "spar/reports/qr_svg.hpp"

#include <sstream>
#include <string>
#include <vector>

namespace spar::reports {

using namespace qr;  // the match-striking model's names (kAngle, Trial, Limit, ...)

namespace {

// The plot's plane: digging depth across, angle up, in SVG user units.
struct Plane {
  static constexpr double kLeft = 70, kTop = 40, kWidth = 560, kHeight = 420;
  const ControlSpec& depth;
  const ControlSpec& angle;
  [[nodiscard]] double x_of(double value) const {
    return kLeft + (value - depth.minimum) / (depth.maximum - depth.minimum) * kWidth;
  }
  [[nodiscard]] double y_of(double value) const {
    return kTop + (angle.maximum - value) / (angle.maximum - angle.minimum) * kHeight;
  }
};

const char* colour_of_goal(int goal) {
  return goal == kBreakOnStrike ? "#d62728" : goal == kBreakOnStart ? "#1f77b4" : "#7f7f7f";
}

// The frame, its tick labels, the axis names and the title.
void write_axes(std::ostringstream& svg, const Plane& plane, const RunResult& run) {
  constexpr double kLeft = Plane::kLeft, kTop = Plane::kTop, kWidth = Plane::kWidth,
                   kHeight = Plane::kHeight;
  svg << "<rect x=\"" << kLeft << "\" y=\"" << kTop << "\" width=\"" << kWidth << "\" height=\""
      << kHeight << "\" fill=\"white\" stroke=\"black\"/>\n";
  for (double d = plane.depth.minimum; d <= plane.depth.maximum + 1e-9; d += 2) {
    svg << "<text x=\"" << plane.x_of(d) << "\" y=\"" << kTop + kHeight + 15
        << "\" text-anchor=\"middle\">" << d << "</text>\n";
  }
  for (double a = plane.angle.minimum; a <= plane.angle.maximum + 1e-9; a += 20) {
    svg << "<text x=\"" << kLeft - 6 << "\" y=\"" << plane.y_of(a) + 4 << "\" text-anchor=\"end\">"
        << a << "</text>\n";
  }
  svg << "<text x=\"" << kLeft + kWidth / 2 << "\" y=\"" << kTop + kHeight + 32
      << "\" text-anchor=\"middle\">digging depth [mm]</text>\n"
      << "<text x=\"18\" y=\"" << kTop + kHeight / 2 << "\" transform=\"rotate(-90 18 "
      << kTop + kHeight / 2 << ")\" text-anchor=\"middle\">angle [deg]</text>\n"
      << "<text x=\"" << kLeft << "\" y=\"24\">match striking search: " << run.trials.size()
      << " trials, " << to_string(run.status)
      << " (limits: grey no ignition, red break on strike, blue break on start)</text>\n";
}

// A limit: a bar on the excluded side of the bound, over the region it is visible from.
void write_limit(std::ostringstream& svg, const Plane& plane, const MatchStrikeModel& model,
                 const Limit& limit) {
  const int other = limit.control == kDiggingDepth ? kAngle : kDiggingDepth;
  const ControlSpec& spec = model.controls[other];
  double low = spec.minimum, high = spec.maximum;
  switch (limit.visibility[other]) {
    case Visibility::kEverywhere:
      break;
    case Visibility::kAtMost:
      high = limit.anchor[other];
      break;
    case Visibility::kAtLeast:
      low = limit.anchor[other];
      break;
    case Visibility::kSameValue:
      low = limit.anchor[other] - spec.resolution;
      high = limit.anchor[other] + spec.resolution;
      break;
  }
  const double thickness = 6;
  double x = 0, y = 0, w = 0, h = 0;
  if (limit.control == kAngle) {
    x = plane.x_of(low);
    w = plane.x_of(high) - x;
    y = limit.side == Side::kUpper ? plane.y_of(limit.bound) - thickness : plane.y_of(limit.bound);
    h = thickness;
  } else {
    y = plane.y_of(high);
    h = plane.y_of(low) - y;
    x = limit.side == Side::kLower ? plane.x_of(limit.bound) - thickness : plane.x_of(limit.bound);
    w = thickness;
  }
  svg << "<rect x=\"" << x << "\" y=\"" << y << "\" width=\"" << w << "\" height=\"" << h
      << "\" fill=\"" << colour_of_goal(limit.goal) << "\" fill-opacity=\"0.45\"><title>limit "
      << "from trial " << limit.trial << "</title></rect>\n";
}

// Trial `i`: its point (filled if it succeeded), number and gap, and an arrow to the change it
// planned.
void write_trial(std::ostringstream& svg, const Plane& plane, const MatchStrikeModel& model,
                 const Trial& trial, std::size_t i) {
  const double x = plane.x_of(trial.controls[kDiggingDepth]);
  const double y = plane.y_of(trial.controls[kAngle]);
  if (trial.plan && trial.plan->control != kJumpingGap) {
    std::vector<double> next = trial.controls;
    next[trial.plan->control] = trial.plan->to;
    svg << "<line x1=\"" << x << "\" y1=\"" << y << "\" x2=\"" << plane.x_of(next[kDiggingDepth])
        << "\" y2=\"" << plane.y_of(next[kAngle])
        << "\" stroke=\"black\" stroke-width=\"1\" marker-end=\"url(#arrow)\"/>\n";
  }
  const char* fill = trial.status == Status::kSuccess ? "#2ca02c" : "white";
  svg << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"4\" fill=\"" << fill
      << "\" stroke=\"black\"/>\n"
      << "<text x=\"" << x + 6 << "\" y=\"" << y - 6 + 12.0 * (i % 2) << "\">" << trial.number
      << (trial.controls[kJumpingGap] < model.controls[kJumpingGap].maximum
              ? " (gap " + std::to_string(static_cast<int>(trial.controls[kJumpingGap])) + ")"
              : "")
      << "</text>\n";
}

}  // namespace

std::string match_strike_svg(const MatchStrikeModel& model, const RunResult& run) {
  const Plane plane{.depth = model.controls[kDiggingDepth], .angle = model.controls[kAngle]};
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"700\" height=\"520\" "
         "font-family=\"sans-serif\" font-size=\"11\">\n"
      << "<defs><marker id=\"arrow\" markerWidth=\"8\" markerHeight=\"8\" refX=\"7\" refY=\"4\" "
         "orient=\"auto\"><path d=\"M0,0 L8,4 L0,8 z\" fill=\"black\"/></marker></defs>\n";
  write_axes(svg, plane, run);
  for (const Trial& trial : run.trials)
    for (const Limit& limit : trial.limits_asserted)
      if (limit.control != kJumpingGap) write_limit(svg, plane, model, limit);  // not in the plane
  for (std::size_t i = 0; i < run.trials.size(); ++i)
    write_trial(svg, plane, model, run.trials[i], i);
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace spar::reports
