#include "python/facade.hpp"

#include <algorithm>
#include <chrono>
#include <numbers>
#include <stdexcept>

#include "spar/bounds/bound.hpp"
#include "spar/bounds/error.hpp"
#include "spar/bounds/inequality.hpp"
#include "spar/common/input_file.hpp"
#include "spar/common/parallel.hpp"
#include "spar/common/text.hpp"
#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/error.hpp"
#include "spar/kinematics/ik.hpp"
#include "spar/kinematics/puma.hpp"
#include "spar/kinematics/robots.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/sense_planning.hpp"
#include "spar/reports/build.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/plan_json.hpp"
#include "spar/reports/sensing.hpp"
#include "spar/sensing/aspects_json.hpp"
#include "spar/sensing/evidence_json.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/smp.hpp"

namespace spar::python {
namespace {

using nlohmann::ordered_json;
using symbolic::Expr;

// An expression as it will be read into `pool`: its node when it is in `pool`, else its text
// (taken under its own pool's lock, before the caller locks `pool`: one lock at a time).
struct Foreign {
  std::optional<Expr> node;
  std::string text;
};

Foreign foreign(const Expression& e, const SharedPool& pool) {
  if (e.pool.get() == &pool) return {e.expr, {}};
  return {std::nullopt, expression_text(e)};
}

// The caller holds pool.mutex.
Expr read_into(const Foreign& e, SharedPool& pool) {
  return e.node ? *e.node : symbolic::parse(pool.pool, e.text);
}

Expression derived(const Expression& from, Expr expr) { return Expression{from.pool, expr}; }

kinematics::Transform rigid(const Matrix4& matrix) {
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> row_major = matrix;
  return kinematics::rigid_transform_from_row_major(std::span<const double>(row_major.data(), 16));
}

Matrix4 matrix(const kinematics::Transform& pose) { return pose.matrix(); }

bounds::Relation relation_named(std::string_view text) {
  if (const std::optional<Relation> relation = relation_from_name(text)) return *relation;
  throw bounds::BoundsError("unknown relation '" + std::string(text) +
                            "' in a constraint: use <, <=, > or >=");
}

// "lhs REL rhs" -> (lhs) - (rhs) REL 0, parsed into `pool`.
bounds::Constraint constraint_from_text(const std::string& text, symbolic::ExprPool& pool) {
  for (const std::string_view relation : {"<=", ">=", "<", ">"}) {
    const std::size_t at = text.find(relation);
    if (at == std::string::npos) continue;
    const std::string lhs = text.substr(0, at), rhs = text.substr(at + relation.size());
    if (rhs.find_first_of("<>") != std::string::npos)
      throw bounds::BoundsError("constraint '" + text + "' has more than one relation");
    return {symbolic::parse(pool, "(" + lhs + ") - (" + rhs + ")"), relation_named(relation)};
  }
  throw bounds::BoundsError("constraint '" + text +
                            "' has no relation: write e.g. 'x + y <= 1' or give (g, '<=')");
}

}  // namespace

// ---- expressions ----

Expression parse_expression(std::string_view text) {
  auto pool = std::make_shared<SharedPool>();
  const std::lock_guard lock(pool->mutex);
  const Expr expr = symbolic::parse(pool->pool, text);
  return Expression{pool, expr};
}

std::string expression_text(const Expression& e) {
  const std::lock_guard lock(e.pool->mutex);
  return symbolic::to_string(e.expr);
}

Expression simplify_expression(const Expression& e) {
  const std::lock_guard lock(e.pool->mutex);
  return derived(e, symbolic::simplify(e.expr));
}

Expression differentiate_expression(const Expression& e, std::string_view variable) {
  const std::lock_guard lock(e.pool->mutex);
  return derived(e, symbolic::differentiate(e.expr, e.pool->pool.variable(variable)));
}

double evaluate_expression(const Expression& e, const std::map<std::string, double>& values) {
  const std::lock_guard lock(e.pool->mutex);
  return symbolic::evaluate(e.expr, values);
}

std::vector<std::string> expression_variables(const Expression& e) {
  const std::lock_guard lock(e.pool->mutex);
  std::vector<std::string> names;
  for (const Expr v : symbolic::free_variables(e.expr)) names.emplace_back(v.name());
  std::sort(names.begin(), names.end());
  return names;
}

bool same_expression(const Expression& a, const Expression& b) {
  const Foreign other = foreign(b, *a.pool);
  const std::lock_guard lock(a.pool->mutex);
  return read_into(other, *a.pool) == a.expr;
}

// ---- bounds ----

reports::BoundRecord bound_expression(const Expression& f, const std::vector<BoxRange>& box,
                                      const std::vector<ConstraintSpec>& constraints,
                                      const BoundSettings& settings) {
  SharedPool& pool = *f.pool;
  std::vector<Foreign> constraint_gs;
  for (const ConstraintSpec& spec : constraints)
    if (spec.g) constraint_gs.push_back(foreign(*spec.g, pool));
  const std::lock_guard lock(pool.mutex);
  bounds::Box bound_box;
  for (const BoxRange& range : box)
    bound_box.add(pool.pool.variable(range.variable), range.lo, range.hi);
  std::vector<bounds::Constraint> parsed;
  std::size_t next_g = 0;
  for (const ConstraintSpec& spec : constraints)
    parsed.push_back(spec.g ? bounds::Constraint{read_into(constraint_gs[next_g++], pool),
                                                 relation_named(spec.relation)}
                            : constraint_from_text(spec.text, pool.pool));
  bounds::BoundOptions options;
  options.tolerance = settings.tolerance;
  options.max_box_evaluations = settings.max_box_evaluations;
  options.max_seconds = settings.max_seconds;
  options.inner = settings.inner;
  const auto start = std::chrono::steady_clock::now();
  const bounds::BoundResult result = bounds::bound(f.expr, bound_box, options, parsed);
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  return reports::bound_record(bound_box, result, elapsed.count());
}

// ---- kinematics ----

std::vector<std::string> robot_names() {
  std::vector<std::string> names;
  for (const std::string_view name : kinematics::robot_model_names()) names.emplace_back(name);
  return names;
}

namespace {

kinematics::RobotModel load(const RobotRef& robot) {
  kinematics::UrdfOptions options{.base = {}, .tip = robot.tip, .package_path = {}};
  for (const std::string& folder : robot.package_path) options.package_path.emplace_back(folder);
  return kinematics::load_robot(robot.robot, options);
}

}  // namespace

RobotInfo robot_info(const RobotRef& robot) {
  const kinematics::RobotModel model = load(robot);
  RobotInfo info{.name = model.name(),
                 .source = model.source(),
                 .base = model.base_link(),
                 .tip = model.tip_link(),
                 .method = std::string(kinematics::to_string(model.ik_method())),
                 .joints = {}};
  const std::vector<std::string_view> dh_robots = kinematics::builtin_robot_names();
  const bool dh = std::find(dh_robots.begin(), dh_robots.end(), robot.robot) != dh_robots.end();
  for (std::size_t i = 0; i < model.dof(); ++i) {
    const kinematics::MovingJoint& joint = model.joints()[i];
    JointInfo entry{.name = joint.name,
                    .type = std::string(kinematics::to_string(joint.type)),
                    .lower = joint.limits.lower,
                    .upper = joint.limits.upper,
                    .dh = std::nullopt};
    if (dh) {
      const kinematics::DhJoint& row = kinematics::builtin_robot(robot.robot).joint(i);
      entry.dh = std::array<double, 4>{row.d, row.a, row.alpha, row.offset};
    }
    info.joints.push_back(std::move(entry));
  }
  return info;
}

Matrix4 forward_kinematics(const RobotRef& robot, const std::vector<double>& q) {
  return matrix(load(robot).forward(q));
}

IkAnswer inverse_kinematics(const RobotRef& robot, const Matrix4& pose, double redundancy_step) {
  const kinematics::Transform target = rigid(pose);
  const kinematics::RobotModel model = load(robot);
  const std::vector<kinematics::JointSolution> found =
      model.inverse(target, {.redundancy_step = redundancy_step});
  IkAnswer answer{.solved = !found.empty(), .singularities = {}, .solutions = {}};
  std::uint8_t flags = kinematics::kNoSingularity;
  for (const kinematics::JointSolution& solution : found) {
    flags |= solution.singularities;
    answer.solutions.push_back(
        {.configuration = solution.configuration,
         .q = solution.q,
         .within_limits = solution.within_limits,
         .singularities = kinematics::singularity_names(solution.singularities)});
  }
  answer.singularities = kinematics::singularity_names(flags);
  return answer;
}

// ---- uncertain poses ----

namespace {

// An object's or the manipulator's possible pose (kinematics::UncertainObject or
// UncertainManipulator: the same interface) in a pool of its own.
template <class Uncertain>
UncertainPose possible_pose(const Matrix4& ideal, const kinematics::PoseUncertainty& uncertainty,
                            std::string_view tag) {
  const kinematics::Transform pose = rigid(ideal);
  auto pool = std::make_shared<SharedPool>();
  const std::lock_guard lock(pool->mutex);
  const Uncertain uncertain(pool->pool, uncertainty, tag);
  const auto& variables = uncertain.variables();
  return UncertainPose{pool, uncertain.possible_pose(pose), {variables.begin(), variables.end()}};
}

}  // namespace

UncertainPose possible_object_pose(const Matrix4& ideal,
                                   const kinematics::PoseUncertainty& uncertainty,
                                   std::string_view tag) {
  return possible_pose<kinematics::UncertainObject>(ideal, uncertainty, tag);
}

UncertainPose possible_manipulator_pose(const Matrix4& ideal,
                                        const kinematics::PoseUncertainty& uncertainty,
                                        std::string_view tag) {
  return possible_pose<kinematics::UncertainManipulator>(ideal, uncertainty, tag);
}

Expression pose_entry(const UncertainPose& pose, int row, int column) {
  if (row < 0 || row > 3 || column < 0 || column > 3)
    throw std::out_of_range("pose entry (" + std::to_string(row) + ", " + std::to_string(column) +
                            ") is outside the 4x4 matrix");
  const std::lock_guard lock(pose.pool->mutex);
  return Expression{pose.pool, pose.transform.entry(row, column)};
}

Matrix4 evaluate_pose(const UncertainPose& pose, const std::map<std::string, double>& values) {
  const std::lock_guard lock(pose.pool->mutex);
  return matrix(pose.transform.evaluate(values));
}

// ---- planner ----

planner::Scenario load_scenario_file(const std::filesystem::path& path) {
  return planner::load_scenario(path);
}

planner::Scenario parse_scenario_text(std::string_view text, const std::string& source,
                                      const std::filesystem::path& base_dir) {
  return planner::parse_scenario(text, source, base_dir);
}

namespace {

// read_input_file, then (for text) the UTF-8 check, every failure as the module's error type.
template <class ModuleError>
std::string read_as_spar_does(const std::filesystem::path& path, std::string_view what,
                              std::size_t max_bytes, bool text) {
  try {
    std::string content = read_input_file(path, what, max_bytes);
    if (text) check_utf8(content, printable(path.string()));
    return content;
  } catch (const InputError& error) {
    throw ModuleError(error.what());
  } catch (const TextError& error) {
    throw ModuleError(error.what());
  }
}

}  // namespace

std::string read_scenario_file_text(const std::filesystem::path& path) {
  return read_as_spar_does<planner::ScenarioError>(path, "scenario file", kMaxYamlFileBytes, true);
}

std::string read_domain_file_text(const std::filesystem::path& path) {
  return read_as_spar_does<planner::DomainError>(path, "domain file", kMaxYamlFileBytes, true);
}

std::string read_mesh_file_bytes(const std::filesystem::path& path) {
  return read_as_spar_does<geometry::GeometryError>(path, "mesh file", kMaxMeshFileBytes, false);
}

std::vector<std::string> scenario_mesh_files(const planner::Scenario& scenario) {
  constexpr std::string_view kMesh = "mesh: ";
  std::vector<std::string> files;
  for (const planner::ObjectSpec& object : scenario.objects)
    if (object.shape.starts_with(kMesh)) files.push_back(object.shape.substr(kMesh.size()));
  return files;
}

namespace {

planner::PlanOptions plan_options(const PlanSettings& settings) {
  planner::PlanOptions options;
  options.max_instances = settings.instances;
  options.posting.max_nodes = settings.max_nodes;
  options.posting.max_steps = settings.max_steps;
  options.threads = settings.threads == 0 ? default_threads() : settings.threads;
  if (!settings.probability) options.probability.reset();
  if (!settings.chosen_extras) {
    options.analysis.reverse = false;
    options.analysis.blame = false;
    options.analysis.samples = 0;
  }
  return options;
}

}  // namespace

PlanRun::PlanRun(planner::PlanResult planned, PlanSettings used)
    : result(std::move(planned)), report(reports::plan_json(result)), settings(std::move(used)) {}

PlanRun plan_scenario(planner::Scenario scenario, const PlanSettings& settings) {
  const planner::Domain domain =
      !settings.domain_text.empty()
          ? planner::parse_domain(settings.domain_text, settings.domain_source)
      : !settings.domain_path.empty() ? planner::load_domain(settings.domain_path)
                                      : planner::builtin_domain();
  return PlanRun(planner::plan(std::move(scenario), domain, plan_options(settings)), settings);
}

std::size_t instance_count(const PlanRun& run) { return run.result.instances.instances.size(); }

ordered_json analyse_instance_json(const PlanRun& run, std::size_t index, bool extras) {
  if (index >= instance_count(run))
    throw std::out_of_range("plan instance " + std::to_string(index) +
                            " does not exist: the run has " + std::to_string(instance_count(run)) +
                            " instance(s)");
  const planner::PlanOptions planned_with = plan_options(run.settings);
  planner::AnalysisOptions options = planned_with.analysis;
  options.threads = planned_with.threads;  // as plan() passes it on
  planner::InstanceAnalysis analysis = planner::analyse_instance(
      run.result.world, run.result.domain, run.result.instances.instances[index], options);
  if (extras) planner::add_margins(analysis, options);
  return reports::to_json(reports::build_chosen(run.result, index, &analysis));
}

// ---- sensing ----

namespace {

nlohmann::ordered_json combined_evidence(const sensing::EvidenceInput& input) {
  return sensing::evidence_json(input.frame, sensing::combine(input.sources, input.frame.size()));
}

}  // namespace

nlohmann::ordered_json evidence_text_json(std::string_view text, const std::string& source) {
  return combined_evidence(sensing::parse_evidence_json(text, source));
}

nlohmann::ordered_json evidence_file_json(const std::filesystem::path& path) {
  return combined_evidence(sensing::load_evidence_file(path));
}

nlohmann::ordered_json object_aspects_json(const std::string& object,
                                           const AspectSettings& settings) {
  const geometry::ObjectModel model = geometry::load_object(object, settings.metres_per_unit);
  sensing::AspectOptions options;
  options.max_angle = settings.max_angle_degrees * std::numbers::pi / 180;
  options.view_sphere_level = settings.level;
  options.resolution = settings.resolution;
  options.force_view_sphere = settings.view_sphere;
  return sensing::aspects_json(model, sensing::compute_aspects(model, options), options,
                               settings.units, settings.metres_per_unit);
}

nlohmann::ordered_json sense_plan_json(const planner::Scenario& scenario) {
  const planner::WorldModel world(scenario);
  return reports::to_json(
      reports::build_sense_plan(scenario, planner::plan_sensing(scenario, world)));
}

}  // namespace spar::python
