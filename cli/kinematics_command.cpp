// `spar fk` and `spar ik`: forward and inverse kinematics of the built-in robots.
//
//   spar fk --robot puma560 --q "0 0.785 3.14 0 0.785 0" [--json]
//   spar ik --robot puma560 --pose "<16 numbers of the 4x4 flange pose, row-major>" [--json]
//           [--max-tilt-deg 45]
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
#include "spar/kinematics/ik.hpp"
#include "spar/kinematics/puma.hpp"
#include "spar/reports/json_values.hpp"

namespace spar::cli {
namespace {

using kinematics::DhChain;
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

// 1-based indices of the joints of q outside their limits (1e-9 rad slack, as the IK uses).
std::vector<int> joints_out_of_limits(const DhChain& robot, std::span<const double> q) {
  std::vector<int> out;
  for (std::size_t i = 0; i < robot.size(); ++i) {
    const kinematics::JointLimits& limits = robot.joint(i).limits;
    if (q[i] < limits.lower - 1e-9 || q[i] > limits.upper + 1e-9)
      out.push_back(static_cast<int>(i) + 1);
  }
  return out;
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

struct CommonOptions {
  std::string robot{"puma560"};
  bool json{false};
};

void add_common_options(CLI::App* command, CommonOptions& options) {
  command->add_option("--robot", options.robot, "Built-in robot: puma560 (default) or puma762");
  command->add_flag("--json", options.json, "Print JSON instead of text");
}

// The built-in robot --robot names; an unknown name is a usage mistake.
const DhChain& robot_named(const std::string& name) {
  std::string known;
  for (const std::string_view robot : kinematics::builtin_robot_names()) {
    if (robot == name) return kinematics::builtin_robot(name);
    known += (known.empty() ? "" : ", ") + std::string(robot);
  }
  throw UsageError("--robot: unknown robot '" + name + "' (built-in: " + known + ")");
}

void run_fk(const CommonOptions& options, const std::string& joint_text) {
  const DhChain& robot = robot_named(options.robot);
  const std::vector<double> q = parse_numbers(joint_text, "--q");
  if (q.size() != robot.size()) {
    throw UsageError("--q: " + options.robot + " needs " + std::to_string(robot.size()) +
                     " joint angles (radians), got " + std::to_string(q.size()));
  }
  const Transform pose = robot.forward(q);
  const std::vector<int> out = joints_out_of_limits(robot, q);
  if (options.json) {
    const nlohmann::ordered_json result = {{"robot", robot.name()},
                                           {"q", q},
                                           {"within_limits", out.empty()},
                                           {"joints_out_of_limits", out},
                                           {"T", reports::matrix_json(pose)}};
    std::cout << result.dump(2) << '\n';
    return;
  }
  std::cout << std::setprecision(10) << "robot " << robot.name() << '\n' << "q (rad):";
  for (double angle : q) std::cout << ' ' << angle;
  std::cout << "\nwithin limits: " << (out.empty() ? "yes" : "no (" + joint_list(out) + ")")
            << "\nflange pose (base frame, 4x4):\n";
  print_matrix(pose);
}

void run_ik(const CommonOptions& options, const std::string& pose_text, double max_tilt_degrees) {
  const DhChain& robot = robot_named(options.robot);
  const Transform pose =
      kinematics::rigid_transform_from_row_major(parse_numbers(pose_text, "--pose"));
  const kinematics::PumaIk solver(robot);
  const kinematics::Reachability reach =
      kinematics::reachable(solver, pose, {.max_tool_tilt = max_tilt_degrees * kDegree});
  const kinematics::IkResult& result = reach.inverse_kinematics;

  nlohmann::ordered_json solutions = nlohmann::ordered_json::array();
  for (const kinematics::IkSolution& solution : result.solutions) {
    if (!result.solved()) break;
    const std::span<const double> q(solution.q.data(), 6);
    const double residual = (robot.forward(q).matrix() - pose.matrix()).cwiseAbs().maxCoeff();
    solutions.push_back({{"config", solution.configuration.label()},
                         {"q", std::vector<double>(q.begin(), q.end())},
                         {"within_limits", solution.within_limits},
                         {"joints_out_of_limits", joints_out_of_limits(robot, q)},
                         {"singularities", singularity_list(solution.singularities)},
                         {"fk_residual_max", residual}});
  }
  if (options.json) {
    const nlohmann::ordered_json output = {
        {"robot", robot.name()},
        {"status", result.solved() ? "solved" : "unreachable"},
        {"singularities", singularity_list(result.singularities)},
        {"solutions", solutions},
        {"within_limits_count", result.count_within_limits()},
        {"reachable", reach.reachable},
        {"tool_tilt_deg", reach.tool_tilt / kDegree},
        {"max_tool_tilt_deg", max_tilt_degrees}};
    std::cout << output.dump(2) << '\n';
    return;
  }
  std::cout << "robot " << robot.name() << '\n';
  if (!result.solved()) {
    std::cout << "status: unreachable (the wrist centre is outside the arm's workspace)\n";
  } else {
    std::cout << "status: solved, singularities: "
              << kinematics::singularity_names(result.singularities) << "\n\n"
              << "config" << std::setw(12) << "q1" << std::setw(12) << "q2" << std::setw(12) << "q3"
              << std::setw(12) << "q4" << std::setw(12) << "q5" << std::setw(12) << "q6"
              << "  (rad)  limits       fk residual\n"
              << std::fixed;
    for (const nlohmann::ordered_json& solution : solutions) {
      std::cout << std::setw(6) << solution["config"].get<std::string>() << std::setprecision(6);
      for (double angle : solution["q"]) std::cout << std::setw(12) << angle;
      const std::vector<int> out = solution["joints_out_of_limits"];
      std::cout << "         " << std::left << std::setw(12)
                << (out.empty() ? "ok" : "out " + joint_list(out)) << std::right << std::scientific
                << std::setprecision(1) << solution["fk_residual_max"].get<double>() << std::fixed;
      const std::vector<std::string> singular = solution["singularities"];
      for (std::size_t i = 0; i < singular.size(); ++i) {
        std::cout << (i == 0 ? "  singular: " : "+") << singular[i];
      }
      std::cout << '\n';
    }
    std::cout << "\nwithin limits: " << result.count_within_limits() << " of 8\n";
  }
  std::cout << std::fixed << std::setprecision(1)
            << "reachable (SPAR: an in-limit configuration and tool z "
            << "within " << max_tilt_degrees << " deg of down; tilt " << reach.tool_tilt / kDegree
            << " deg): " << (reach.reachable ? "yes" : "no") << '\n';
}

}  // namespace

void add_fk_command(CLI::App& app) {
  auto* command = app.add_subcommand("fk", "Forward kinematics of a built-in robot");
  auto options = std::make_shared<CommonOptions>();
  auto joints = std::make_shared<std::string>();
  add_common_options(command, *options);
  command->add_option("--q", *joints, "Joint angles in radians, e.g. \"0 0.785 3.14 0 0.785 0\"")
      ->required();
  command->callback([options, joints] { run_fk(*options, *joints); });
}

void add_ik_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "ik", "All eight closed-form inverse kinematics solutions, with joint-limit status");
  auto options = std::make_shared<CommonOptions>();
  auto pose = std::make_shared<std::string>();
  auto max_tilt = std::make_shared<double>(45.0);
  add_common_options(command, *options);
  command->add_option("--pose", *pose, "Flange pose: 16 numbers of the 4x4 matrix, row-major")
      ->required();
  add_number_option(*command, "--max-tilt-deg", *max_tilt,
                    "Cone half-angle around world -z for the tool z axis (reachability)", {0, 180});
  command->callback([options, pose, max_tilt] { run_ik(*options, *pose, *max_tilt); });
}

}  // namespace spar::cli
