// The facade the `spar` Python module binds: plain C++ functions over spar's modules, shaped for
// a binding (names, strings and maps in, plain values out), so python/module.cpp only converts
// types and nothing in it knows how spar works. Every function here can be called from C++ too.
//
// Expressions. An Expression is an Expr with the pool that owns it, shared: expressions derived
// from one another (simplify, diff, the entries of one uncertain pose) live in one pool, and the
// pool lives as long as any of them. Pools are not thread-safe, so every function that touches a
// pool holds its mutex (SharedPool::mutex) for the whole call; a binding that releases the GIL
// lets other threads work on other pools in parallel, and serialises work on one pool. Mixing
// expressions of two pools is allowed: the other one is re-parsed into this pool from its text
// (the printer's output re-parses to the same node, symbolic/parse.hpp). The text of an
// expression depends on its pool (operands print in node order), so equal expressions of two
// pools may print differently; same_expression compares nodes in one pool.
//
// Errors are spar's own exceptions (spar::Error and its module subclasses), unchanged, so the
// binding can map each type to a Python exception with the same message.
//
// Example:
//   const Expression f = parse_expression("x^2 - y");
//   const reports::BoundRecord r = bound_expression(f, {{"x", -1, 2}, {"y", 0, 1}}, {}, {});
//   // r.lo <= -1, r.hi >= 4, r.argmax == {{"x", 2}, {"y", 0}}
//   const PlanRun run = plan_scenario(load_scenario_file("examples/peg_block_face_down.yaml"), {});
//   std::cout << run.report.dump(2);   // what `spar plan --json` prints
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "spar/kinematics/symbolic_transform.hpp"
#include "spar/kinematics/uncertain_pose.hpp"
#include "spar/planner/plan.hpp"
#include "spar/reports/model.hpp"
#include "spar/symbolic/expr.hpp"

