#include "spar/sensing/selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "spar/sensing/error.hpp"

namespace spar::sensing {
namespace {

Eigen::Vector3d target_centre(const HypothesisWorld& world) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& vertex :
       world.scene.objects()[static_cast<std::size_t>(world.target)].vertices)
    box.extend(vertex);
  return box.center();
}

std::vector<int> aspects_toward(const SelectionProblem& problem, const Eigen::Vector3d& direction) {
  std::vector<int> out;
  for (const HypothesisWorld& world : problem.hypotheses) {
    const Eigen::Matrix3d rotation =
        world.scene.objects()[static_cast<std::size_t>(world.target)].pose.linear();
    out.push_back(world.aspects->aspect_at(rotation.transpose() * direction));
  }
  return out;
}

void check_problem(const SelectionProblem& problem) {
  if (problem.hypotheses.empty()) throw SensingError("sense planning: no hypothesis");
  const int n = static_cast<int>(problem.hypotheses.size());
  if (problem.prior.frame_size() != n)
    throw SensingError("sense planning: a prior over " +
                       std::to_string(problem.prior.frame_size()) + " hypotheses for " +
                       std::to_string(n));
  if (problem.tolerances.size() != problem.sensors.size())
    throw SensingError("sense planning: one set of match tolerances per sensor is needed");
  for (const HypothesisWorld& world : problem.hypotheses) {
    if (!world.aspects)
      throw SensingError("sense planning: hypothesis '" + world.label + "' has no aspects");
    if (world.target < 0 || world.target >= static_cast<int>(world.scene.objects().size()))
      throw SensingError("sense planning: hypothesis '" + world.label + "' has no target");
  }
  for (const SensorModel& sensor : problem.sensors) check_sensor(sensor);
}

// The worst-case ambiguity of `candidate` from `belief`, given its expectations.
void score(const SelectionProblem& problem, const std::vector<Expectation>& expected,
           const MassFunction& belief, CandidateOperation& candidate,
           MassFunction* worst_belief = nullptr) {
  const int s = candidate.viewpoint.sensor;
  const SensorModel& sensor = problem.sensors[static_cast<std::size_t>(s)];
  candidate.ambiguity.clear();
  candidate.max_ambiguity = -1;
  for (std::size_t h = 0; h < expected.size(); ++h) {
    // What the sensor would report if h were true: h's expectation, noise-free, all found.
    Observation predicted{.sensor = sensor.name,
                          .kind = sensor.kind,
                          .sensor_pose = candidate.viewpoint.sensor_pose,
                          .faces = expected[h].faces,
                          .edges = expected[h].edges};
    const Weighing weighed = weigh_evidence(
        predicted, expected, problem.tolerances[static_cast<std::size_t>(s)], sensor, belief);
    const double ambiguity = weighed.combined.ambiguity();
    candidate.ambiguity.push_back(ambiguity);
    if (ambiguity > candidate.max_ambiguity) {
      candidate.max_ambiguity = ambiguity;
      candidate.worst = static_cast<int>(h);
      if (worst_belief) *worst_belief = weighed.combined;
    }
  }
}

}  // namespace

std::vector<Expectation> expectations(const SelectionProblem& problem, int sensor,
                                      const Eigen::Isometry3d& sensor_pose) {
  std::vector<Expectation> out;
  for (const HypothesisWorld& world : problem.hypotheses)
    out.push_back(expect(world.scene, world.target,
                         problem.sensors.at(static_cast<std::size_t>(sensor)), sensor_pose));
  return out;
}

