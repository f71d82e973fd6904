// An independent checker of plan instances: it simulates the steps of an instance on its own world
// state (object poses, what the gripper holds, what is assembled), from the scenario and the
// geometry alone, and returns every rule a step breaks. It reuses none of the planner's tables.
//
// Rules per step: the operational preconditions (gripper empty to pick up; holding the object to
// put it down or insert it; the object where the step says it is); the reported gripper pose is
// T_O T_G (an insertion: T_f Ta T_G); base * FK(joints) * tool equals the gripper pose; the joints
// are within their limits; the gripper's approach axis points down within the robot's tilt cone;
// no contact face of the grasp lies on the table in the object's current pose (and at its
// destination); a put-down object, with what is assembled into it, rests on the table (its
// lowest vertex at z = 0, the joint centre of mass strictly inside the footing its vertices on
// the table make); at an insertion the fixed object's mating faces are off the table and the
// mating vector points down. Objects assembled into one move with it. At the end, every goal
// holds: an assembled pair at its relative pose, an object at its place (resting, turned by one
// of the place's yaws, either in one of its stable poses with its centre of mass above the place,
// or, with parts assembled into it, in any orientation where they rest that the smallest turn of
// its down direction to world -z gives, their joint centre of mass above the place).
// Collisions: collision_checker.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "spar/planner/plan.hpp"

namespace spar::planner::testing {

inline bool same_pose(const kinematics::Transform& a, const kinematics::Transform& b,
                      double tolerance = 1e-6) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff() <= tolerance;
}

// Faces of `model` lying on the table (outward normal straight down, on the plane z = 0) when the
// object is at `pose`.
inline std::vector<int> faces_on_table(const geometry::ObjectModel& model,
                                       const kinematics::Transform& pose) {
  std::vector<int> on_table;
  for (const geometry::Face& face : model.faces()) {
    const Eigen::Vector3d normal = pose.linear() * face.normal;
    const Eigen::Vector3d centroid = pose * face.centroid;
    if (normal.z() < -1 + 1e-6 && std::abs(centroid.z()) < 1e-6) on_table.push_back(face.id);
  }
  return on_table;
}

inline double lowest_z(const geometry::ObjectModel& model, const kinematics::Transform& pose) {
  double lowest = INFINITY;
  for (const Eigen::Vector3d& vertex : model.mesh().vertices)
    lowest = std::min(lowest, (pose * vertex).z());
  return lowest;
}

// Whether the objects `group` at `poses` rest on the table as one body: no vertex below it, and
// their joint centre of mass (volume-weighted) strictly inside the convex hull, seen from above,
// of their vertices on it.
inline bool stands(const Scenario& scenario, const std::vector<int>& group,
                   const std::vector<kinematics::Transform>& poses) {
  std::vector<Eigen::Vector2d> footing;
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double volume = 0;
  for (const int o : group) {
    const geometry::ObjectModel& model = scenario.objects[o].model;
    for (const Eigen::Vector3d& vertex : model.mesh().vertices) {
      const Eigen::Vector3d at = poses[o] * vertex;
      if (at.z() < -1e-6) return false;
      if (at.z() < 1e-6) footing.push_back(at.head<2>());
    }
    center += model.volume() * (poses[o] * model.center_of_mass()).head<2>();
    volume += model.volume();
  }
  center /= volume;
  // Andrew's monotone chain, counter-clockwise.
  std::sort(footing.begin(), footing.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull(2 * footing.size() + 1);
  std::size_t k = 0;
  for (std::size_t i = 0; i < footing.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], footing[i]) <= 0) --k;
    hull[k++] = footing[i];
  }
  for (std::size_t i = footing.size(), lower = k + 1; i-- > 1;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], footing[i - 1]) <= 0) --k;
    hull[k++] = footing[i - 1];
  }
  if (k < 4) return false;  // fewer than three corners: an edge or a point
  for (std::size_t i = 0; i + 1 < k; ++i) {
    const Eigen::Vector2d edge = hull[i + 1] - hull[i];
    if (cross(hull[i], hull[i + 1], center) <= 1e-9 * edge.norm()) return false;
  }
  return true;
}

