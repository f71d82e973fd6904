#include "spar/reports/internal/cell.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>
#include <utility>

#include "spar/bounds/bound.hpp"
#include "spar/common/parallel.hpp"
#include "spar/geometry/collision.hpp"
#include "spar/reports/internal/silhouette.hpp"
#include "spar/symbolic/operations.hpp"

namespace spar::reports::internal {
namespace {

using Eigen::Vector3d;
using kinematics::Transform;

// Coordinates in the report: the length unit, rounded to 1e-6 so that files stay small and stable.
double shown(double metres, double scale) { return std::round(metres * scale * 1e6) / 1e6; }

std::vector<Ring> rounded_rings(std::vector<Ring> rings) {
  for (Ring& ring : rings)
    for (auto& point : ring)
      for (double& c : point) c = std::round(c * 1e6) / 1e6 + 0.0;  // + 0.0: no -0 in the file
  return rings;
}

// Projections of world points (metres) into the report's unit: from above (x, y), from the front
// (x, z).
Eigen::Vector2d top_of(const Vector3d& p, double scale) { return {p.x() * scale, p.y() * scale}; }
Eigen::Vector2d side_of(const Vector3d& p, double scale) { return {p.x() * scale, p.z() * scale}; }

Silhouette silhouette_of(const std::vector<std::vector<Vector3d>>& faces, double scale) {
  std::vector<Polygon2> top, side;
  for (const auto& face : faces) {
    Polygon2& t = top.emplace_back();
    Polygon2& s = side.emplace_back();
    for (const Vector3d& p : face) t.push_back(top_of(p, scale)), s.push_back(side_of(p, scale));
  }
  return {rounded_rings(silhouette(top)), rounded_rings(silhouette(side))};
}

Silhouette object_outline(const geometry::Mesh& mesh, const Transform& pose, double scale) {
  std::vector<std::vector<Vector3d>> faces;
  for (const auto& triangle : mesh.triangles)
    faces.push_back({pose * mesh.vertices[triangle[0]], pose * mesh.vertices[triangle[1]],
                     pose * mesh.vertices[triangle[2]]});
  return silhouette_of(faces, scale);
}

// The gripper's three boxes at `pose`, closed to `opening`.
Silhouette gripper_outline(const geometry::GripperSpec& spec, double opening, const Transform& pose,
                           double scale) {
  std::vector<std::vector<Vector3d>> faces;
  const geometry::Body body = geometry::gripper_body(spec, opening);
  for (const geometry::BodyPart& part : body.parts()) {
    const Eigen::AlignedBox3d& box = part.shape.bounds();
    const auto corner = [&](int i) {
      return Vector3d(i & 1 ? box.max().x() : box.min().x(), i & 2 ? box.max().y() : box.min().y(),
                      i & 4 ? box.max().z() : box.min().z());
    };
    for (const auto& quad :
         {std::array{0, 1, 3, 2}, std::array{4, 5, 7, 6}, std::array{0, 1, 5, 4},
          std::array{2, 3, 7, 6}, std::array{0, 2, 6, 4}, std::array{1, 3, 7, 5}}) {
      std::vector<Vector3d>& face = faces.emplace_back();
      for (const int i : quad) face.push_back(pose * part.pose * corner(i));
    }
  }
  return silhouette_of(faces, scale);
}

// The shoulder: joint 2's frame at q = 0 (body 1's origin composed with joint 2's; on joint 1's
// axis for the Puma, UR and Panda arms, so it does not move with q1).
Vector3d shoulder_of(const kinematics::RobotModel& arm) {
  const std::vector<double> zero(arm.dof(), 0.0);
  const std::vector<kinematics::Transform> bodies = arm.body_poses(zero);
  if (arm.dof() < 2) return bodies.back().translation();
  return (bodies[1] * arm.joints()[1].origin).translation();
}

// An upper bound of the gripper's distance from the shoulder: the joint offsets after joint 2,
// prismatic joints at full stroke, the tip's and the tool's offsets.
double reach_of(const planner::RobotSpec& robot) {
  const auto& joints = robot.arm.joints();
  double reach = robot.arm.tip_offset().translation().norm() + robot.tool.translation().norm();
  for (std::size_t i = 2; i < joints.size(); ++i) {
    reach += joints[i].origin.translation().norm();
    if (joints[i].type == kinematics::JointType::kPrismatic)
      reach += std::max(std::fabs(joints[i].limits.lower), std::fabs(joints[i].limits.upper));
  }
  return reach;
}

// Phase 2's propagation replayed step by step, for the boxes of positions objects may occupy.
class Replay {
 public:
  Replay(const planner::PlanResult& result, const planner::InstanceAnalysis& analysis)
      : world_(&result.world),
        analysis_(&analysis),
        state_(result.world, result.domain, pool_),
        release_action_(release_action(result.domain)) {}

