#include "spar/planner/internal/scenario_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "spar/common/input_file.hpp"
#include "spar/common/limits.hpp"
#include "spar/common/text.hpp"
#include "spar/common/units.hpp"
#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/mesh_io.hpp"
#include "spar/geometry/stable_poses.hpp"
#include "spar/kinematics/robots.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/internal/yaml_syntax.hpp"

namespace spar::planner::internal {
namespace {

using kinematics::Transform;

// Edit distance with adjacent transpositions (optimal string alignment), for "did you mean"
// suggestions: "modle" is one edit from "model".
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min(
          {d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& word : words) out += (out.empty() ? "" : ", ") + word;
  return out.empty() ? "none" : out;
}

// " (did you mean 'x'?)" when a known word is within a typo's distance of `word`, else "".
std::string suggestion(std::string_view word, const std::vector<std::string>& known) {
  const std::string* best = nullptr;
  std::size_t best_distance = 0;
  for (const std::string& candidate : known) {
    const std::size_t distance = edit_distance(word, candidate);
    if (!best || distance < best_distance) {
      best = &candidate;
      best_distance = distance;
    }
  }
  // One edit per three letters (at least one): "ft" is not a typo of "m".
  const std::size_t allowed = std::max<std::size_t>(1, word.size() / 3);
  if (!best || best_distance > allowed) return "";
  return " (did you mean '" + *best + "'?)";
}

bool is_identifier(std::string_view name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

std::string describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Scalar:
      return single_quoted(node.Scalar());
    default:
      return "nothing";
  }
}

// Rz(yaw) Ry(pitch) Rx(roll): URDF's and Drake's roll-pitch-yaw about fixed world axes.
Eigen::Matrix3d rpy_rotation(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

class Reader;

// A YAML map whose keys have been checked: each is a known one and none repeats. `path` names the
// map in messages ("robot.gripper").
class Fields {
 public:
  Fields(const Reader& reader, const YAML::Node& map, std::string path,
         std::vector<std::string> known);

  // The value of `key`; an undefined node when the key is absent.
  [[nodiscard]] YAML::Node get(const std::string& key) const;
  [[nodiscard]] bool has(const std::string& key) const { return get(key).IsDefined(); }
  // The value of `key`, or a ScenarioError at the map when it is absent.
  [[nodiscard]] YAML::Node require(const std::string& key) const;
  // "robot.gripper.max_opening"
  [[nodiscard]] std::string path(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }
  [[nodiscard]] const YAML::Node& node() const { return map_; }
  [[nodiscard]] const std::string& name() const { return path_; }  // "robot.gripper"

 private:
  const Reader& reader_;
  YAML::Node map_;
  std::string path_;
  std::vector<std::pair<std::string, YAML::Node>> entries_;  // in file order
};

class Reader {
 public:
  // `source` may come from the file system: it is kept printable (common/text.hpp).
  Reader(const std::string& source, std::filesystem::path base_dir)
      : source_(printable(source)), base_dir_(std::move(base_dir)) {}

  [[nodiscard]] Scenario read(std::string_view document_text);

  [[nodiscard]] SourceLocation where(const YAML::Node& node) const {
    SourceLocation location{.file = source_};
    if (node.IsDefined() && !node.Mark().is_null()) {
      location.line = node.Mark().line + 1;
      location.column = node.Mark().column + 1;
    }
    return location;
  }
  // Every message goes through printable(): what it echoes from the file (a key, a scalar) can
  // hold control characters that YAML escapes such as "\b" or "\0" produce.
  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    throw ScenarioError(where(node).str() + ": " + printable(what));
  }

  [[nodiscard]] const YAML::Node& expect_map(const YAML::Node& node,
                                             const std::string& path) const {
    if (!node.IsMap()) fail(node, path + ": expected a map, got " + describe(node));
    return node;
  }
  [[nodiscard]] const YAML::Node& expect_list(const YAML::Node& node,
                                              const std::string& path) const {
    if (!node.IsSequence()) fail(node, path + ": expected a list, got " + describe(node));
    return node;
  }
  // A name or a one-line text: no control characters (a NUL or a backspace from a YAML escape
  // would print as something else in every report).
  [[nodiscard]] std::string text(const YAML::Node& node, const std::string& path,
                                 bool lines = false) const {
    if (!node.IsScalar() || node.Scalar().empty())
      fail(node, path + ": expected a name, got " + describe(node));
    if (const auto at = find_control_character(node.Scalar(), lines))
      fail(node, path + ": " + describe(node) + " holds a control character (byte " +
                     std::to_string(*at + 1) + "): names and texts must be printable");
    return node.Scalar();
  }
  [[nodiscard]] std::string identifier(const YAML::Node& node, const std::string& path) const {
    const std::string name = text(node, path);
    if (!is_identifier(name))
      fail(node, path + ": '" + name +
                     "' is not a name (letters, digits and _, not starting with a digit)");
    return name;
  }

 private:
  [[nodiscard]] double number(const YAML::Node& node, const std::string& path) const;
  [[nodiscard]] std::vector<double> numbers(const YAML::Node& node, const std::string& path,
                                            std::size_t count) const;
  // A number in the file's units, converted to metres or radians by the quantity of the row
  // `limit_key` of common/limits.hpp and checked against it.
  [[nodiscard]] double quantity(const YAML::Node& node, const std::string& path,
                                std::string_view limit_key) const;
  [[nodiscard]] std::vector<double> quantities(const YAML::Node& node, const std::string& path,
                                               std::size_t count, std::string_view limit_key) const;
  // Refuses a list or map holding more entries than the row `limit_key` allows.
  void check_count(const YAML::Node& node, const std::string& path,
                   std::string_view limit_key) const;

  void read_units(const YAML::Node& node, Units& units) const;
  [[nodiscard]] Transform rigid_pose(const YAML::Node& node, const std::string& path) const;
  [[nodiscard]] Transform rigid_pose(const Fields& pose) const;
  // Half-widths {dx, dy, dz, dtheta}, and in `model` how they are distributed; `also` names
  // further keys the caller reads (robot.uncertainty's joints).
  [[nodiscard]] kinematics::PoseUncertainty uncertainty(
      const YAML::Node& node, const std::string& path, UncertaintyModel& model,
      const std::vector<std::string>& also = {}) const;
  void read_robot(const YAML::Node& node, RobotSpec& robot) const;
  [[nodiscard]] kinematics::DhChain dh_chain(const YAML::Node& node, const std::string& path) const;
  void read_gripper(const YAML::Node& node, geometry::GripperSpec& gripper) const;
  void read_grasping(const YAML::Node& node, geometry::GraspQuantization& grasping) const;
  [[nodiscard]] ObjectSpec read_object(const YAML::Node& key, const YAML::Node& node) const;
  [[nodiscard]] geometry::ObjectModel object_model(const Fields& entry, const std::string& name,
                                                   std::string& shape) const;
  // A built-in (`mesh` false) or a mesh file's model; `shape` gets the "builtin: x" form.
  [[nodiscard]] geometry::ObjectModel shape_model(const YAML::Node& node, const std::string& path,
                                                  bool mesh, const std::string& name,
                                                  std::string& shape) const;
  [[nodiscard]] std::vector<ObjectIdentity> read_identities(const YAML::Node& node,
                                                            const std::string& path,
                                                            const std::string& name) const;
  void read_pose(const YAML::Node& node, const std::string& path, ObjectSpec& object) const;
  // `pose` of an object with candidate identities or a list of stable poses: its hypotheses.
  void read_hypotheses(const Fields& pose, ObjectSpec& object) const;
  // read_hypotheses' two forms: a pose given outright (the identity alone is uncertain), or a
  // place with the stable poses `pose.stable` lists (every one of each candidate's without it).
  [[nodiscard]] std::vector<ObjectHypothesis> rigid_hypotheses(
      const Fields& pose, const std::vector<ObjectIdentity>& candidates) const;
  [[nodiscard]] std::vector<ObjectHypothesis> stable_hypotheses(
      const Fields& pose, const std::vector<ObjectIdentity>& candidates,
      const ObjectSpec& object) const;
  // The labels `pose.stable` lists (one or a list, none repeated), each with its node.
  [[nodiscard]] std::vector<std::pair<std::string, YAML::Node>> listed_stable_poses(
      const Fields& pose, bool identities) const;
  // Face ids named by `node` (a face id, a face name, or with `features`, a feature name; or a
  // list of these), ascending and distinct.
  [[nodiscard]] std::vector<int> faces(const YAML::Node& node, const std::string& path,
                                       const ObjectSpec& object, bool features) const;
  [[nodiscard]] std::vector<Place> read_places(const YAML::Node& node) const;
  void read_sensors(const YAML::Node& node, Scenario& scenario) const;
  [[nodiscard]] CollisionSettings read_collision(const YAML::Node& node) const;
  [[nodiscard]] bool boolean(const YAML::Node& node, const std::string& path) const;
  [[nodiscard]] AtGoal read_at(const YAML::Node& node, const std::string& path,
                               const Scenario& scenario) const;
  // Goals that cannot all hold, or that name a fixed object as moving: the first such goal fails.
  void check_goals(const Scenario& scenario, const std::vector<YAML::Node>& nodes) const;
  [[nodiscard]] CameraSensor read_camera(const YAML::Node& node, const std::string& path) const;
  // What cameras and the range scanner share: `mount` (fixed | wrist; `fallback` when absent),
  // intrinsics {fx, fy, cx, cy, width, height} in pixels, detection_probability in (0, 1].
  [[nodiscard]] sensing::Mount mount(const Fields& fields, sensing::Mount fallback) const;
  [[nodiscard]] sensing::Intrinsics intrinsics(const YAML::Node& node,
                                               const std::string& path) const;
  [[nodiscard]] double detection_probability(const Fields& fields, double fallback) const;
  [[nodiscard]] SensingSettings read_sensing(const YAML::Node& node) const;
  [[nodiscard]] AssembledGoal read_assembled(const YAML::Node& node, const std::string& path,
                                             const Scenario& scenario) const;

  // Adds a warning to the scenario when a mesh's size is implausible in the file's length unit.
  void check_mesh_size(const geometry::Mesh& mesh, const YAML::Node& node,
                       const std::string& path) const;

  std::string source_;
  std::filesystem::path base_dir_;
  Units units_;                                // the file's, once read_units has run
  mutable std::vector<std::string> warnings_;  // Scenario::warnings, in file order
};

Fields::Fields(const Reader& reader, const YAML::Node& map, std::string path,
               std::vector<std::string> known)
    : reader_(reader), map_(map), path_(std::move(path)) {
  (void)reader_.expect_map(map, path_.empty() ? "the scenario" : path_);
  for (const auto& entry : map) {
    const YAML::Node key = entry.first;
    if (!key.IsScalar()) reader_.fail(key, path_ + ": keys must be names, got " + describe(key));
    const std::string& name = key.Scalar();
    if (std::find(known.begin(), known.end(), name) == known.end())
      reader_.fail(key, (path_.empty() ? "" : path_ + ": ") + "unknown key '" + name + "'" +
                            suggestion(name, known) + "; known keys: " + join(known));
    for (const auto& [seen, value] : entries_)
      if (seen == name)
        reader_.fail(key, (path_.empty() ? "" : path_ + ": ") + "duplicate key '" + name + "'");
    entries_.emplace_back(name, entry.second);
  }
}

YAML::Node Fields::get(const std::string& key) const {
  for (const auto& [name, value] : entries_)
    if (name == key) return value;
  return YAML::Node(YAML::NodeType::Undefined);
}

YAML::Node Fields::require(const std::string& key) const {
  const YAML::Node value = get(key);
  if (!value.IsDefined())
    reader_.fail(map_, (path_.empty() ? "" : path_ + ": ") + "missing key '" + key + "'");
  return value;
}

double Reader::number(const YAML::Node& node, const std::string& path) const {
  if (!node.IsScalar()) fail(node, path + ": expected a number, got " + describe(node));
  std::string_view scalar = node.Scalar();
  // YAML's spellings of the special values, so that they reach the finiteness check below.
  for (const std::string_view nan : {".nan", ".NaN", ".NAN"})
    if (scalar == nan) scalar = "nan";
  for (const std::string_view inf : {".inf", ".Inf", ".INF", "+.inf", "+.Inf", "+.INF"})
    if (scalar == inf) scalar = "inf";
  for (const std::string_view inf : {"-.inf", "-.Inf", "-.INF"})
    if (scalar == inf) scalar = "-inf";
  if (scalar.starts_with('+')) scalar.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(scalar.data(), scalar.data() + scalar.size(), value);
  if (error != std::errc() || end != scalar.data() + scalar.size())
    fail(node, path + ": expected a number, got " + describe(node));
  if (!std::isfinite(value)) fail(node, path + ": expected a finite number, got " + describe(node));
  return value;
}

std::vector<double> Reader::numbers(const YAML::Node& node, const std::string& path,
                                    std::size_t count) const {
  if (!node.IsSequence() || node.size() != count)
    fail(node,
         path + ": expected a list of " + std::to_string(count) + " numbers, got " +
             (node.IsSequence() ? "a list of " + std::to_string(node.size()) : describe(node)));
  std::vector<double> values;
  for (std::size_t i = 0; i < count; ++i)
    values.push_back(number(node[i], path + "[" + std::to_string(i) + "]"));
  return values;
}

double Reader::quantity(const YAML::Node& node, const std::string& path,
                        std::string_view limit_key) const {
  const NumericLimit& limit = numeric_limit(limit_key);
  GivenUnit unit;
  if (limit.quantity == Quantity::kLength)
    unit = {units_.metres_per_length_unit(), units_.length_name()};
  if (limit.quantity == Quantity::kAngle)
    unit = {units_.radians_per_angle_unit(), units_.angle_name()};
  const double value = number(node, path) * unit.si_per_unit;
  if (const auto problem = limit_problem(limit, value, unit, node.Scalar()))
    fail(node, path + ": " + *problem);
  return value;
}

std::vector<double> Reader::quantities(const YAML::Node& node, const std::string& path,
                                       std::size_t count, std::string_view limit_key) const {
  (void)numbers(node, path, count);  // the shape and the numbers first
  std::vector<double> values;
  for (std::size_t i = 0; i < count; ++i)
    values.push_back(quantity(node[i], path + "[" + std::to_string(i) + "]", limit_key));
  return values;
}

void Reader::check_count(const YAML::Node& node, const std::string& path,
                         std::string_view limit_key) const {
  const std::size_t count = node.size();
  if (const auto problem = limit_problem(numeric_limit(limit_key), static_cast<double>(count)))
    fail(node, path + ": holds " + std::to_string(count) + " entries; their number " + *problem);
}

void Reader::read_units(const YAML::Node& node, Units& units) const {
  const Fields fields(*this, node, "units", {"length", "angle"});
  // The unit `value` names among `choices`, or the error listing them.
  const auto named = [&](const YAML::Node& value, const std::string& quantity, auto choices) {
    const std::string name = text(value, "units." + quantity);
    std::vector<std::string> known;
    for (const auto& [choice, unit] : choices) {
      if (name == choice) return unit;
      known.emplace_back(choice);
    }
    fail(value, "units." + quantity + ": unknown " + quantity + " unit '" + name + "'" +
                    suggestion(name, known) + "; known: " + join(known));
  };
  if (const YAML::Node length = fields.get("length"); length.IsDefined()) {
    units.length =
        named(length, "length",
              std::to_array<std::pair<const char*, LengthUnit>>({{"m", LengthUnit::kMetre},
                                                                 {"mm", LengthUnit::kMillimetre},
                                                                 {"in", LengthUnit::kInch}}));
  }
  if (const YAML::Node angle = fields.get("angle"); angle.IsDefined()) {
    units.angle = named(angle, "angle",
                        std::to_array<std::pair<const char*, AngleUnit>>(
                            {{"rad", AngleUnit::kRadian}, {"deg", AngleUnit::kDegree}}));
  }
}

Transform Reader::rigid_pose(const YAML::Node& node, const std::string& path) const {
  return rigid_pose(Fields(*this, node, path, {"xyz", "rpy", "matrix"}));
}

// {xyz, rpy} (either may be left out: zero) or {matrix: 4 rows of 4}, translation in the file's
// length unit.
Transform Reader::rigid_pose(const Fields& pose) const {
  if (const YAML::Node matrix = pose.get("matrix"); matrix.IsDefined()) {
    if (pose.has("xyz") || pose.has("rpy"))
      fail(pose.node(), pose.path("matrix") + ": give a pose either as a matrix or as xyz/rpy");
    const std::string path = pose.path("matrix");
    if (!matrix.IsSequence() || matrix.size() != 4)
      fail(matrix, path + ": expected 4 rows of 4 numbers, got " + describe(matrix));
    std::vector<double> values;
    for (std::size_t r = 0; r < 4; ++r) {
      const std::string row_path = path + "[" + std::to_string(r) + "]";
      std::vector<double> row = numbers(matrix[r], row_path, 4);
      if (r < 3)  // the translation, in the file's length unit (converted below)
        row[3] = quantity(matrix[r][3], row_path + "[3]", "pose.position") /
                 units_.metres_per_length_unit();
      values.insert(values.end(), row.begin(), row.end());
    }
    Transform transform;
    try {
      transform = kinematics::rigid_transform_from_row_major(values);
    } catch (const kinematics::KinematicsError& error) {
      fail(matrix, path + ": not a rigid transform: " + error.what());
    }
    transform.translation() *= units_.metres_per_length_unit();
    return transform;
  }
  Transform transform = Transform::Identity();
  if (const YAML::Node xyz = pose.get("xyz"); xyz.IsDefined()) {
    const std::vector<double> v = quantities(xyz, pose.path("xyz"), 3, "pose.position");
    transform.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  if (const YAML::Node rpy = pose.get("rpy"); rpy.IsDefined()) {
    const std::vector<double> v = quantities(rpy, pose.path("rpy"), 3, "pose.angle");
    transform.linear() = rpy_rotation(v[0], v[1], v[2]);
  }
  return transform;
}

kinematics::PoseUncertainty Reader::uncertainty(const YAML::Node& node, const std::string& path,
                                                UncertaintyModel& model,
                                                const std::vector<std::string>& also) const {
  std::vector<std::string> known = {"dx", "dy", "dz", "dtheta", "distribution", "sigma", "cost"};
  known.insert(known.end(), also.begin(), also.end());
  const Fields fields(*this, node, path, known);
  kinematics::PoseUncertainty result;
  // Each of the four components with its target in the half-widths, sigma and cost, and whether
  // it is an angle.
  struct Component {
    const char* key;
    double kinematics::PoseUncertainty::*member;
    bool angle;
  };
  static constexpr Component kComponents[] = {
      {"dx", &kinematics::PoseUncertainty::dx, false},
      {"dy", &kinematics::PoseUncertainty::dy, false},
      {"dz", &kinematics::PoseUncertainty::dz, false},
      {"dtheta", &kinematics::PoseUncertainty::dtheta, true}};
  const auto value_of = [&](const Fields& map, const Component& c) {
    const YAML::Node value = map.get(c.key);
    const std::string at = map.path(c.key);
    return quantity(value, at, c.angle ? "uncertainty.angle" : "uncertainty.length");
  };
  for (const Component& c : kComponents)
    if (fields.has(c.key)) result.*c.member = value_of(fields, c);
  model = UncertaintyModel{};
  if (const YAML::Node kind = fields.get("distribution"); kind.IsDefined()) {
    const std::string name = text(kind, fields.path("distribution"));
    const std::vector<std::string> known = {"uniform", "gaussian"};
    if (name == "gaussian")
      model.distribution = Distribution::kGaussian;
    else if (name != "uniform")
      fail(kind, fields.path("distribution") + ": unknown distribution '" + name + "'" +
                     suggestion(name, known) + "; known: " + join(known));
  }
  if (const YAML::Node sigma = fields.get("sigma"); sigma.IsDefined()) {
    if (model.distribution != Distribution::kGaussian)
      fail(sigma, fields.path("sigma") + ": sigma needs 'distribution: gaussian'");
    const Fields given(*this, sigma, fields.path("sigma"), {"dx", "dy", "dz", "dtheta"});
    for (const Component& c : kComponents)
      if (given.has(c.key)) {
        model.sigma.*c.member = value_of(given, c);
        if (result.*c.member > 0 && !(model.sigma.*c.member > 0))
          fail(given.get(c.key), given.path(c.key) + ": must be > 0 where the half-width is, got " +
                                     given.get(c.key).Scalar());
      }
  }
  // A Gaussian component without its sigma: the half-width is 3 sigma.
  if (model.distribution == Distribution::kGaussian)
    for (const Component& c : kComponents)
      if (model.sigma.*c.member == 0) model.sigma.*c.member = result.*c.member / 3;
  if (const YAML::Node cost = fields.get("cost"); cost.IsDefined()) {
    const Fields given(*this, cost, fields.path("cost"), {"dx", "dy", "dz", "dtheta"});
    for (const Component& c : kComponents)
      if (given.has(c.key))  // a weight: no unit
        model.cost.*c.member = quantity(given.get(c.key), given.path(c.key), "uncertainty.cost");
  }
  return result;
}

kinematics::DhChain Reader::dh_chain(const YAML::Node& node, const std::string& path) const {
  if (!expect_list(node, path).size()) fail(node, path + ": the DH table has no joints");
  std::vector<kinematics::DhJoint> joints;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const Fields row(*this, node[i], path + "[" + std::to_string(i) + "]",
                     {"d", "a", "alpha", "offset", "limits"});
    kinematics::DhJoint joint;
    if (row.has("d")) joint.d = quantity(row.get("d"), row.path("d"), "robot.dh.length");
    if (row.has("a")) joint.a = quantity(row.get("a"), row.path("a"), "robot.dh.length");
    if (row.has("alpha"))
      joint.alpha = quantity(row.get("alpha"), row.path("alpha"), "robot.dh.angle");
    if (row.has("offset"))
      joint.offset = quantity(row.get("offset"), row.path("offset"), "robot.dh.angle");
    const YAML::Node limits = row.require("limits");
    const std::vector<double> bounds = quantities(limits, row.path("limits"), 2, "robot.dh.limits");
    joint.limits = {bounds[0], bounds[1]};
    if (joint.limits.lower > joint.limits.upper)
      fail(limits, row.path("limits") + ": the lower limit is above the upper one");
    joints.push_back(joint);
  }
  try {
    return kinematics::DhChain("dh", std::move(joints), source_);
  } catch (const kinematics::KinematicsError& error) {
    fail(node, path + ": " + error.what());
  }
}

void Reader::read_gripper(const YAML::Node& node, geometry::GripperSpec& gripper) const {
  struct Length {
    const char* key;
    double* target;
  };
  const Length lengths[] = {{"max_opening", &gripper.max_opening},
                            {"min_opening", &gripper.min_opening},
                            {"finger_length", &gripper.finger_length},
                            {"finger_width", &gripper.finger_width},
                            {"finger_thickness", &gripper.finger_thickness},
                            {"tip_beyond_contact", &gripper.tip_beyond_contact},
                            {"palm_width", &gripper.palm_width},
                            {"palm_height", &gripper.palm_height}};
  std::vector<std::string> known;
  for (const Length& field : lengths) known.emplace_back(field.key);
  const Fields fields(*this, node, "robot.gripper", known);
  for (const Length& field : lengths) {
    const YAML::Node value = fields.get(field.key);
    if (!value.IsDefined()) continue;
    const std::string path = fields.path(field.key);
    *field.target = quantity(value, path, path);  // the limit's key is the key path
  }
  if (gripper.min_opening >= gripper.max_opening)
    fail(node, "robot.gripper: min_opening must be below max_opening");
}

void Reader::read_robot(const YAML::Node& node, RobotSpec& robot) const {
  const Fields fields(*this, node, "robot",
                      {"model", "dh", "urdf", "tip", "package_path", "base", "tool", "gripper",
                       "max_tilt", "approach_distance", "uncertainty"});
  const YAML::Node model = fields.get("model"), urdf = fields.get("urdf");
  if (model.IsDefined() && urdf.IsDefined())
    fail(urdf, "robot.urdf: give either model: <name> or urdf: <file>, not both");
  if (model.IsDefined()) {
    robot.model = text(model, "robot.model");
    std::vector<std::string> known;
    for (const std::string_view name : kinematics::robot_model_names()) known.emplace_back(name);
    known.emplace_back("dh");
    if (std::find(known.begin(), known.end(), robot.model) == known.end())
      fail(model, "robot.model: unknown robot model '" + robot.model + "'" +
                      suggestion(robot.model, known) + "; known: " + join(known) +
                      " (or urdf: <file>)");
  }
  // A URDF robot's ends and where its package:// names are (relative to the scenario's folder).
  kinematics::UrdfOptions options;
  if (const YAML::Node tip = fields.get("tip"); tip.IsDefined()) {
    if (!urdf.IsDefined() && (robot.model == "dh" || robot.model.starts_with("puma")))
      fail(tip, "robot.tip: a tip link goes with urdf: <file> or a URDF built-in (ur5, panda)");
    options.tip = text(tip, "robot.tip");
  }
  if (const YAML::Node folders = fields.get("package_path"); folders.IsDefined())
    for (std::size_t i = 0; i < expect_list(folders, "robot.package_path").size(); ++i)
      options.package_path.push_back(
          (base_dir_ / text(folders[i], "robot.package_path[" + std::to_string(i) + "]"))
              .lexically_normal());
  const YAML::Node dh = fields.get("dh");
  if (dh.IsDefined() && robot.model != "dh")
    fail(dh, "robot.dh: a DH table goes with model: dh, not " +
                 (urdf.IsDefined() ? std::string("a URDF file") : robot.model));
  try {
    if (urdf.IsDefined()) {
      robot.model = "urdf";
      robot.urdf = text(urdf, "robot.urdf");
      robot.arm = kinematics::load_urdf((base_dir_ / robot.urdf).lexically_normal(), options);
    } else if (robot.model == "dh") {
      robot.arm = kinematics::RobotModel::from_dh(dh_chain(fields.require("dh"), "robot.dh"));
    } else {
      robot.arm = kinematics::load_robot(robot.model, options);
    }
  } catch (const kinematics::KinematicsError& error) {
    const YAML::Node& where = urdf.IsDefined() ? urdf : model.IsDefined() ? model : node;
    fail(where, std::string(urdf.IsDefined() ? "robot.urdf: " : "robot: ") + error.what());
  }
  if (fields.has("base")) robot.base = rigid_pose(fields.get("base"), "robot.base");
  if (fields.has("tool")) robot.tool = rigid_pose(fields.get("tool"), "robot.tool");
  if (fields.has("gripper")) read_gripper(fields.get("gripper"), robot.gripper);
  if (const YAML::Node tilt = fields.get("max_tilt"); tilt.IsDefined()) {
    robot.max_tool_tilt = quantity(tilt, "robot.max_tilt", "robot.max_tilt");
  }
  if (const YAML::Node distance = fields.get("approach_distance"); distance.IsDefined())
    robot.approach_distance =
        quantity(distance, "robot.approach_distance", "robot.approach_distance");
  if (fields.has("uncertainty")) {
    const YAML::Node node = fields.get("uncertainty");
    robot.uncertainty = uncertainty(node, "robot.uncertainty", robot.uncertainty_model, {"joints"});
    if (const YAML::Node joints = node["joints"]; joints.IsDefined()) {
      // One half-width per moving joint: an angle (revolute) or a length (prismatic).
      const std::string path = "robot.uncertainty.joints";
      const std::size_t n = robot.arm.dof();
      if (!joints.IsSequence() || joints.size() != n)
        fail(joints, path + ": give one half-width per moving joint of " + robot.arm.name() + " (" +
                         std::to_string(n) + ")");
      for (std::size_t i = 0; i < n; ++i)
        robot.joint_uncertainty.push_back(quantity(
            joints[i], path + "[" + std::to_string(i) + "]",
            robot.arm.joints()[i].type == kinematics::JointType::kPrismatic ? "uncertainty.length"
                                                                            : "uncertainty.angle"));
    }
  }
}

void Reader::read_grasping(const YAML::Node& node, geometry::GraspQuantization& grasping) const {
  const Fields fields(*this, node, "grasping", {"approach_step", "positions_per_axis"});
  if (const YAML::Node step = fields.get("approach_step"); step.IsDefined()) {
    grasping.approach_step = quantity(step, "grasping.approach_step", "grasping.approach_step");
  }
  if (const YAML::Node positions = fields.get("positions_per_axis"); positions.IsDefined()) {
    grasping.positions_per_axis = static_cast<int>(
        quantity(positions, "grasping.positions_per_axis", "grasping.positions_per_axis"));
  }
}

geometry::ObjectModel Reader::object_model(const Fields& entry, const std::string& name,
                                           std::string& shape) const {
  const YAML::Node builtin = entry.get("builtin"), mesh = entry.get("mesh");
  if (builtin.IsDefined() == mesh.IsDefined())
    fail(entry.node(), entry.name() +
                           ": needs exactly one of 'builtin: <name>', 'mesh: <file>' and "
                           "'identity: [<candidates>]'");
  return builtin.IsDefined() ? shape_model(builtin, entry.path("builtin"), false, name, shape)
                             : shape_model(mesh, entry.path("mesh"), true, name, shape);
}

geometry::ObjectModel Reader::shape_model(const YAML::Node& node, const std::string& path,
                                          bool mesh, const std::string& name,
                                          std::string& shape) const {
  if (!mesh) {
    const std::string builtin_name = text(node, path);
    shape = "builtin: " + builtin_name;
    const auto known = geometry::builtin_object_names();
    if (std::find(known.begin(), known.end(), builtin_name) == known.end())
      fail(node, path + ": unknown built-in object '" + builtin_name + "'" +
                     suggestion(builtin_name, known) + "; known: " + join(known));
    return geometry::ObjectModel(name, geometry::builtin_mesh(builtin_name));
  }
  const std::string file = text(node, path);
  shape = "mesh: " + file;
  const std::filesystem::path resolved = (base_dir_ / file).lexically_normal();
  if (const std::string problem = input_file_problem(resolved, "mesh file"); !problem.empty())
    fail(node, path + ": " + printable(resolved.string()) + ": " + problem);
  try {
    geometry::Mesh scaled =
        geometry::read_mesh_file(resolved.string(), units_.metres_per_length_unit());
    check_mesh_size(scaled, node, path);
    return geometry::ObjectModel(name, std::move(scaled));
  } catch (const geometry::GeometryError& problem) {
    fail(node, path + ": bad mesh " + printable(resolved.string()) + ": " + problem.what());
  }
}

// `identity: [block, cube, meshes/part.off]`: two or more distinct candidates, each a built-in
// name or (ending in .off or .obj) a mesh file.
std::vector<ObjectIdentity> Reader::read_identities(const YAML::Node& node, const std::string& path,
                                                    const std::string& name) const {
  if (!node.IsSequence() || node.size() < 2)
    fail(node,
         path + ": expected a list of at least two candidate shapes, got " +
             (node.IsSequence() ? "a list of " + std::to_string(node.size()) : describe(node)));
  check_count(node, path, "object.identity");
  std::vector<ObjectIdentity> out;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string item = path + "[" + std::to_string(i) + "]";
    const std::string candidate = text(node[i], item);
    for (const ObjectIdentity& other : out)
      if (other.name == candidate) fail(node[i], item + ": '" + candidate + "' is listed twice");
    std::string lower = candidate;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const bool mesh = lower.ends_with(".off") || lower.ends_with(".obj");
    std::string shape;
    geometry::ObjectModel model = shape_model(node[i], item, mesh, name, shape);
    std::vector<geometry::StablePose> poses = geometry::stable_poses(model);
    out.push_back({.name = candidate,
                   .shape = std::move(shape),
                   .model = std::move(model),
                   .stable_poses = std::move(poses)});
  }
  return out;
}