inline bool intersects(const std::vector<int>& a, const std::vector<int>& b) {
  for (const int x : a)
    for (const int y : b)
      if (x == y) return true;
  return false;
}

// Every broken rule, as text ("step 3 (pickup block): ..."); empty when the instance is valid.
inline std::vector<std::string> check_instance(
    const Scenario& scenario, const std::vector<std::vector<geometry::Grasp>>& grasps,
    const PlanInstance& instance) {
  std::vector<std::string> problems;
  std::vector<kinematics::Transform> poses;
  for (const ObjectSpec& object : scenario.objects) poses.push_back(object.initial_pose);
  std::vector<bool> assembled_into(scenario.objects.size(), false);
  int held = -1;
  const auto find = [&](const std::string& name) {
    for (std::size_t i = 0; i < scenario.objects.size(); ++i)
      if (scenario.objects[i].name == name) return static_cast<int>(i);
    return -1;
  };
  // What each object is assembled into (it moves with that one): goals true at the start first.
  std::vector<int> carrier(scenario.objects.size(), -1);
  for (const Goal& goal : scenario.goals)
    if (const auto* a = std::get_if<AssembledGoal>(&goal)) {
      const int h = find(a->held), f = find(a->fixed);
      if ((poses[f] * a->relative).isApprox(poses[h], 1e-7)) {
        carrier[h] = f;
        assembled_into[h] = true;
      }
    }
  // `object` and what is assembled into it.
  const auto group_of = [&](int object) {
    std::vector<int> group = {object};
    for (std::size_t i = 0; i < group.size(); ++i)
      for (std::size_t k = 0; k < carrier.size(); ++k)
        if (carrier[k] == group[i]) group.push_back(static_cast<int>(k));
    return group;
  };
  const auto lowest_of = [&](const std::vector<int>& group) {
    double lowest = INFINITY;
    for (const int k : group)
      lowest = std::min(lowest, lowest_z(scenario.objects[k].model, poses[k]));
    return lowest;
  };
  // Moves `object` to `pose` and what is assembled into it along.
  const auto move = [&](int object, const kinematics::Transform& pose) {
    const std::vector<int> group = group_of(object);
    const kinematics::Transform change = pose * poses[object].inverse(Eigen::Isometry);
    for (const int k : group) poses[k] = change * poses[k];
  };
  int number = 0;
  for (const InstanceStep& step : instance.steps) {
    ++number;
    const std::string where = "step " + std::to_string(number) + " (" + step.action_name + " " +
                              scenario.objects.at(step.object).name + "): ";
    const auto fail = [&](const std::string& what) { problems.push_back(where + what); };
    const geometry::ObjectModel& model = scenario.objects[step.object].model;
    const geometry::Grasp& grasp = grasps.at(step.object).at(step.grasp);
    const std::vector<int> contacts = {grasp.face_plus_y, grasp.face_minus_y};
    // The gripper pose and the arm's joints.
    const kinematics::Transform expected_gripper = step.object_pose * grasp.gripper_in_object;
    if (!same_pose(step.gripper_pose, expected_gripper)) fail("gripper pose is not T_O T_G");
    if (!step.reach.solution) {
      fail("no joint solution");
    } else {
      const std::vector<double>& q = step.reach.solution->q;
      const kinematics::Transform fk =
          scenario.robot.base * scenario.robot.arm.forward(q) * scenario.robot.tool;
      if (!same_pose(fk, step.gripper_pose, 1e-6)) fail("base * FK(joints) * tool != gripper pose");
      if (!scenario.robot.arm.within_limits(q)) fail("joints outside their limits");
    }
    const double tilt = std::acos(std::clamp(-step.gripper_pose.linear().col(2).z(), -1.0, 1.0));
    if (tilt > scenario.robot.max_tool_tilt + 1e-9) fail("gripper does not point down");
    if (step.action_name == "pickup") {
      if (held != -1) fail("gripper not empty");
      if (!same_pose(poses[step.object], step.object_pose))
        fail("object is not where the step says");
      if (intersects(faces_on_table(model, poses[step.object]), contacts))
        fail("a contact face lies on the table");
      held = step.object;
    } else if (step.action_name == "putdown") {
      if (held != step.object) fail("not holding the object");
      if (intersects(faces_on_table(model, step.object_pose), contacts))
        fail("a contact face would lie on the table");
      move(step.object, step.object_pose);
      const std::vector<int> body = group_of(step.object);
      if (std::abs(lowest_of(body)) > 1e-6) fail("destination not on the table");
      if (!stands(scenario, body, poses)) fail("what is put down does not rest on the table");
      held = -1;
    } else if (step.action_name == "assemble") {
      if (held != step.object) fail("not holding the held object");
      if (!same_pose(poses[step.fixed_object], step.fixed_pose)) fail("fixed object is elsewhere");
      for (const Goal& goal : scenario.goals) {
        const auto* found = std::get_if<AssembledGoal>(&goal);
        if (found == nullptr || find(found->held) != step.object ||
            find(found->fixed) != step.fixed_object)
          continue;
        const AssembledGoal& assembled = *found;
        if (!same_pose(step.held_pose, step.fixed_pose * assembled.relative))
          fail("held pose is not T_fixed Ta");
        const geometry::ObjectModel& fixed = scenario.objects[step.fixed_object].model;
        if (intersects(faces_on_table(fixed, step.fixed_pose), assembled.fixed_faces))
          fail("a mating face of the fixed object lies on the table");
        if ((step.fixed_pose.linear() * assembled.mating_vector).z() >= 0)
          fail("the mating vector does not point down");
        if (intersects(grasp.obscured_faces, assembled.held_faces))
          fail("the grasp obscures a mating face of the held object");
        assembled_into[step.object] = true;
        move(step.object, step.held_pose);
        carrier[step.object] = step.fixed_object;
      }
      held = -1;
    } else {
      fail("unknown action");
    }
  }
  for (const Goal& goal : scenario.goals) {
    if (const auto* assembled = std::get_if<AssembledGoal>(&goal)) {
      const int h = find(assembled->held), f = find(assembled->fixed);
      if (!assembled_into[h] || !same_pose(poses[h], poses[f] * assembled->relative))
        problems.push_back("goal assembled(" + assembled->held + ", " + assembled->fixed +
                           ") not reached");
      continue;
    }
    // at(object, place): resting on the table with its frame's turn about z one of the place's
    // yaws and its centre of mass above the place.
    const AtGoal& at = std::get<AtGoal>(goal);
    const int o = find(at.object);
    const ObjectSpec& object = scenario.objects[o];
    const Place& place = scenario.places[scenario.place_index(at.place)];
    // Above the place: the object's own centre of mass when it rests in one of its stable poses,
    // the joint one of it and its parts when they rest in another orientation.
    const std::vector<int> body = group_of(o);
    const auto above_place = [&](const std::vector<int>& parts) {
      Eigen::Vector3d com = Eigen::Vector3d::Zero();
      double volume = 0;
      for (const int k : parts) {
        const geometry::ObjectModel& model = scenario.objects[k].model;
        com += model.volume() * (poses[k] * model.center_of_mass());
        volume += model.volume();
      }
      com /= volume;
      return std::hypot(com.x() - place.x, com.y() - place.y) < 1e-6;
    };
    const bool there = std::abs(lowest_of(body)) < 1e-6;
    bool turned = false;
    for (const double yaw : place.yaws) {
      const Eigen::Matrix3d unturned =
          Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * poses[o].linear();
      for (const geometry::StablePose& stable : object.stable_poses)
        turned |= (unturned - stable.object_to_world.linear()).cwiseAbs().maxCoeff() <= 1e-6 &&
                  above_place({o});
      if (body.size() > 1) {
        const Eigen::Vector3d down = unturned.transpose() * -Eigen::Vector3d::UnitZ();
        const Eigen::Matrix3d smallest =
            Eigen::Quaterniond::FromTwoVectors(down, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
        turned |= (unturned - smallest).cwiseAbs().maxCoeff() <= 1e-6 && above_place(body) &&
                  stands(scenario, body, poses);
      }
    }
    if (!there || !turned)
      problems.push_back("goal at(" + at.object + ", " + at.place + ") not reached");
  }
  if (held != -1) problems.push_back("the plan ends holding an object");
  return problems;
}

}  // namespace spar::planner::testing
