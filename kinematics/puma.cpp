#include "spar/kinematics/puma.hpp"

#include <numbers>
#include <string>

namespace spar::kinematics {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kHalfPi = std::numbers::pi / 2.0;

// Joint limits shared by both models (Wang & Chen, IEEE T-RA 7(4) 1991, as used in the toolbox).
constexpr JointLimits kPumaLimits[6] = {
    {-160 * kDegree, 160 * kDegree}, {-110 * kDegree, 110 * kDegree},
    {-135 * kDegree, 135 * kDegree}, {-266 * kDegree, 266 * kDegree},
    {-100 * kDegree, 100 * kDegree}, {-266 * kDegree, 266 * kDegree}};

// The Puma arm geometry with Paul's alpha signs; only d1, a2, d3, a3, d4 differ between models.
DhChain make_puma(std::string name, double d1, double a2, double d3, double a3, double d4,
                  std::string source) {
  return DhChain(
      std::move(name),
      {
          {.d = d1, .a = 0.0, .alpha = kHalfPi, .offset = 0.0, .limits = kPumaLimits[0]},
          {.d = 0.0, .a = a2, .alpha = 0.0, .offset = 0.0, .limits = kPumaLimits[1]},
          {.d = d3, .a = a3, .alpha = -kHalfPi, .offset = 0.0, .limits = kPumaLimits[2]},
          {.d = d4, .a = 0.0, .alpha = kHalfPi, .offset = 0.0, .limits = kPumaLimits[3]},
          {.d = 0.0, .a = 0.0, .alpha = -kHalfPi, .offset = 0.0, .limits = kPumaLimits[4]},
          {.d = 0.0, .a = 0.0, .alpha = 0.0, .offset = 0.0, .limits = kPumaLimits[5]},
      },
      std::move(source));
}

}  // namespace

const DhChain& puma560() {
  static const DhChain robot = make_puma(
      "puma560", /*d1=*/0.67183, /*a2=*/0.4318, /*d3=*/0.15005, /*a3=*/0.0203, /*d4=*/0.4318,
      "Unimation Puma 560, standard DH as in P. Corke, Robotics Toolbox for Python, "
      "models/DH/Puma560.py (Corke & Armstrong-Helouvry, ICRA 1994; d3 = 150.05 mm; pedestal "
      "d1 = 26.45 in; Paul's alpha signs; limits Wang & Chen 1991). Corpus: puma560.json");
  return robot;
}

const DhChain& puma762() {
  static const DhChain robot = make_puma(
      "puma762", /*d1=*/0.0, /*a2=*/0.65, /*d3=*/0.19, /*a3=*/0.0, /*d4=*/0.6,
      "Puma 762 COMMUNITY model, not a Unimation document: D. Riley, '3D Puma Robot Demo' "
      "(MathWorks File Exchange #14932), transcribed to standard DH with Paul's alpha signs; "
      "pedestal unknown (d1 = 0); limits are the Puma 560's, UNVERIFIED. Corpus: puma560.json");
  return robot;
}

std::vector<std::string_view> builtin_robot_names() { return {"puma560", "puma762"}; }

const DhChain& builtin_robot(std::string_view name) {
  if (name == "puma560") return puma560();
  if (name == "puma762") return puma762();
  throw KinematicsError("unknown robot '" + std::string(name) +
                        "'; built-in robots are: puma560, puma762");
}

}  // namespace spar::kinematics
