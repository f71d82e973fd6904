// `spar fk` and `spar ik`: forward and inverse kinematics of a built-in robot or a URDF file.
//
//   spar fk --robot ur5|panda|puma560|puma762|FILE.urdf [--tip LINK] [--package-path DIR]...
//           --q "q1 ... qn" [--json]
//       prints the tip pose in the base frame: JSON {"robot", "base", "tip", "q", "within_limits",
//       "joints_out_of_limits", "pose": 4x4 rows (metres)}
//   spar ik --robot ... [--tip LINK] [--package-path DIR]... --pose "<16 numbers, row-major>"
//           [--redundancy-step DEG] [--max-tilt-deg 45] [--json]
//       prints every solution (kinematics/robot.hpp): JSON {"robot", "base", "tip", "method",
//       "status", "solutions": [{"configuration", "q", "within_limits", "joints_out_of_limits",
//       "singularities", "fk_residual_max"}], "within_limits_count", "reachable",
//       "tool_tilt_deg", "max_tool_tilt_deg"}
// Joint values are radians (metres for prismatic joints).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "spar/common/number.hpp"
#include "spar/kinematics/robots.hpp"
#include "spar/reports/json_values.hpp"

namespace spar::cli {
namespace {

using kinematics::RobotModel;
using kinematics::Transform;

constexpr double kDegree = std::numbers::pi / 180.0;

// Numbers separated by spaces and/or commas; throws UsageError naming the option and the
// offending token.
std::vector<double> parse_numbers(const std::string& text, const std::string& option) {
  std::vector<double> numbers;
  std::string token;
  std::istringstream stream(text);
  while (stream >> token) {
    std::size_t start = 0;
    while (start <= token.size()) {
      const std::size_t comma = token.find(',', start);
      const std::string piece =
          token.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      if (!piece.empty()) {
        try {
          numbers.push_back(read_number(piece, option));
        } catch (const NumberError& error) {
          throw UsageError(error.what());
        }
      }
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return numbers;
}

std::string joint_list(const std::vector<int>& joints) {
  std::string text;
  for (int joint : joints) text += (text.empty() ? "q" : ",q") + std::to_string(joint);
  return text;
}

std::vector<std::string> singularity_list(std::uint8_t flags) {
  std::vector<std::string> names;
  if (flags & kinematics::kShoulderSingularity) names.emplace_back("shoulder");
  if (flags & kinematics::kElbowSingularity) names.emplace_back("elbow");
  if (flags & kinematics::kWristSingularity) names.emplace_back("wrist");
  return names;
}

void print_matrix(const Transform& pose) {
  for (int row = 0; row < 4; ++row) {
    std::cout << "  ";
    for (int col = 0; col < 4; ++col) {
      std::cout << std::fixed << std::setprecision(10) << std::setw(15) << pose.matrix()(row, col);
    }
    std::cout << '\n';
  }
}

struct RobotOptions {
  std::string robot{"puma560"};
  std::string tip;
  std::vector<std::string> package_path;
  bool json{false};
};

void add_robot_options(CLI::App* command, RobotOptions& options) {
  command
      ->add_option("--robot", options.robot,
                   "Built-in robot (puma560, puma762, ur5, panda) or a URDF file")
      ->capture_default_str();
  command->add_option("--tip", options.tip,
                      "Tip link of a URDF robot (default: the built-in's, else the end of the "
                      "longest chain)");
  command->add_option("--package-path", options.package_path,
                      "Folder to look for package:// names in (repeatable), before "
                      "ROS_PACKAGE_PATH");
  command->add_flag("--json", options.json, "Print JSON instead of text");
}

// The robot --robot names; an unknown name is a usage mistake, a bad URDF file the file's.
RobotModel robot_named(const RobotOptions& options) {
  const std::vector<std::string_view> names = kinematics::robot_model_names();
  const bool builtin = std::find(names.begin(), names.end(), options.robot) != names.end();
  if (!builtin && !options.robot.ends_with(".urdf")) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(options.robot, error)) {
      std::string known;
      for (const std::string_view name : names)
        known += (known.empty() ? "" : ", ") + std::string(name);
      throw UsageError("--robot: unknown robot '" + options.robot + "' (built-in: " + known +
                       "; or a URDF file)");
    }
  }
  kinematics::UrdfOptions urdf{.base = {}, .tip = options.tip, .package_path = {}};
  for (const std::string& folder : options.package_path) urdf.package_path.emplace_back(folder);
  return kinematics::load_robot(options.robot, urdf);
}

void run_fk(const RobotOptions& options, const std::string& joint_text) {
  const RobotModel robot = robot_named(options);
  const std::vector<double> q = parse_numbers(joint_text, "--q");
  if (q.size() != robot.dof()) {
    throw UsageError("--q: " + options.robot + " needs " + std::to_string(robot.dof()) +
                     " joint values (radians" +
                     (robot.dof() > 0 ? ", metres for prismatic joints" : "") + "), got " +
                     std::to_string(q.size()));
  }
  const Transform pose = robot.forward(q);
  const std::vector<int> out = robot.joints_out_of_limits(q);
  if (options.json) {
    const nlohmann::ordered_json result = {{"robot", robot.name()},
                                           {"base", robot.base_link()},
                                           {"tip", robot.tip_link()},
                                           {"q", q},
                                           {"within_limits", out.empty()},
                                           {"joints_out_of_limits", out},
                                           {"pose", reports::matrix_json(pose)}};
    std::cout << result.dump(2) << '\n';
    return;
  }
  std::cout << std::setprecision(10) << "robot " << robot.name() << " (" << robot.base_link()
            << " -> " << robot.tip_link() << ")\nq:";
  for (double value : q) std::cout << ' ' << value;
  std::cout << "\nwithin limits: " << (out.empty() ? "yes" : "no (" + joint_list(out) + ")")
            << "\ntip pose (" << robot.tip_link() << " in " << robot.base_link()
            << ", 4x4, metres):\n";
  print_matrix(pose);
}

// The angle between the pose's z axis and the base frame's -z.
double tilt_from_down(const Transform& pose) {
  const Eigen::Vector3d z = pose.linear().col(2);
  return std::atan2(std::hypot(z.x(), z.y()), -z.z());
}

void print_solutions_table(const nlohmann::ordered_json& solutions, std::size_t dof) {
  std::size_t label_width = std::string("configuration").size();
  std::size_t limits_width = std::string("limits").size();
  for (const nlohmann::ordered_json& solution : solutions) {
    label_width = std::max(label_width, solution["configuration"].get<std::string>().size());
    const std::vector<int> out = solution["joints_out_of_limits"];
    limits_width = std::max(limits_width, out.empty() ? 2 : 4 + joint_list(out).size());
  }
  constexpr int kColumn = 12;
  std::cout << std::left << std::setw(static_cast<int>(label_width)) << "configuration"
            << std::right;
  for (std::size_t j = 1; j <= dof; ++j) std::cout << std::setw(kColumn) << "q" + std::to_string(j);
  std::cout << "  " << std::left << std::setw(static_cast<int>(limits_width)) << "limits"
            << "  fk residual" << std::right << '\n';
  for (const nlohmann::ordered_json& solution : solutions) {
    std::cout << std::left << std::setw(static_cast<int>(label_width))
              << solution["configuration"].get<std::string>() << std::right << std::fixed
              << std::setprecision(6);
    for (double angle : solution["q"]) std::cout << std::setw(kColumn) << angle;
    const std::vector<int> out = solution["joints_out_of_limits"];
    std::cout << "  " << std::left << std::setw(static_cast<int>(limits_width))
              << (out.empty() ? "ok" : "out " + joint_list(out)) << std::right << "  "
              << std::scientific << std::setprecision(1)
              << solution["fk_residual_max"].get<double>() << std::fixed;
    const std::vector<std::string> singular = solution["singularities"];
    for (std::size_t i = 0; i < singular.size(); ++i)
      std::cout << (i == 0 ? "  singular: " : "+") << singular[i];
    std::cout << '\n';
  }
}

void run_ik(const RobotOptions& options, const std::string& pose_text, double max_tilt_degrees,
            double redundancy_step_degrees) {
  const RobotModel robot = robot_named(options);
  const Transform pose =
      kinematics::rigid_transform_from_row_major(parse_numbers(pose_text, "--pose"));
  const std::vector<kinematics::JointSolution> found =
      robot.inverse(pose, {.redundancy_step = redundancy_step_degrees * kDegree});

  nlohmann::ordered_json solutions = nlohmann::ordered_json::array();
  int within = 0;
  std::uint8_t singularities = kinematics::kNoSingularity;
  for (const kinematics::JointSolution& solution : found) {
    const double residual =
        (robot.forward(solution.q).matrix() - pose.matrix()).cwiseAbs().maxCoeff();
    within += solution.within_limits ? 1 : 0;
    singularities |= solution.singularities;
    solutions.push_back({{"configuration", solution.configuration},
                         {"q", solution.q},
                         {"within_limits", solution.within_limits},
                         {"joints_out_of_limits", robot.joints_out_of_limits(solution.q)},
                         {"singularities", singularity_list(solution.singularities)},
                         {"fk_residual_max", residual}});
  }
  const double tilt = tilt_from_down(pose);
  const bool reachable = within > 0 && tilt <= max_tilt_degrees * kDegree + 1e-12;
  if (options.json) {
    const nlohmann::ordered_json output = {{"robot", robot.name()},
                                           {"base", robot.base_link()},
                                           {"tip", robot.tip_link()},
                                           {"method", kinematics::to_string(robot.ik_method())},
                                           {"status", found.empty() ? "unreachable" : "solved"},
                                           {"singularities", singularity_list(singularities)},
                                           {"solutions", solutions},
                                           {"within_limits_count", within},
                                           {"reachable", reachable},
                                           {"tool_tilt_deg", tilt / kDegree},
                                           {"max_tool_tilt_deg", max_tilt_degrees}};
    std::cout << output.dump(2) << '\n';
    return;
  }
  std::cout << "robot " << robot.name() << " (" << robot.base_link() << " -> " << robot.tip_link()
            << "), inverse kinematics: " << kinematics::to_string(robot.ik_method()) << '\n';
  if (found.empty()) {
    std::cout << "status: unreachable (no joint values reach the pose"
              << (robot.ik_method() == kinematics::IkMethod::kPumaClosedForm ||
                          robot.ik_method() == kinematics::IkMethod::kUrClosedForm
                      ? ")\n"
                      : " within the joint limits)\n");
  } else {
    std::cout << "status: solved, singularities: " << kinematics::singularity_names(singularities)
              << "\n\n";
    print_solutions_table(solutions, robot.dof());
    std::cout << "\nwithin limits: " << within << " of " << found.size() << '\n';
  }
  std::cout << std::fixed << std::setprecision(1)
            << "reachable (SPAR: an in-limit configuration and tool z within " << max_tilt_degrees
            << " deg of down; tilt " << tilt / kDegree << " deg): " << (reachable ? "yes" : "no")
            << '\n';
}

}  // namespace

void add_fk_command(CLI::App& app) {
  auto* command = app.add_subcommand("fk", "Forward kinematics: the tip pose for joint values");
  auto options = std::make_shared<RobotOptions>();
  auto joints = std::make_shared<std::string>();
  add_robot_options(command, *options);
  command
      ->add_option("--q", *joints,
                   "Joint values, radians (metres for prismatic joints), e.g. \"0 0.785 3.14 0 "
                   "0.785 0\"")
      ->required();
  command->callback([options, joints] { run_fk(*options, *joints); });
}

void add_ik_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "ik", "Inverse kinematics: every labelled solution for a tip pose, with joint limits");
  auto options = std::make_shared<RobotOptions>();
  auto pose = std::make_shared<std::string>();
  auto max_tilt = std::make_shared<double>(45.0);
  auto redundancy_step = std::make_shared<double>(5.0);
  add_robot_options(command, *options);
  command->add_option("--pose", *pose, "Tip pose in the base frame: 16 numbers, row-major")
      ->required();
  add_number_option(*command, "--max-tilt-deg", *max_tilt,
                    "Cone half-angle around -z for the tool z axis (reachability)", {0, 180});
  add_number_option(*command, "--redundancy-step", *redundancy_step,
                    "7-joint arms: q7 is sampled every this many degrees", {0, 360, true});
  command->callback([options, pose, max_tilt, redundancy_step] {
    run_ik(*options, *pose, *max_tilt, *redundancy_step);
  });
}

}  // namespace spar::cli