std::vector<Viewpoint> candidate_viewpoints(const SelectionProblem& problem,
                                            const SelectionOptions& options) {
  check_problem(problem);
  if (!(options.standoff > 0)) throw SensingError("sense planning: the standoff must be > 0");
  if (options.viewpoint_level < 0 || options.viewpoint_level > 4)
    throw SensingError("sense planning: viewpoint_level must be 0 to 4");
  const Eigen::Vector3d centre = target_centre(problem.hypotheses.front());
  std::vector<Viewpoint> out;
  for (std::size_t s = 0; s < problem.sensors.size(); ++s) {
    const SensorModel& sensor = problem.sensors[s];
    if (sensor.mount == Mount::kFixed) {
      Viewpoint viewpoint;
      viewpoint.sensor = static_cast<int>(s);
      viewpoint.label = sensor.name;
      viewpoint.sensor_pose = sensor.pose;
      viewpoint.direction =
          sensor.projection == Projection::kOrthographic
              ? Eigen::Vector3d(-sensor.pose.linear().col(2))
              : Eigen::Vector3d((sensor.pose.translation() - centre).normalized());
      viewpoint.aspects = aspects_toward(problem, viewpoint.direction);
      out.push_back(viewpoint);
      continue;
    }
    // Wrist: directions above the table grouped by the aspects the hypotheses show.
    std::map<std::vector<int>, std::vector<Eigen::Vector3d>> classes;
    for (const Eigen::Vector3d& d : view_directions(options.viewpoint_level))
      if (std::asin(std::clamp(d.z(), -1.0, 1.0)) >= options.min_elevation)
        classes[aspects_toward(problem, d)].push_back(d);
    int index = 0;
    for (auto& [aspects, members] : classes) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& d : members) mean += d;
      std::sort(members.begin(), members.end(),
                [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
                  return a.dot(mean) > b.dot(mean);
                });
      Viewpoint viewpoint;
      viewpoint.sensor = static_cast<int>(s);
      char label[16];
      std::snprintf(label, sizeof label, "V%d", ++index);
      viewpoint.label = label;
      viewpoint.aspects = aspects;
      viewpoint.reachable = false;
      for (const Eigen::Vector3d& d : members) {
        const Eigen::Vector3d eye = centre + options.standoff * d;
        const Eigen::Vector3d up0 =
            std::abs(d.z()) < 0.99 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
        for (int roll = 0; roll < 4 && !viewpoint.reachable; ++roll) {
          const Eigen::Vector3d up = Eigen::AngleAxisd(roll * std::numbers::pi / 2, d) * up0;
          const Eigen::Isometry3d pose = look_at(eye, centre, up);
          if (!options.reachable || options.reachable(static_cast<int>(s), pose)) {
            viewpoint.sensor_pose = pose;
            viewpoint.direction = d;
            viewpoint.reachable = true;
          }
        }
        if (viewpoint.reachable) break;
      }
      if (!viewpoint.reachable) {  // listed with its best direction, never chosen
        viewpoint.direction = members.front();
        const Eigen::Vector3d up = std::abs(members.front().z()) < 0.99 ? Eigen::Vector3d::UnitZ()
                                                                        : Eigen::Vector3d::UnitX();
        viewpoint.sensor_pose = look_at(centre + options.standoff * members.front(), centre, up);
      }
      out.push_back(viewpoint);
    }
  }
  return out;
}

Selection select_operations(const SelectionProblem& problem, const SelectionOptions& options) {
  const std::vector<Viewpoint> viewpoints = candidate_viewpoints(problem, options);
  Selection out;
  out.ambiguity_before = problem.prior.ambiguity();
  std::vector<std::vector<Expectation>> expected(viewpoints.size());
  for (std::size_t c = 0; c < viewpoints.size(); ++c) {
    CandidateOperation candidate;
    candidate.viewpoint = viewpoints[c];
    if (viewpoints[c].reachable) {
      expected[c] = expectations(problem, viewpoints[c].sensor, viewpoints[c].sensor_pose);
      score(problem, expected[c], problem.prior, candidate);
    } else {
      candidate.max_ambiguity = std::numeric_limits<double>::infinity();
    }
    out.candidates.push_back(std::move(candidate));
  }
  MassFunction belief = problem.prior;
  std::vector<char> used(viewpoints.size(), 0);
  for (int step = 0; step < options.max_operations; ++step) {
    int best = -1;
    CandidateOperation best_score;
    MassFunction best_belief;
    for (std::size_t c = 0; c < viewpoints.size(); ++c) {
      if (used[c] || !viewpoints[c].reachable) continue;
      CandidateOperation scored;
      scored.viewpoint = viewpoints[c];
      MassFunction worst_belief;
      score(problem, expected[c], belief, scored, &worst_belief);
      if (best < 0 || scored.max_ambiguity < best_score.max_ambiguity - 1e-12) {
        best = static_cast<int>(c);
        best_score = scored;
        best_belief = worst_belief;
      }
    }
    // Stop when nothing is left or nothing lowers the worst-case ambiguity.
    if (best < 0 || best_score.max_ambiguity >= belief.ambiguity() - 1e-9) break;
    used[static_cast<std::size_t>(best)] = 1;
    out.sequence.push_back({.candidate = best,
                            .predicted_max_ambiguity = best_score.max_ambiguity,
                            .worst = best_score.worst,
                            .predicted = best_belief});
    belief = best_belief;
    if (best_score.max_ambiguity < options.ambiguity_threshold) {
      out.resolved = true;
      break;
    }
  }
  if (out.sequence.empty()) out.resolved = out.ambiguity_before < options.ambiguity_threshold;
  return out;
}

}  // namespace spar::sensing
