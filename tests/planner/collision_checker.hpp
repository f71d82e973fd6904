// An independent collision checker for plan instances (issue 21): it re-simulates an instance on
// its own world state and checks, with its own geometry, that no two bodies interpenetrate in any
// state and anywhere along SPAR's straight-line approaches and retreats. It shares no code with
// the planner's collision layer (no FCL, no geometry/collision.hpp): triangles from the objects'
// meshes, the gripper's three boxes built here from the GripperSpec, and two exact-in-spirit
// tests on doubles:
//   * crossing: some edge of one triangle set passes through some triangle of the other
//     (segment-triangle intersection, Moller-Trumbore), in either direction;
//   * containment: a vertex of one closed mesh lies inside the other (ray casting: the parity of
//     the crossings of a ray in a fixed, skew direction).
// Two closed bodies interpenetrate exactly when one of these holds (surfaces that cross have an
// edge of one through a face of the other). Touching counts as interpenetrating, so it checks
// more strictly than "no overlap": the planner keeps its margin (1 mm by default) anyway.
//
// The motions checked (the rules of planner/world.hpp, re-derived from SPAR's execution): with T
// the gripper pose, a its approach axis, d = robot.approach_distance:
//   pickup, putdown, squeeze:  the open gripper between T - d a and T (against every other
//                              object, and its own object with the gripper shrunk by 1 um: the
//                              pads may rest on the contact faces), and the gripper closed on the
//                              object (with what is assembled into it) between T and T - d a;
//   assemble h into f:         the closed gripper with h from T - d m to T (m the mating vector
//                              in the world) against everything but h and f, the gripper against
//                              f, h's faces other than its mating ones against f's (each triangle
//                              pulled in by 1 um: faces meeting the joint along an edge do not
//                              count; h and f touch at the joint by design); then the open
//                              gripper from T to T - d a against everything but h.
// Each motion is checked at samples `kStep` apart (0.25 mm, a quarter of the default margin: an
// overlap the planner's sweep let through, which keeps half the margin everywhere, would show).
// The table: no body below z = -1e-6 m at a motion's ends (translations: the lowest point is at
// an end). After every step every object rests on the table or sits in the one it is assembled
// into, and every subassembly that has moved (or started in a stable pose) stands as one body:
// its centre of mass (the parts' volume centres, from signed tetrahedra, weighted by volume)
// lies seen from above strictly inside the convex hull of its vertices on the table (brute
// force: inside every line through two of them that has all of them on one side).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "spar/planner/plan.hpp"

namespace spar::planner::testing {

struct Triangles {
  std::vector<std::array<Eigen::Vector3d, 3>> faces;
  bool closed{true};  // containment is asked of closed sets only
};

inline Triangles posed(const Triangles& local, const kinematics::Transform& pose) {
  Triangles out{.faces = {}, .closed = local.closed};
  for (const auto& face : local.faces)
    out.faces.push_back({pose * face[0], pose * face[1], pose * face[2]});
  return out;
}

inline void append(Triangles& to, const Triangles& more) {
  to.faces.insert(to.faces.end(), more.faces.begin(), more.faces.end());
}

// The mesh's triangles; with `without`, all but those faces, each triangle pulled in toward its
// centroid by `inset` (a patch: not closed; faces that meet the missing ones only along an edge
// then do not touch them).
inline Triangles mesh_triangles(const geometry::ObjectModel& model,
                                const std::vector<int>& without = {}, double inset = 0) {
  std::vector<char> dropped(model.mesh().triangles.size(), 0);
  for (const int id : without)
    for (const int t : model.face(id).triangles) dropped[t] = 1;
  Triangles out{.faces = {}, .closed = without.empty()};
  const auto& mesh = model.mesh();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (dropped[t]) continue;
    std::array<Eigen::Vector3d, 3> face = {mesh.vertices[mesh.triangles[t][0]],
                                           mesh.vertices[mesh.triangles[t][1]],
                                           mesh.vertices[mesh.triangles[t][2]]};
    const Eigen::Vector3d centroid = (face[0] + face[1] + face[2]) / 3;
    for (Eigen::Vector3d& corner : face)
      corner += (centroid - corner) * std::min(1.0, inset / (centroid - corner).norm());
    out.faces.push_back(face);
  }
  return out;
}