  // Applies step k (0-based) as phase 2 did.
  void advance(std::size_t k) { (void)state_.step(analysis_->steps.at(k).step, int(k) + 1); }

  // The box of world positions of `object`'s origin: on the table, its pose error; held, as if
  // released where it was grasped (`grasp_step`: that pickup) with one more motion's arm error.
  std::optional<UncertaintyRegion> region(int object, std::optional<std::size_t> grasp_step,
                                          double scale) {
    if (!grasp_step) return region_on_table(state_, object, scale);
    if (!release_action_) return std::nullopt;  // a domain without a putdown
    planner::Propagation released = state_;
    planner::Phase2Step release = analysis_->steps.at(*grasp_step).step;
    release.action = *release_action_;
    release.effect = planner::Effect::kRelease;
    (void)released.step(release, kReleaseIndex);
    return region_on_table(released, object, scale);
  }

 private:
  // The domain's first action that only releases (no precondition builders), for the imagined
  // release of a held object.
  static std::optional<int> release_action(const planner::Domain& domain) {
    for (std::size_t a = 0; a < domain.actions.size(); ++a)
      if (domain.actions[a].effect == planner::Effect::kRelease &&
          domain.actions[a].uncertainty.empty())
        return int(a);
    return std::nullopt;
  }

  // An index no step of the plan has: the arm error of the imagined release gets its own names.
  static constexpr int kReleaseIndex = 1'000'000;

  std::optional<UncertaintyRegion> region_on_table(const planner::Propagation& state, int object,
                                                   double scale) const {
    const std::optional<planner::TableState>& table = state.on_table(object);
    if (!table) return std::nullopt;
    const Vector3d origin = table->ideal.translation();
    UncertaintyRegion out{world_->scenario().objects.at(object).name, {}, {}};
    const std::array<symbolic::Expr, 3> errors = {table->error.dx, table->error.dy,
                                                  table->error.dz};
    for (int axis = 0; axis < 3; ++axis) {
      const bounds::BoundResult b = bound_over_space(state.space(), errors[axis]);
      out.lo[axis] = std::floor((origin[axis] + b.lo) * scale * 1e6) / 1e6;  // outward
      out.hi[axis] = std::ceil((origin[axis] + b.hi) * scale * 1e6) / 1e6;
    }
    return out;
  }

  static bounds::BoundResult bound_over_space(const planner::UncertaintySpace& space,
                                              symbolic::Expr f) {
    bounds::Box box;
    for (const symbolic::Expr v : symbolic::free_variables(f)) {
      const planner::SpaceVariable& meta = space.variable(space.id_of(v).value());
      box.add(v, meta.lower, meta.upper);
    }
    // With witnesses (the vertex ascent finds these nearly linear errors' extremes at once) the
    // search converges in a box or a few; without, it bisected up to 125 boxes for the same
    // outer bounds. Without SMP: f alone converges, and looking for its rewrites cost more than
    // the bound (the same boxes on every example).
    return bounds::bound(f, box,
                         {.tolerance = 1e-2, .max_box_evaluations = 300, .simplify = false});
  }