// An object a parallel gripper picks up is a few millimetres to a metre or two across; a mesh far
// outside that was most likely written in another unit than the scenario's (a metre mesh in an
// inch scenario is 39 times too small). It still loads: the warning names the units that would
// give a plausible size.
void Reader::check_mesh_size(const geometry::Mesh& mesh, const YAML::Node& node,
                             const std::string& path) const {
  constexpr double kSmallest = 0.005, kLargest = 5;  // metres, largest extent
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const auto& triangle : mesh.triangles)
    for (const int v : triangle) {
      low = low.cwiseMin(mesh.vertices[v]);
      high = high.cwiseMax(mesh.vertices[v]);
    }
  const double extent = (high - low).maxCoeff();
  if (!(extent < kSmallest || extent > kLargest)) return;
  const double in_file_unit = extent / units_.metres_per_length_unit();
  std::string plausible;
  for (const LengthUnit unit : {LengthUnit::kMetre, LengthUnit::kMillimetre, LengthUnit::kInch}) {
    const Units other{.length = unit, .angle = units_.angle};
    const double metres = in_file_unit * other.metres_per_length_unit();
    if (unit != units_.length && metres >= kSmallest && metres <= kLargest)
      plausible += (plausible.empty() ? "" : " or ") + std::string(other.length_name());
  }
  std::ostringstream out;
  out << where(node).str() << ": " << path << ": the mesh is " << in_file_unit << ' '
      << units_.length_name() << " across (" << extent << " m), implausibly "
      << (extent < kSmallest ? "small" : "large")
      << " for an object a gripper picks up; its coordinates are read in the scenario's length "
         "unit (units.length: "
      << units_.length_name() << ")";
  if (!plausible.empty()) out << ": is the mesh in " << plausible << "?";
  warnings_.push_back(printable(out.str()));
}