inline Triangles box_triangles(Eigen::Vector3d low, Eigen::Vector3d high) {
  const auto corner = [&](int i) {
    return Eigen::Vector3d((i & 1) ? high.x() : low.x(), (i & 2) ? high.y() : low.y(),
                           (i & 4) ? high.z() : low.z());
  };
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  Triangles out;
  for (const auto& q : quads) {
    out.faces.push_back({corner(q[0]), corner(q[1]), corner(q[2])});
    out.faces.push_back({corner(q[0]), corner(q[2]), corner(q[3])});
  }
  return out;
}

// The gripper in its frame: fingers at y = +-opening/2 outward by the thickness, from the palm
// (finger_length - tip_beyond_contact behind z = 0) to tip_beyond_contact; the palm spans the
// fully open fingers. Each box shrunk by `shrink`. Boxes are separate closed sets.
inline std::vector<Triangles> gripper_triangles(const geometry::GripperSpec& g, double opening,
                                                double shrink = 0) {
  const double tip = g.tip_beyond_contact, palm = tip - g.finger_length;
  const double fx = g.finger_width / 2, px = g.palm_width / 2;
  const double in = opening / 2, out = opening / 2 + g.finger_thickness;
  const double py = g.max_opening / 2 + g.finger_thickness;
  const Eigen::Vector3d s = Eigen::Vector3d::Constant(shrink);
  return {box_triangles(Eigen::Vector3d(-fx, in, palm) + s, Eigen::Vector3d(fx, out, tip) - s),
          box_triangles(Eigen::Vector3d(-fx, -out, palm) + s, Eigen::Vector3d(fx, -in, tip) - s),
          box_triangles(Eigen::Vector3d(-px, -py, palm - g.palm_height) + s,
                        Eigen::Vector3d(px, py, palm) - s)};
}

// Does the closed segment p-q meet the triangle? (Moller-Trumbore, with the parameter in [0, 1].)
inline bool segment_meets_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                   const std::array<Eigen::Vector3d, 3>& t) {
  const Eigen::Vector3d d = q - p, e1 = t[1] - t[0], e2 = t[2] - t[0];
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-18) return false;  // parallel: a crossing shows on another edge
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = p - t[0];
  const double u = inv * s.dot(h);
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0 || u + v > 1) return false;
  const double along = inv * e2.dot(qv);
  return along >= 0 && along <= 1;
}

inline Eigen::AlignedBox3d box_of(const Triangles& set) {
  Eigen::AlignedBox3d box;
  for (const auto& face : set.faces)
    for (const auto& v : face) box.extend(v);
  return box;
}

inline bool edges_cross(const Triangles& a, const Triangles& b) {
  const Eigen::AlignedBox3d box_b = box_of(b);
  for (const auto& face : a.faces)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d &p = face[k], &q = face[(k + 1) % 3];
      Eigen::AlignedBox3d edge;
      edge.extend(p);
      edge.extend(q);
      if (!edge.intersects(box_b)) continue;
      for (const auto& other : b.faces)
        if (segment_meets_triangle(p, q, other)) return true;
    }
  return false;
}

// Ray casting along a skew direction: an odd number of crossings means inside.
inline bool point_inside(const Eigen::Vector3d& point, const Triangles& closed) {
  if (!closed.closed || !box_of(closed).contains(point)) return false;
  const Eigen::Vector3d far = point + 1e3 * Eigen::Vector3d(0.5773, 0.5129, 0.6352);
  int crossings = 0;
  for (const auto& face : closed.faces) crossings += segment_meets_triangle(point, far, face);
  return crossings % 2 == 1;
}

inline bool interpenetrate(const Triangles& a, const Triangles& b) {
  if (a.faces.empty() || b.faces.empty() || !box_of(a).intersects(box_of(b))) return false;
  return edges_cross(a, b) || edges_cross(b, a) || point_inside(a.faces[0][0], b) ||
         point_inside(b.faces[0][0], a);
}

inline double lowest(const Triangles& set) {
  double z = INFINITY;
  for (const auto& face : set.faces)
    for (const auto& v : face) z = std::min(z, v.z());
  return z;
}

// The volume and the centre of a closed set (signed tetrahedra from the origin).
inline std::pair<double, Eigen::Vector3d> volume_and_centre(const Triangles& closed) {
  double volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const auto& f : closed.faces) {
    const double v = f[0].dot(f[1].cross(f[2])) / 6;
    volume += v;
    moment += v * (f[0] + f[1] + f[2]) / 4;
  }
  return {volume, moment / volume};
}

