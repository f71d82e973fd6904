// WorldModel: what SPAR's constraint manipulation system knows about a scenario, computed once:
// each object's grasp labels and position labels, and the geometric predicates of the constraint
// network as tables over label pairs (the planner posts them as arcs and unary constraints).
//
// Labels (SPAR quantizes geometry so plan variables take symbolic values):
//   grasp labels     an object's quantized grasps (geometry/grasps.hpp), "G1", "G2", ...
//   position labels  [0] "initial": the object's initial pose; then, for every stable pose s,
//                    every free place p of the scenario and every yaw of p, "P<s>@<place>" (a
//                    place with several yaws: "P<s>@<place>/<yaw in the file's angle unit>"):
//                    resting in s above p, turned by the yaw; then, for an object a goal moves
//                    (an at goal's, or the held one of an assembled goal) that is the fixed
//                    object of an assembled goal, "J<k>+<held>@<place>" for every orientation in
//                    which the two joined rest and the object alone does not
//                    (geometry::joint_stable_poses; their joint centre of mass above p; the
//                    label's PositionLabel::joined_goal). Every position is an absolute world
//                    pose. A fixed object (`fixed: true`) has no grasps and only "initial".
// Predicates (tables indexed [grasp][position]):
//   reachable(g, p)       the grasp is usable in p's stable pose (no contact face on the table, the
//                         gripper not below it) and the robot reaches T = T_O(p) T_G with an
//                         in-limit IK solution whose approach axis lies within the robot's
//                         max_tool_tilt of world -z (SPAR: never reach up through the table);
//   mate_reachable(g, p)  for an assembled goal: the robot reaches T = T_fixed(p) Ta T_G the same
//                         way (held grasp g, fixed position p);
//   grasps_leaving_mating_faces_free   the held object's grasps obscuring none of its mating faces;
//   mating_poses          the fixed object's positions whose stable pose leaves its mating faces
//                         off the table and turn the mating vector into the friction cone (within
//                         kFrictionCone of world -z: the insertion pushes the object onto the
//                         table), and where it rests with the held object in it;
//   rests_assembled(p)    the fixed object at position p, with the held object assembled into it,
//                         stands on the table as one body (geometry::resting_margin above
//                         geometry::kTableTolerance). Once joined, they move as one: only these
//                         positions are the fixed object's destinations; before, only positions
//                         where it rests alone (no joined one; not a mating pose either). A `fixed:
//                         true` object (held by its fixture) and an initial pose that is no stable
//                         pose (the sensing system tells how it is supported) count as resting.
// An initial pose that is not a stable pose has no table lookup: its contact faces count as free
// (SPAR: the sensing system tells), and it is a mating pose only by the mating-vector test.
// Goals: world.goals()[i] belongs to scenario().goals[i]; an at goal's table is the object's
// positions at the place (the initial one too when the object starts there), and a goal that
// holds in the initial world is marked so (posting then needs no step for it).
//
// Collisions (geometry/collision.hpp, margin `collision.margin`). SPAR's execution moves the
// gripper above a destination and then straight down; spar checks those straight lines, of
// length d = robot.approach_distance, for every step. With T the gripper pose, a its approach (z)
// axis, the motions of a step are
//   grasp or release (pickup, putdown, squeeze): the open gripper between T - d a and T, and the
//       gripper closed on the object (with what is assembled into it) between T and T - d a;
//   insertion (assemble h into f, mating vector m in the world): the gripper closed on h (and
//       its parts) from T - d m to T, then the open gripper from T to T - d a.
// Each motion is swept against every other object where it rests (geometry::sweep: no sample
// closer than the margin, so no point of the path closer than half of it), and its ends against
// the table (nothing below z = 0). Exempt: the gripper and the object it grasps (the grasp is
// dropped if the open gripper's approach hits its own object), and in an insertion h and f at
// their mating faces: there they may touch (they are being joined), and elsewhere their surfaces
// may not meet at all (their other faces, each triangle pulled in by a micrometre so that faces
// meeting the joint along an edge do not count, sampled along the insertion at most a margin
// apart); objects assembled together (a subassembly) move as one and are not checked against
// each other.
// The tables above include what never changes: `reachable` and `mate_reachable` are false where a
// motion hits a fixed object or goes through the table, and a position where the object would
// meet a fixed object is nobody's destination. What depends on the order of the steps (where the
// other movable objects are) is checked by posting (initial_conflicts, placement_conflicts: see
// posting.hpp) and, exactly, per plan instance (check_grasp, check_insertion on the simulated
// WorldState, and check_rest after every release: a subassembly must stand as one body). The
// initial world is checked once: objects that meet (unless assembled there already), rest below
// the table or float, and subassemblies that do not stand are an error naming them at their
// `pose`.
// The arm (a robot with collision geometry; a DH table has none, so Puma plans are unchanged):
// reach() takes the first in-limit IK branch, in the robot's order, with no moving link below the
// table. A grasp or insertion takes the first such branch whose links, except those on the last
// body (next to the gripper), keep the margin from every object but the held one (the fixed one
// of an insertion included) and whose moving links stay above the table, at T and along each of
// the step's straight lines (grasp: T to T - d a; insertion: T to T - d m and T to T - d a),
// following the same branch, within its joint limits and the arm's reach all along (the closed
// forms' label; the numeric solver's solution nearest the last sample). When every branch is
// blocked the step is refused: "every IK branch of the arm is blocked: lun: forearm_link hits
// block; run: upper_arm_link hits block along the approach; ruf: leaves its reach or joint
// limits along the approach" (docs/scenario.md, Collisions). StepCheck::arm is the branch taken:
// the plan instance reports it and joint-level uncertainty acts at it.
// Along a line the branch is sampled by bisection until, between every two consecutive samples,
// each link's sum_i lever_i |dq_i| (lever_i bounds the distance from joint i's axis to the
// link's points, so this bounds how far any of them moves when the joints change by dq) is at
// most the link's slack at one of the two: its distance bound to every obstacle less margin/2
// (the distance of the boxes, or the margin when only FCL says they are clear) and its height
// above the table. Guarantee: every sample keeps the margin, and if each joint moves
// monotonically between two consecutive samples (which the bisection makes close) no point of
// the arm comes closer than margin/2 to an object or goes below the table. A line that needs
// more than 2^16 samples counts as blocked for that branch. Cost: a few IK and FK evaluations per
// line when the arm is far from everything, about (link travel) / (margin/2) where it passes
// within a few margins of an object. A 7-joint arm's branch keeps its label's q7, so a sample
// along a line solves that one q7 (InverseOptions::redundancy_at: the same solution as the
// sweep's at it); the branches at T come from the whole redundancy sweep.
//
// Example:
//   const WorldModel world(load_scenario("examples/peg_block_face_down.yaml"));
//   const int block = world.object_index("block");
//   world.object(block).positions[0].name;              // "initial"
//   world.object(block).reachable[0][0];                // G1 reachable at the initial pose?
//   const Reach reach = world.reach(gripper_pose);      // joints, configuration, tilt
#pragma once

