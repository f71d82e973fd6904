// The robots spar knows by name, and load_robot: a built-in name or a URDF file.
//
//   puma560, puma762  the DH tables of puma.hpp, with ik.hpp's closed form; no link geometry;
//                     base link0, tip flange
//   ur5               Universal Robots UR5, data/robots/.../ur5_robot.urdf (example-robot-data,
//                     BSD-3): base_link -> tool0, UR closed form
//   panda             Franka Emika Panda, data/robots/.../panda.urdf: panda_link0 -> panda_link8
//                     (the flange; the hand is the tool), closed form over q7
// The URDF-based ones read their files from the robot data folder: $SPAR_DATA_DIR/robots if that
// variable is set, else the installed share/spar/data/robots, else the source tree's data/robots.
//
// Example:
//   const RobotModel& panda = builtin_robot_model("panda");      // loaded once, then shared
//   const RobotModel mine = load_robot("cell/arm.urdf", {.tip = "flange"});
//   const RobotModel ur5_ee = load_robot("ur5", {.tip = "ee_link"});   // another tip
#pragma once

#include <filesystem>
#include <string_view>
#include <vector>

#include "spar/kinematics/robot.hpp"
#include "spar/kinematics/urdf.hpp"

namespace spar::kinematics {

// "puma560", "puma762", "ur5", "panda".
[[nodiscard]] std::vector<std::string_view> robot_model_names();
// Throws KinematicsError naming the built-in robots for another name (or when the robot data
// folder is missing). Thread-safe; the model lives until the program ends.
[[nodiscard]] const RobotModel& builtin_robot_model(std::string_view name);
// A built-in name (with `options`' tip and base, when given: the built-in's file with those
// ends), else a path to a URDF file (load_urdf). Throws KinematicsError.
[[nodiscard]] RobotModel load_robot(std::string_view name_or_path, const UrdfOptions& options = {});
// The folder holding the built-in robots' URDF files and meshes (see above); throws
// KinematicsError naming the places it looked when none exists.
[[nodiscard]] std::filesystem::path robot_data_directory();

}  // namespace spar::kinematics