// `point` lies further than `inset` inside every supporting line of `points` (a line through two
// of them with none on its right); false when there is no such line or the points are collinear
// (then both orientations of their line support them).
inline bool strictly_inside_hull(const std::vector<Eigen::Vector2d>& points,
                                 const Eigen::Vector2d& point, double inset) {
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
  };
  bool supported = false;
  for (const auto& p : points)
    for (const auto& q : points) {
      const Eigen::Vector2d edge = q - p;
      if (edge.norm() < 1e-12) continue;
      const bool supporting = std::all_of(points.begin(), points.end(), [&](const auto& r) {
        return cross(edge, r - p) / edge.norm() >= -1e-12;
      });
      if (!supporting) continue;
      supported = true;
      if (cross(edge, point - p) / edge.norm() <= inset) return false;
    }
  return supported;
}

class IndependentCollisionChecker {
 public:
  static constexpr double kStep = 0.00025;  // metres between samples of a motion

  // `scenario` must outlive the checker.
  IndependentCollisionChecker(const Scenario& scenario,
                              std::vector<std::vector<geometry::Grasp>> grasps)
      : scenario_(scenario), grasps_(std::move(grasps)) {
    for (const ObjectSpec& object : scenario.objects)
      meshes_.push_back(mesh_triangles(object.model));
  }

  // Every collision of the instance, as text; empty when there is none.
  std::vector<std::string> check(const PlanInstance& instance) const {
    std::vector<std::string> problems;
    const std::size_t n = scenario_.objects.size();
    std::vector<kinematics::Transform> poses;
    for (const ObjectSpec& object : scenario_.objects) poses.push_back(object.initial_pose);
    std::vector<int> carrier(n, -1);
    for (const Goal& goal : scenario_.goals)
      if (const auto* a = std::get_if<AssembledGoal>(&goal)) {
        const int h = index(a->held), f = index(a->fixed);
        if ((poses[f] * a->relative).isApprox(poses[h], 1e-7)) carrier[h] = f;
      }
    const auto group = [&](int o) {
      std::vector<int> members = {o};
      for (std::size_t i = 0; i < members.size(); ++i)
        for (std::size_t k = 0; k < n; ++k)
          if (carrier[k] == members[i]) members.push_back(static_cast<int>(k));
      return members;
    };
    const auto move = [&](int o, const kinematics::Transform& pose) {
      const kinematics::Transform change = pose * poses[o].inverse(Eigen::Isometry);
      for (const int k : group(o)) poses[k] = change * poses[k];
    };
    const double d = scenario_.robot.approach_distance;
    const geometry::GripperSpec& spec = scenario_.robot.gripper;
    int number = 0;
    for (const InstanceStep& step : instance.steps) {
      ++number;
      if (step.grasp < 0) continue;
      const std::string where = "step " + std::to_string(number) + " (" + step.action_name + " " +
                                scenario_.objects[step.object].name + "): ";
      const geometry::Grasp& grasp = grasps_.at(step.object).at(step.grasp);
      if (step.is_assembly()) {
        const AssembledGoal& goal = goal_of(step.object, step.fixed_object);
        move(step.object, step.held_pose);
        const std::vector<int> moving = group(step.object);
        const kinematics::Transform t = step.held_pose * grasp.gripper_in_object;
        const Eigen::Vector3d m = (step.fixed_pose.linear() * goal.mating_vector).normalized();
        closed_against_parts(problems, where, grasp, moving, poses, t);
        // Closed gripper + h (+ parts) along m, against all but h's group and f.
        const kinematics::Transform start = Eigen::Translation3d(-d * m) * t;
        std::vector<int> excluded = moving;
        excluded.push_back(step.fixed_object);
        sweep(problems, where + "inserting, ", held_set(grasp, moving, poses, t), start, d * m,
              others(poses, excluded));
        // The gripper (+ h's parts) against f; h's patch against f's patch.
        std::vector<Triangles> gripper = gripper_triangles(spec, grasp.width);
        for (std::size_t k = 1; k < moving.size(); ++k)
          gripper.push_back(
              posed(meshes_[moving[k]], t.inverse(Eigen::Isometry) * poses[moving[k]]));
        const std::string& fixed_name = scenario_.objects[step.fixed_object].name;
        sweep(problems, where + "the gripper inserting, ", gripper, start, d * m,
              {{fixed_name, posed(meshes_[step.fixed_object], poses[step.fixed_object])}});
        const Triangles held_patch =
            mesh_triangles(scenario_.objects[step.object].model, goal.held_faces, 1e-6);
        const Triangles fixed_patch = posed(
            mesh_triangles(scenario_.objects[step.fixed_object].model, goal.fixed_faces, 1e-6),
            poses[step.fixed_object]);
        sweep(problems, where + "outside the mating faces, ", {held_patch},
              Eigen::Translation3d(-d * m) * step.held_pose, d * m, {{fixed_name, fixed_patch}});
        // Released: the open gripper back along its axis, against all but h.
        sweep(problems, where + "leaving, ", gripper_triangles(spec, spec.max_opening), t,
              -d * t.linear().col(2), others(poses, {step.object}));
        carrier[step.object] = step.fixed_object;
      } else {
        const bool puts = step.action_name == "putdown";
        if (puts) move(step.object, step.object_pose);
        const std::vector<int> moving = group(step.object);
        const kinematics::Transform t = step.object_pose * grasp.gripper_in_object;
        const Eigen::Vector3d a = t.linear().col(2);
        // The open gripper between T - d a and T: against the others and the object's parts,
        // and against the object itself with the pads allowed to rest on it.
        const kinematics::Transform above = Eigen::Translation3d(-d * a) * t;
        sweep(problems, where + "the open gripper, ", gripper_triangles(spec, spec.max_opening),
              above, d * a, others(poses, {step.object}));
        sweep(problems, where + "the open gripper at its own object, ",
              gripper_triangles(spec, spec.max_opening, 1e-6), above, d * a,
              {{scenario_.objects[step.object].name,
                posed(meshes_[step.object], poses[step.object])}});
        closed_against_parts(problems, where, grasp, moving, poses, t);
        // Closed on the object (and parts): between T and T - d a among the others.
        sweep(problems, where + "holding, ", held_set(grasp, moving, poses, t), t, -d * a,
              others(poses, moving));
      }
      if (!problems.empty()) return problems;
      for (std::size_t o = 0; o < n; ++o) {
        if (carrier[o] >= 0) continue;
        const double z = lowest(posed(meshes_[o], poses[o]));
        if (std::abs(z) > 1e-6)
          problems.push_back(where + scenario_.objects[o].name + " is not on the table after it");
        else if (!stands(group(static_cast<int>(o)), poses))
          problems.push_back(where + scenario_.objects[o].name +
                             " with its parts topples after it");
      }
    }
    return problems;
  }