  const planner::WorldModel* world_;
  const planner::InstanceAnalysis* analysis_;
  symbolic::ExprPool pool_;
  planner::Propagation state_;
  std::optional<int> release_action_;
};

// Where a step leaves things, from phase 2's step (or the instance's, without phase 2).
struct StepMotion {
  planner::Effect effect{planner::Effect::kNone};
  int object{-1};
  int grasp{-1};
  Transform object_pose{Transform::Identity()};  // where it is or goes (assemblies: T_f Ta)
};

std::vector<StepMotion> motions(const planner::PlanResult& result,
                                const planner::PlanInstance& instance,
                                const planner::InstanceAnalysis* analysis) {
  std::vector<StepMotion> out;
  if (analysis != nullptr) {
    for (const planner::AnalysedStep& step : analysis->steps)
      out.push_back({step.step.effect, step.step.object, step.step.grasp, step.step.object_pose});
    return out;
  }
  for (const planner::InstanceStep& step : instance.steps)
    out.push_back({result.domain.actions.at(step.action).effect, step.object, step.grasp,
                   step.is_assembly() ? step.held_pose : step.object_pose});
  return out;
}

// The plan walked step by step into views (the initial state, then after each step that grasps,
// releases or inserts), with the outlines the views need listed, not made: each object's once
// per exact pose (most objects keep theirs from view to view), the gripper's once per view that
// shows it. make_outlines() makes them, as tasks on the plan's threads: uniting a mesh's
// projected triangles is the costly part of a view.
class ViewWalk {
 public:
  ViewWalk(const planner::PlanResult& result, const Chosen& chosen,
           const planner::InstanceAnalysis* analysis, double scale)
      : result_(&result), chosen_(&chosen), scenario_(&result.world.scenario()), scale_(scale) {
    if (analysis != nullptr) replay_.emplace(result, *analysis);
    for (const planner::ObjectSpec& object : scenario_->objects)
      pose_.push_back(object.initial_pose);
  }

  void walk(const std::vector<StepMotion>& steps) {
    view(std::nullopt, std::nullopt, 0.0, -1);
    for (std::size_t k = 0; k < steps.size() && k < chosen_->steps.size(); ++k) {
      const StepMotion& step = steps[k];
      if (replay_) replay_->advance(k);
      const auto gripper_at = [&](const Transform& object_pose) {
        return step.grasp >= 0
                   ? std::optional<Transform>(
                         object_pose *
                         result_->world.object(step.object).grasps[step.grasp].gripper_in_object)
                   : std::nullopt;
      };
      const double width =
          step.grasp >= 0 ? result_->world.object(step.object).grasps[step.grasp].width : 0.0;
      const double open = scenario_->robot.gripper.max_opening;
      switch (step.effect) {
        case planner::Effect::kGrasp:
          held_ = step.object;
          held_since_ = k;
          view(k, gripper_at(pose_[step.object]), std::max(width, 1e-6), step.object);
          break;
        case planner::Effect::kRelease:
        case planner::Effect::kInsert: {
          // A subassembly moves as one body: what is assembled into the object follows it.
          const Transform moved = step.object_pose * pose_[step.object].inverse();
          for (const std::string& name : chosen_->steps[k].carried)
            for (std::size_t o = 0; o < scenario_->objects.size(); ++o)
              if (scenario_->objects[o].name == name) pose_[o] = moved * pose_[o];
          pose_[step.object] = step.object_pose;
          held_ = -1;
          held_since_.reset();
          view(k, gripper_at(step.object_pose), open, step.object);
          break;
        }
        case planner::Effect::kSense:
          sensed_.push_back({step_label(*chosen_, k), scenario_->objects.at(step.object).name});
          break;
        case planner::Effect::kReduce:
        case planner::Effect::kNone:
          break;
      }
    }
  }

  // The views with their outlines, made on `threads` threads.
  Cell make_outlines(unsigned threads) {
    std::vector<Silhouette> made(poses_.size() + grippers_.size());
    run_tasks(made.size(), threads, [&](std::size_t t) {
      if (t < poses_.size()) {
        const auto& [o, at] = poses_[t];
        made[t] = object_outline(scenario_->objects[o].model.mesh(), at, scale_);
      } else {
        const auto& [v, opening, at] = grippers_[t - poses_.size()];
        made[t] = gripper_outline(scenario_->robot.gripper, opening, at, scale_);
      }
    });
    for (std::size_t v = 0; v < cell_.views.size(); ++v)
      for (std::size_t o = 0; o < cell_.views[v].objects.size(); ++o)
        cell_.views[v].objects[o].outline = made[view_outlines_[v][o]];
    for (std::size_t g = 0; g < grippers_.size(); ++g)
      cell_.views[std::get<0>(grippers_[g])].gripper = std::move(made[poses_.size() + g]);
    return std::move(cell_);
  }

 private:
  using PoseKey = std::pair<std::size_t, std::array<double, 16>>;  // object, its pose's matrix

