#include "spar/kinematics/robots.hpp"

#include <cstdlib>
#include <map>
#include <mutex>
#include <string>

#include "spar/kinematics/puma.hpp"

namespace spar::kinematics {
namespace {

namespace fs = std::filesystem;

struct UrdfRobot {
  std::string_view name;
  std::string_view file;  // under the robot data folder
  std::string_view base;
  std::string_view tip;
};
constexpr UrdfRobot kUrdfRobots[] = {
    {"ur5", "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf", "base_link", "tool0"},
    {"panda", "example-robot-data/robots/panda_description/urdf/panda.urdf", "panda_link0",
     "panda_link8"},
};

const UrdfRobot* urdf_robot(std::string_view name) {
  for (const UrdfRobot& robot : kUrdfRobots)
    if (robot.name == name) return &robot;
  return nullptr;
}

RobotModel load_builtin(std::string_view name, const UrdfOptions& given) {
  if (const UrdfRobot* robot = urdf_robot(name)) {
    const fs::path folder = robot_data_directory();
    UrdfOptions options = given;
    if (options.base.empty()) options.base = robot->base;
    if (options.tip.empty()) options.tip = robot->tip;
    options.package_path.insert(options.package_path.begin(), folder);
    RobotModel model = load_urdf(folder / robot->file, options);
    return model;
  }
  const DhChain& chain = builtin_robot(name);  // throws for an unknown name
  if ((!given.tip.empty() && given.tip != "flange") ||
      (!given.base.empty() && given.base != "link0"))
    throw KinematicsError("robot '" + std::string(name) +
                          "' is a DH table: its base is link0 and its tip is flange");
  return RobotModel::from_dh(chain);
}

std::string known_robots() {
  std::string known;
  for (const std::string_view name : robot_model_names())
    known += (known.empty() ? "" : ", ") + std::string(name);
  return known;
}

}  // namespace

std::vector<std::string_view> robot_model_names() { return {"puma560", "puma762", "ur5", "panda"}; }

fs::path robot_data_directory() {
  std::vector<fs::path> candidates;
  if (const char* data = std::getenv("SPAR_DATA_DIR"); data != nullptr && *data != '\0')
    candidates.push_back(fs::path(data) / "robots");
  candidates.emplace_back(SPAR_INSTALLED_ROBOT_DATA);
  candidates.emplace_back(SPAR_SOURCE_ROBOT_DATA);
  std::error_code error;
  std::string looked;
  for (const fs::path& candidate : candidates) {
    if (fs::is_directory(candidate / "example-robot-data", error)) return candidate;
    looked += (looked.empty() ? "" : ", ") + candidate.string();
  }
  throw KinematicsError("the built-in robots' files are missing (looked in " + looked +
                        "; set SPAR_DATA_DIR to the folder holding robots/)");
}

const RobotModel& builtin_robot_model(std::string_view name) {
  static std::mutex mutex;
  static std::map<std::string, RobotModel, std::less<>> loaded;
  const std::lock_guard lock(mutex);
  if (const auto found = loaded.find(name); found != loaded.end()) return found->second;
  bool known = false;
  for (const std::string_view candidate : robot_model_names()) known |= candidate == name;
  if (!known)
    throw KinematicsError("unknown robot '" + std::string(name) +
                          "'; built-in robots: " + known_robots());
  return loaded.emplace(std::string(name), load_builtin(name, {})).first->second;
}

RobotModel load_robot(std::string_view name_or_path, const UrdfOptions& options) {
  for (const std::string_view name : robot_model_names()) {
    if (name != name_or_path) continue;
    if (options.tip.empty() && options.base.empty() && options.package_path.empty())
      return builtin_robot_model(name);
    return load_builtin(name, options);
  }
  std::error_code error;
  if (name_or_path.ends_with(".urdf") || fs::is_regular_file(fs::path(name_or_path), error))
    return load_urdf(fs::path(name_or_path), options);
  throw KinematicsError("unknown robot '" + std::string(name_or_path) +
                        "'; built-in robots: " + known_robots() + "; or the path of a URDF file");
}

}  // namespace spar::kinematics
