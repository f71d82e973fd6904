// Joint-level uncertainty (issue 23): robot.uncertainty.joints adds one variable δq_i per joint
// and step, propagated through the chain's exact kinematics at the step's IK solution. Checked
// against the numeric physics written here (finger frames and the released object's pose from
// the robot's forward kinematics at q + δq), and end to end: the preconditions of a UR5 plan
// depend on the joints, and blame names them.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/uncertainty/propagation.hpp"
#include "spar/planner/uncertainty/repair.hpp"
#include "spar/symbolic/operations.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

using testing::action_with;

using kinematics::Transform;

const std::string kScenario =
    std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/ur5_joint_uncertainty.yaml";

// The actual gripper at step `index`: G(q + δq) for joints q, the δq drawn into `values` as
// dq<i>_g<index> (every other variable of the step stays 0).
Transform actual_gripper(const WorldModel& world, std::vector<double> q, int index,
                         std::mt19937& random, std::map<std::string, double>& values) {
  const RobotSpec& robot = world.scenario().robot;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double h = robot.joint_uncertainty[i];
    const double dq = std::uniform_real_distribution<double>(-h, h)(random);
    values["dq" + std::to_string(i + 1) + "_g" + std::to_string(index)] = dq;
    q[i] += dq;
  }
  return robot.base * robot.arm.forward(q) * robot.tool;
}

// Pickup condition i (finger i / 2, contact i % 2) as physics: the y of the ideal object's
// contact point (grasp `grasp`, ideal gripper `ideal`) in the frame of the actual finger.
double finger_contact_y(const WorldModel& world, const geometry::Grasp& grasp,
                        const Transform& ideal, const Transform& actual, int i) {
  const double half_opening = world.gripper().max_opening / 2, half_width = grasp.width / 2;
  const Transform finger_frame =
      actual * Eigen::Translation3d(0, i / 2 == 0 ? -half_opening : half_opening, 0);
  const Eigen::Vector3d point =
      ideal * Eigen::Vector3d(0, i % 2 == 0 ? half_width : -half_width, 0);
  return (finger_frame.inverse(Eigen::Isometry) * point).y();
}

// Every variable of the space at 0 except those already in `values`.
std::map<std::string, double> with_zeros(const UncertaintySpace& space,
                                         std::map<std::string, double> values) {
  for (const SpaceVariable& v : space.variables()) values.emplace(v.name, 0.0);
  return values;
}

// The four pickup (or squeeze) `conditions` of step 1 (grasp `grasp`, ideal gripper `ideal`) equal
// the fingers' physics at joints q + δq for 20 random δq (seeded by `seed`); returns how far they
// are at most from the physics at `other` + δq.
double expect_fingers_at(const WorldModel& world, const std::vector<Precondition>& conditions,
                         const UncertaintySpace& space, const geometry::Grasp& grasp,
                         const Transform& ideal, const std::vector<double>& q,
                         const std::vector<double>& other, unsigned seed) {
  EXPECT_EQ(conditions.size(), 4u);
  std::mt19937 random(seed);
  double off_other = 0.0;
  for (int sample = 0; sample < 20; ++sample) {
    std::map<std::string, double> values;
    std::mt19937 same = random;
    const Transform actual = actual_gripper(world, q, 1, random, values);
    std::map<std::string, double> unused;
    const Transform at_other = actual_gripper(world, other, 1, same, unused);
    values = with_zeros(space, values);
    for (std::size_t i = 0; i < 4 && i < conditions.size(); ++i) {
      const double value = symbolic::evaluate(conditions[i].inequality.expression, values);
      const int c = static_cast<int>(i);
      EXPECT_NEAR(value, finger_contact_y(world, grasp, ideal, actual, c), 1e-12);
      off_other =
          std::max(off_other, std::abs(value - finger_contact_y(world, grasp, ideal, at_other, c)));
    }
  }
  return off_other;
}

class JointUncertainty : public ::testing::Test {
 protected:
  JointUncertainty() : world_(load_scenario(kScenario)) {
    peg_ = world_.object_index("peg");
    // The first grasp of the peg the UR5 reaches where it lies.
    const Transform& pose = world_.scenario().objects[peg_].initial_pose;
    for (std::size_t g = 0; g < world_.object(peg_).grasps.size(); ++g)
      if (world_.reach(pose * world_.object(peg_).grasps[g].gripper_in_object).reachable) {
        grasp_ = static_cast<int>(g);
        break;
      }
  }
  WorldModel world_;
  int peg_{0};
  int grasp_{-1};
};