namespace spar::python {

// ---- expressions ----

struct SharedPool {
  symbolic::ExprPool pool;
  std::mutex mutex;  // held by every facade call that reads or grows `pool`
};

struct Expression {
  std::shared_ptr<SharedPool> pool;  // owns `expr`; never null
  symbolic::Expr expr;
};

// A new pool holding the parsed text. Throws symbolic::SymbolicError (token and column).
[[nodiscard]] Expression parse_expression(std::string_view text);
[[nodiscard]] std::string expression_text(const Expression& e);
[[nodiscard]] Expression simplify_expression(const Expression& e);
// d e / d variable; `variable` is a name (it need not occur in e).
[[nodiscard]] Expression differentiate_expression(const Expression& e, std::string_view variable);
// Every variable needs a value; throws symbolic::SymbolicError naming a missing one.
[[nodiscard]] double evaluate_expression(const Expression& e,
                                         const std::map<std::string, double>& values);
// Names of the free variables, sorted.
[[nodiscard]] std::vector<std::string> expression_variables(const Expression& e);
// Same node, after reading b into a's pool when they differ.
[[nodiscard]] bool same_expression(const Expression& a, const Expression& b);

// ---- bounds ----

struct BoxRange {
  std::string variable;
  double lo{0.0};
  double hi{0.0};
};

// `g rel 0`, or text with one relation: "x + y <= 1" is (x + y) - (1) <= 0.
struct ConstraintSpec {
  std::optional<Expression> g;  // when nullopt, `text` holds the whole constraint
  std::string relation;         // "<", "<=", ">", ">=" (with g)
  std::string text;
};

struct BoundSettings {
  double tolerance{1e-3};
  std::size_t max_box_evaluations{200'000};
  double max_seconds{0.0};
  bool inner{true};
};

// bounds::bound(f, box, ...) as the bound record `spar bound --json` writes (witnesses named,
// the wall-clock time in seconds). Throws bounds::BoundsError (bad range, a variable of f not in
// the box, a bad relation) or symbolic::SymbolicError (a constraint's text).
[[nodiscard]] reports::BoundRecord bound_expression(const Expression& f,
                                                    const std::vector<BoxRange>& box,
                                                    const std::vector<ConstraintSpec>& constraints,
                                                    const BoundSettings& settings);

// ---- kinematics (numeric: 4x4 homogeneous matrices, metres and radians) ----

using Matrix4 = Eigen::Matrix4d;

// A robot: a built-in name (kinematics/robots.hpp) or a URDF path, with its tip link ("": the
// built-in's or the end of the longest chain) and folders for package:// names.
struct RobotRef {
  std::string robot;
  std::string tip;
  std::vector<std::string> package_path;
};
struct JointInfo {
  std::string name, type;
  double lower, upper;
  std::optional<std::array<double, 4>> dh;  // d, a, alpha, offset of a DH table's joint
};
struct RobotInfo {
  std::string name, source, base, tip, method;
  std::vector<JointInfo> joints;
};
[[nodiscard]] std::vector<std::string> robot_names();
// Throws kinematics::KinematicsError naming the built-in robots for an unknown name, or the
// URDF file's mistake.
[[nodiscard]] RobotInfo robot_info(const RobotRef& robot);
// Tip pose in the base frame for joint values q. Throws KinematicsError for a wrong joint count.
[[nodiscard]] Matrix4 forward_kinematics(const RobotRef& robot, const std::vector<double>& q);

struct IkSolutionInfo {
  std::string configuration;  // "lun", ..., "rdf"; "run@q7=35deg"; "n1"
  std::vector<double> q;
  bool within_limits{false};
  std::string singularities;  // "none" or e.g. "shoulder+wrist"
};
struct IkAnswer {
  bool solved{false};
  std::string singularities;              // union over the solutions
  std::vector<IkSolutionInfo> solutions;  // kinematics/robot.hpp's order; none when unreachable
};
// Every solution for a tip pose (7-joint arms: q7 every `redundancy_step` radians). Throws
// KinematicsError for a pose that is not rigid (the message names the defect).
[[nodiscard]] IkAnswer inverse_kinematics(const RobotRef& robot, const Matrix4& pose,
                                          double redundancy_step);

// ---- uncertain poses (kinematics/uncertain_pose.hpp) ----

struct UncertainPose {
  std::shared_ptr<SharedPool> pool;
  kinematics::SymbolicTransform transform;
  std::vector<kinematics::UncertaintyVariable> variables;  // dx_<tag>, dy_, dz_, dtheta_
};
// Object, eq. 2: trans(dx, dy, dz) Tr_O rotz(dtheta) R_O; manipulator, eq. 1: T_M T_ΔM.
// Throws KinematicsError for a non-rigid ideal pose, a negative half-width or a bad tag.
[[nodiscard]] UncertainPose possible_object_pose(const Matrix4& ideal,
                                                 const kinematics::PoseUncertainty& uncertainty,
                                                 std::string_view tag);
[[nodiscard]] UncertainPose possible_manipulator_pose(
    const Matrix4& ideal, const kinematics::PoseUncertainty& uncertainty, std::string_view tag);
// Entry (row, column) of the 4x4 matrix; throws std::out_of_range outside 0..3.
[[nodiscard]] Expression pose_entry(const UncertainPose& pose, int row, int column);
[[nodiscard]] Matrix4 evaluate_pose(const UncertainPose& pose,
                                    const std::map<std::string, double>& values);

// ---- planner ----

// What `spar plan` takes besides the scenario; the defaults are the CLI's.
struct PlanSettings {
  std::size_t instances{16};
  std::size_t max_nodes{200'000};
  int max_steps{64};
  // The domain: a file, or its text (which travels to another machine), else the built-in one.
  std::string domain_path;
  std::string domain_text;
  std::string domain_source;  // names domain_text in messages
  // Off: no probabilistic analysis / tolerance allocation (chosen.probability), and no reverse
  // analysis, blame or Monte Carlo on the chosen instance. Phase 2's verdicts do not change.
  bool probability{true};
  bool chosen_extras{true};
  // PlanOptions::threads: threads for one plan's parts (0: one per core); the report is the same.
  unsigned threads{1};
};

// A finished planning run: the planner's result, kept for per-instance analysis, and its report.
// Move-only (the result owns its expression pools).
struct PlanRun {
  PlanRun(planner::PlanResult planned, PlanSettings used);
  PlanRun(PlanRun&&) = default;
  PlanRun& operator=(PlanRun&&) = default;
  PlanRun(const PlanRun&) = delete;
  PlanRun& operator=(const PlanRun&) = delete;

