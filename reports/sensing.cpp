#include "spar/reports/sensing.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "spar/reports/internal/text.hpp"

namespace spar::reports {
namespace {

using internal::cell_escape;
using internal::html_escape;
using internal::rounded;

constexpr int kSampleLevel = 2;  // the drawings' samples: 320 directions

std::array<double, 3> array_of(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

NamedValues<double> named(const std::vector<std::string>& names,
                          const std::vector<double>& values) {
  NamedValues<double> out;
  for (std::size_t i = 0; i < names.size() && i < values.size(); ++i)
    out.emplace_back(names[i], values[i]);
  return out;
}

ViewSphere view_sphere(const std::string& identity, const sensing::AspectSet& aspects) {
  ViewSphere out;
  out.identity = identity;
  out.method = sensing::to_string(aspects.method);
  for (const sensing::Aspect& aspect : aspects.aspects)
    out.aspects.push_back({.label = aspect.label,
                           .faces = aspect.faces,
                           .solid_angle = aspect.solid_angle,
                           .direction = array_of(aspect.direction)});
  for (const Eigen::Vector3d& direction : sensing::view_directions(kSampleLevel)) {
    out.samples.push_back(array_of(direction));
    const int index = aspects.aspect_at(direction);
    out.sample_aspects.push_back(
        index < 0 ? "" : aspects.aspects[static_cast<std::size_t>(index)].label);
  }
  return out;
}

// "P1 0.5, P2 0.5".
std::string beliefs_text(const NamedValues<double>& beliefs) {
  std::string out;
  for (const auto& [name, value] : beliefs)
    out += (out.empty() ? "" : ", ") + name + " " + rounded(value);
  return out;
}

std::string aspects_text(const NamedValues<std::string>& aspects) {
  std::string out;
  for (const auto& [hypothesis, label] : aspects)
    out += (out.empty() ? "" : ", ") + hypothesis + ": " + (label.empty() ? "-" : label);
  return out;
}

std::string direction_text(const std::array<double, 3>& d) {
  return "(" + internal::fixed(d[0], 2) + ", " + internal::fixed(d[1], 2) + ", " +
         internal::fixed(d[2], 2) + ")";
}

std::string max_text(const Nullable<double>& value) {
  return value ? rounded(*value) + " bits" : "-";
}

// The reachable candidates, least predicted worst-case ambiguity first (ties in planning order):
// the table a reader scans for the best view. The unreachable ones are only listed by name.
std::vector<const SensingCandidate*> reachable_by_ambiguity(const ObjectSensing& object) {
  std::vector<const SensingCandidate*> rows;
  for (const SensingCandidate& candidate : object.candidates)
    if (candidate.reachable) rows.push_back(&candidate);
  std::ranges::stable_sort(rows, {}, [](const SensingCandidate* candidate) {
    return candidate->predicted_max_ambiguity.value_or(0.0);
  });
  return rows;
}

// "3 unreachable viewpoints: camera v12, camera v13, arm v2" (empty when every one is reachable).
std::string unreachable_text(const ObjectSensing& object) {
  std::string names;
  int count = 0;
  for (const SensingCandidate& candidate : object.candidates)
    if (!candidate.reachable) {
      names += (names.empty() ? "" : ", ") + candidate.sensor + " " + candidate.viewpoint;
      ++count;
    }
  if (count == 0) return "";
  return std::to_string(count) +
         (count == 1 ? " unreachable viewpoint: " : " unreachable viewpoints: ") + names;
}

// A colour per aspect label, far apart for neighbours (golden-angle hues).
std::string colour(const std::map<std::string, int>& index, const std::string& label) {
  const auto found = index.find(label);
  if (found == index.end()) return "#cccccc";
  const int hue = static_cast<int>(std::fmod(found->second * 137.508, 360.0));
  return "hsl(" + std::to_string(hue) + ",65%,55%)";
}

}  // namespace

ObjectSensing build_object_sensing(const planner::ObjectSensePlan& plan) {
  ObjectSensing out;
  out.object = plan.object;
  out.hypotheses = plan.hypotheses;
  out.identities = plan.identities;
  out.threshold = plan.threshold;
  out.beliefs_before = named(plan.hypotheses, plan.beliefs_before);
  out.ambiguity_before = plan.selection.ambiguity_before;
  const auto aspects_of = [&](std::size_t candidate) {
    NamedValues<std::string> labels;
    for (std::size_t h = 0; h < plan.hypotheses.size(); ++h)
      labels.emplace_back(plan.hypotheses[h], plan.candidate_aspects[candidate][h]);
    return labels;
  };
  for (std::size_t c = 0; c < plan.selection.candidates.size(); ++c) {
    const sensing::CandidateOperation& candidate = plan.selection.candidates[c];
    SensingCandidate row;
    row.sensor = plan.sensors[static_cast<std::size_t>(candidate.viewpoint.sensor)];
    row.viewpoint = candidate.viewpoint.label;
    row.direction = array_of(candidate.viewpoint.direction);
    row.reachable = candidate.viewpoint.reachable;
    row.aspects = aspects_of(c);
    if (row.reachable) {
      row.predicted_ambiguity = named(plan.hypotheses, candidate.ambiguity);
      row.predicted_max_ambiguity = candidate.max_ambiguity;
    }
    out.candidates.push_back(std::move(row));
  }
  std::vector<double> after = plan.beliefs_before;
  out.ambiguity_after = plan.selection.ambiguity_before;
  for (const sensing::ChosenOperation& chosen : plan.selection.sequence) {
    const SensingCandidate& row = out.candidates[static_cast<std::size_t>(chosen.candidate)];
    SensingOperation operation;
    operation.sensor = row.sensor;
    operation.viewpoint = row.viewpoint;
    operation.aspects = row.aspects;
    operation.aspect = row.aspects.empty() ? "" : row.aspects.front().second;
    operation.predicted_max_ambiguity = chosen.predicted_max_ambiguity;
    operation.worst_case = plan.hypotheses[static_cast<std::size_t>(chosen.worst)];
    after = chosen.predicted.pignistic();
    operation.beliefs = named(plan.hypotheses, after);
    out.ambiguity_after = chosen.predicted_max_ambiguity;
    out.sequence.push_back(std::move(operation));
  }
  out.resolved = plan.selection.resolved;
  out.beliefs_after = named(plan.hypotheses, after);
  for (std::size_t i = 0; i < plan.identities.size(); ++i)
    out.view_spheres.push_back(view_sphere(plan.identities[i], plan.identity_aspects[i]));
  return out;
}

SensePlanRecord build_sense_plan(const planner::Scenario& scenario,
                                 const planner::SensePlan& plan) {
  SensePlanRecord out;
  out.scenario = scenario.name;
  for (const planner::ObjectSensePlan& object : plan.objects)
    out.objects.push_back(build_object_sensing(object));
  return out;
}

std::string sensing_markdown(const std::vector<ObjectSensing>& objects) {
  if (objects.empty()) return "";
  std::ostringstream out;
  out << "\n## Sensing\n";
  for (const ObjectSensing& object : objects) {
    out << "\n### " << object.object << ": " << object.hypotheses.size()
        << " hypotheses, threshold " << rounded(object.threshold) << " bits\n\n"
        << "Beliefs before (pignistic): " << beliefs_text(object.beliefs_before) << "; ambiguity "
        << rounded(object.ambiguity_before) << " bits.\n\n"
        << "| sensor | viewpoint | direction | aspects | predicted ambiguity | max |\n"
        << "|---|---|---|---|---|--:|\n";
    for (const SensingCandidate* candidate : reachable_by_ambiguity(object))
      out << "| " << cell_escape(candidate->sensor) << " | " << cell_escape(candidate->viewpoint)
          << " | " << direction_text(candidate->direction) << " | "
          << cell_escape(aspects_text(candidate->aspects)) << " | "
          << cell_escape(beliefs_text(candidate->predicted_ambiguity)) << " | "
          << max_text(candidate->predicted_max_ambiguity) << " |\n";
    out << '\n';
    if (const std::string unreachable = unreachable_text(object); !unreachable.empty())
      out << unreachable << ".\n\n";
    if (object.sequence.empty()) out << "No operation lowers the ambiguity.\n";
    int number = 0;
    for (const SensingOperation& operation : object.sequence)
      out << ++number << ". " << operation.sensor << " at " << operation.viewpoint << " (aspect "
          << (operation.aspect.empty() ? "-" : operation.aspect) << "): at most "
          << rounded(operation.predicted_max_ambiguity) << " bits (worst case "
          << operation.worst_case << "), beliefs then " << beliefs_text(operation.beliefs) << "\n";
    out << "\n"
        << (object.resolved ? "Resolved" : "Not resolved")
        << ": beliefs after, worst case: " << beliefs_text(object.beliefs_after) << "; ambiguity "
        << rounded(object.ambiguity_after) << " bits.\n";
  }
  return out.str();
}

std::string view_sphere_svg(const ViewSphere& sphere) {
  constexpr double kRadius = 90, kGap = 30, kTop = 22;
  std::map<std::string, int> index;
  for (std::size_t i = 0; i < sphere.aspects.size(); ++i)
    index[sphere.aspects[i].label] = static_cast<int>(i);
  std::ostringstream svg;
  const double width = 4 * kRadius + 3 * kGap;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"view-sphere\" width=\"" << width
      << "\" height=\"" << 2 * kRadius + kTop + 10 << "\">";
  for (int half = 0; half < 2; ++half) {
    const double cx = kGap + kRadius + half * (2 * kRadius + kGap), cy = kTop + kRadius;
    svg << "<text x=\"" << cx << "\" y=\"14\" font-size=\"11\" text-anchor=\"middle\">"
        << (half == 0 ? "from above (z > 0)" : "from below (z < 0)") << "</text>"
        << "<circle cx=\"" << cx << "\" cy=\"" << cy << "\" r=\"" << kRadius
        << "\" fill=\"none\" stroke=\"#888\"/>";
    for (std::size_t s = 0; s < sphere.samples.size(); ++s) {
      const auto& d = sphere.samples[s];
      if ((half == 0) != (d[2] >= 0)) continue;
      // Orthographic from above (x right, y up) or from below (x mirrored).
      const double x = cx + (half == 0 ? d[0] : -d[0]) * kRadius, y = cy - d[1] * kRadius;
      svg << "<circle cx=\"" << internal::fixed(x, 1) << "\" cy=\"" << internal::fixed(y, 1)
          << "\" r=\"4\" fill=\"" << colour(index, sphere.sample_aspects[s]) << "\"><title>"
          << html_escape(sphere.sample_aspects[s]) << "</title></circle>";
    }
  }
  svg << "</svg>";
  return svg.str();
}

std::string sensing_html(const std::vector<ObjectSensing>& objects) {
  if (objects.empty()) return "";
  std::ostringstream out;
  out << "<section><h2>Sensing</h2>\n";
  for (const ObjectSensing& object : objects) {
    out << "<h3>" << html_escape(object.object) << ": " << object.hypotheses.size()
        << " hypotheses, threshold " << rounded(object.threshold)
        << " bits</h3>\n<p>Beliefs before "
        << "(pignistic): " << html_escape(beliefs_text(object.beliefs_before)) << "; ambiguity "
        << rounded(object.ambiguity_before) << " bits.</p>\n<div class=\"scroll\"><table><tr>"
        << "<th>sensor</th><th>viewpoint</th><th>direction</th><th>aspects</th>"
        << "<th>predicted ambiguity</th><th>max</th></tr>\n";
    for (const SensingCandidate* candidate : reachable_by_ambiguity(object))
      out << "<tr><td>" << html_escape(candidate->sensor) << "</td><td>"
          << html_escape(candidate->viewpoint) << "</td><td>"
          << direction_text(candidate->direction) << "</td><td>"
          << html_escape(aspects_text(candidate->aspects)) << "</td><td>"
          << html_escape(beliefs_text(candidate->predicted_ambiguity)) << "</td><td>"
          << max_text(candidate->predicted_max_ambiguity) << "</td></tr>\n";
    out << "</table></div>\n";
    if (const std::string unreachable = unreachable_text(object); !unreachable.empty())
      out << "<details><summary>" << html_escape(unreachable.substr(0, unreachable.find(':')))
          << "</summary><p>" << html_escape(unreachable.substr(unreachable.find(':') + 2))
          << "</p></details>\n";
    out << "<ol>";
    for (const SensingOperation& operation : object.sequence)
      out << "<li>" << html_escape(operation.sensor) << " at " << html_escape(operation.viewpoint)
          << " (aspect " << html_escape(operation.aspect.empty() ? "-" : operation.aspect)
          << "): at most " << rounded(operation.predicted_max_ambiguity) << " bits (worst case "
          << html_escape(operation.worst_case) << "), beliefs then "
          << html_escape(beliefs_text(operation.beliefs)) << "</li>";
    out << "</ol>\n<p>" << (object.resolved ? "Resolved" : "Not resolved")
        << ": beliefs after, worst case: " << html_escape(beliefs_text(object.beliefs_after))
        << ".</p>\n";
    for (const ViewSphere& sphere : object.view_spheres)
      out << "<h4>View sphere of " << html_escape(sphere.identity) << " (" << sphere.aspects.size()
          << " aspects, " << html_escape(sphere.method) << ")</h4>\n<div class=\"scroll\">"
          << view_sphere_svg(sphere) << "</div>\n";
  }
  out << "</section>\n";
  return out.str();
}

}  // namespace spar::reports