TEST_F(JointUncertainty, LoadsOneHalfWidthPerJointInRadians) {
  const std::vector<double>& joints = world_.scenario().robot.joint_uncertainty;
  ASSERT_EQ(joints.size(), 6u);
  for (const double h : joints) EXPECT_NEAR(h, 0.01 * std::numbers::pi / 180, 1e-15);
}

TEST(JointUncertaintyInput, RefusesAWrongCount) {
  EXPECT_THROW_MESSAGE(
      (void)parse_scenario("robot: {model: ur5, uncertainty: {joints: [0.1, 0.1]}}\n"
                           "objects: {peg: {builtin: peg, pose: {stable: P7, at: [14, 12]}}}\n",
                           "cell.yaml", "."),
      "cell.yaml:1:43: robot.uncertainty.joints: give one half-width per moving joint of ur5 (6)");
}

// The pickup's finger conditions at random joint errors equal the physics: the contact points of
// the ideal object in the frames of the actual fingers G(q + δq) trans(0, ∓W_m/2, 0), q the
// step's IK branch (Phase2Step::arm, the one its collisions were checked at): reach()'s first one,
// or the next in-limit branch, whose joints err differently.
TEST_F(JointUncertainty, PickupConditionsAreTheFingersAtTheActualJoints) {
  ASSERT_GE(grasp_, 0);
  const Domain& domain = builtin_domain();
  const Transform& object_pose = world_.scenario().objects[peg_].initial_pose;
  const geometry::Grasp& grasp = world_.object(peg_).grasps[grasp_];
  const Transform ideal = object_pose * grasp.gripper_in_object;
  const kinematics::JointSolution first = world_.reach(ideal).solution.value();
  std::optional<kinematics::JointSolution> other;
  for (kinematics::JointSolution& s :
       world_.scenario().robot.arm.inverse(world_.flange_in_base(ideal)))
    if (s.within_limits && s.configuration != first.configuration && !other) other = std::move(s);
  ASSERT_TRUE(other);
  for (const bool taken_other : {false, true}) {
    const kinematics::JointSolution& branch = taken_other ? *other : first;
    SCOPED_TRACE(branch.configuration);
    const Phase2Step step{.action = action_with(domain, Effect::kGrasp),
                          .effect = Effect::kGrasp,
                          .object = peg_,
                          .grasp = grasp_,
                          .object_pose = object_pose,
                          .arm = branch};
    symbolic::ExprPool pool;
    Propagation propagation(world_, domain, pool);
    const std::vector<Precondition> pickup = propagation.step(step, 1);
    ASSERT_EQ(pickup.size(), 4u);
    const double off_first =
        expect_fingers_at(world_, pickup, propagation.space(), grasp, ideal, branch.q, first.q, 23);
    if (taken_other) {
      EXPECT_GT(off_first, 1e-7);  // the branch matters
    }
  }
}

// Picked up without error and put down with joint errors, the object lies where the actual
// gripper G(q + δq) leaves it: M_ideal ΔT T_G^-1, its origin displaced by the table state's d.
TEST_F(JointUncertainty, ReleaseLeavesTheObjectWhereTheActualJointsPutIt) {
  ASSERT_GE(grasp_, 0);
  const Domain& domain = builtin_domain();
  const Transform& object_pose = world_.scenario().objects[peg_].initial_pose;
  const Transform there = Eigen::Translation3d(0.02, -0.03, 0) * object_pose;
  const geometry::Grasp& grasp = world_.object(peg_).grasps[grasp_];
  ASSERT_TRUE(world_.reach(there * grasp.gripper_in_object).reachable);
  const std::optional<kinematics::JointSolution> at_there =
      world_.reach(there * grasp.gripper_in_object).solution;
  ASSERT_TRUE(at_there);
  Phase2Step pickup{.action = action_with(domain, Effect::kGrasp),
                    .effect = Effect::kGrasp,
                    .object = peg_,
                    .grasp = grasp_,
                    .object_pose = object_pose,
                    .arm = world_.reach(object_pose * grasp.gripper_in_object).solution};
  Phase2Step putdown = pickup;
  putdown.action = action_with(domain, Effect::kRelease);
  putdown.effect = Effect::kRelease;
  putdown.object_pose = there;
  putdown.arm = at_there;
  symbolic::ExprPool pool;
  Propagation propagation(world_, domain, pool);
  (void)propagation.step(pickup, 1);
  (void)propagation.step(putdown, 2);
  const TableState& state = propagation.on_table(peg_).value();
  std::mt19937 random(2323);
  for (int sample = 0; sample < 20; ++sample) {
    std::map<std::string, double> values;
    const Transform gripper = actual_gripper(world_, at_there->q, 2, random, values);
    values = with_zeros(propagation.space(), values);
    const Transform actual = gripper * grasp.gripper_in_object.inverse(Eigen::Isometry);
    const Eigen::Vector3d d = actual.translation() - there.translation();
    EXPECT_NEAR(symbolic::evaluate(state.error.dx, values), d.x(), 1e-12);
    EXPECT_NEAR(symbolic::evaluate(state.error.dy, values), d.y(), 1e-12);
    EXPECT_NEAR(symbolic::evaluate(state.error.dz, values), d.z(), 1e-12);
  }
}