std::vector<int> Reader::faces(const YAML::Node& node, const std::string& path,
                               const ObjectSpec& object, bool features) const {
  std::vector<YAML::Node> items;
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) items.push_back(item);
  } else {
    items.push_back(node);
  }
  const int count = static_cast<int>(object.model.faces().size());
  std::set<int> ids;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const YAML::Node& item = items[i];
    const std::string item_path = node.IsSequence() ? path + "[" + std::to_string(i) + "]" : path;
    const std::string name = text(item, item_path);
    int id = 0;
    if (std::from_chars(name.data(), name.data() + name.size(), id).ptr ==
        name.data() + name.size()) {
      if (id < 1 || id > count)
        fail(item, item_path + ": object '" + object.name + "' has no face " + name +
                       " (faces 1.." + std::to_string(count) + ")");
      ids.insert(id);
      continue;
    }
    if (features) {
      if (const auto feature = object.features.find(name); feature != object.features.end()) {
        ids.insert(feature->second.begin(), feature->second.end());
        continue;
      }
    }
    bool found = false;
    for (const geometry::Face& face : object.model.faces())
      if (face.name == name) {
        ids.insert(face.id);
        found = true;
      }
    if (found) continue;
    std::vector<std::string> known;
    if (features)
      for (const auto& [feature, unused] : object.features) known.push_back(feature);
    for (const geometry::Face& face : object.model.faces())
      if (!face.name.empty() && std::find(known.begin(), known.end(), face.name) == known.end())
        known.push_back(face.name);
    fail(item, item_path + ": object '" + object.name + "' has no face " +
                   (features ? "or feature " : "") + "named '" + name + "'" +
                   suggestion(name, known) + "; known: " + join(known));
  }
  return {ids.begin(), ids.end()};
}

