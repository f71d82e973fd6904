#include "spar/planner/world.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <span>

#include "spar/common/parallel.hpp"
#include "spar/geometry/stable_poses.hpp"
#include "spar/planner/error.hpp"

namespace spar::planner {

double tilt_from_down(const kinematics::Transform& pose) {
  const double cosine = -pose.linear().col(2).z();
  return std::acos(std::clamp(cosine, -1.0, 1.0));
}

namespace {

using kinematics::Transform;

// "/180" for a place with several yaws (in the file's angle unit), "" for one.
std::string yaw_suffix(const Place& place, std::size_t k, const Units& units) {
  if (place.yaws.size() == 1) return "";
  char text[32];
  std::snprintf(text, sizeof text, "/%.6g", units.to_file_angle(place.yaws[k]));
  return text;
}

// Whether a goal moves `object`: an at goal's object, or the held object of an assembled goal.
bool moved_by_a_goal(const Scenario& scenario, const std::string& object) {
  return std::any_of(scenario.goals.begin(), scenario.goals.end(), [&](const Goal& goal) {
    if (const auto* at = std::get_if<AtGoal>(&goal)) return at->object == object;
    return std::get<AssembledGoal>(goal).held == object;
  });
}

// The orientations in which `object` with the held object of `goal` assembled into it rests and
// `object` alone does not (PositionLabel::joined_goal), as transforms of its frame.
std::vector<kinematics::Transform> joined_only_poses(const Scenario& scenario,
                                                     const ObjectSpec& object,
                                                     const AssembledGoal& goal) {
  const ObjectSpec& held = scenario.object(goal.held);
  const geometry::PosedPart pair[] = {{&object.model, kinematics::Transform::Identity()},
                                      {&held.model, goal.relative}};
  std::vector<kinematics::Transform> poses;
  for (const geometry::JointStablePose& joint :
       geometry::joint_stable_poses(pair, geometry::kTableTolerance))
    if (std::none_of(object.stable_poses.begin(), object.stable_poses.end(),
                     [&](const geometry::StablePose& own) {
                       return (own.facet_normal - joint.down).norm() < 1e-9;
                     }))
      poses.push_back(joint.frame_to_world);
  return poses;
}

std::vector<PositionLabel> position_labels(const Scenario& scenario, const ObjectSpec& object) {
  std::vector<PositionLabel> labels;
  labels.push_back({.name = "initial",
                    .stable_pose = object.initial_stable_pose.value_or(-1),
                    .place = -1,
                    .pose = object.initial_pose});
  for (std::size_t p = 0; p < scenario.places.size(); ++p)
    if (resting_yaw(object, scenario.places[p])) labels[0].place = static_cast<int>(p);
  if (object.fixed) return labels;
  // Every resting orientation at every place and yaw; `name` names the orientation.
  const auto at_every_place = [&](const std::string& name, const kinematics::Transform& resting,
                                  int stable_pose, int joined_goal) {
    for (std::size_t p = 0; p < scenario.places.size(); ++p) {
      const Place& place = scenario.places[p];
      for (std::size_t k = 0; k < place.yaws.size(); ++k)
        labels.push_back({.name = name + "@" + place.name + yaw_suffix(place, k, scenario.units),
                          .stable_pose = stable_pose,
                          .place = static_cast<int>(p),
                          .pose = place_pose(place, place.yaws[k], resting),
                          .joined_goal = joined_goal});
    }
  };
  for (std::size_t s = 0; s < object.stable_poses.size(); ++s)
    at_every_place(object.stable_poses[s].label, object.stable_poses[s].object_to_world,
                   static_cast<int>(s), -1);
  if (!moved_by_a_goal(scenario, object.name)) return labels;
  for (std::size_t g = 0; g < scenario.goals.size(); ++g) {
    const auto* assembled = std::get_if<AssembledGoal>(&scenario.goals[g]);
    if (assembled == nullptr || assembled->fixed != object.name) continue;
    const std::vector<kinematics::Transform> joined =
        joined_only_poses(scenario, object, *assembled);
    for (std::size_t j = 0; j < joined.size(); ++j)
      at_every_place("J" + std::to_string(j + 1) + "+" + assembled->held, joined[j], -1,
                     static_cast<int>(g));
  }
  return labels;
}

// An object's faces other than `faces` (ids), as a surface whose triangles are pulled in by a
// micrometre (geometry::CollisionShape::surface); nullopt when nothing is left.
std::optional<geometry::Body> other_faces(const ObjectSpec& object, const std::vector<int>& faces) {
  const geometry::Mesh& mesh = object.model.mesh();
  std::vector<char> mating(mesh.triangles.size(), 0);
  for (const int id : faces)
    for (const int t : object.model.face(id).triangles) mating[t] = 1;
  std::vector<int> rest;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (!mating[t]) rest.push_back(static_cast<int>(t));
  if (rest.empty()) return std::nullopt;
  return geometry::Body(object.name + " but its mating faces",
                        geometry::CollisionShape::surface(mesh, rest, 1e-6));
}

// A link of the arm with collision geometry, as a body in the link's frame.
struct ArmLink {
  std::size_t link{0};  // index into RobotModel::links()
  int body{0};          // the moving body it rides on (RobotLinkInfo::body)
  geometry::Body shape;
  double radius{0.0};  // the farthest point of its shapes from its body's frame origin
};

// Link `l` of the arm as a body of its collision shapes, if it moves with the arm (the base's
// never does): a mesh as it is, a box as itself, a cylinder or a sphere as the box around it
// (conservative). A shape without volume (an empty mesh, a zero-sized box) is left out; nullopt
// when none is left.
std::optional<ArmLink> arm_link(const kinematics::RobotModel& arm, std::size_t l) {
  using kinematics::ShapeKind;
  const kinematics::RobotLinkInfo& link = arm.links()[l];
  if (link.body == 0) return std::nullopt;
  std::vector<geometry::BodyPart> parts;
  double radius = 0.0;
  for (const kinematics::LinkShape& shape : link.collision) {
    const Transform in_body = link.offset * shape.origin;
    if (shape.kind == ShapeKind::kMesh) {
      if (shape.mesh && !shape.mesh->triangles.empty()) {
        parts.push_back({geometry::CollisionShape(*shape.mesh), shape.origin});
        for (const Eigen::Vector3d& v : shape.mesh->vertices)
          radius = std::max(radius, (in_body * v).norm());
      }
      continue;
    }
    const Eigen::Vector3d half =
        shape.kind == ShapeKind::kSphere ? shape.size
        : shape.kind == ShapeKind::kCylinder
            ? Eigen::Vector3d(shape.size.x(), shape.size.y(), shape.size.z() / 2)
            : Eigen::Vector3d(shape.size / 2);
    if ((half.array() > 0).all()) {
      parts.push_back({geometry::CollisionShape::box(-half, half), shape.origin});
      radius = std::max(radius, in_body.translation().norm() + half.norm());
    }
  }
  if (parts.empty()) return std::nullopt;
  return ArmLink{l, link.body, geometry::Body(link.name, std::move(parts)), radius};
}

// Per link l and moving joint i: a bound on the distance from joint i's axis to any point of link
// l (its radius about its body's origin plus the lengths of the joints in between, a prismatic
// joint's stroke at its larger limit; 0 when joint i does not move the link), so turning joint i
// alone by dq moves no point of the link farther than lever[l][i] |dq| (a prismatic joint: |dq|).
std::vector<std::vector<double>> joint_levers(const kinematics::RobotModel& arm,
                                              const std::vector<ArmLink>& links) {
  using kinematics::JointType;
  const std::vector<kinematics::MovingJoint>& joints = arm.joints();
  std::vector<std::vector<double>> lever(links.size(), std::vector<double>(joints.size(), 0.0));
  for (std::size_t l = 0; l < links.size(); ++l)
    for (std::size_t i = 0; static_cast<int>(i) < links[l].body; ++i) {  // body k follows joint k-1
      if (joints[i].type == JointType::kPrismatic) {
        lever[l][i] = 1.0;
        continue;
      }
      double length = links[l].radius;
      for (std::size_t j = i + 1; static_cast<int>(j) < links[l].body; ++j) {
        length += joints[j].origin.translation().norm();
        if (joints[j].type == JointType::kPrismatic)
          length += std::max(std::abs(joints[j].limits.lower), std::abs(joints[j].limits.upper));
      }
      lever[l][i] = length;
    }
  return lever;
}

// The arm's moving links with collision geometry, and joint_levers over them.
struct ArmGeometry {
  std::vector<ArmLink> links;
  std::vector<std::vector<double>> lever;  // [link][moving joint]
};

// The flange pose in the robot's base frame for a gripper pose in the world.
Transform flange_pose(const RobotSpec& robot, const Transform& gripper_pose) {
  return robot.base.inverse(Eigen::Isometry) * gripper_pose * robot.tool.inverse(Eigen::Isometry);
}

// The arm's links at joint values q, in the world.
std::vector<geometry::PlacedBody> placed_arm(const RobotSpec& robot,
                                             const std::vector<ArmLink>& links,
                                             std::span<const double> q) {
  std::vector<geometry::PlacedBody> placed;
  if (links.empty()) return placed;
  const std::vector<Transform> poses = robot.arm.link_poses(q);
  for (const ArmLink& link : links) placed.push_back({&link.shape, robot.base * poses[link.link]});
  return placed;
}

// Some link of the arm at q reaches below the table (the box test first: it is cheap).
bool arm_below_table(const RobotSpec& robot, const std::vector<ArmLink>& links,
                     std::span<const double> q) {
  for (const geometry::PlacedBody& placed : placed_arm(robot, links, q))
    if (geometry::world_bounds(placed).min().z() < -geometry::kTableTolerance &&
        geometry::lowest_z(placed) < -geometry::kTableTolerance)
      return true;
  return false;
}

// The gap between two boxes (0 when they overlap): a lower bound on the distance of what they hold.
double box_gap(const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b) {
  const Eigen::Vector3d gap =
      (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(Eigen::Vector3d::Zero());
  return gap.norm();
}

// Checks IK branches of the arm against the table and a set of obstacles at the step's gripper
// pose T and along the gripper's straight lines from it (world.hpp, "The arm"). Along a line the
// branch is followed by its label (the closed forms' labels name continuous branches; the numeric
// solver's ranks "n1", "n2", ... do not, so there the solution nearest to the last one is taken)
// and sampled by bisection until, between every two consecutive samples, each link's
// displacement bound sum_i lever[l][i] |dq_i| is within its slack at one of them (its distance
// bound to every obstacle less half the margin, its height above the table).
class BranchCheck {
 public:
  BranchCheck(const RobotSpec& robot, const ArmGeometry& arm,
              std::vector<geometry::PlacedBody> obstacles, std::vector<std::string> names,
              double margin)
      : robot_(robot),
        arm_(arm),
        obstacles_(std::move(obstacles)),
        names_(std::move(names)),
        margin_(margin) {
    for (const geometry::PlacedBody& obstacle : obstacles_)
      boxes_.push_back(geometry::world_bounds(obstacle));
  }

  // What the branch hits at T or along `lines` ("forearm_link hits block along the approach"),
  // or nullopt.
  [[nodiscard]] std::optional<std::string> conflict(const kinematics::JointSolution& branch,
                                                    const Transform& gripper_pose,
                                                    std::span<const ArmLine> lines) const {
    if (arm_.links.empty() || (lines.empty() && obstacles_.empty())) return std::nullopt;
    const Sample at = sample(branch.q);
    if (at.hit) return at.hit;
    for (const ArmLine& line : lines) {
      const Segment start{0.0, branch.q, at.slack};
      const auto pose = [&](double s) {
        return Eigen::Translation3d(s * line.travel) * gripper_pose;
      };
      std::optional<std::string> hit;
      if (const std::optional<std::vector<double>> q =
              follow(branch.configuration, pose(1.0), start.q)) {
        const Sample end = sample(*q);
        hit =
            end.hit ? end.hit : between(branch.configuration, pose, start, {1.0, *q, end.slack}, 0);
      } else {
        hit = kLost;
      }
      if (hit) return *hit + " along the " + line.name;
    }
    return std::nullopt;
  }

 private:
  // One sample of a line: its hit, or per link how far its points may move with it still clear.
  struct Sample {
    std::optional<std::string> hit;
    std::vector<double> slack;
  };
  struct Segment {
    double s{0.0};  // fraction of the line
    std::vector<double> q;
    std::vector<double> slack;
  };
  static constexpr int kMaxDepth = 16;  // at most 2^16 samples on a line
  static constexpr const char* kLost = "leaves its reach or joint limits";

  [[nodiscard]] Sample sample(std::span<const double> q) const {
    const std::vector<geometry::PlacedBody> placed = placed_arm(robot_, arm_.links, q);
    const int last_body = static_cast<int>(robot_.arm.dof());
    Sample result{std::nullopt, {}};
    for (std::size_t l = 0; l < placed.size(); ++l) {
      const Eigen::AlignedBox3d box = geometry::world_bounds(placed[l]);
      double height = box.min().z();
      if (height < -geometry::kTableTolerance) height = geometry::lowest_z(placed[l]);
      if (height < -geometry::kTableTolerance)
        return {arm_.links[l].shape.name() + " goes below the table", {}};
      double slack = height + geometry::kTableTolerance;
      if (arm_.links[l].body != last_body)  // links next to the gripper are exempt
        for (std::size_t o = 0; o < obstacles_.size(); ++o) {
          double distance = box_gap(box, boxes_[o]);
          if (distance < margin_) {
            if (geometry::collide(placed[l], obstacles_[o], margin_))
              return {arm_.links[l].shape.name() + " hits " + names_[o], {}};
            distance = margin_;
          }
          slack = std::min(slack, distance - margin_ / 2);
        }
      result.slack.push_back(slack);
    }
    return result;
  }

  // sum_i lever[link][i] |q1_i - q0_i| (revolute joints by the shorter way round).
  [[nodiscard]] double displacement(std::size_t link, std::span<const double> q0,
                                    std::span<const double> q1) const {
    double total = 0.0;
    for (std::size_t i = 0; i < q0.size(); ++i) {
      const bool prismatic = robot_.arm.joints()[i].type == kinematics::JointType::kPrismatic;
      const double change =
          prismatic ? q1[i] - q0[i] : std::remainder(q1[i] - q0[i], 2 * std::numbers::pi);
      total += arm_.lever[link][i] * std::abs(change);
    }
    return total;
  }

  // The branch `label` at gripper pose `pose`: nullopt when it has no in-limit solution there.
  [[nodiscard]] std::optional<std::vector<double>> follow(const std::string& label,
                                                          const Transform& pose,
                                                          std::span<const double> near) const {
    const bool ranked = label.size() > 1 && label[0] == 'n' && std::isdigit(label[1]) != 0;
    std::optional<std::vector<double>> best;
    double best_distance = std::numeric_limits<double>::infinity();
    // A 7-joint closed form's branch keeps the q7 of its label ("run@q7=35deg"), the q7 of every
    // sample of it: that one sample of the sweep has the branch's solution.
    kinematics::InverseOptions options;
    if (!ranked && robot_.arm.ik_method() == kinematics::IkMethod::kRedundantClosedForm)
      options.redundancy_at = near.back();
    for (kinematics::JointSolution& solution :
         robot_.arm.inverse(flange_pose(robot_, pose), options)) {
      if (!solution.within_limits) continue;
      if (!ranked) {
        if (solution.configuration == label) return std::move(solution.q);
        continue;
      }
      double distance = 0.0;
      for (std::size_t l = 0; l < arm_.links.size(); ++l)
        distance = std::max(distance, displacement(l, near, solution.q));
      if (distance < best_distance) {
        best_distance = distance;
        best = std::move(solution.q);
      }
    }
    return best;
  }

  // The motion between two clear samples: nullopt when clear, else what the samples between hit.
  template <typename Pose>
  [[nodiscard]] std::optional<std::string> between(const std::string& label, const Pose& pose,
                                                   const Segment& from, const Segment& to,
                                                   int depth) const {
    bool clear = true;
    for (std::size_t l = 0; l < arm_.links.size() && clear; ++l)
      clear = displacement(l, from.q, to.q) <= std::max(from.slack[l], to.slack[l]);
    if (clear) return std::nullopt;
    if (depth == kMaxDepth)
      return std::string("moves its joints too fast to be checked (near a singularity?)");
    const double s = (from.s + to.s) / 2;
    const std::optional<std::vector<double>> q = follow(label, pose(s), from.q);
    if (!q) return std::string(kLost);
    const Sample middle = sample(*q);
    if (middle.hit) return middle.hit;
    const Segment mid{s, *q, middle.slack};
    if (std::optional<std::string> hit = between(label, pose, from, mid, depth + 1)) return hit;
    return between(label, pose, mid, to, depth + 1);
  }

  const RobotSpec& robot_;
  const ArmGeometry& arm_;
  std::vector<geometry::PlacedBody> obstacles_;
  std::vector<std::string> names_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  double margin_;
};

// "every IK branch of the arm is blocked: lun: forearm_link hits block; ..." (at most kListed
// branches named).
std::string every_branch_hits(const std::vector<std::string>& hits) {
  constexpr std::size_t kListed = 6;
  std::string text = "every IK branch of the arm is blocked: ";
  for (std::size_t i = 0; i < hits.size() && i < kListed; ++i) text += (i ? "; " : "") + hits[i];
  if (hits.size() > kListed)
    text += "; and " + std::to_string(hits.size() - kListed) + " more branches";
  return text;
}

geometry::PlacedBody shifted(const geometry::PlacedBody& placed, const Eigen::Vector3d& offset) {
  return {placed.body, Eigen::Translation3d(offset) * placed.pose};
}

}  // namespace

struct WorldModel::Caches {
  std::mutex mutex;
  std::map<std::pair<int, int>, Table> initial, insertion, placement;
  // Not a memo: the arm's link bodies, built once by the constructor and shared by copies too.
  ArmGeometry arm;
};

std::vector<int> WorldState::moving_with(int object) const {
  std::vector<int> group = {object};
  for (std::size_t i = 0; i < group.size(); ++i)
    for (std::size_t o = 0; o < carrier.size(); ++o)
      if (carrier[o] == group[i]) group.push_back(static_cast<int>(o));
  return group;
}

void WorldState::move(int object, const kinematics::Transform& pose) {
  const kinematics::Transform change = pose * poses[object].inverse(Eigen::Isometry);
  for (const int o : moving_with(object)) poses[o] = change * poses[o];
}

// What the construction steps share: the objects that are not fixed, the initial state's fixed
// objects, the open gripper shrunk by a micrometre for the approach to its own object (its pads
// may rest on the contact faces), the closed gripper at each grasp width, built once (grasps
// share widths; a body builds three box hierarchies; copies share them), and the threads the
// per-grasp tables run on (one task per grasp: the checks only read the model, its memo tables
// under a lock, and each task writes its grasp's row).
struct WorldModel::Setting {
  std::vector<int> movable;
  WorldState fixed_only;
  geometry::Body open_shrunk;
  std::map<double, geometry::Body> closed_at_width;
  unsigned threads{1};
};

WorldModel::WorldModel(Scenario scenario, unsigned threads) : scenario_(std::move(scenario)) {
  gripper_ = scenario_.robot.gripper;
  gripper_.max_approach_tilt = scenario_.robot.max_tool_tilt;
  caches_ = std::make_shared<Caches>();
  // Independent of each other, so one list of tasks on the threads: the grasp searches, one per
  // movable object and the longest, first (parts of one shape, a table of cubes, and the same
  // parts planned again share one: remembered_grasps, which any thread may ask); then the box
  // hierarchies of the arm's links (a URDF arm's meshes) and of the objects. Errors, whatever
  // the schedule: the first failing link's, else object's, else grasp search's.
  const std::size_t objects = scenario_.objects.size();
  const std::size_t links = scenario_.robot.arm.links().size();
  std::vector<std::shared_ptr<const std::vector<geometry::Grasp>>> grasp_lists(objects);
  std::vector<std::optional<ArmLink>> arm(links);
  std::vector<std::optional<geometry::Body>> bodies(objects);
  std::vector<std::exception_ptr> failed(2 * objects + links);
  run_tasks(failed.size(), threads, [&](std::size_t t) {
    try {
      if (t < objects) {
        const ObjectSpec& spec = scenario_.objects[t];
        if (!spec.fixed)
          grasp_lists[t] = geometry::remembered_grasps(spec.model, gripper_, scenario_.grasping);
      } else if (t < objects + links) {
        arm[t - objects] = arm_link(scenario_.robot.arm, t - objects);
      } else {
        const ObjectSpec& spec = scenario_.objects[t - objects - links];
        bodies[t - objects - links].emplace(spec.name, geometry::CollisionShape(spec.model.mesh()));
      }
    } catch (...) {
      failed[t] = std::current_exception();
    }
  });
  for (std::size_t i = 0; i < failed.size(); ++i)  // links and objects, then grasp searches
    if (const std::exception_ptr& error = failed[(objects + i) % failed.size()])
      std::rethrow_exception(error);
  for (std::optional<ArmLink>& link : arm)
    if (link) caches_->arm.links.push_back(std::move(*link));
  caches_->arm.lever = joint_levers(scenario_.robot.arm, caches_->arm.links);
  for (std::optional<geometry::Body>& body : bodies) bodies_.push_back(std::move(*body));
  open_gripper_ = geometry::gripper_body(gripper_, gripper_.max_opening);
  check_initial_world();
  Setting setting{.movable = {},
                  .fixed_only = initial_state(),
                  .open_shrunk = geometry::gripper_body(gripper_, gripper_.max_opening, 1e-6),
                  .closed_at_width = {},
                  .threads = threads};
  for (std::size_t o = 0; o < objects; ++o)
    if (!scenario_.objects[o].fixed) setting.movable.push_back(static_cast<int>(o));
  for (std::size_t o = 0; o < scenario_.objects.size(); ++o)
    add_object(scenario_.objects[o],
               grasp_lists[o] ? *grasp_lists[o] : std::vector<geometry::Grasp>{}, setting);
  for (const Goal& goal : scenario_.goals) {
    if (const auto* at = std::get_if<AtGoal>(&goal))
      add_at_goal(*at);
    else
      add_assembled_goal(std::get<AssembledGoal>(goal), setting);
  }
}

void WorldModel::add_object(const ObjectSpec& spec, std::vector<geometry::Grasp> grasps,
                            Setting& setting) {
  ObjectWorld object;
  if (!spec.fixed) {
    object.grasps = std::move(grasps);
    if (object.grasps.empty())
      throw PlanError(spec.location.str() + ": object '" + spec.name +
                      "' has no grasp the gripper can make (opening " +
                      std::to_string(gripper_.max_opening) +
                      " m); if it never moves, say `fixed: true`");
  }
  object.positions = position_labels(scenario_, spec);
  const int index = static_cast<int>(objects_.size());
  const geometry::Body& own = bodies_[index];
  std::vector<int> except = setting.movable;
  except.push_back(index);
  const std::vector<Obstacle> fixed_objects = obstacles(setting.fixed_only, except);
  // A place where the object would meet a fixed object is no destination.
  std::vector<char> position_free(object.positions.size(), 1);
  for (std::size_t p = 1; p < object.positions.size(); ++p)
    for (const Obstacle& other : fixed_objects)
      if (geometry::collide({&own, object.positions[p].pose}, other.placed, margin()))
        position_free[p] = 0;
  held_.emplace_back();
  closed_.emplace_back();
  object.reachable.assign(object.grasps.size(), std::vector<char>(object.positions.size(), 0));
  objects_.push_back(std::move(object));  // grasp_check reads it
  ObjectWorld& added = objects_.back();
  for (const geometry::Grasp& grasp : added.grasps) {
    auto closed = setting.closed_at_width.find(grasp.width);
    if (closed == setting.closed_at_width.end())
      closed = setting.closed_at_width
                   .emplace(grasp.width, geometry::gripper_body(gripper_, grasp.width))
                   .first;
    closed_.back().push_back(closed->second);
    held_.back().push_back(closed_.back().back().joined(
        own, grasp.gripper_in_object.inverse(Eigen::Isometry), spec.name + " in the gripper"));
  }
  run_tasks(added.grasps.size(), setting.threads, [&](std::size_t g) {
    const geometry::Grasp& grasp = added.grasps[g];
    // The gripper's approach to its own object, a translation in the object's frame: the open
    // gripper must keep clear of the object along the whole approach.
    const Eigen::Vector3d approach =
        scenario_.robot.approach_distance * grasp.gripper_in_object.linear().col(2);
    const geometry::PlacedBody start{&setting.open_shrunk,
                                     Eigen::Translation3d(-approach) * grasp.gripper_in_object};
    const geometry::PlacedBody object_at_origin{&own, kinematics::Transform::Identity()};
    const bool approach_clear =
        geometry::sweep(start, approach, std::span(&object_at_origin, 1), margin()).clear;
    for (std::size_t p = 0; p < added.positions.size(); ++p)
      added.reachable[g][p] =
          approach_clear && position_free[p] && grasp_usable_at(grasp, spec, added.positions[p]) &&
          reach(added.positions[p].pose * grasp.gripper_in_object).reachable &&
          grasp_check(index, static_cast<int>(g), added.positions[p].pose, fixed_objects, {}).clear;
  });
}

void WorldModel::add_at_goal(const AtGoal& at) {
  GoalWorld tables;
  tables.kind = GoalWorld::Kind::kAt;
  tables.held = object_index(at.object);
  tables.place = scenario_.place_index(at.place);
  const std::vector<PositionLabel>& positions = objects_[tables.held].positions;
  for (std::size_t p = 0; p < positions.size(); ++p)
    if (positions[p].place == tables.place) tables.at_place.push_back(static_cast<int>(p));
  tables.initially_true = positions[0].place == tables.place;
  goals_.push_back(std::move(tables));
  held_rest_.emplace_back();
  fixed_rest_.emplace_back();
  pair_conflict_.emplace_back();
}

void WorldModel::add_assembled_goal(const AssembledGoal& assembled, const Setting& setting) {
  GoalWorld tables;
  tables.held = object_index(assembled.held);
  tables.fixed = object_index(assembled.fixed);
  const ObjectWorld& held = objects_[tables.held];
  const ObjectWorld& fixed = objects_[tables.fixed];
  // On the threads: the objects but their mating faces (two surfaces' box hierarchies) and, per
  // grasp of f, whether the gripper taking f with h in it keeps clear of h (the same relative
  // geometry wherever f is).
  std::optional<geometry::Body> held_rest, fixed_rest;
  tables.grasp_clears_assembled.assign(fixed.grasps.size(), 0);
  run_tasks(2 + fixed.grasps.size(), setting.threads, [&](std::size_t t) {
    if (t == 0) {
      held_rest = other_faces(scenario_.objects[tables.held], assembled.held_faces);
      return;
    }
    if (t == 1) {
      fixed_rest = other_faces(scenario_.objects[tables.fixed], assembled.fixed_faces);
      return;
    }
    const std::size_t g = t - 2;
    const kinematics::Transform gripper = fixed.grasps[g].gripper_in_object;
    const Eigen::Vector3d approach = scenario_.robot.approach_distance * gripper.linear().col(2);
    const geometry::PlacedBody part{&bodies_[tables.held], assembled.relative};
    tables.grasp_clears_assembled[g] =
        geometry::sweep({&*open_gripper_, Eigen::Translation3d(-approach) * gripper}, approach,
                        std::span(&part, 1), margin())
            .clear &&
        !geometry::collide({&closed_[tables.fixed][g], gripper}, part, margin());
  });
  held_rest_.push_back(std::move(held_rest));
  fixed_rest_.push_back(std::move(fixed_rest));
  const ObjectSpec& fixed_spec = scenario_.objects[tables.fixed];
  tables.initially_true = (fixed_spec.initial_pose * assembled.relative)
                              .isApprox(scenario_.objects[tables.held].initial_pose, 1e-7);
  for (const geometry::Grasp& grasp : held.grasps)
    tables.grasp_leaves_mating_free.push_back(
        geometry::grasp_leaves_free(grasp, assembled.held_faces));
  const ObjectSpec& held_spec = scenario_.objects[tables.held];
  for (const PositionLabel& position : fixed.positions) {
    // An initial pose that is no stable pose: the sensing system tells how it is supported.
    const bool sensed = position.stable_pose < 0 && position.joined_goal < 0;
    const bool faces_free =
        sensed || (position.stable_pose >= 0 &&
                   geometry::pose_leaves_free(fixed_spec.stable_poses[position.stable_pose],
                                              assembled.fixed_faces));
    const Eigen::Vector3d mating = position.pose.linear() * assembled.mating_vector;
    const geometry::PosedPart pair[] = {{&fixed_spec.model, position.pose},
                                        {&held_spec.model, position.pose * assembled.relative}};
    const std::optional<double> margin =
        fixed_spec.fixed || sensed ? std::optional<double>(std::numeric_limits<double>::infinity())
                                   : geometry::resting_margin(pair, geometry::kTableTolerance);
    tables.rests_assembled.push_back(margin && *margin > geometry::kTableTolerance);
    // A position where only a pair rests is none for an insertion: the object stands alone
    // until the held one is in (faces_free is false there).
    tables.mating_pose.push_back(faces_free && -mating.z() >= std::cos(kFrictionCone) &&
                                 tables.rests_assembled.back());
  }
  std::vector<int> except = setting.movable;
  except.push_back(tables.fixed);
  const std::vector<Obstacle> fixed_objects = obstacles(setting.fixed_only, except);
  const int goal_index = static_cast<int>(goals_.size());
  goals_.push_back(tables);  // insertion_check reads the goal's objects
  // The insertion's motions relative to f, per grasp of h (f's pose does not change them).
  pair_conflict_.emplace_back(held.grasps.size());
  tables.mate_reachable.assign(held.grasps.size(), std::vector<char>(fixed.positions.size(), 0));
  run_tasks(held.grasps.size(), setting.threads, [&](std::size_t g) {
    pair_conflict_.back()[g] = tables.grasp_leaves_mating_free[g]
                                   ? insertion_pair_conflict(goal_index, static_cast<int>(g),
                                                             kinematics::Transform::Identity(), {})
                                   : std::optional<std::string>("the grasp obscures a mating face");
    for (std::size_t p = 0; p < fixed.positions.size(); ++p)
      tables.mate_reachable[g][p] =
          reach(fixed.positions[p].pose * assembled.relative * held.grasps[g].gripper_in_object)
              .reachable &&
          insertion_check(goal_index, static_cast<int>(g), fixed.positions[p].pose, fixed_objects,
                          {})
              .clear;
  });
  goals_.back() = std::move(tables);
}

int WorldModel::object_index(std::string_view name) const {
  for (std::size_t i = 0; i < scenario_.objects.size(); ++i)
    if (scenario_.objects[i].name == name) return static_cast<int>(i);
  std::string known;
  for (const ObjectSpec& object : scenario_.objects)
    known += (known.empty() ? "" : ", ") + object.name;
  throw PlanError("no object '" + std::string(name) + "' (known: " + known + ")");
}

const GoalWorld* WorldModel::goal(int held, int fixed) const {
  for (const GoalWorld& tables : goals_)
    if (tables.kind == GoalWorld::Kind::kAssembled && tables.held == held && tables.fixed == fixed)
      return &tables;
  return nullptr;
}

Transform WorldModel::flange_in_base(const Transform& gripper_pose) const {
  return flange_pose(scenario_.robot, gripper_pose);
}

Reach WorldModel::reach(const Transform& gripper_pose) const {
  Reach result;
  result.tilt = tilt_from_down(gripper_pose);
  result.solution = arm_branch(gripper_pose, {}, {}).branch;
  result.reachable = result.solution.has_value();
  return result;
}

WorldModel::ArmChoice WorldModel::arm_branch(const Transform& gripper_pose,
                                             std::span<const ArmLine> lines,
                                             const std::vector<Obstacle>& obstacles) const {
  ArmChoice choice;
  if (tilt_from_down(gripper_pose) > scenario_.robot.max_tool_tilt)
    return choice;  // never reach up
  std::vector<geometry::PlacedBody> placed;
  std::vector<std::string> names;
  for (const Obstacle& obstacle : obstacles) {
    placed.push_back(obstacle.placed);
    names.push_back(scenario_.objects[obstacle.object].name);
  }
  const BranchCheck check(scenario_.robot, caches_->arm, std::move(placed), std::move(names),
                          margin());
  std::vector<std::string> hits;
  for (kinematics::JointSolution& solution :
       scenario_.robot.arm.inverse(flange_in_base(gripper_pose))) {
    if (!solution.within_limits || arm_below_table(scenario_.robot, caches_->arm.links, solution.q))
      continue;
    if (std::optional<std::string> hit = check.conflict(solution, gripper_pose, lines)) {
      hits.push_back(solution.configuration + ": " + *hit);
      continue;
    }
    choice.branch = std::move(solution);
    return choice;
  }
  if (!hits.empty()) choice.conflict = every_branch_hits(hits);
  return choice;
}

namespace {

// Per object and position: whether the object can be brought there from its initial position
// (0) by moves alone, each a grasp that reaches it both where it is and where it goes.
std::vector<std::vector<char>> brought_by_moves(const std::vector<ObjectWorld>& objects) {
  std::vector<std::vector<char>> out;
  for (const ObjectWorld& object : objects) {
    std::vector<char> seen(object.positions.size(), 0);
    std::vector<std::size_t> queue = {0};
    seen[0] = 1;
    while (!queue.empty()) {
      const std::size_t from = queue.back();
      queue.pop_back();
      for (std::size_t to = 1; to < object.positions.size(); ++to) {
        if (seen[to]) continue;
        for (std::size_t g = 0; g < object.grasps.size(); ++g)
          if (object.reachable[g][from] && object.reachable[g][to]) {
            seen[to] = 1;
            queue.push_back(to);
            break;
          }
      }
    }
    out.push_back(std::move(seen));
  }
  return out;
}

// Whether some grasp reaches the object at position p.
bool graspable_at(const ObjectWorld& object, std::size_t p) {
  return std::any_of(object.reachable.begin(), object.reachable.end(),
                     [&](const std::vector<char>& row) { return row[p] != 0; });
}

// Why an at-goal cannot be reached by relaxed moves, or nullopt.
std::optional<std::string> at_goal_obstacle(const GoalWorld& goal, const Scenario& scenario,
                                            const std::vector<ObjectWorld>& objects,
                                            const std::vector<std::vector<char>>& brought) {
  const std::string& held = scenario.objects[goal.held].name;
  const std::string& place = scenario.places[goal.place].name;
  bool placeable = false, reached = false;
  for (const int p : goal.at_place) {
    placeable |= graspable_at(objects[goal.held], p);
    reached |= brought[goal.held][p] != 0;
  }
  if (!placeable)
    return held + ": no stable pose at place " + place +
           " is reachable with any grasp (reachable(grasp, position) has no pair there)";
  if (!graspable_at(objects[goal.held], 0))
    return held + ": no grasp reaches it at its initial pose";
  if (!reached)
    return held + ": no sequence of moves the robot can make brings it to place " + place;
  return std::nullopt;
}

// Why an assembled goal cannot be reached by relaxed moves (picking the held object up, bringing
// the fixed one to a mating pose, inserting), or nullopt.
std::optional<std::string> assembled_goal_obstacle(const GoalWorld& goal, const Scenario& scenario,
                                                   const std::vector<ObjectWorld>& objects,
                                                   const std::vector<std::vector<char>>& brought) {
  const std::string& held = scenario.objects[goal.held].name;
  const std::string& fixed = scenario.objects[goal.fixed].name;
  const bool fixed_is_fixed = scenario.objects[goal.fixed].fixed;
  const ObjectWorld& h = objects[goal.held];
  if (!graspable_at(h, 0))
    return held + ": no grasp reaches it at its initial pose (within reach and the " +
           "tilt limit)";
  bool any_mating = false, mating_reached = false;
  for (std::size_t p = 0; p < goal.mating_pose.size(); ++p) {
    any_mating |= goal.mating_pose[p] != 0;
    mating_reached |= goal.mating_pose[p] && brought[goal.fixed][p];
  }
  if (!any_mating)
    return fixed + ": no position leaves its mating faces off the table with the " +
           "mating vector pointing down (in_position_class(position, mating_poses) is empty" +
           (fixed_is_fixed ? "; it is fixed: its only position is where it is" : "") + ")";
  if (!mating_reached)
    return fixed + ": none of its mating poses can be reached by moves the robot " + "can make" +
           (fixed_is_fixed                         ? " (it is fixed)"
            : graspable_at(objects[goal.fixed], 0) ? ""
                                                   : " (no grasp reaches it at its initial pose)");
  bool any_free = false, free_pickable = false, insertable = false;
  for (std::size_t g = 0; g < h.grasps.size(); ++g) {
    if (!goal.grasp_leaves_mating_free[g]) continue;
    any_free = true;
    bool pickable = false;
    for (std::size_t p = 0; p < h.positions.size(); ++p)
      pickable |= brought[goal.held][p] && h.reachable[g][p] != 0;
    free_pickable |= pickable;
    for (std::size_t p = 0; p < goal.mating_pose.size() && pickable; ++p)
      insertable |= brought[goal.fixed][p] && goal.mating_pose[p] && goal.mate_reachable[g][p];
  }
  if (!any_free)
    return held + ": every grasp obscures a mating face " +
           "(member(grasp, grasps_leaving_mating_faces_free) is empty)";
  if (!free_pickable)
    return held + ": no grasp that leaves its mating faces free picks it up at a " +
           "pose it can be brought to";
  if (!insertable)
    return fixed + ": at none of the mating poses it can be brought to can the robot " +
           "reach the insertion of " + held + " with a grasp that leaves " + held +
           "'s mating faces free (mate_reachable(grasp, position) is empty)";
  return std::nullopt;
}

}  // namespace

std::optional<std::string> WorldModel::relaxed_obstacle() const {
  const std::vector<std::vector<char>> brought = brought_by_moves(objects_);
  for (std::size_t i = 0; i < goals_.size(); ++i) {
    const GoalWorld& goal = goals_[i];
    if (goal.initially_true) continue;
    const Goal& spec = scenario_.goals[i];
    const std::optional<std::string> obstacle =
        goal.kind == GoalWorld::Kind::kAt
            ? at_goal_obstacle(goal, scenario_, objects_, brought)
            : assembled_goal_obstacle(goal, scenario_, objects_, brought);
    if (obstacle) return "goal " + describe(spec) + " (" + location(spec).str() + "): " + *obstacle;
  }
  return std::nullopt;
}

WorldState WorldModel::initial_state() const {
  WorldState state;
  for (const ObjectSpec& object : scenario_.objects) state.poses.push_back(object.initial_pose);
  state.carrier.assign(scenario_.objects.size(), -1);
  // The assembled goals that hold at the start (found from the poses: the constructor's first
  // checks run before goals_ is filled).
  for (const Goal& goal : scenario_.goals)
    if (const auto* assembled = std::get_if<AssembledGoal>(&goal)) {
      const int held = object_index(assembled->held), fixed = object_index(assembled->fixed);
      if ((state.poses[fixed] * assembled->relative).isApprox(state.poses[held], 1e-7))
        state.carrier[held] = fixed;
    }
  return state;
}

std::vector<WorldModel::Obstacle> WorldModel::obstacles(const WorldState& state,
                                                        const std::vector<int>& except) const {
  std::vector<Obstacle> out;
  for (std::size_t o = 0; o < state.poses.size(); ++o)
    if (std::find(except.begin(), except.end(), static_cast<int>(o)) == except.end())
      out.push_back({static_cast<int>(o), {&bodies_[o], state.poses[o]}});
  return out;
}

std::string WorldModel::length_text(double metres) const {
  char text[48];
  std::snprintf(text, sizeof text, "%.4g %s", scenario_.units.to_file_length(metres),
                std::string(scenario_.units.length_name()).c_str());
  return text;
}

std::optional<std::string> WorldModel::check_rest(const WorldState& state, int object) const {
  int root = object;
  while (state.carrier[root] >= 0) root = state.carrier[root];
  const std::vector<int> group = state.moving_with(root);
  const ObjectSpec& base = scenario_.objects[root];
  const bool unmoved_unstable =
      !base.initial_stable_pose && state.poses[root].isApprox(base.initial_pose, 1e-9);
  // An object alone in one of its stable poses rests (a joined position, "J1+peg@left", is no
  // stable pose of the object alone: a plan putting it there alone is refused here).
  const bool alone_in_stable_pose =
      group.size() == 1 &&
      geometry::classify_orientation(base.stable_poses, state.poses[root].linear(), 1e-6);
  if (base.fixed || unmoved_unstable || alone_in_stable_pose) return std::nullopt;
  std::vector<geometry::PosedPart> parts;
  std::string named = base.name + (group.size() > 1 ? " with " : "");
  for (std::size_t k = 0; k < group.size(); ++k) {
    parts.push_back({&scenario_.objects[group[k]].model, state.poses[group[k]]});
    if (k > 0) named += (k > 1 ? ", " : "") + scenario_.objects[group[k]].name;
  }
  named += group.size() > 1 ? " assembled into it does not " : " does not ";
  const std::optional<double> margin = geometry::resting_margin(parts, geometry::kTableTolerance);
  if (!margin)
    return named + "stand flat on the table there (it touches it along an edge or at a corner " +
           "only, or a part goes below it)";
  if (*margin > geometry::kTableTolerance) return std::nullopt;
  return named + "rest on the table there: its centre of mass lies " +
         (*margin < 0 ? length_text(-*margin) + " outside" : std::string("on the edge of")) +
         " its footing";
}

void WorldModel::check_initial_world() const {
  const WorldState state = initial_state();
  const auto where = [&](std::size_t o) {
    return "objects." + scenario_.objects[o].name + ".pose (" +
           scenario_.objects[o].pose_location.str() + ")";
  };
  constexpr double kResting = 1e-6;  // metres: how far from z = 0 still counts as on the table
  for (std::size_t o = 0; o < bodies_.size(); ++o) {
    const double lowest = geometry::lowest_z({&bodies_[o], state.poses[o]});
    if (lowest < -kResting)
      throw PlanError(where(o) + ": " + scenario_.objects[o].name + " reaches " +
                      length_text(-lowest) + " below the table (the plane z = 0)");
    if (lowest > kResting && state.carrier[o] < 0)
      throw PlanError(where(o) + ": " + scenario_.objects[o].name + " floats " +
                      length_text(lowest) +
                      " above the table: an object rests on the table or sits assembled in " +
                      "another (an assembled goal that holds at the start)");
  }
  // The root of an object's subassembly: objects assembled together may touch.
  const auto root = [&](int o) {
    while (state.carrier[o] >= 0) o = state.carrier[o];
    return o;
  };
  for (std::size_t a = 0; a < bodies_.size(); ++a)
    for (std::size_t b = a + 1; b < bodies_.size(); ++b) {
      if (root(static_cast<int>(a)) == root(static_cast<int>(b))) continue;
      if (geometry::collide({&bodies_[a], state.poses[a]}, {&bodies_[b], state.poses[b]}, 0.0))
        throw PlanError(where(a) + " and " + where(b) + ": " + scenario_.objects[a].name + " and " +
                        scenario_.objects[b].name +
                        " interpenetrate or touch in the initial world");
    }
  for (std::size_t o = 0; o < bodies_.size(); ++o)
    if (state.carrier[o] < 0)
      if (const std::optional<std::string> topples = check_rest(state, static_cast<int>(o)))
        throw PlanError(where(o) + ": " + *topples);
}

namespace {

// The first obstacle that `moving`, swept by `travel`, comes within the margin of; -1 if none.
template <typename Obstacles>
int first_hit(const geometry::PlacedBody& moving, const Eigen::Vector3d& travel,
              const Obstacles& obstacles, double margin) {
  std::vector<geometry::PlacedBody> placed;
  for (const auto& obstacle : obstacles) placed.push_back(obstacle.placed);
  const geometry::Sweep sweep = geometry::sweep(moving, travel, placed, margin);
  return sweep.clear ? -1 : sweep.obstacle;
}

bool below_table(const geometry::PlacedBody& placed, const Eigen::Vector3d& travel) {
  return std::min(geometry::lowest_z(placed), geometry::lowest_z(shifted(placed, travel))) <
         -geometry::kTableTolerance;
}

// A conflict table [grasp][position]: set where the pair is reachable and `blocked(grasp,
// position)` (its motion checked against one obstacle) finds the motion not clear.
template <typename Blocked>
void fill_conflicts(WorldModel::Table& table, const std::vector<std::vector<char>>& reachable,
                    std::size_t positions, const Blocked& blocked) {
  table.assign(reachable.size(), std::vector<char>(positions, 0));
  for (std::size_t g = 0; g < reachable.size(); ++g)
    for (std::size_t p = 0; p < positions; ++p)
      table[g][p] = reachable[g][p] && blocked(static_cast<int>(g), p);
}

}  // namespace

StepCheck WorldModel::grasp_check(int object, int grasp, const kinematics::Transform& pose,
                                  const std::vector<Obstacle>& others,
                                  const std::vector<Obstacle>& parts, bool measure) const {
  const std::string& name = scenario_.objects[object].name;
  const kinematics::Transform gripper_pose =
      pose * objects_[object].grasps[grasp].gripper_in_object;
  const Eigen::Vector3d approach = scenario_.robot.approach_distance * gripper_pose.linear().col(2);
  StepCheck check;
  const auto fail = [&](std::string what) {
    check.clear = false;
    check.conflict = std::move(what);
    return check;
  };
  // The open gripper between T - d a and T, among everything but the object itself.
  const geometry::PlacedBody open_start{&*open_gripper_,
                                        Eigen::Translation3d(-approach) * gripper_pose};
  std::vector<Obstacle> around = others;
  around.insert(around.end(), parts.begin(), parts.end());
  if (const int hit = first_hit(open_start, approach, around, margin()); hit >= 0)
    return fail("the open gripper, coming to " + name + ", hits " +
                scenario_.objects[around[hit].object].name);
  if (below_table(open_start, approach))
    return fail("the open gripper, coming to " + name + ", goes below the table");
  // Closed on the object: against what is assembled into it (they do not move apart), then with
  // it (and them) between T and T - d a among the others.
  const geometry::PlacedBody closed{&closed_[object][grasp], gripper_pose};
  for (const Obstacle& part : parts)
    if (geometry::collide(closed, part.placed, margin()))
      return fail("the gripper, closed on " + name + ", hits " +
                  scenario_.objects[part.object].name + " assembled into it");
  const std::optional<geometry::Body> with_parts =
      carrying(held_[object][grasp], gripper_pose, parts);
  const geometry::PlacedBody held{with_parts ? &*with_parts : &held_[object][grasp], gripper_pose};
  if (const int hit = first_hit(held, -approach, others, margin()); hit >= 0)
    return fail(name + " in the gripper hits " + scenario_.objects[others[hit].object].name);
  if (below_table(held, -approach)) return fail(name + " in the gripper goes below the table");
  const ArmLine line{-approach, "approach"};
  ArmChoice arm = arm_branch(gripper_pose, std::span(&line, 1), others);
  if (arm.conflict) return fail(std::move(*arm.conflict));
  check.arm = std::move(arm.branch);
  if (!measure) return check;
  std::vector<geometry::PlacedBody> placed;
  for (const Obstacle& other : others) placed.push_back(other.placed);
  const geometry::Nearest nearest = geometry::nearest(held, placed);
  check.clearance = nearest.distance;
  check.nearest = nearest.index >= 0 ? others[nearest.index].object : -1;
  return check;
}

WorldModel::InsertionFrame WorldModel::insertion_frame(
    int goal, int grasp, const kinematics::Transform& fixed_pose) const {
  const GoalWorld& tables = goals_[goal];
  const AssembledGoal& assembled = std::get<AssembledGoal>(scenario_.goals[goal]);
  const kinematics::Transform held_pose = fixed_pose * assembled.relative;
  return {.held_name = scenario_.objects[tables.held].name,
          .fixed_name = scenario_.objects[tables.fixed].name,
          .held_pose = held_pose,
          .gripper_pose = held_pose * objects_[tables.held].grasps[grasp].gripper_in_object,
          .insertion = scenario_.robot.approach_distance *
                       (fixed_pose.linear() * assembled.mating_vector).normalized()};
}

std::optional<geometry::Body> WorldModel::carrying(const geometry::Body& body,
                                                   const kinematics::Transform& gripper_pose,
                                                   const std::vector<Obstacle>& parts) {
  if (parts.empty()) return std::nullopt;
  geometry::Body joined = body;
  for (const Obstacle& part : parts)
    joined = joined.joined(*part.placed.body,
                           gripper_pose.inverse(Eigen::Isometry) * part.placed.pose, body.name());
  return joined;
}

std::optional<std::string> WorldModel::insertion_pair_conflict(
    int goal, int grasp, const kinematics::Transform& fixed_pose,
    const std::vector<Obstacle>& held_parts) const {
  const GoalWorld& tables = goals_[goal];
  const auto [held_name, fixed_name, held_pose, gripper_pose, insertion] =
      insertion_frame(goal, grasp, fixed_pose);
  const std::vector<Obstacle> fixed_alone = {{tables.fixed, {&bodies_[tables.fixed], fixed_pose}}};
  // The gripper (with h's parts) along the mating vector against f.
  const std::optional<geometry::Body> with_parts =
      carrying(closed_[tables.held][grasp], gripper_pose, held_parts);
  const geometry::PlacedBody gripper_start{with_parts ? &*with_parts : &closed_[tables.held][grasp],
                                           Eigen::Translation3d(-insertion) * gripper_pose};
  if (first_hit(gripper_start, insertion, fixed_alone, margin()) >= 0)
    return "the gripper, inserting " + held_name + ", hits " + fixed_name;
  // h against f: they may touch on their mating faces (that is the joint), and where those meet
  // the faces around them; elsewhere their surfaces may not meet (the faces other than the
  // mating ones, each triangle pulled in by a micrometre, sampled along the insertion at most a
  // margin apart, at least 100 samples).
  if (held_rest_[goal] && fixed_rest_[goal]) {
    const geometry::PlacedBody fixed_at{&*fixed_rest_[goal], fixed_pose};
    const int samples = static_cast<int>(std::ceil(
        std::max(100.0, margin() > 0 ? scenario_.robot.approach_distance / margin() : 0.0)));
    for (int k = 0; k <= samples; ++k) {
      const kinematics::Transform held_at =
          Eigen::Translation3d(-insertion * (1.0 - static_cast<double>(k) / samples)) * held_pose;
      if (geometry::collide({&*held_rest_[goal], held_at}, fixed_at, 0.0))
        return held_name + " meets " + fixed_name + " outside their mating faces";
    }
  }
  // Released, the open gripper back along its axis, against f.
  const geometry::PlacedBody open_end{&*open_gripper_, gripper_pose};
  if (first_hit(open_end, -scenario_.robot.approach_distance * gripper_pose.linear().col(2),
                fixed_alone, margin()) >= 0)
    return "the open gripper, leaving " + held_name + ", hits " + fixed_name;
  return std::nullopt;
}

StepCheck WorldModel::insertion_check(int goal, int grasp, const kinematics::Transform& fixed_pose,
                                      const std::vector<Obstacle>& others,
                                      const std::vector<Obstacle>& held_parts, bool measure) const {
  const GoalWorld& tables = goals_[goal];
  const auto [held_name, fixed_name, held_pose, gripper_pose, insertion] =
      insertion_frame(goal, grasp, fixed_pose);
  const Eigen::Vector3d retreat = -scenario_.robot.approach_distance * gripper_pose.linear().col(2);
  StepCheck check;
  const auto fail = [&](std::string what) {
    check.clear = false;
    check.conflict = std::move(what);
    return check;
  };
  const geometry::PlacedBody closed_end{&closed_[tables.held][grasp], gripper_pose};
  for (const Obstacle& part : held_parts)
    if (geometry::collide(closed_end, part.placed, margin()))
      return fail("the gripper, closed on " + held_name + ", hits " +
                  scenario_.objects[part.object].name + " assembled into it");
  // Against f: the same relative motion wherever f is, so known per grasp (pair_conflict_),
  // unless h carries parts.
  const std::optional<std::string> pair =
      held_parts.empty() ? pair_conflict_[goal][grasp]
                         : insertion_pair_conflict(goal, grasp, fixed_pose, held_parts);
  if (pair) return fail(*pair);
  // The gripper with h (and h's parts) along the mating vector among the others.
  const std::optional<geometry::Body> with_parts =
      carrying(held_[tables.held][grasp], gripper_pose, held_parts);
  const geometry::Body* moving = with_parts ? &*with_parts : &held_[tables.held][grasp];
  const geometry::PlacedBody held_start{moving, Eigen::Translation3d(-insertion) * gripper_pose};
  if (const int hit = first_hit(held_start, insertion, others, margin()); hit >= 0)
    return fail(held_name + ", inserted into " + fixed_name + ", hits " +
                scenario_.objects[others[hit].object].name);
  if (below_table(held_start, insertion))
    return fail(held_name + ", inserted into " + fixed_name + ", goes below the table");
  // Released: the open gripper back along its axis, among the others and h's parts.
  std::vector<Obstacle> around = others;
  around.insert(around.end(), held_parts.begin(), held_parts.end());
  const geometry::PlacedBody open_end{&*open_gripper_, gripper_pose};
  if (const int hit = first_hit(open_end, retreat, around, margin()); hit >= 0)
    return fail("the open gripper, leaving " + held_name + ", hits " +
                scenario_.objects[around[hit].object].name);
  if (below_table(open_end, retreat))
    return fail("the open gripper, leaving " + held_name + ", goes below the table");
  std::vector<Obstacle> with_fixed = others;
  with_fixed.push_back({tables.fixed, {&bodies_[tables.fixed], fixed_pose}});
  const std::array lines = {ArmLine{-insertion, "insertion"}, ArmLine{retreat, "retreat"}};
  ArmChoice arm = arm_branch(gripper_pose, lines, with_fixed);
  if (arm.conflict) return fail(std::move(*arm.conflict));
  check.arm = std::move(arm.branch);
  if (!measure) return check;
  // Clearance at T: the gripper with h against the others, the gripper against f.
  std::vector<geometry::PlacedBody> placed;
  for (const Obstacle& other : others) placed.push_back(other.placed);
  const geometry::PlacedBody held_end{moving, gripper_pose};
  const geometry::Nearest nearest = geometry::nearest(held_end, placed);
  check.clearance = nearest.distance;
  check.nearest = nearest.index >= 0 ? others[nearest.index].object : -1;
  const double to_fixed =
      geometry::proximity(closed_end, {&bodies_[tables.fixed], fixed_pose}).distance;
  if (to_fixed < check.clearance) {
    check.clearance = to_fixed;
    check.nearest = tables.fixed;
  }
  return check;
}

StepCheck WorldModel::check_grasp(const WorldState& state, int object, int grasp,
                                  const kinematics::Transform& object_pose, bool measure) const {
  WorldState moved = state;
  moved.move(object, object_pose);
  const std::vector<int> group = moved.moving_with(object);
  const std::vector<int> parts_only(group.begin() + 1, group.end());
  std::vector<int> not_parts;
  for (std::size_t o = 0; o < state.poses.size(); ++o)
    if (std::find(parts_only.begin(), parts_only.end(), static_cast<int>(o)) == parts_only.end())
      not_parts.push_back(static_cast<int>(o));
  return grasp_check(object, grasp, object_pose, obstacles(moved, group),
                     obstacles(moved, not_parts), measure);
}

StepCheck WorldModel::check_insertion(const WorldState& state, int goal, int grasp,
                                      const kinematics::Transform& fixed_pose, bool measure) const {
  const GoalWorld& tables = goals_[goal];
  const AssembledGoal& assembled = std::get<AssembledGoal>(scenario_.goals[goal]);
  WorldState moved = state;
  moved.move(tables.held, fixed_pose * assembled.relative);
  std::vector<int> group = moved.moving_with(tables.held);
  const std::vector<int> parts_only(group.begin() + 1, group.end());
  std::vector<int> not_parts;
  for (std::size_t o = 0; o < state.poses.size(); ++o)
    if (std::find(parts_only.begin(), parts_only.end(), static_cast<int>(o)) == parts_only.end())
      not_parts.push_back(static_cast<int>(o));
  group.push_back(tables.fixed);
  return insertion_check(goal, grasp, fixed_pose, obstacles(moved, group),
                         obstacles(moved, not_parts), measure);
}

std::optional<kinematics::JointSolution> WorldModel::still_branch(
    const WorldState& state, const kinematics::Transform& gripper_pose) const {
  const std::vector<Obstacle> all = obstacles(state, {});
  const geometry::PlacedBody open{&*open_gripper_, gripper_pose};
  if (below_table(open, Eigen::Vector3d::Zero())) return std::nullopt;
  for (const Obstacle& obstacle : all)
    if (geometry::collide(open, obstacle.placed, margin())) return std::nullopt;
  return arm_branch(gripper_pose, {}, all).branch;
}

const WorldModel::Table& WorldModel::initial_conflicts(int object, int other) const {
  const std::lock_guard lock(caches_->mutex);
  const auto [entry, fresh] = caches_->initial.try_emplace({object, other});
  if (!fresh) return entry->second;
  const ObjectWorld& labels = objects_[object];
  Table& table = entry->second;
  table.assign(labels.grasps.size(), std::vector<char>(labels.positions.size(), 0));
  const WorldState start = initial_state();
  const std::vector<int> group = start.moving_with(object);
  if (std::find(group.begin(), group.end(), other) != group.end()) return table;
  const std::vector<Obstacle> obstacle = {{other, {&bodies_[other], start.poses[other]}}};
  const Eigen::AlignedBox3d other_box = geometry::world_bounds(obstacle.front().placed);
  // A reachable grasp and position already passed every check that needs no other object, so
  // with an arm that has no link geometry only the two sweeps can meet `other`: when `other`
  // lies `margin` or more beyond the boxes they sweep (geometry::sweep's own broad phase, over
  // the same boxes), the grasp is clear of it without running grasp_check.
  const auto beyond_sweeps = [&](int g, std::size_t p) {
    if (!caches_->arm.links.empty()) return false;
    const kinematics::Transform gripper_pose =
        labels.positions[p].pose * labels.grasps[static_cast<std::size_t>(g)].gripper_in_object;
    const Eigen::Translation3d back(-scenario_.robot.approach_distance *
                                    gripper_pose.linear().col(2));
    Eigen::AlignedBox3d swept = geometry::world_bounds({&*open_gripper_, gripper_pose});
    swept.extend(geometry::world_bounds({&*open_gripper_, back * gripper_pose}));
    const geometry::Body& held =
        held_[static_cast<std::size_t>(object)][static_cast<std::size_t>(g)];
    swept.extend(geometry::world_bounds({&held, gripper_pose}));
    swept.extend(geometry::world_bounds({&held, back * gripper_pose}));
    const double gap = std::sqrt(swept.squaredExteriorDistance(other_box));
    return gap > 0 && gap >= margin();
  };
  fill_conflicts(table, labels.reachable, labels.positions.size(), [&](int g, std::size_t p) {
    return !beyond_sweeps(g, p) &&
           !grasp_check(object, g, labels.positions[p].pose, obstacle, {}).clear;
  });
  return table;
}

const WorldModel::Table& WorldModel::insertion_conflicts(int goal, int other) const {
  const std::lock_guard lock(caches_->mutex);
  const auto [entry, fresh] = caches_->insertion.try_emplace({goal, other});
  if (!fresh) return entry->second;
  const GoalWorld& tables = goals_[goal];
  const ObjectWorld& fixed = objects_[tables.fixed];
  const std::vector<Obstacle> obstacle = {{other, {&bodies_[other], initial_state().poses[other]}}};
  fill_conflicts(entry->second, tables.mate_reachable, fixed.positions.size(),
                 [&](int g, std::size_t p) {
                   return !insertion_check(goal, g, fixed.positions[p].pose, obstacle, {}).clear;
                 });
  return entry->second;
}

const WorldModel::Table& WorldModel::placement_conflicts(int object, int other) const {
  const std::lock_guard lock(caches_->mutex);
  const auto [entry, fresh] = caches_->placement.try_emplace({object, other});
  if (!fresh) return entry->second;
  const std::vector<PositionLabel>& mine = objects_[object].positions;
  const std::vector<PositionLabel>& theirs = objects_[other].positions;
  Table& table = entry->second;
  table.assign(mine.size(), std::vector<char>(theirs.size(), 0));
  for (std::size_t p = 0; p < mine.size(); ++p)
    for (std::size_t q = 0; q < theirs.size(); ++q)
      table[p][q] = (mine[p].place >= 0 && mine[p].place == theirs[q].place) ||
                    geometry::collide({&bodies_[object], mine[p].pose},
                                      {&bodies_[other], theirs[q].pose}, margin());
  return table;
}

bool WorldModel::grasp_usable_at(const geometry::Grasp& grasp, const ObjectSpec& object,
                                 const PositionLabel& position) const {
  if (position.stable_pose < 0) return true;  // no table lookup: the IK tilt test still applies
  return geometry::grasp_usable(grasp, object.stable_poses[position.stable_pose], gripper_);
}

}  // namespace spar::planner