#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spar/geometry/collision.hpp"
#include "spar/geometry/grasps.hpp"
#include "spar/kinematics/robot.hpp"
#include "spar/planner/scenario.hpp"

namespace spar::planner {

// Half-angle about world -z within which the world mating vector must lie.
inline constexpr double kFrictionCone = std::numbers::pi / 4;

struct PositionLabel {
  std::string name;     // "initial" or "P5@left"
  int stable_pose{-1};  // index into the object's stable_poses, -1 if the pose is not one
  // Index into Scenario::places; for the initial pose the place it starts at, else -1.
  int place{-1};
  kinematics::Transform pose{kinematics::Transform::Identity()};  // object frame in the world
  // Index into Scenario::goals of the assembled goal whose held object, assembled into this
  // object, makes it rest here ("J1+peg@left": the pair rests so, the object alone does not;
  // stable_pose is then -1); -1 when the object rests here by itself or starts here.
  int joined_goal{-1};
};

struct ObjectWorld {
  std::vector<geometry::Grasp> grasps;
  std::vector<PositionLabel> positions;      // [0] is the initial pose
  std::vector<std::vector<char>> reachable;  // [grasp][position]
};

// The tables of one goal. An assembled goal fills held, fixed and the three tables; an at goal
// fills held (the object), place and at_place.
struct GoalWorld {
  enum class Kind { kAssembled, kAt };
  Kind kind{Kind::kAssembled};
  int held{0};  // object indices
  int fixed{-1};
  bool initially_true{false};                     // the goal holds in the initial world
  std::vector<char> grasp_leaves_mating_free;     // [held grasp]
  std::vector<char> mating_pose;                  // [fixed position]
  std::vector<char> rests_assembled;              // [fixed position]
  std::vector<std::vector<char>> mate_reachable;  // [held grasp][fixed position]
  int place{-1};                                  // an at goal's place
  std::vector<int> at_place;                      // the object's position labels at it
  // [fixed grasp]: the gripper can still take the fixed object with the held one in it (the open
  // gripper's approach and the closed gripper keep the margin from it). Once the assembly is
  // made, only these grasps move the fixed object.
  std::vector<char> grasp_clears_assembled;
};

// Where every object is at one moment of a plan instance.
struct WorldState {
  std::vector<kinematics::Transform> poses;  // every object's pose in the world
  // The object it is assembled into (it moves with that one), -1 if none.
  std::vector<int> carrier;
  int held{-1};  // the object in the gripper, -1 if none
  // `object` and every object assembled into it, directly or not (what moves when it moves).
  [[nodiscard]] std::vector<int> moving_with(int object) const;
  // Puts `object` at `pose`, carrying what is assembled into it.
  void move(int object, const kinematics::Transform& pose);
};

// The collision check of one step's motions.
struct StepCheck {
  bool clear{true};
  std::string conflict;  // what hit what, when not clear: "the open gripper hits cube"
  // The IK branch the step uses (the first clear one, see the header comment): the joints the
  // report shows and joint-level uncertainty acts at. None when not clear or out of reach.
  std::optional<kinematics::JointSolution> arm{};
  // At the step's configuration (the gripper at T, closed): the distance from the gripper and
  // what it moves to the nearest other object (+inf when there is none), and that object.
  double clearance{0.0};
  int nearest{-1};
};

// A straight line of the gripper from a step's pose T: to T + travel (world), named in messages
// ("approach", "insertion", "retreat").
struct ArmLine {
  Eigen::Vector3d travel{Eigen::Vector3d::Zero()};
  const char* name{""};
};

// The angle between the frame's z axis (a gripper's approach) and world -z.
[[nodiscard]] double tilt_from_down(const kinematics::Transform& pose);

// One IK query: the gripper frame at `gripper_pose` (world).
struct Reach {
  bool reachable{false};  // an in-limit solution exists and the approach axis points down
  double tilt{0.0};       // angle between the gripper z axis and world -z
  // The first in-limit solution in the robot's order (kinematics/robot.hpp: Puma and UR arms by
  // label, lun first; a 7-joint arm's largest limit margin first) whose arm links are all above
  // the table; none when the tilt fails. A step may take a later one (StepCheck::arm).
  std::optional<kinematics::JointSolution> solution;
};

class WorldModel {
 public:
  // Computes every label and table; the movable objects' grasp searches, the box hierarchies of
  // the arm's links and of the objects, and each object's and goal's per-grasp reach and
  // collision tables run on up to `threads` threads (common/parallel.hpp; the model does not
  // depend on it). Throws PlanError if a movable object has no grasp, or if in the initial world
  // two objects meet or one is below the table or floats (naming the objects and their poses'
  // file:line:col).
  explicit WorldModel(Scenario scenario, unsigned threads = 1);