 private:
  int index(const std::string& name) const {
    for (std::size_t i = 0; i < scenario_.objects.size(); ++i)
      if (scenario_.objects[i].name == name) return static_cast<int>(i);
    return -1;
  }
  const AssembledGoal& goal_of(int held, int fixed) const {
    for (const Goal& goal : scenario_.goals)
      if (const auto* a = std::get_if<AssembledGoal>(&goal);
          a != nullptr && index(a->held) == held && index(a->fixed) == fixed)
        return *a;
    throw std::logic_error("no goal");
  }
  // Whether the subassembly `group` (root first) stands on the table: alone, fixed, or unmoved
  // in an initial pose that is no stable pose, it needs no check (see the header comment).
  bool stands(const std::vector<int>& group,
              const std::vector<kinematics::Transform>& poses) const {
    const ObjectSpec& root = scenario_.objects[group.front()];
    if (group.size() < 2 || root.fixed ||
        (!root.initial_stable_pose && poses[group.front()].isApprox(root.initial_pose, 1e-9)))
      return true;
    double volume = 0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector2d> footing;
    for (const int o : group) {
      const Triangles placed = posed(meshes_[o], poses[o]);
      const auto [v, centre] = volume_and_centre(placed);
      volume += v;
      moment += v * centre;
      for (const auto& face : placed.faces)
        for (const auto& corner : face)
          if (std::abs(corner.z()) <= 1e-6) footing.push_back(corner.head<2>());
    }
    const auto before = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
    };
    std::sort(footing.begin(), footing.end(), before);  // a corner is in several triangles
    footing.erase(std::unique(footing.begin(), footing.end()), footing.end());
    return strictly_inside_hull(footing, (moment / volume).head<2>(), 1e-7);
  }
  std::vector<std::pair<std::string, Triangles>> others(
      const std::vector<kinematics::Transform>& poses, const std::vector<int>& except) const {
    std::vector<std::pair<std::string, Triangles>> out;
    for (std::size_t o = 0; o < poses.size(); ++o)
      if (std::find(except.begin(), except.end(), static_cast<int>(o)) == except.end())
        out.push_back({scenario_.objects[o].name, posed(meshes_[o], poses[o])});
    return out;
  }
  // The closed gripper's boxes and the moving objects, in the gripper frame at `t` (closed
  // sets each, so a part inside an obstacle shows).
  std::vector<Triangles> held_set(const geometry::Grasp& grasp, const std::vector<int>& moving,
                                  const std::vector<kinematics::Transform>& poses,
                                  const kinematics::Transform& t) const {
    std::vector<Triangles> parts = gripper_triangles(scenario_.robot.gripper, grasp.width);
    for (const int o : moving)
      parts.push_back(posed(meshes_[o], t.inverse(Eigen::Isometry) * poses[o]));
    return parts;
  }
  // The gripper closed on moving[0] at `t` against the objects assembled into it.
  void closed_against_parts(std::vector<std::string>& problems, const std::string& where,
                            const geometry::Grasp& grasp, const std::vector<int>& moving,
                            const std::vector<kinematics::Transform>& poses,
                            const kinematics::Transform& t) const {
    for (const Triangles& box : gripper_triangles(scenario_.robot.gripper, grasp.width))
      for (std::size_t k = 1; k < moving.size(); ++k)
        if (interpenetrate(posed(box, t), posed(meshes_[moving[k]], poses[moving[k]])))
          problems.push_back(where + "the closed gripper meets " +
                             scenario_.objects[moving[k]].name + " assembled into the object");
  }

  // `parts` (each in the frame `from`) placed at translate(s motion) from for s from 0 to 1, at
  // samples kStep apart, against `obstacles` (world); the table at both ends. The motion is a pure
  // translation, so a part's box at a sample is its start box moved along: a sample whose moved
  // box (grown by kBoxSlack against rounding) misses an obstacle's box cannot meet it, and only
  // the others are posed and tested exactly.
  void sweep(std::vector<std::string>& problems, const std::string& what,
             const std::vector<Triangles>& parts, const kinematics::Transform& from,
             const Eigen::Vector3d& motion,
             const std::vector<std::pair<std::string, Triangles>>& obstacles) const {
    constexpr double kBoxSlack = 1e-9;
    std::vector<Eigen::AlignedBox3d> start_boxes, obstacle_boxes;
    std::vector<double> start_lowest;
    for (const Triangles& part : parts) {
      const Triangles start = posed(part, from);
      start_boxes.push_back(box_of(start));
      start_lowest.push_back(lowest(start));
    }
    for (const auto& obstacle : obstacles) obstacle_boxes.push_back(box_of(obstacle.second));
    const int samples = std::max(1, static_cast<int>(std::ceil(motion.norm() / kStep)));
    for (int k = 0; k <= samples; ++k) {
      const Eigen::Vector3d shift = motion * (static_cast<double>(k) / samples);
      const kinematics::Transform at = Eigen::Translation3d(shift) * from;
      for (std::size_t p = 0; p < parts.size(); ++p) {
        if ((k == 0 || k == samples) && start_lowest[p] + shift.z() < -1e-6) {
          problems.push_back(what + "goes below the table");
          return;
        }
        Eigen::AlignedBox3d moved(start_boxes[p].min() + shift, start_boxes[p].max() + shift);
        moved.min().array() -= kBoxSlack;
        moved.max().array() += kBoxSlack;
        for (std::size_t o = 0; o < obstacles.size(); ++o)
          if (moved.intersects(obstacle_boxes[o]) &&
              interpenetrate(posed(parts[p], at), obstacles[o].second)) {
            problems.push_back(what + "meets " + obstacles[o].first);
            return;
          }
      }
    }
  }

  const Scenario& scenario_;
  std::vector<std::vector<geometry::Grasp>> grasps_;
  std::vector<Triangles> meshes_;  // object frame
};

}  // namespace spar::planner::testing