void Reader::read_pose(const YAML::Node& node, const std::string& path, ObjectSpec& object) const {
  const Fields pose(*this, node, path, {"stable", "at", "yaw", "xyz", "rpy", "matrix"});
  const YAML::Node stable = pose.get("stable");
  if (!object.identities.empty() || stable.IsSequence()) {
    read_hypotheses(pose, object);
    return;
  }
  if (!stable.IsDefined()) {
    for (const char* key : {"at", "yaw"})
      if (pose.has(key))
        fail(pose.get(key), pose.path(key) + ": '" + key + "' goes with 'stable: <pose label>'");
    object.initial_pose = rigid_pose(pose);
    // Resting on the table (lowest point at z = 0) in one of the stable orientations?
    double lowest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& vertex : object.model.mesh().vertices)
      lowest = std::min(lowest, (object.initial_pose * vertex).z());
    if (std::abs(lowest) <= 1e3 * object.model.tolerance())
      if (const auto id =
              geometry::classify_orientation(object.stable_poses, object.initial_pose.linear()))
        object.initial_stable_pose = *id - 1;  // ids are 1-based
    return;
  }
  for (const char* key : {"xyz", "rpy", "matrix"})
    if (pose.has(key))
      fail(pose.get(key), pose.path(key) +
                              ": give either {stable, at, yaw} or {xyz, rpy} / "
                              "{matrix}, not both");
  const std::string label = text(stable, pose.path("stable"));
  std::vector<std::string> labels;
  for (const geometry::StablePose& candidate : object.stable_poses)
    labels.push_back(candidate.label);
  const auto found = std::find(labels.begin(), labels.end(), label);
  if (found == labels.end())
    fail(stable, pose.path("stable") + ": object '" + object.name + "' has no stable pose '" +
                     label + "'; its stable poses: " + join(labels) + " (spar object prints them)");
  const int index = static_cast<int>(found - labels.begin());
  const std::vector<double> at =
      quantities(pose.require("at"), pose.path("at"), 2, "pose.position");
  const double yaw =
      pose.has("yaw") ? quantity(pose.get("yaw"), pose.path("yaw"), "pose.angle") : 0.0;
  object.initial_pose = Eigen::Translation3d(at[0], at[1], 0) *
                        Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                        object.stable_poses[index].object_to_world;
  object.initial_stable_pose = index;
}