  // A view after step `after` (none: the initial state), the gripper at `gripper` opened to
  // `opening`, object `handled` (-1: none) with its region of positions.
  void view(std::optional<std::size_t> after, std::optional<Transform> gripper, double opening,
            int handled) {
    CellView& v = cell_.views.emplace_back();
    if (after) v.after = int(*after) + 1;
    v.title = after ? "after " + step_label(*chosen_, *after) : "initial state";
    std::vector<std::size_t>& outlines = view_outlines_.emplace_back();
    for (std::size_t o = 0; o < scenario_->objects.size(); ++o) {
      v.objects.push_back({scenario_->objects[o].name, int(o) == held_, {}});
      PoseKey key{o, {}};
      Eigen::Map<Eigen::Matrix4d>(key.second.data()) = pose_[o].matrix();
      const auto [found, fresh] = object_outline_of_.try_emplace(key, poses_.size());
      if (fresh) poses_.emplace_back(o, pose_[o]);
      outlines.push_back(found->second);
    }
    if (gripper) grippers_.emplace_back(cell_.views.size() - 1, opening, *gripper);
    if (replay_ && handled >= 0)
      if (auto region =
              replay_->region(handled, handled == held_ ? held_since_ : std::nullopt, scale_))
        v.region = *region;
    v.sensed = std::move(sensed_);
    sensed_.clear();
  }

  const planner::PlanResult* result_;
  const Chosen* chosen_;
  const planner::Scenario* scenario_;
  double scale_;
  std::optional<Replay> replay_;
  std::vector<Transform> pose_;            // per object, as the walk goes
  int held_{-1};                           // the object in the gripper
  std::optional<std::size_t> held_since_;  // the pickup that grasped it
  std::vector<CellSensing> sensed_;        // since the last view
  Cell cell_;
  std::map<PoseKey, std::size_t> object_outline_of_;                  // -> index into poses_
  std::vector<std::pair<std::size_t, Transform>> poses_;              // object, pose
  std::vector<std::vector<std::size_t>> view_outlines_;               // per view and object
  std::vector<std::tuple<std::size_t, double, Transform>> grippers_;  // view, opening, pose
};

// The table the views are drawn on (what they and the places cover, and a margin), the places
// and the robot.
void add_table(Cell& cell, const planner::Scenario& scenario, double scale) {
  Eigen::AlignedBox2d covered;
  for (const CellView& v : cell.views)
    for (const CellObject& object : v.objects)
      for (const Ring& ring : object.outline.top)
        for (const auto& p : ring) covered.extend(Eigen::Vector2d(p[0], p[1]));
  for (const planner::Place& place : scenario.places) {
    // A place may list several yaws (a putdown chooses one); the drawing shows the first.
    cell.places.push_back(
        {place.name, shown(place.x, scale), shown(place.y, scale),
         std::round(scenario.units.to_file_angle(place.yaws.front()) * 1e6) / 1e6});
    covered.extend(Eigen::Vector2d(place.x * scale, place.y * scale));
  }
  const double margin = 0.15 * covered.sizes().maxCoeff();
  cell.table_x = {std::floor(covered.min().x() - margin), std::ceil(covered.max().x() + margin)};
  cell.table_y = {std::floor(covered.min().y() - margin), std::ceil(covered.max().y() + margin)};
  const Vector3d base = scenario.robot.base.translation();
  cell.robot_base = {shown(base.x(), scale), shown(base.y(), scale), shown(base.z(), scale)};
  cell.reach = shown(reach_of(scenario.robot), scale);
  cell.shoulder = shown(shoulder_of(scenario.robot.arm).z(), scale);  // above the base
}

}  // namespace

Cell build_cell(const planner::PlanResult& result, const Chosen& chosen,
                const planner::PlanInstance& instance, const planner::InstanceAnalysis* analysis) {
  const planner::Scenario& scenario = result.world.scenario();
  const double scale = 1.0 / scenario.units.metres_per_length_unit();
  ViewWalk walk(result, chosen, analysis, scale);
  walk.walk(motions(result, instance, analysis));
  Cell cell = walk.make_outlines(result.analysis.threads);
  add_table(cell, scenario, scale);
  return cell;
}

}  // namespace spar::reports::internal