  [[nodiscard]] const Scenario& scenario() const { return scenario_; }
  [[nodiscard]] std::size_t object_count() const { return objects_.size(); }
  [[nodiscard]] const ObjectWorld& object(int index) const { return objects_.at(index); }
  // Throws PlanError naming the known objects.
  [[nodiscard]] int object_index(std::string_view name) const;
  [[nodiscard]] const std::vector<GoalWorld>& goals() const { return goals_; }
  // The goal tables for assembled(held, fixed), or nullptr.
  [[nodiscard]] const GoalWorld* goal(int held, int fixed) const;
  // The gripper spec used for grasps and usability (the scenario's, with the robot's tilt cone).
  [[nodiscard]] const geometry::GripperSpec& gripper() const { return gripper_; }

  [[nodiscard]] Reach reach(const kinematics::Transform& gripper_pose) const;
  // The IK branch that holds the open gripper still at `gripper_pose` among the objects where
  // `state` has them (sense planning's wrist viewpoints): the first in-limit one, in the robot's
  // order, whose links keep the margin from every object (links on the last body exempt, as for
  // steps) and stay above the table, the open gripper there keeping the margin and above the
  // table too; none when no branch is clear or the tilt fails.
  [[nodiscard]] std::optional<kinematics::JointSolution> still_branch(
      const WorldState& state, const kinematics::Transform& gripper_pose) const;