std::vector<ObjectHypothesis> Reader::rigid_hypotheses(
    const Fields& pose, const std::vector<ObjectIdentity>& candidates) const {
  for (const char* key : {"stable", "at", "yaw"})
    if (pose.has(key))
      fail(pose.get(key), pose.path(key) +
                              ": give either {stable, at, yaw} or {xyz, rpy} / {matrix}, not "
                              "both");
  const Transform placed = rigid_pose(pose);
  std::vector<ObjectHypothesis> hypotheses;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    ObjectHypothesis hypothesis{.label = candidates[i].name,
                                .identity = static_cast<int>(i),
                                .stable_pose = std::nullopt,
                                .pose = placed};
    if (const auto id = geometry::classify_orientation(candidates[i].stable_poses, placed.linear()))
      hypothesis.stable_pose = *id - 1;
    hypotheses.push_back(hypothesis);
  }
  return hypotheses;
}

std::vector<std::pair<std::string, YAML::Node>> Reader::listed_stable_poses(const Fields& pose,
                                                                            bool identities) const {
  const YAML::Node stable = pose.get("stable");
  std::vector<std::pair<std::string, YAML::Node>> listed;
  if (stable.IsSequence()) {
    if (stable.size() == 0)
      fail(stable, pose.path("stable") + ": the list of stable poses is empty");
    for (std::size_t k = 0; k < stable.size(); ++k) {
      const std::string item = pose.path("stable") + "[" + std::to_string(k) + "]";
      const std::string label = text(stable[k], item);
      for (const auto& [seen, unused] : listed)
        if (seen == label) fail(stable[k], item + ": '" + label + "' is listed twice");
      listed.emplace_back(label, stable[k]);
    }
  } else if (stable.IsDefined()) {
    listed.emplace_back(text(stable, pose.path("stable")), stable);
  } else if (!identities) {
    fail(pose.node(), pose.name() + ": missing key 'stable'");
  }
  return listed;
}

