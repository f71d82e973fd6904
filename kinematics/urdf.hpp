// URDF import: a robot description file (ROS's Unified Robot Description Format) as a RobotModel
// (robot.hpp), read by urdfdom (the ROS reference parser), not by hand.
//
// What is read: the kinematic tree (revolute, continuous, prismatic and fixed joints with their
// origins xyz/rpy, axes and limits) along the path from the base link (the tree's root unless
// named) to the tip link, the links rigidly attached to that path by fixed joints, and their
// <collision> geometry: boxes, cylinders, spheres, and meshes (STL, OBJ or OFF, through the mesh
// reader objects use; `scale` applied). Links beyond the tip (a hand, fingers) are the tool's and
// not part of the arm; visual geometry is ignored, so a missing visual mesh is not an error.
//
// Mesh file names: a relative path is relative to the URDF file's folder; `file://PATH` is PATH;
// `package://NAME/REST` is NAME/REST under the first folder of `package_path`, then of the
// ROS_PACKAGE_PATH environment variable (':'-separated) that has it (a folder called NAME itself
// counts too: DIR/REST when DIR's name is NAME).
//
// The tip: `tip` if given, else the child link of the last moving joint of the longest path of
// moving joints below the base (UR5's file: wrist_3_link); when several links end such paths (the
// Panda's two fingers), the error lists them.
//
// Every mistake throws KinematicsError "file:line: what is wrong" (urdfdom reports no lines: the
// line is that of the element the problem is about, found by TinyXML, urdfdom's own XML reader):
// unreadable file, XML syntax, what urdfdom rejects (its message), a joint type spar's chains do
// not take (floating, planar) or a mimic joint on the chain, limits out of order or not finite, a
// zero axis, an unknown base or tip link, a tip not below the base, a missing or unreadable
// collision mesh (also off the arm: every collision mesh the file names must exist), a mesh format
// other than STL/OBJ/OFF.
//
// Example:
//   const RobotModel ur5 = load_urdf("data/robots/example-robot-data/robots/ur_description/urdf/"
//                                    "ur5_robot.urdf",
//                                    {.base = "base_link", .tip = "tool0",
//                                     .package_path = {"data/robots"}});
//   ur5.dof();                       // 6
//   ur5.ik_method();                 // IkMethod::kUrClosedForm
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "spar/kinematics/robot.hpp"

namespace spar::kinematics {

struct UrdfOptions {
  std::string base{};  // empty: the root link
  std::string tip{};   // empty: see the header comment
  // Searched for package:// names before ROS_PACKAGE_PATH.
  std::vector<std::filesystem::path> package_path{};
};

[[nodiscard]] RobotModel load_urdf(const std::filesystem::path& path,
                                   const UrdfOptions& options = {});
// The same from text: `source` names it in messages, `base_dir` resolves relative mesh paths.
[[nodiscard]] RobotModel parse_urdf(const std::string& text, const std::string& source,
                                    const std::filesystem::path& base_dir,
                                    const UrdfOptions& options = {});

// Where a mesh file name points (the header's rules), or "" when a package:// name is on no
// folder of the search path. Does not check that the file exists.
[[nodiscard]] std::filesystem::path resolve_mesh_uri(
    std::string_view uri, const std::filesystem::path& base_dir,
    const std::vector<std::filesystem::path>& package_path);

}  // namespace spar::kinematics