  planner::PlanResult result;
  nlohmann::ordered_json report;  // reports::plan_json(result): `spar plan --json`
  PlanSettings settings;
};

[[nodiscard]] planner::Scenario load_scenario_file(const std::filesystem::path& path);
// `source` names the text in messages (and gives the scenario its name when it has no `name:`);
// mesh paths are relative to `base_dir`.
[[nodiscard]] planner::Scenario parse_scenario_text(std::string_view text,
                                                    const std::string& source,
                                                    const std::filesystem::path& base_dir);
// Files as spar itself reads them (common/input_file.hpp: regular files only, within the size
// limits; text checked for UTF-8), for spar.dask, which ships them to other machines: the text
// of a scenario file (throws planner::ScenarioError), of a domain file (DomainError), the bytes
// of a mesh file (geometry::GeometryError).
[[nodiscard]] std::string read_scenario_file_text(const std::filesystem::path& path);
[[nodiscard]] std::string read_domain_file_text(const std::filesystem::path& path);
[[nodiscard]] std::string read_mesh_file_bytes(const std::filesystem::path& path);
// The mesh files a scenario references, as written (relative to its folder, or absolute).
[[nodiscard]] std::vector<std::string> scenario_mesh_files(const planner::Scenario& scenario);

// planner::plan + reports::plan_json. Throws planner::ScenarioError / PlanError / DomainError.
[[nodiscard]] PlanRun plan_scenario(planner::Scenario scenario, const PlanSettings& settings);
// Number of plan instances enumerated (up to PlanSettings::instances).
[[nodiscard]] std::size_t instance_count(const PlanRun& run);
// Phase 2 on instance `index` on its own (whether or not the run examined it), with the chosen
// instance's extras (blame, reverse analysis, Monte Carlo) when `extras`: the report's `chosen`
// record for that instance (reports::build_chosen: index, steps with their preconditions, errors,
// repairs, uncertainty_variables), the same keys and units as `spar plan --json`.
// Throws std::out_of_range for an index >= instance_count(run).
[[nodiscard]] nlohmann::ordered_json analyse_instance_json(const PlanRun& run, std::size_t index,
                                                           bool extras);

// ---- sensing ----

// `spar evidence --json` (sensing/evidence_json.hpp) for its input as JSON text (`source` names it
// in messages) or a file. Throws sensing::SensingError.
[[nodiscard]] nlohmann::ordered_json evidence_text_json(std::string_view text,
                                                        const std::string& source);
[[nodiscard]] nlohmann::ordered_json evidence_file_json(const std::filesystem::path& path);

struct AspectSettings {
  std::string units{"m"};       // named in the output
  double metres_per_unit{1.0};  // of a mesh file's coordinates and of the output
  double max_angle_degrees{75};
  int level{3};
  int resolution{128};
  bool view_sphere{false};
};
// `spar aspects --json` (sensing/aspects_json.hpp) of a built-in name or a mesh file. Throws
// geometry::GeometryError (no such object, a bad mesh) or sensing::SensingError (bad settings).
[[nodiscard]] nlohmann::ordered_json object_aspects_json(const std::string& object,
                                                         const AspectSettings& settings);
// `spar sense-plan --json` (reports/sensing.hpp's SensePlanRecord) of a scenario. Throws
// planner::ScenarioError (an uncertain object without sensors) or planner::PlanError.
[[nodiscard]] nlohmann::ordered_json sense_plan_json(const planner::Scenario& scenario);

}  // namespace spar::python