std::vector<ObjectHypothesis> Reader::stable_hypotheses(
    const Fields& pose, const std::vector<ObjectIdentity>& candidates,
    const ObjectSpec& object) const {
  const bool identities = !object.identities.empty();
  const std::vector<std::pair<std::string, YAML::Node>> listed =
      listed_stable_poses(pose, identities);
  const std::vector<double> at =
      quantities(pose.require("at"), pose.path("at"), 2, "pose.position");
  const double yaw =
      pose.has("yaw") ? quantity(pose.get("yaw"), pose.path("yaw"), "pose.angle") : 0.0;
  const Transform above =
      Eigen::Translation3d(at[0], at[1], 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  for (const auto& [label, node] : listed) {
    bool any = false;
    for (const ObjectIdentity& candidate : candidates)
      for (const geometry::StablePose& stable_pose : candidate.stable_poses)
        any = any || stable_pose.label == label;
    if (any) continue;
    std::vector<std::string> labels;
    for (const geometry::StablePose& stable_pose : candidates.front().stable_poses)
      labels.push_back(stable_pose.label);
    fail(node, pose.path("stable") + ": object '" + object.name + "' has no stable pose '" + label +
                   "'" + (identities ? " in any of its identities" : "") +
                   "; its stable poses: " + join(labels) + " (spar object prints them)");
  }
  std::vector<ObjectHypothesis> hypotheses;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    for (std::size_t p = 0; p < candidates[i].stable_poses.size(); ++p) {
      const geometry::StablePose& stable_pose = candidates[i].stable_poses[p];
      const bool wanted =
          listed.empty() || std::any_of(listed.begin(), listed.end(), [&](const auto& entry) {
            return entry.first == stable_pose.label;
          });
      if (!wanted) continue;
      hypotheses.push_back(
          {.label = identities ? candidates[i].name + ":" + stable_pose.label : stable_pose.label,
           .identity = static_cast<int>(i),
           .stable_pose = static_cast<int>(p),
           .pose = above * stable_pose.object_to_world});
    }
  return hypotheses;
}

void Reader::read_hypotheses(const Fields& pose, ObjectSpec& object) const {
  // The candidates: the identities, or the object's one shape.
  std::vector<ObjectIdentity> candidates = object.identities;
  if (candidates.empty())
    candidates.push_back({.name = object.name,
                          .shape = object.shape,
                          .model = object.model,
                          .stable_poses = object.stable_poses});
  const bool rigid = pose.has("xyz") || pose.has("rpy") || pose.has("matrix");
  std::vector<ObjectHypothesis> hypotheses =
      rigid ? rigid_hypotheses(pose, candidates) : stable_hypotheses(pose, candidates, object);
  // The first hypothesis stands for the object wherever a single shape and pose is needed.
  const ObjectIdentity& first = candidates[static_cast<std::size_t>(hypotheses.front().identity)];
  object.shape = first.shape;
  object.model = first.model;
  object.stable_poses = first.stable_poses;
  object.initial_pose = hypotheses.front().pose;
  object.initial_stable_pose = hypotheses.front().stable_pose;
  if (hypotheses.size() > 1) object.hypotheses = std::move(hypotheses);
}

ObjectSpec Reader::read_object(const YAML::Node& key, const YAML::Node& node) const {
  const std::string name = identifier(key, "objects");
  const Fields entry(*this, node, "objects." + name,
                     {"builtin", "mesh", "identity", "features", "pose", "uncertainty", "fixed"});
  std::string shape;
  std::vector<ObjectIdentity> identities;
  if (const YAML::Node identity = entry.get("identity"); identity.IsDefined()) {
    for (const char* key : {"builtin", "mesh"})
      if (entry.has(key))
        fail(entry.get(key),
             entry.path(key) + ": give either '" + key + "' or 'identity', not both");
    identities = read_identities(identity, entry.path("identity"), name);
  }
  geometry::ObjectModel model =
      identities.empty() ? object_model(entry, name, shape) : identities.front().model;
  if (!identities.empty()) shape = identities.front().shape;
  std::vector<geometry::StablePose> stable_poses = geometry::stable_poses(model);
  ObjectSpec object{.name = name,
                    .shape = std::move(shape),
                    .model = std::move(model),
                    .stable_poses = std::move(stable_poses),
                    .features = {},
                    .initial_pose = Transform::Identity(),
                    .initial_stable_pose = std::nullopt,
                    .uncertainty = {},
                    .fixed = false,
                    .location = where(key),
                    .pose_location = {},
                    .identities = std::move(identities)};
  if (const YAML::Node features = entry.get("features"); features.IsDefined()) {
    // A map from feature names (the user's own, so not checked against known keys) to faces.
    for (const auto& feature : expect_map(features, entry.path("features"))) {
      const std::string name = identifier(feature.first, entry.path("features"));
      if (object.features.contains(name))
        fail(feature.first, entry.path("features") + ": duplicate feature '" + name + "'");
      object.features[name] =
          faces(feature.second, entry.path("features") + "." + name, object, false);
    }
  }
  read_pose(entry.require("pose"), entry.path("pose"), object);
  object.pose_location = where(entry.get("pose"));
  if (const YAML::Node fixed = entry.get("fixed"); fixed.IsDefined())
    object.fixed = boolean(fixed, entry.path("fixed"));
  if (entry.has("uncertainty"))
    object.uncertainty =
        uncertainty(entry.get("uncertainty"), entry.path("uncertainty"), object.uncertainty_model);
  return object;
}

std::vector<Place> Reader::read_places(const YAML::Node& node) const {
  std::vector<Place> places;
  check_count(expect_list(node, "places"), "places", "scenario.places");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string path = "places[" + std::to_string(i) + "]";
    const Fields fields(*this, node[i], path, {"name", "at", "yaw"});
    Place place;
    place.location = where(node[i]);
    place.name = identifier(fields.require("name"), fields.path("name"));
    for (const Place& other : places)
      if (other.name == place.name)
        fail(fields.get("name"),
             fields.path("name") + ": duplicate place name '" + place.name + "'");
    const std::vector<double> at =
        quantities(fields.require("at"), fields.path("at"), 2, "pose.position");
    place.x = at[0];
    place.y = at[1];
    if (const YAML::Node yaw = fields.get("yaw"); yaw.IsSequence()) {
      if (yaw.size() == 0) fail(yaw, fields.path("yaw") + ": the list of yaws is empty");
      place.yaws.clear();
      for (std::size_t k = 0; k < yaw.size(); ++k) {
        const std::string at_k = fields.path("yaw") + "[" + std::to_string(k) + "]";
        const double value = quantity(yaw[k], at_k, "pose.angle");
        if (std::find(place.yaws.begin(), place.yaws.end(), value) != place.yaws.end())
          fail(yaw[k], at_k + ": yaw " + yaw[k].Scalar() + " is listed twice");
        place.yaws.push_back(value);
      }
    } else if (yaw.IsDefined()) {
      place.yaws = {quantity(yaw, fields.path("yaw"), "pose.angle")};
    }
    places.push_back(place);
  }
  return places;
}

void Reader::read_sensors(const YAML::Node& node, Scenario& scenario) const {
  const Fields sensors(*this, node, "sensors", {"range_scan", "cameras"});
  if (sensors.has("range_scan")) {
    const Fields range_scan(*this, sensors.get("range_scan"), "sensors.range_scan",
                            {"residual", "pose", "intrinsics", "mount", "position_noise",
                             "normal_noise", "max_angle", "detection_probability"});
    RangeScanSensor sensor;
    sensing::SensorModel& model = sensor.model;
    sensor.residual = uncertainty(range_scan.require("residual"), range_scan.path("residual"),
                                  sensor.residual_model);
    // On the wrist (at the gripper's frame) unless it has a pose.
    model.mount =
        mount(range_scan, range_scan.has("pose") ? sensing::Mount::kFixed : sensing::Mount::kWrist);
    if (const YAML::Node pose = range_scan.get("pose"); pose.IsDefined())
      model.pose = rigid_pose(pose, range_scan.path("pose"));
    else if (model.mount == sensing::Mount::kFixed)
      fail(range_scan.node(), "sensors.range_scan: a fixed sensor needs a 'pose'");
    if (const YAML::Node node = range_scan.get("intrinsics"); node.IsDefined())
      model.intrinsics = intrinsics(node, range_scan.path("intrinsics"));
    model.detection_probability = detection_probability(range_scan, model.detection_probability);
    for (const auto& [key, target] :
         {std::pair{"position_noise", &model.position_noise},
          std::pair{"normal_noise", &model.normal_noise}, std::pair{"max_angle", &model.max_angle}})
      if (const YAML::Node value = range_scan.get(key); value.IsDefined())
        *target = quantity(value, range_scan.path(key), std::string("sensor.") + key);
    scenario.range_scan = sensor;
  }
  const YAML::Node list = sensors.get("cameras");
  if (!list.IsDefined()) return;
  check_count(expect_list(list, "sensors.cameras"), "sensors.cameras", "sensors.cameras");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string path = "sensors.cameras[" + std::to_string(i) + "]";
    CameraSensor camera = read_camera(list[i], path);
    for (const CameraSensor& other : scenario.cameras)
      if (other.name == camera.name)
        fail(list[i], path + ".name: duplicate camera name '" + camera.name + "'");
    // Sense planning names its operations by sensor: the range scanner is `range_scan`.
    if (camera.name == "range_scan")
      fail(list[i], path +
                        ".name: 'range_scan' is the range scanner's name; name the camera "
                        "otherwise");
    scenario.cameras.push_back(std::move(camera));
  }
}