  // Why the goals cannot be reached even with the interactions between steps ignored (each object
  // moved alone, places shared): "goal <goal> (file:line:col): <object>: <what is empty>", naming
  // the first goal, the object and the constraint whose domain is empty; nullopt when that
  // relaxed problem is solvable. Positions reachable by moves: from the initial one, any position
  // a grasp reaches together with the current one (pick up there, put down here).
  [[nodiscard]] std::optional<std::string> relaxed_obstacle() const;
  // The flange pose in the robot's base frame for a gripper pose in the world.
  [[nodiscard]] kinematics::Transform flange_in_base(
      const kinematics::Transform& gripper_pose) const;

  // --- collisions (see the header comment) ---
  using Table = std::vector<std::vector<char>>;
  [[nodiscard]] const geometry::Body& body(int object) const { return bodies_.at(object); }
  [[nodiscard]] double margin() const { return scenario_.collision.margin; }
  [[nodiscard]] WorldState initial_state() const;
  // The grasp or release of `object` with `grasp`, the object at `object_pose` (a pickup: where
  // it is; a putdown: where it goes), every other object where `state` has it.
  // `measure`: also the clearance (a nearest-body query; the verdict alone is cheaper).
  [[nodiscard]] StepCheck check_grasp(const WorldState& state, int object, int grasp,
                                      const kinematics::Transform& object_pose,
                                      bool measure = true) const;
  // The insertion of goal `goal`'s held object with `grasp` into its fixed object at
  // `fixed_pose`.
  [[nodiscard]] StepCheck check_insertion(const WorldState& state, int goal, int grasp,
                                          const kinematics::Transform& fixed_pose,
                                          bool measure = true) const;
  // [grasp][position] of `object`: its grasp or release there hits `other` resting where it
  // starts. Computed on first use, then cached (the cache is shared by copies).
  [[nodiscard]] const Table& initial_conflicts(int object, int other) const;
  // Whether the subassembly `object` belongs to rests on the table as `state` has it (call it
  // after a release): nullopt when it does, or when there is nothing to check (an object alone
  // in the orientation of one of its stable poses rests; a fixed root, or a root unmoved in an
  // initial pose that is no stable pose, is supported otherwise); else why not: "base with part
  // assembled into it does not rest on the table there: its centre of mass lies 0.2121 in outside
  // its footing", or for an object alone in a joined position "base does not rest ...".
  [[nodiscard]] std::optional<std::string> check_rest(const WorldState& state, int object) const;
  // [held grasp][fixed position] of assembled goal `goal`: its insertion hits `other` where it
  // starts.
  [[nodiscard]] const Table& insertion_conflicts(int goal, int other) const;
  // [position][other's position]: `object` resting there and `other` resting there meet or come
  // closer than the margin.
  [[nodiscard]] const Table& placement_conflicts(int object, int other) const;