// A step without a collision-checked branch has no configuration for its joint errors: refused,
// never bounded at some other branch.
TEST_F(JointUncertainty, RefusesAStepWithoutItsArmBranch) {
  ASSERT_GE(grasp_, 0);
  const Domain& domain = builtin_domain();
  const Phase2Step step{.action = action_with(domain, Effect::kGrasp),
                        .effect = Effect::kGrasp,
                        .object = peg_,
                        .grasp = grasp_,
                        .object_pose = world_.scenario().objects[peg_].initial_pose};
  symbolic::ExprPool pool;
  Propagation propagation(world_, domain, pool);
  EXPECT_THROW_MESSAGE((void)propagation.step(step, 3),
                       "step 3: the step has no collision-checked arm configuration, so its joint "
                       "errors have nowhere to act");
}

// The joint-uncertainty scenario with a 1 in cube far from the others, and a squeeze of the peg
// where it starts: the cube put (by an earlier putdown) on the first IK branch of the squeeze's
// grasp, so that the squeeze's grasp check takes another branch.
class JointUncertaintySqueeze : public ::testing::Test {
 protected:
  static WorldModel with_cube() {
    std::ifstream file(kScenario);
    std::stringstream text;
    text << file.rdbuf();
    std::string yaml = text.str();
    const std::string objects = "objects:\n";
    yaml.insert(yaml.find(objects) + objects.size(),
                "  cube:\n    builtin: cube\n    pose: {stable: P5, at: [-20, -20]}\n");
    return WorldModel(parse_scenario(yaml, kScenario, std::string(SPAR_SOURCE_DIR) + "/examples"));
  }

  // The phase 2 steps: the cube picked up and put down at `cube_pose`, then the peg's pickup
  // with grasp `pickup_grasp` where it starts (the step the squeezes go before).
  [[nodiscard]] std::vector<Phase2Step> steps(const Transform& cube_pose) const {
    const Transform& peg_pose = world_.scenario().objects[peg_].initial_pose;
    const Phase2Step take{.action = action_with(domain_, Effect::kGrasp),
                          .effect = Effect::kGrasp,
                          .object = cube_,
                          .grasp = 0,
                          .position = 0,
                          .object_pose = world_.scenario().objects[cube_].initial_pose};
    Phase2Step put = take;
    put.action = action_with(domain_, Effect::kRelease);
    put.effect = Effect::kRelease;
    put.object_pose = cube_pose;
    const Phase2Step pickup{
        .action = action_with(domain_, Effect::kGrasp),
        .effect = Effect::kGrasp,
        .object = peg_,
        .grasp = pickup_grasp_,
        .position = 0,
        .object_pose = peg_pose,
        .arm = world_.reach(peg_pose * world_.object(peg_).grasps[pickup_grasp_].gripper_in_object)
                   .solution};
    return {take, put, pickup};
  }