CollisionSettings Reader::read_collision(const YAML::Node& node) const {
  const Fields fields(*this, node, "collision", {"margin"});
  CollisionSettings settings;
  if (const YAML::Node margin = fields.get("margin"); margin.IsDefined())
    settings.margin = quantity(margin, "collision.margin", "collision.margin");
  return settings;
}

bool Reader::boolean(const YAML::Node& node, const std::string& path) const {
  if (node.IsScalar() && (node.Scalar() == "true" || node.Scalar() == "false"))
    return node.Scalar() == "true";
  fail(node, path + ": expected true or false, got " + describe(node));
}

AtGoal Reader::read_at(const YAML::Node& node, const std::string& path,
                       const Scenario& scenario) const {
  const Fields fields(*this, node, path, {"object", "place"});
  AtGoal goal;
  const YAML::Node object = fields.require("object");
  goal.object = text(object, fields.path("object"));
  std::vector<std::string> objects;
  for (const ObjectSpec& spec : scenario.objects) objects.push_back(spec.name);
  if (std::find(objects.begin(), objects.end(), goal.object) == objects.end())
    fail(object, fields.path("object") + ": unknown object '" + goal.object + "'" +
                     suggestion(goal.object, objects) + "; objects: " + join(objects));
  const YAML::Node place = fields.require("place");
  goal.place = text(place, fields.path("place"));
  if (scenario.place_index(goal.place) < 0) {
    std::vector<std::string> places;
    for (const Place& known : scenario.places) places.push_back(known.name);
    fail(place, fields.path("place") + ": unknown place '" + goal.place + "'" +
                    suggestion(goal.place, places) + "; places: " + join(places));
  }
  goal.location = where(node);
  return goal;
}

void Reader::check_goals(const Scenario& scenario, const std::vector<YAML::Node>& nodes) const {
  // An earlier goal, as "goals[i] (file:line:col)".
  const auto earlier = [&](std::size_t i) {
    return "goals[" + std::to_string(i) + "] (" + location(scenario.goals[i]).str() + ")";
  };
  const auto is_fixed = [&](const std::string& name) { return scenario.object(name).fixed; };
  for (std::size_t i = 0; i < scenario.goals.size(); ++i) {
    const std::string path = "goals[" + std::to_string(i) + "]";
    const Goal& goal = scenario.goals[i];
    const auto contradiction = [&](std::size_t j, const std::string& why) {
      fail(nodes[i], path + ": " + describe(goal) + " contradicts " + describe(scenario.goals[j]) +
                         " of " + earlier(j) + ": " + why);
    };
    if (const auto* assembled = std::get_if<AssembledGoal>(&goal)) {
      if (is_fixed(assembled->held))
        fail(nodes[i], path + ": " + describe(goal) + ": object '" + assembled->held +
                           "' is fixed (never moves) and cannot be the held object");
      for (std::size_t j = 0; j < i; ++j) {
        if (const auto* other = std::get_if<AssembledGoal>(&scenario.goals[j])) {
          if (other->held == assembled->held && other->fixed == assembled->fixed)
            contradiction(j, other->relative.isApprox(assembled->relative, 1e-9)
                                 ? "the same goal twice"
                                 : "the same pair with another relative pose");
          if (other->held == assembled->held)
            contradiction(j, assembled->held + " cannot go into two objects");
          if (other->held == assembled->fixed && other->fixed == assembled->held)
            contradiction(j, "each would be inside the other");
        } else if (std::get<AtGoal>(scenario.goals[j]).object == assembled->held) {
          contradiction(
              j, assembled->held + " would rest inside " + assembled->fixed + ", not at a place");
        }
      }
      // A longer cycle: following held -> fixed from `fixed` comes back to `held`.
      std::string next = assembled->fixed;
      for (std::size_t hops = 0; hops <= i; ++hops) {
        const auto found =
            std::find_if(scenario.goals.begin(), scenario.goals.begin() + i, [&](const Goal& g) {
              const auto* a = std::get_if<AssembledGoal>(&g);
              return a != nullptr && a->held == next;
            });
        if (found == scenario.goals.begin() + i) break;
        next = std::get<AssembledGoal>(*found).fixed;
        if (next == assembled->held)
          contradiction(static_cast<std::size_t>(found - scenario.goals.begin()),
                        "the assemblies form a cycle through " + assembled->held);
      }
      continue;
    }
    const AtGoal& at = std::get<AtGoal>(goal);
    for (std::size_t j = 0; j < i; ++j) {
      if (const auto* other = std::get_if<AtGoal>(&scenario.goals[j])) {
        if (other->object == at.object)
          contradiction(j, at.object + (other->place == at.place ? " is sent there twice"
                                                                 : " cannot rest at two places"));
        if (other->place == at.place)
          contradiction(j, "place " + at.place + " holds one object at a time");
      } else if (std::get<AssembledGoal>(scenario.goals[j]).held == at.object) {
        contradiction(j, at.object + " would rest inside " +
                             std::get<AssembledGoal>(scenario.goals[j]).fixed + ", not at a place");
      }
    }
    const ObjectSpec& object = scenario.object(at.object);
    if (object.fixed && !resting_yaw(object, scenario.places[scenario.place_index(at.place)]))
      fail(nodes[i], path + ": " + describe(goal) + ": object '" + at.object +
                         "' is fixed (never moves) and does not rest at place '" + at.place + "'");
  }
}

// {name, pose: {xyz, rpy}, intrinsics: {fx, fy, cx, cy, width, height}, mount, noise_px,
// detection_probability, projection, uncertainty}: intrinsics in pixels, the pose in the file's
// units (in the gripper frame with `mount: wrist`).
CameraSensor Reader::read_camera(const YAML::Node& node, const std::string& path) const {
  const Fields fields(*this, node, path,
                      {"name", "pose", "intrinsics", "mount", "noise_px", "detection_probability",
                       "projection", "uncertainty", "residual"});
  CameraSensor camera;
  camera.name = identifier(fields.require("name"), fields.path("name"));
  camera.location = where(node);
  camera.pose = rigid_pose(fields.require("pose"), fields.path("pose"));
  camera.mount = mount(fields, sensing::Mount::kFixed);
  if (const YAML::Node kind = fields.get("projection"); kind.IsDefined()) {
    const std::string name = text(kind, fields.path("projection"));
    const std::vector<std::string> known = {"pinhole", "orthographic"};
    if (name == "orthographic")
      camera.projection = sensing::Projection::kOrthographic;
    else if (name != "pinhole")
      fail(kind, fields.path("projection") + ": unknown projection '" + name + "'" +
                     suggestion(name, known) + "; known: " + join(known));
  }
  camera.intrinsics = intrinsics(fields.require("intrinsics"), fields.path("intrinsics"));
  if (const YAML::Node value = fields.get("noise_px"); value.IsDefined())
    camera.noise_px = quantity(value, fields.path("noise_px"), "camera.noise_px");
  camera.detection_probability = detection_probability(fields, camera.detection_probability);
  if (fields.has("uncertainty")) {
    if (camera.mount == sensing::Mount::kWrist)
      fail(fields.get("uncertainty"), fields.path("uncertainty") +
                                          ": a camera on the wrist is where the robot puts it; "
                                          "'uncertainty' is for a fixed camera");
    camera.uncertainty = uncertainty(fields.get("uncertainty"), fields.path("uncertainty"),
                                     camera.uncertainty_model);
  }
  if (fields.has("residual")) {
    if (camera.mount == sensing::Mount::kWrist)
      fail(fields.get("residual"), fields.path("residual") +
                                       ": phase 2 verifies with fixed cameras only (a wrist "
                                       "camera's view depends on where the robot puts it)");
    camera.residual =
        uncertainty(fields.get("residual"), fields.path("residual"), camera.residual_model);
  }
  return camera;
}

