// Joint-level uncertainty (issue 23): robot.uncertainty.joints adds one variable δq_i per joint
// and step, propagated through the chain's exact kinematics at the step's IK solution. Checked
// against the numeric physics written here (finger frames and the released object's pose from
// the robot's forward kinematics at q + δq), and end to end: the preconditions of a UR5 plan
// depend on the joints, and blame names them.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/uncertainty/propagation.hpp"
#include "spar/symbolic/operations.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::planner {
namespace {

using kinematics::Transform;

const std::string kScenario =
    std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/ur5_joint_uncertainty.yaml";

int action_with(const Domain& domain, Effect effect) {
  for (std::size_t a = 0; a < domain.actions.size(); ++a)
    if (domain.actions[a].effect == effect) return static_cast<int>(a);
  ADD_FAILURE() << "the domain has no action with that effect";
  return -1;
}

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

// Every variable of the space at 0 except those already in `values`.
std::map<std::string, double> with_zeros(const UncertaintySpace& space,
                                         std::map<std::string, double> values) {
  for (const SpaceVariable& v : space.variables()) values.emplace(v.name, 0.0);
  return values;
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
// step's IK branch: reach()'s first one by default, or the one its collisions were checked at
// (Phase2Step::arm, here the next in-limit branch), whose joints err differently.
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
                          .arm = taken_other ? other : std::nullopt};
    symbolic::ExprPool pool;
    Propagation propagation(world_, domain, pool);
    const std::vector<Precondition> pickup = propagation.step(step, 1);
    ASSERT_EQ(pickup.size(), 4u);
    std::mt19937 random(23);
    const double half_opening = world_.gripper().max_opening / 2, half_width = grasp.width / 2;
    double off_first = 0.0;  // how far the conditions are from the first branch's physics
    for (int sample = 0; sample < 20; ++sample) {
      std::map<std::string, double> values;
      std::mt19937 same = random;
      const Transform gripper = actual_gripper(world_, branch.q, 1, random, values);
      std::map<std::string, double> unused;
      const Transform at_first = actual_gripper(world_, first.q, 1, same, unused);
      values = with_zeros(propagation.space(), values);
      for (int finger = 0; finger < 2; ++finger)
        for (int contact = 0; contact < 2; ++contact) {
          const auto finger_y = [&](const Transform& actual) {
            const Transform finger_frame =
                actual * Eigen::Translation3d(0, finger == 0 ? -half_opening : half_opening, 0);
            const Eigen::Vector3d point =
                ideal * Eigen::Vector3d(0, contact == 0 ? half_width : -half_width, 0);
            return (finger_frame.inverse(Eigen::Isometry) * point).y();
          };
          const double value =
              symbolic::evaluate(pickup[finger * 2 + contact].inequality.expression, values);
          EXPECT_NEAR(value, finger_y(gripper), 1e-12);
          off_first = std::max(off_first, std::abs(value - finger_y(at_first)));
        }
    }
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
  Phase2Step pickup{.action = action_with(domain, Effect::kGrasp),
                    .effect = Effect::kGrasp,
                    .object = peg_,
                    .grasp = grasp_,
                    .object_pose = object_pose};
  Phase2Step putdown = pickup;
  putdown.action = action_with(domain, Effect::kRelease);
  putdown.effect = Effect::kRelease;
  putdown.object_pose = there;
  symbolic::ExprPool pool;
  Propagation propagation(world_, domain, pool);
  (void)propagation.step(pickup, 1);
  (void)propagation.step(putdown, 2);
  const TableState& state = propagation.on_table(peg_).value();
  std::mt19937 random(2323);
  for (int sample = 0; sample < 20; ++sample) {
    std::map<std::string, double> values;
    const Transform gripper =
        actual_gripper(world_, world_.reach(there * grasp.gripper_in_object).solution.value().q, 2,
                       random, values);
    values = with_zeros(propagation.space(), values);
    const Transform actual = gripper * grasp.gripper_in_object.inverse(Eigen::Isometry);
    const Eigen::Vector3d d = actual.translation() - there.translation();
    EXPECT_NEAR(symbolic::evaluate(state.error.dx, values), d.x(), 1e-12);
    EXPECT_NEAR(symbolic::evaluate(state.error.dy, values), d.y(), 1e-12);
    EXPECT_NEAR(symbolic::evaluate(state.error.dz, values), d.z(), 1e-12);
  }
}

// Planning options for the end-to-end tests: one instance, no probability or reverse analysis,
// `report` bounds as quick as deciding's (the chosen instance's tight bounds and blame cost minutes
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
      unprinted += p.expression.empty();
      EXPECT_EQ(p.monte_carlo_violation, 0.0) << step.action;
    }
  EXPECT_GT(satisfied, 0);
  EXPECT_GT(unprinted, 0);  // the case this test is about
}

}  // namespace
}  // namespace spar::planner