  // Calls `visit(grasp, first branch, cube pose)` for each squeeze grasp reachable where the peg
  // starts and each cube centred at a frame origin of that grasp's first branch's moving links.
  void each_cube_on_first_branch(const std::function<void(int, const kinematics::JointSolution&,
                                                          const Transform&)>& visit) const {
    const RobotSpec& robot = world_.scenario().robot;
    const Transform& peg_pose = world_.scenario().objects[peg_].initial_pose;
    const double half = 0.0254 / 2;
    for (int g = 0; g < static_cast<int>(world_.object(peg_).grasps.size()); ++g) {
      if (g == pickup_grasp_ || !world_.object(peg_).reachable[g][0]) continue;
      const std::optional<kinematics::JointSolution> first =
          world_.reach(peg_pose * world_.object(peg_).grasps[g].gripper_in_object).solution;
      if (!first) continue;
      for (const Transform& link : robot.arm.link_poses(first->q))
        visit(g, *first,
              Eigen::Translation3d((robot.base * link).translation() -
                                   Eigen::Vector3d::Constant(half)) *
                  Transform::Identity());
    }
  }

  // The candidate squeeze with `grasp`, or nullptr.
  static const RepairCandidate* squeeze_with(const std::vector<RepairCandidate>& candidates,
                                             int grasp) {
    for (const RepairCandidate& c : candidates)
      if (c.effect == Effect::kReduce && c.grasp == grasp) return &c;
    return nullptr;
  }

  const Domain& domain_ = builtin_domain();
  WorldModel world_ = with_cube();
  int peg_ = world_.object_index("peg"), cube_ = world_.object_index("cube");
  int pickup_grasp_ = [this] {
    for (std::size_t g = 0; g < world_.object(peg_).grasps.size(); ++g)
      if (world_.object(peg_).reachable[g][0]) return static_cast<int>(g);
    return -1;
  }();
};

// The squeeze acts at the branch its grasp check takes, not at reach()'s first one: its four
// conditions at random joint errors are the fingers' physics at that branch's q + δq (and not at
// the first branch's, which hits the cube).
TEST_F(JointUncertaintySqueeze, BoundsTheSqueezeAtItsCollisionCheckedBranch) {
  ASSERT_GE(pickup_grasp_, 0);
  int squeezed = 0;
  each_cube_on_first_branch([&](int g, const kinematics::JointSolution& first,
                                const Transform& cube_pose) {
    if (squeezed > 0) return;
    // The squeeze's grasp check with the cube where the putdown leaves it takes another
    // branch than the first (the first hits the cube).
    WorldState state = world_.initial_state();
    state.poses[cube_] = cube_pose;
    const Transform& peg_pose = world_.scenario().objects[peg_].initial_pose;
    const StepCheck check = world_.check_grasp(state, peg_, g, peg_pose, false);
    if (!check.clear || check.arm->configuration == first.configuration) return;
    ++squeezed;
    const std::vector<Phase2Step> plan = steps(cube_pose);
    const RepairKinds squeezing{.squeeze = action_with(domain_, Effect::kReduce),
                                .squeeze_grasps = 100};
    const std::vector<RepairCandidate> candidates = repair_candidates(world_, plan, 2, squeezing);
    const RepairCandidate* squeeze = squeeze_with(candidates, g);
    ASSERT_NE(squeeze, nullptr);
    const unsigned set = 1u << (squeeze - candidates.data());
    const SplicedPlan spliced = splice(plan, 2, candidates, set, squeezing, 0);
    const Phase2Step& step = spliced.steps.at(spliced.inserted.at(0));
    ASSERT_TRUE(step.arm);
    EXPECT_EQ(step.arm->configuration, check.arm->configuration);
    // Its conditions, propagated from the initial world (the peg where the squeeze finds it).
    symbolic::ExprPool pool;
    Propagation propagation(world_, domain_, pool);
    const std::vector<Precondition> conditions = propagation.step(step, 1);
    ASSERT_EQ(conditions.size(), 4u);
    const geometry::Grasp& grasp = world_.object(peg_).grasps[g];
    const Transform ideal = step.object_pose * grasp.gripper_in_object;
    EXPECT_GT(expect_fingers_at(world_, conditions, propagation.space(), grasp, ideal, check.arm->q,
                                first.q, 2324),
              1e-7);  // the branch matters
  });
  EXPECT_GT(squeezed, 0) << "no cube on a first branch leaves the squeeze another branch";
}

