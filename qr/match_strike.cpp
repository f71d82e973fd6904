#include "spar/qr/match_strike.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>

#include "spar/common/number.hpp"

namespace spar::qr {
namespace {

constexpr double kForcePerMillimetre = 0.5;      // N per mm of digging depth
constexpr double kVelocityPerMillimetre = 0.05;  // m/s per mm of jumping gap
constexpr double kDegree = std::numbers::pi / 180.0;
const char* const kControlKeys[] = {"depth", "angle", "gap"};

double force(double depth) { return kForcePerMillimetre * depth; }

}  // namespace

MatchStrikeModel match_strike_model() {
  MatchStrikeModel model;
  Network& net = model.network;
  const int depth = net.add_control("digging depth");
  const int angle = net.add_control("angle");
  const int gap = net.add_control("jumping gap");
  const int landmark = net.add_constant("landmark angle", Sign::kMinus);
  const int force_node = net.add_relation(NodeKind::kMonotonePlus, "force", {depth});
  const int velocity = net.add_relation(NodeKind::kMonotonePlus, "velocity", {gap});
  const int heat = net.add_relation(NodeKind::kProduct, "heat", {force_node, velocity});
  const int minus_landmark = net.add_relation(NodeKind::kNegative, "-landmark", {landmark});
  const int offset = net.add_relation(NodeKind::kSum, "strike offset", {angle, minus_landmark});
  const int strike_lever = net.add_relation(NodeKind::kAbs, "strike lever", {offset});
  const int strike_moment =
      net.add_relation(NodeKind::kProduct, "strike moment", {force_node, strike_lever});
  const int start_lever = net.add_relation(NodeKind::kAbs, "start lever", {angle});
  const int start_moment =
      net.add_relation(NodeKind::kProduct, "start moment", {force_node, start_lever});
  const int break_start = net.add_threshold("break on move to start", start_moment);
  const int break_strike = net.add_threshold("break on strike", strike_moment);
  const int ignition = net.add_threshold("ignition", heat);
  model.controls = {{depth, 2.0, 20.0, 0.5, 1.5, "mm"},
                    {angle, -60.0, 60.0, 1.0, 10.0, "deg"},
                    {gap, 1.0, 20.0, 1.0, 5.0, "mm"}};
  model.goals = {{break_start, false}, {break_strike, false}, {ignition, true}};
  return model;
}

std::vector<double> parse_match_start(const std::string& text,
                                      const std::vector<double>& defaults) {
  const MatchStrikeModel model = match_strike_model();
  std::vector<double> start = defaults;
  std::stringstream stream(text);
  std::string token;
  while (std::getline(stream, token, ',')) {
    const auto equals = token.find('=');
    if (equals == std::string::npos) {
      throw QrError("bad --start token '" + token + "': expected key=value, e.g. depth=8");
    }
    const std::string key = token.substr(0, equals);
    const std::string number = token.substr(equals + 1);
    const auto found = std::find(std::begin(kControlKeys), std::end(kControlKeys), key);
    if (found == std::end(kControlKeys)) {
      throw QrError("bad --start key '" + key + "': expected depth, angle or gap");
    }
    const std::optional<double> parsed = parse_number(number);
    if (!parsed || !std::isfinite(*parsed)) {
      throw QrError("bad --start value '" + number + "' for " + key + ": expected a number");
    }
    const double value = *parsed;
    const ControlSpec& spec = model.controls[found - std::begin(kControlKeys)];
    if (value < spec.minimum || value > spec.maximum) {
      std::ostringstream message;
      message << "--start " << key << "=" << number << " is outside the physical limits ["
              << spec.minimum << ", " << spec.maximum << "] " << spec.unit;
      throw QrError(message.str());
    }
    start[found - std::begin(kControlKeys)] = value;
  }
  return start;
}

double WorldParameters::landmark_degrees() const { return -std::atan(friction) / kDegree; }

SimulatedWorld::SimulatedWorld(WorldParameters parameters, std::uint64_t seed)
    : parameters_(parameters), random_(seed) {}

SimulatedWorld SimulatedWorld::random(std::uint64_t seed) {
  std::mt19937_64 draw(seed);
  auto uniform = [&draw](double low, double high) {
    return std::uniform_real_distribution<double>(low, high)(draw);
  };
  WorldParameters p;
  const double landmark = uniform(10.0, 35.0);  // degrees behind perpendicular
  p.friction = std::tan(landmark * kDegree);
  // Depth at which the match ignites at the maximum gap, and the half-width of the unbroken angle
  // window around the landmark at that depth: wide enough that the window overlaps the start
  // motion's window around 0 (so some control values succeed).
  const double ignition_depth = uniform(7.0, 15.0);
  const double half_window = uniform(landmark / 2 + 5.0, std::min(landmark / 2 + 20.0, 60.0));
  p.ignition_heat = p.friction * force(ignition_depth) * kVelocityPerMillimetre * 20.0;
  p.breaking_moment = force(ignition_depth) * p.stick_length * std::sin(half_window * kDegree);
  p.variation = uniform(0.0, 0.03);
  return SimulatedWorld(p, seed ^ 0x9e3779b97f4a7c15ULL);
}

SimulatedWorld SimulatedWorld::paper_like() {
  WorldParameters p;
  p.friction = std::tan(25.0 * kDegree);
  p.ignition_heat = p.friction * force(13.8) * kVelocityPerMillimetre * 20.0;
  p.breaking_moment = force(11.75) * p.stick_length * std::sin(45.0 * kDegree);
  p.variation = 0.0;
  return SimulatedWorld(p, 1);
}

Outcome SimulatedWorld::outcome(const std::vector<double>& controls, double strength_factor,
                                double ignition_factor) const {
  const double f = force(controls[kDiggingDepth]);
  const double angle = controls[kAngle];
  const double strength = parameters_.breaking_moment * strength_factor;
  auto moment = [&](double lever_degrees) {
    return f * parameters_.stick_length *
           std::sin(std::min(std::abs(lever_degrees), 90.0) * kDegree);
  };
  Outcome result(3);
  result[kBreakOnStart] = moment(angle) > strength;
  if (*result[kBreakOnStart]) return result;  // the strike never happens
  result[kBreakOnStrike] = moment(angle - parameters_.landmark_degrees()) > strength;
  if (*result[kBreakOnStrike]) return result;  // a broken match does not light
  const double heat = parameters_.friction * f * kVelocityPerMillimetre * controls[kJumpingGap];
  result[kIgnition] = heat >= parameters_.ignition_heat * ignition_factor;
  return result;
}

Outcome SimulatedWorld::nominal(const std::vector<double>& controls) const {
  return outcome(controls, 1.0, 1.0);
}

Outcome SimulatedWorld::execute(const std::vector<double>& controls) {
  std::normal_distribution<double> variation(0.0, parameters_.variation);
  const double strength = 1.0 + variation(random_);
  const double ignition = 1.0 + variation(random_);
  return outcome(controls, strength, ignition);
}

World SimulatedWorld::as_function() {
  return [this](const std::vector<double>& controls) { return execute(controls); };
}

}  // namespace spar::qr
