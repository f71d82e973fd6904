#include "spar/common/limits.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "spar/common/number.hpp"
#include "spar/common/text.hpp"
#include "spar/common/units.hpp"

namespace spar {
namespace {

constexpr double kTurn = 2 * std::numbers::pi;
constexpr double kGripper = 2.0;    // metres: the widest parallel gripper spar models
constexpr double kWorkspace = 100;  // metres from the origin: a robot cell, with room to spare

using enum Quantity;

// Keep the rows grouped by where they are read; the reason is printed after the range.
constexpr std::array kNumericLimits{
    // robot.gripper (geometry::GripperSpec), also `spar object --max-opening`
    NumericLimit{"robot.gripper.max_opening", kLength, 0, kGripper, true,
                 "the widest parallel gripper spar models"},
    NumericLimit{"robot.gripper.min_opening", kLength, 0, kGripper, false,
                 "the widest parallel gripper spar models"},
    NumericLimit{"robot.gripper.finger_length", kLength, 0, kGripper, true, "a gripper's size"},
    NumericLimit{"robot.gripper.finger_width", kLength, 0, kGripper, true, "a gripper's size"},
    NumericLimit{"robot.gripper.finger_thickness", kLength, 0, kGripper, true, "a gripper's size"},
    NumericLimit{"robot.gripper.tip_beyond_contact", kLength, 0, kGripper, false,
                 "a gripper's size"},
    NumericLimit{"robot.gripper.palm_width", kLength, 0, kGripper, true, "a gripper's size"},
    NumericLimit{"robot.gripper.palm_height", kLength, 0, kGripper, true, "a gripper's size"},
    NumericLimit{"robot.max_tilt", kAngle, 0, std::numbers::pi, true, "a tilt from straight down"},
    NumericLimit{"robot.approach_distance", kLength, 0, 2, false,
                 "the straight-line approach and retreat above a destination"},
    NumericLimit{"collision.margin", kLength, 0, 0.1, false,
                 "the least distance kept between two bodies"},
    // grasping (geometry::GraspQuantization), also `spar object --approach-step / --positions`:
    // a face pair has positions_per_axis^2 x (360 deg / approach_step) grasps.
    NumericLimit{"grasping.approach_step", kAngle, 1 * units::kDegree, kTurn, false,
                 "each step is one more grasp per contact position"},
    NumericLimit{"grasping.positions_per_axis", kCount, 1, 20, false,
                 "a face pair gets the square of it as contact positions"},
    // Poses: every translation (xyz, at, places, a matrix's last column, robot base and tool)
    // and every orientation angle (rpy, yaw).
    NumericLimit{"pose.position", kLength, -kWorkspace, kWorkspace, false,
                 "a coordinate in a robot cell"},
    NumericLimit{"pose.angle", kAngle, -kTurn, kTurn, false, "one turn either way"},
    // robot.dh (a Puma-type arm of kinematics::DhChain)
    NumericLimit{"robot.dh.length", kLength, -kWorkspace, kWorkspace, false,
                 "a link length in a robot cell"},
    NumericLimit{"robot.dh.angle", kAngle, -kTurn, kTurn, false, "one turn either way"},
    NumericLimit{"robot.dh.limits", kAngle, -2 * kTurn, 2 * kTurn, false, "two turns either way"},
    // Uncertainty half-widths and Gaussian sigmas (robot, objects, sensors.range_scan.residual),
    // and the relative cost of reducing each component.
    NumericLimit{"uncertainty.length", kLength, 0, 10, false, "an error in a robot cell"},
    NumericLimit{"uncertainty.angle", kAngle, 0, std::numbers::pi, false,
                 "a half-width of half a turn already allows any heading"},
    NumericLimit{"uncertainty.cost", kNumber, 0, 1e6, true, "a relative weight"},
    // goals[].assembled
    NumericLimit{"goal.clearance", kLength, 0, 1, false, "an insertion's clearance"},
    NumericLimit{"goal.angular_clearance", kAngle, 0, std::numbers::pi / 2, false,
                 "an insertion's angular clearance"},
    NumericLimit{"goal.mating_vector", kNumber, -1e6, 1e6, false,
                 "a direction (only its sense matters)"},
    // sensors.cameras[] (planner::CameraSensor): intrinsics and noise in pixels. The image side's
    // bound is sensing::kMaxImageSide (common/ cannot include sensing/; the scenario test checks).
    NumericLimit{"camera.focal", kNumber, 0, 1e6, true, "a focal length in pixels"},
    NumericLimit{"camera.principal_point", kNumber, -1e6, 1e6, false, "a pixel coordinate"},
    NumericLimit{"camera.image_side", kCount, 1, 16384, false, "an image side in pixels"},
    NumericLimit{"camera.noise_px", kNumber, 0, 100, false, "an edge detector's noise in pixels"},
    NumericLimit{"camera.detection_probability", kNumber, 0, 1, true, "a probability"},
    // How many entries a scenario's lists and maps may hold: the geometric level tries every
    // place for every object, stable pose and grasp, and every object's mesh is processed.
    NumericLimit{"scenario.objects", kCount, 1, 100, false, "each object is a mesh to process"},
    NumericLimit{"scenario.places", kCount, 0, 1000, false,
                 "every place is tried with every object, stable pose and grasp"},
    NumericLimit{"sensors.cameras", kCount, 0, 100, false, "each camera renders the whole scene"},
    NumericLimit{"scenario.goals", kCount, 0, 100, false, "each goal is a subplan"},
};

std::string short_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

std::string_view default_unit(Quantity quantity) {
  switch (quantity) {
    case kLength:
      return "m";
    case kAngle:
      return "rad";
    case kCount:
    case kNumber:
      break;
  }
  return "";
}

std::string_view noun(Quantity quantity) {
  switch (quantity) {
    case kLength:
      return "a length";
    case kAngle:
      return "an angle";
    case kCount:
      return "a whole number";
    case kNumber:
      break;
  }
  return "a number";
}

}  // namespace

bool NumericLimit::contains(double value) const {
  if (!std::isfinite(value) || value > high) return false;
  if (low_exclusive ? value <= low : value < low) return false;
  return quantity != kCount || value == std::floor(value);
}

std::span<const NumericLimit> numeric_limits() { return kNumericLimits; }

const NumericLimit& numeric_limit(std::string_view key) {
  for (const NumericLimit& limit : kNumericLimits)
    if (limit.key == key) return limit;
  throw std::logic_error("no numeric limit for '" + std::string(key) + "' in common/limits.cpp");
}

std::string describe_limit(const NumericLimit& limit, GivenUnit unit) {
  const std::string_view name = unit.name.empty() ? default_unit(limit.quantity) : unit.name;
  std::string suffix;
  if (!name.empty()) suffix.append(1, ' ').append(name);  // piecewise: GCC 12 -Wrestrict
  const auto in_unit = [&](double si) { return short_number(si / unit.si_per_unit) + suffix; };
  std::string out(noun(limit.quantity));
  if (limit.low == -limit.high && !limit.low_exclusive)
    return out + " from " + in_unit(limit.low) + " to " + in_unit(limit.high);
  out += limit.low_exclusive ? " > " : " >= ";
  return out + short_number(limit.low / unit.si_per_unit) + " and <= " + in_unit(limit.high);
}

std::optional<std::string> limit_problem(const NumericLimit& limit, double value, GivenUnit unit,
                                         std::string_view given_text) {
  if (limit.contains(value)) return std::nullopt;
  const std::string_view name = unit.name.empty() ? default_unit(limit.quantity) : unit.name;
  std::string given = printable(given_text, 40);
  if (given.empty())
    given = limit.quantity == kCount && value == std::floor(value) && std::abs(value) < 1e15
                ? std::to_string(static_cast<long long>(value))
                : format_number(value / unit.si_per_unit);
  std::string out = "must be " + describe_limit(limit, unit);
  out.append(" (").append(limit.reason).append("), got ").append(given);
  if (!name.empty()) out.append(1, ' ').append(name);
  return out;
}

}  // namespace spar