sensing::Mount Reader::mount(const Fields& fields, sensing::Mount fallback) const {
  const YAML::Node node = fields.get("mount");
  if (!node.IsDefined()) return fallback;
  const std::string name = text(node, fields.path("mount"));
  const std::vector<std::string> known = {"fixed", "wrist"};
  if (name != "fixed" && name != "wrist")
    fail(node, fields.path("mount") + ": unknown mount '" + name + "'" + suggestion(name, known) +
                   "; known: " + join(known));
  return name == "wrist" ? sensing::Mount::kWrist : sensing::Mount::kFixed;
}

sensing::Intrinsics Reader::intrinsics(const YAML::Node& node, const std::string& path) const {
  const Fields k(*this, node, path, {"fx", "fy", "cx", "cy", "width", "height"});
  const auto pixels = [&](const char* key, std::string_view limit_key) {
    return quantity(k.require(key), k.path(key), limit_key);
  };
  return {.fx = pixels("fx", "camera.focal"),
          .fy = pixels("fy", "camera.focal"),
          .cx = pixels("cx", "camera.principal_point"),
          .cy = pixels("cy", "camera.principal_point"),
          .width = static_cast<int>(pixels("width", "camera.image_side")),
          .height = static_cast<int>(pixels("height", "camera.image_side"))};
}

double Reader::detection_probability(const Fields& fields, double fallback) const {
  const YAML::Node value = fields.get("detection_probability");
  return value.IsDefined()
             ? quantity(value, fields.path("detection_probability"), "sensor.detection_probability")
             : fallback;
}

SensingSettings Reader::read_sensing(const YAML::Node& node) const {
  const Fields fields(*this, node, "sensing",
                      {"ambiguity_threshold", "max_operations", "standoff"});
  SensingSettings settings;
  if (const YAML::Node value = fields.get("ambiguity_threshold"); value.IsDefined())
    settings.ambiguity_threshold =
        quantity(value, fields.path("ambiguity_threshold"), "sensing.ambiguity_threshold");
  if (const YAML::Node value = fields.get("max_operations"); value.IsDefined())
    settings.max_operations =
        static_cast<int>(quantity(value, fields.path("max_operations"), "sensing.max_operations"));
  if (const YAML::Node value = fields.get("standoff"); value.IsDefined())
    settings.standoff = quantity(value, fields.path("standoff"), "sensing.standoff");
  return settings;
}

AssembledGoal Reader::read_assembled(const YAML::Node& node, const std::string& path,
                                     const Scenario& scenario) const {
  const Fields fields(*this, node, path,
                      {"held", "fixed", "held_faces", "fixed_faces", "relative", "mating_vector",
                       "clearance", "angular_clearance"});
  AssembledGoal goal;
  const auto object_named = [&](const char* key) -> const ObjectSpec& {
    const YAML::Node value = fields.require(key);
    const std::string name = text(value, fields.path(key));
    std::vector<std::string> known;
    for (const ObjectSpec& object : scenario.objects) {
      if (object.name == name) return object;
      known.push_back(object.name);
    }
    fail(value, fields.path(key) + ": unknown object '" + name + "'" + suggestion(name, known) +
                    "; objects: " + join(known));
  };
  const ObjectSpec& held = object_named("held");
  const ObjectSpec& fixed = object_named("fixed");
  goal.held = held.name;
  goal.fixed = fixed.name;
  if (goal.held == goal.fixed)
    fail(fields.get("fixed"), fields.path("fixed") + ": held and fixed must be different objects");
  if (fields.has("held_faces"))
    goal.held_faces = faces(fields.get("held_faces"), fields.path("held_faces"), held, true);
  if (fields.has("fixed_faces"))
    goal.fixed_faces = faces(fields.get("fixed_faces"), fields.path("fixed_faces"), fixed, true);
  goal.relative = rigid_pose(fields.require("relative"), fields.path("relative"));
  if (const YAML::Node vector = fields.get("mating_vector"); vector.IsDefined()) {
    const std::vector<double> v =
        quantities(vector, fields.path("mating_vector"), 3, "goal.mating_vector");
    const Eigen::Vector3d direction(v[0], v[1], v[2]);
    if (!(direction.norm() > 1e-12))
      fail(vector, fields.path("mating_vector") + ": must not be zero");
    goal.mating_vector = direction.normalized();
  }
  if (const YAML::Node value = fields.get("clearance"); value.IsDefined())
    goal.clearance = quantity(value, fields.path("clearance"), "goal.clearance");
  if (const YAML::Node value = fields.get("angular_clearance"); value.IsDefined())
    goal.angular_clearance =
        quantity(value, fields.path("angular_clearance"), "goal.angular_clearance");
  goal.location = where(node);
  return goal;
}

Scenario Reader::read(std::string_view document_text) {
  const YAML::Node document = load_yaml_document<ScenarioError>(document_text, source_);
  if (!document.IsDefined() || document.IsNull())
    throw ScenarioError(source_ + ":1:1: the scenario is empty (it needs at least 'objects')");
  const Fields top(*this, document, "",
                   {"name", "description", "units", "robot", "objects", "places", "sensors",
                    "sensing", "collision", "grasping", "goals"});
  Scenario scenario;
  scenario.name = top.has("name") ? text(top.get("name"), "name")
                                  : std::filesystem::path(source_).stem().string();
  if (top.has("description"))
    scenario.description = text(top.get("description"), "description", /*lines=*/true);
  if (top.has("units")) read_units(top.get("units"), units_);
  scenario.units = units_;
  if (top.has("robot")) read_robot(top.get("robot"), scenario.robot);
  if (top.has("grasping")) read_grasping(top.get("grasping"), scenario.grasping);

  const YAML::Node objects = top.require("objects");
  if (!expect_map(objects, "objects").size()) fail(objects, "objects: the scenario has no object");
  check_count(objects, "objects", "scenario.objects");
  std::set<std::string> names;
  for (const auto& entry : objects) {
    const YAML::Node key = entry.first;
    if (!key.IsScalar()) fail(key, "objects: keys must be object names, got " + describe(key));
    if (!names.insert(key.Scalar()).second)
      fail(key, "objects: duplicate object name '" + key.Scalar() + "'");
    scenario.objects.push_back(read_object(key, entry.second));
  }
  if (top.has("places")) scenario.places = read_places(top.get("places"));
  if (top.has("sensors")) read_sensors(top.get("sensors"), scenario);
  if (top.has("sensing")) scenario.sensing = read_sensing(top.get("sensing"));
  if (top.has("collision")) scenario.collision = read_collision(top.get("collision"));
  scenario.warnings = warnings_;  // after every object's mesh
  if (const YAML::Node goals = top.get("goals"); goals.IsDefined()) {
    check_count(expect_list(goals, "goals"), "goals", "scenario.goals");
    std::vector<YAML::Node> nodes;
    for (std::size_t i = 0; i < goals.size(); ++i) {
      const std::string path = "goals[" + std::to_string(i) + "]";
      const YAML::Node goal = goals[i];
      if (!goal.IsMap() || goal.size() != 1)
        fail(goal, path +
                       ": expected one goal, e.g. 'assembled: {held: ..., fixed: ...}' or "
                       "'at: {object: ..., place: ...}'");
      const Fields kind(*this, goal, path, {"assembled", "at"});
      if (kind.has("at"))
        scenario.goals.emplace_back(read_at(kind.get("at"), kind.path("at"), scenario));
      else
        scenario.goals.emplace_back(
            read_assembled(kind.get("assembled"), kind.path("assembled"), scenario));
      nodes.push_back(goal);
    }
    check_goals(scenario, nodes);
  }
  return scenario;
}

}  // namespace

Scenario read_scenario_yaml(std::string_view text, const std::string& source,
                            const std::filesystem::path& base_dir) {
  return Reader(source, base_dir).read(text);
}

}  // namespace spar::planner::internal