// A squeeze whose every branch (or gripper) hits the cube is not a candidate: it is never kept
// with some other configuration standing in for its arm.
TEST_F(JointUncertaintySqueeze, NoSqueezeWhereItsGraspCheckFails) {
  ASSERT_GE(pickup_grasp_, 0);
  int refused = 0;
  each_cube_on_first_branch([&](int g, const kinematics::JointSolution&, const Transform& pose) {
    WorldState state = world_.initial_state();
    state.poses[cube_] = pose;
    const Transform& peg_pose = world_.scenario().objects[peg_].initial_pose;
    if (world_.check_grasp(state, peg_, g, peg_pose, false).clear) return;
    ++refused;
    const RepairKinds squeezing{.squeeze = action_with(domain_, Effect::kReduce),
                                .squeeze_grasps = 100};
    EXPECT_EQ(squeeze_with(repair_candidates(world_, steps(pose), 2, squeezing), g), nullptr);
  });
  EXPECT_GT(refused, 0);
}

// Planning options for the end-to-end tests: one instance, no probability or reverse analysis,
// `report` bounds as quick as deciding's (the chosen instance's tight bounds cost tens of seconds
// on the peg-in-block plan's joint expressions: docs/scenario.md).
PlanOptions quick_options(bool blame, std::size_t samples) {
  PlanOptions options;
  options.probability.reset();
  options.max_instances = 1;
  options.analysis.samples = samples;
  options.analysis.reverse = false;
  options.analysis.blame = blame;
  options.analysis.report = options.analysis.quick;
  return options;
}

bool of_a_joint(const InstanceAnalysis& analysis, VariableId id) {
  return analysis.variables[id.index].provenance.source == UncertaintySource::kJoint;
}

// Moving the peg to a place (pickup, putdown): every precondition depends on joint variables
// (named dq<i>_g<step>), and blame names a joint.
TEST(JointUncertaintyPlan, BlameNamesTheJoints) {
  Scenario scenario = load_scenario(kScenario);
  scenario.goals = parse_scenario(
                       "robot: {model: ur5}\n"
                       "objects: {peg: {builtin: peg, pose: {stable: P7, at: [14, 12]}}}\n"
                       "places: [{name: left, at: [14, -12], yaw: 0}]\n"
                       "goals: [{at: {object: peg, place: left}}]\n",
                       "goal.yaml", ".")
                       .goals;
  const PlanResult result = plan(std::move(scenario), builtin_domain(), quick_options(true, 0));
  ASSERT_TRUE(result.planned());
  const InstanceAnalysis* analysis = result.chosen_analysis();
  ASSERT_NE(analysis, nullptr);
  for (const SpaceVariable& v : analysis->variables)
    if (v.provenance.source == UncertaintySource::kJoint) {
      EXPECT_EQ(v.name.rfind("dq", 0), 0u);
    }
  int blamed_joints = 0;
  for (const AnalysedStep& step : analysis->steps)
    for (const PreconditionResult& p : step.preconditions) {
      EXPECT_TRUE(std::ranges::any_of(p.variables, [&](VariableId id) {
        return of_a_joint(*analysis, id);
      })) << step.action;
      for (const auto& entry : p.blame) blamed_joints += of_a_joint(*analysis, entry.variable);
    }
  EXPECT_GT(blamed_joints, 0);
}

// The whole peg-in-block task: every satisfied precondition holds at random points of its box,
// the insertion's included: their text passes the printer's 1e7 tree nodes and is left empty, but
// their verdict is the bound of the same expression as a DAG (fail-safe: an expression that cannot
// be bounded is undecided, never satisfied).
TEST(JointUncertaintyPlan, SatisfiedPreconditionsHoldAtRandomJointErrors) {
  const PlanResult result =
      plan(load_scenario(kScenario), builtin_domain(), quick_options(false, 200));
  ASSERT_TRUE(result.planned());
  const InstanceAnalysis* analysis = result.chosen_analysis();
  ASSERT_NE(analysis, nullptr);
  int satisfied = 0, unprinted = 0;
  for (const AnalysedStep& step : analysis->steps)
    for (const PreconditionResult& p : step.preconditions) {
      if (p.verdict != bounds::Verdict::kSatisfied) continue;
      ++satisfied;
      unprinted += printed_expression(p).empty();
      EXPECT_EQ(p.monte_carlo_violation, 0.0) << step.action;
    }
  EXPECT_GT(satisfied, 0);
  EXPECT_GT(unprinted, 0);  // the case this test is about
}

}  // namespace
}  // namespace spar::planner