 private:
  struct Obstacle {
    int object{-1};
    geometry::PlacedBody placed;
  };
  struct Caches;
  // The constructor's steps, in this order: each object's world (its grasps, from the grasp
  // search, its positions and what is reachable), then each goal's tables.
  struct Setting;  // what the steps share (world.cpp)
  void add_object(const ObjectSpec& spec, std::vector<geometry::Grasp> grasps, Setting& setting);
  void add_at_goal(const AtGoal& at);
  void add_assembled_goal(const AssembledGoal& assembled, const Setting& setting);
  // Every object of `state` except those in `except`, as obstacles.
  [[nodiscard]] std::vector<Obstacle> obstacles(const WorldState& state,
                                                const std::vector<int>& except) const;
  void check_initial_world() const;
  // A length in the scenario file's unit: "0.25 in".
  [[nodiscard]] std::string length_text(double metres) const;
  // The IK branch of a step at `gripper_pose`: the first in-limit one in the robot's order whose
  // links clear the table and `obstacles` there and along `lines` (the header comment); when
  // every such branch is blocked, `conflict` names what blocks each. Neither when the tilt
  // fails or no in-limit branch clears the table at T (reach() is this with nothing to hit).
  struct ArmChoice {
    std::optional<kinematics::JointSolution> branch;
    std::optional<std::string> conflict;
  };
  [[nodiscard]] ArmChoice arm_branch(const kinematics::Transform& gripper_pose,
                                     std::span<const ArmLine> lines,
                                     const std::vector<Obstacle>& obstacles) const;
  // The checks behind check_grasp and check_insertion, against `others` (and the parts moving
  // with the handled object); `measure`: also the clearance (the tables need only the verdict).
  [[nodiscard]] StepCheck grasp_check(int object, int grasp, const kinematics::Transform& pose,
                                      const std::vector<Obstacle>& others,
                                      const std::vector<Obstacle>& parts,
                                      bool measure = false) const;
  [[nodiscard]] StepCheck insertion_check(int goal, int grasp,
                                          const kinematics::Transform& fixed_pose,
                                          const std::vector<Obstacle>& others,
                                          const std::vector<Obstacle>& held_parts,
                                          bool measure = false) const;
  // An insertion of goal `goal`'s held object h with grasp `grasp` into f at `fixed_pose`: the
  // objects' names, h's and the gripper's poses at the end, and the motion into f (the mating
  // vector, approach_distance long).
  struct InsertionFrame {
    const std::string& held_name;
    const std::string& fixed_name;
    kinematics::Transform held_pose, gripper_pose;
    Eigen::Vector3d insertion;
  };
  [[nodiscard]] InsertionFrame insertion_frame(int goal, int grasp,
                                               const kinematics::Transform& fixed_pose) const;
  // `body` (gripper frame, the gripper at `gripper_pose`) joined with `parts` (world poses): what
  // moves when the gripper carries an object with what is assembled into it; nullopt without
  // parts (`body` moves alone).
  [[nodiscard]] static std::optional<geometry::Body> carrying(
      const geometry::Body& body, const kinematics::Transform& gripper_pose,
      const std::vector<Obstacle>& parts);
  // What an insertion hits of its fixed object (the gripper, h's parts, h outside its mating
  // faces, the open gripper leaving), or nullopt.
  [[nodiscard]] std::optional<std::string> insertion_pair_conflict(
      int goal, int grasp, const kinematics::Transform& fixed_pose,
      const std::vector<Obstacle>& held_parts) const;
  [[nodiscard]] bool grasp_usable_at(const geometry::Grasp& grasp, const ObjectSpec& object,
                                     const PositionLabel& position) const;

  Scenario scenario_;
  geometry::GripperSpec gripper_;
  std::vector<ObjectWorld> objects_;  // same order as scenario_.objects
  std::vector<GoalWorld> goals_;      // same order as scenario_.goals
  // Collision bodies: each object's mesh; the gripper open, and closed on each object with each
  // grasp (held_[o][g]: the gripper at width W_g joined with o at T_G^-1, in the gripper frame;
  // closed_[o][g]: the same gripper alone); per assembled goal the held and fixed objects' other
  // faces than their mating ones, each triangle pulled in by a micrometre (nullopt when none).
  std::vector<geometry::Body> bodies_;
  std::optional<geometry::Body> open_gripper_;
  std::vector<std::vector<geometry::Body>> held_;
  std::vector<std::vector<geometry::Body>> closed_;  // [o][g]: the gripper closed to W_g alone
  std::vector<std::optional<geometry::Body>> held_rest_, fixed_rest_;  // [goal]
  // [goal][held grasp]: insertion_pair_conflict with nothing assembled into h yet.
  std::vector<std::vector<std::optional<std::string>>> pair_conflict_;
  std::shared_ptr<Caches> caches_;  // memo of the conflict tables, shared by copies
};

}  // namespace spar::planner
