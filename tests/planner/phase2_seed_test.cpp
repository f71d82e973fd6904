// The seed's worked example through phase 2 (seed 001, "Constraints at the Uncertainty-Reduction
// Level", Table 2, figures 11 and 12): the peg picked up across its 3 in base with the 4 in
// opening (tests/planner/data/phase2_peg_pickup.yaml). Under Table 2 all four pickup inequalities
// hold; with the peg's position uncertainty wider than the 0.5 in to spare, the two inequalities
// of the near sides fail and a range-scan before the pickup makes them hold again; with a sensor
// coarser than the peg's own uncertainty nothing helps, and the pickup gets its verification
// action, the recovery plans and one error.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/vision.hpp"
#include "spar/sensing/camera.hpp"
#include "spar/sensing/model_features.hpp"
#include "spar/symbolic/operations.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

using testing::peg_pickup;

using bounds::Verdict;
constexpr double kInch = units::kInch;

using testing::quick_options;

ObjectSpec& peg_of(Scenario& scenario) {
  auto found = std::find_if(scenario.objects.begin(), scenario.objects.end(),
                            [](const ObjectSpec& o) { return o.name == "peg"; });
  return *found;
}

// The peg's displacement uncertainty widened past the grasp's 0.5 in to spare on each side: along
// any finger axis the worst displacement is at least 0.7 in.
Scenario widened() {
  Scenario scenario = peg_pickup();
  ObjectSpec& peg = peg_of(scenario);
  peg.uncertainty.dx = peg.uncertainty.dy = peg.uncertainty.dz = 0.7 * kInch;
  return scenario;
}

std::vector<std::string> actions(const InstanceAnalysis& analysis) {
  std::vector<std::string> out;
  for (const AnalysedStep& step : analysis.steps) out.push_back(step.action);
  return out;
}

int failing(const std::vector<Verdict>& verdicts) {
  return static_cast<int>(std::count_if(verdicts.begin(), verdicts.end(),
                                        [](Verdict v) { return v != Verdict::kSatisfied; }));
}

TEST(Phase2SeedExample, Table2PickupSatisfiesAllFourInequalities) {
  const PlanResult result = plan(peg_pickup(), builtin_domain(), quick_options(2));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const InstanceAnalysis& chosen = *result.chosen_analysis();
  EXPECT_EQ(chosen.errors, 0);
  EXPECT_TRUE(chosen.repairs.empty());
  EXPECT_EQ(actions(chosen), (std::vector<std::string>{"pickup", "assemble"}));
  const AnalysedStep& pickup = chosen.steps.front();
  // The seed's geometry: W_g = 3 in, W_m = 4 in.
  const double w_g = result.world.object(pickup.step.object).grasps[pickup.step.grasp].width;
  EXPECT_NEAR(w_g, 3 * kInch, 1e-9);
  EXPECT_NEAR(result.world.gripper().max_opening, 4 * kInch, 1e-12);
  const std::vector<std::string> names = {"0 < [0,1,0,0] P1^-1 C1", "0 < [0,1,0,0] P1^-1 C2",
                                          "0 > [0,1,0,0] P2^-1 C1", "0 > [0,1,0,0] P2^-1 C2"};
  // Nominal values: a contact's offset from a finger, (W_m ± W_g) / 2 with the finger's sign.
  const std::vector<double> nominal = {3.5 * kInch, 0.5 * kInch, -0.5 * kInch, -3.5 * kInch};
  ASSERT_EQ(pickup.preconditions.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const PreconditionResult& p = pickup.preconditions[i];
    SCOPED_TRACE(p.inequality.name);
    EXPECT_EQ(p.kind, Builder::kPickup);
    EXPECT_EQ(p.inequality.name, names[i]);
    EXPECT_EQ(p.verdict, Verdict::kSatisfied);
    std::map<std::string, double> zero;
    for (const VariableId v : p.variables) zero[chosen.variables[v.index].name] = 0.0;
    const double at_nominal = symbolic::evaluate(p.inequality.expression, zero);
    EXPECT_NEAR(at_nominal, nominal[i], 1e-12);
    EXPECT_LE(p.bound.lo, at_nominal);
    EXPECT_GE(p.bound.hi, at_nominal);
    // The margin left is less than the nominal: Table 2's uncertainty is real, not ignored.
    if (i < 2) {
      EXPECT_GT(p.bound.lo, 0.0);
      EXPECT_LT(p.bound.lo, at_nominal - 0.1 * kInch);
    } else {
      EXPECT_LT(p.bound.hi, 0.0);
      EXPECT_GT(p.bound.hi, at_nominal + 0.1 * kInch);
    }
    // The variables: the peg's initial error and the arm's at this step, except the arm's dz
    // (along the approach, it moves no finger across the peg).
    std::string components;
    for (const VariableId id : p.variables) {
      ASSERT_LT(id.index, chosen.variables.size());
      const SpaceVariable* v = &chosen.variables[id.index];
      const std::string& name = v->name;
      if (v->provenance.source == UncertaintySource::kManipulator) {
        EXPECT_EQ(v->provenance.step, 1) << name;
        EXPECT_NE(v->component, PoseComponent::kDz) << name;
      } else {
        EXPECT_EQ(v->provenance.source, UncertaintySource::kInitial) << name;
        EXPECT_EQ(v->provenance.object, pickup.step.object) << name;
      }
      components += std::string(to_string(v->component)) + " ";
    }
    // Both dx, dy and dtheta; only the object's dz.
    for (const char* component : {"dx ", "dy ", "dtheta "}) {
      std::size_t count = 0;
      for (std::size_t at = components.find(component); at != std::string::npos;
           at = components.find(component, at + 1))
        count += at == 0 || components[at - 1] == ' ';
      EXPECT_EQ(count, 2u) << component << " in " << components;
    }
    EXPECT_EQ(p.variables.size(), 7u) << components;
  }
}

TEST(Phase2SeedExample, WidenedUncertaintyFailsTwoAndARangeScanRepairsThem) {
  const PlanResult result = plan(widened(), builtin_domain(), quick_options(2));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const InstanceAnalysis& chosen = *result.chosen_analysis();
  EXPECT_EQ(chosen.errors, 0);
  EXPECT_EQ(actions(chosen), (std::vector<std::string>{"range-scan", "pickup", "assemble"}));
  const AnalysedStep& scan = chosen.steps[0];
  EXPECT_TRUE(scan.inserted);
  EXPECT_EQ(scan.step.effect, Effect::kSense);
  EXPECT_EQ(result.world.scenario().objects[scan.step.object].name, "peg");
  EXPECT_EQ(scan.step.instance_step, -1);
  EXPECT_FALSE(chosen.steps[1].inserted);
  EXPECT_EQ(chosen.steps[1].step.instance_step, 0);

  ASSERT_EQ(chosen.repairs.size(), 1u);
  const RepairAttempt& attempt = chosen.repairs.front();
  EXPECT_EQ(attempt.action, "range-scan");
  EXPECT_EQ(result.world.scenario().objects[attempt.object].name, "peg");
  EXPECT_EQ(attempt.for_instance_step, 0);
  EXPECT_TRUE(attempt.helped);
  ASSERT_EQ(attempt.before.size(), 4u);
  ASSERT_EQ(attempt.after.size(), 4u);
  // The two inequalities of the near sides (finger 1 against contact 2, finger 2 against contact
  // 1, 0.5 in apart nominally) fail before and hold after; the far ones hold throughout.
  EXPECT_EQ(failing(attempt.verdicts_before), 2);
  EXPECT_EQ(attempt.verdicts_before[1], Verdict::kViolated);
  EXPECT_EQ(attempt.verdicts_before[2], Verdict::kViolated);
  EXPECT_EQ(failing(attempt.verdicts_after), 0);
  EXPECT_LT(attempt.before[1].lo, 0.0);
  EXPECT_GT(attempt.after[1].lo, 0.0);
  EXPECT_GT(attempt.before[2].hi, 0.0);
  EXPECT_LT(attempt.after[2].hi, 0.0);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_LT(attempt.after[i].hi - attempt.after[i].lo,
              attempt.before[i].hi - attempt.before[i].lo)
        << "precondition " << i << " is not narrower after the scan";

  // The pickup is decided over the scan's residual, not the peg's initial error.
  for (const PreconditionResult& p : chosen.steps[1].preconditions) {
    EXPECT_EQ(p.verdict, Verdict::kSatisfied) << p.inequality.name;
    int sensed = 0;
    for (const VariableId id : p.variables) {
      const Provenance& from = chosen.variables.at(id.index).provenance;
      EXPECT_NE(from.source, UncertaintySource::kInitial) << chosen.variables[id.index].name;
      sensed += from.source == UncertaintySource::kSensor && from.step == 1;
    }
    EXPECT_EQ(sensed, 4) << p.inequality.name;
  }
}

TEST(Phase2SeedExample, WithoutRepairTheWidenedPickupIsAnError) {
  PlanOptions options = quick_options(1);
  options.analysis.repair = false;
  const PlanResult result = plan(widened(), builtin_domain(), options);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const InstanceAnalysis& chosen = *result.chosen_analysis();
  EXPECT_EQ(chosen.errors, 1);
  EXPECT_TRUE(chosen.repairs.empty());
  EXPECT_EQ(actions(chosen), (std::vector<std::string>{"pickup", "assemble"}));
  EXPECT_TRUE(chosen.steps[0].failed);
}

// Without a sensor, a squeeze across another grasp of the peg (more room between the fingers than
// the pickup's) re-centres it and removes its rotation error, and the pickup is proved.
TEST(Phase2SeedExample, WithoutASensorASqueezeWithAnotherGraspRepairsThePickup) {
  Scenario scenario = peg_pickup();
  scenario.range_scan.reset();
  ObjectSpec& peg = peg_of(scenario);
  peg.uncertainty.dx = peg.uncertainty.dy = 0.5 * kInch;
  const PlanResult result = plan(scenario, builtin_domain(), quick_options(1));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const InstanceAnalysis& chosen = *result.chosen_analysis();
  EXPECT_EQ(chosen.errors, 0);
  ASSERT_EQ(actions(chosen), (std::vector<std::string>{"squeeze", "pickup", "assemble"}));
  EXPECT_TRUE(chosen.steps[0].inserted);
  EXPECT_NE(chosen.steps[0].step.grasp, chosen.steps[1].step.grasp);
  for (const AnalysedStep& step : chosen.steps)
    for (const PreconditionResult& p : step.preconditions)
      EXPECT_EQ(p.verdict, Verdict::kSatisfied) << step.action << ": " << p.inequality.name;
  ASSERT_FALSE(chosen.repairs.empty());
  EXPECT_TRUE(chosen.repairs.back().helped);
  EXPECT_EQ(chosen.repairs.back().action, "squeeze");
}

TEST(Phase2SeedExample, CoarseSensorGivesVerificationRecoveryAndOneError) {
  Scenario scenario = widened();
  // A residual wider than the peg's own uncertainty: a scan can only make things worse.
  scenario.range_scan = RangeScanSensor{{1.0 * kInch, 1.0 * kInch, 1.0 * kInch, 0.2}};
  const PlanResult result = plan(scenario, builtin_domain(), quick_options(2));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  // No instance gets rid of the error, so every one is examined and the first is kept.
  ASSERT_EQ(result.examined.size(), result.instances.instances.size());
  EXPECT_EQ(result.chosen_index, result.examined.front().instance);
  const InstanceAnalysis& chosen = *result.chosen_analysis();
  EXPECT_EQ(chosen.errors, 1);
  EXPECT_EQ(actions(chosen), (std::vector<std::string>{"pickup", "assemble"}));

  // Searched and dropped: the scan (wider after) and squeezes with the peg's other reachable
  // grasps (with the pickup's own grasp a squeeze's preconditions would be the failing pickup's
  // four); no set gets the pickup proved, so nothing is inserted and the drops are counted.
  EXPECT_TRUE(chosen.repairs.empty());
  ASSERT_EQ(chosen.repair_searches.size(), 1u);
  const RepairSearch& search = chosen.repair_searches.front();
  EXPECT_EQ(search.for_instance_step, 0);
  EXPECT_EQ(search.kept, 0);
  EXPECT_FALSE(search.holds);
  EXPECT_EQ(search.dropped.at("range-scan"), 1);
  EXPECT_GE(search.dropped.at("squeeze"), 1);
  EXPECT_EQ(search.candidates, search.dropped.at("range-scan") + search.dropped.at("squeeze"));
  EXPECT_GE(search.sets_tried, search.candidates);

  const AnalysedStep& pickup = chosen.steps[0];
  EXPECT_TRUE(pickup.failed);
  EXPECT_FALSE(chosen.steps[1].failed);
  EXPECT_TRUE(chosen.steps[1].verification.empty());
  // Figure 11: check the gripper's opening after the grasp; figure 12: the recovery per outcome.
  ASSERT_EQ(pickup.verification.size(), 1u);
  const VerificationPlan& check = pickup.verification.front();
  EXPECT_EQ(check.name, "grasp_width");
  EXPECT_NE(check.sense.find("peg"), std::string::npos) << check.sense;
  EXPECT_NE(check.expect.find("3 in"), std::string::npos) << check.expect;
  std::vector<std::string> recoveries;
  for (const VerificationPlan::Outcome& outcome : check.outcomes) {
    recoveries.push_back(outcome.recovery);
    EXPECT_FALSE(outcome.error.empty());
    EXPECT_FALSE(outcome.recovery_steps.empty()) << outcome.recovery;
    EXPECT_EQ(outcome.when.find('{'), std::string::npos) << "uninstantiated: " << outcome.when;
    for (const std::string& text : outcome.recovery_steps)
      EXPECT_EQ(text.find('{'), std::string::npos) << "uninstantiated: " << text;
  }
  for (const std::string& text : {check.sense, check.expect})
    EXPECT_EQ(text.find('{'), std::string::npos) << "uninstantiated: " << text;
  EXPECT_EQ(recoveries,
            (std::vector<std::string>{"grope", "retry_toward_contact", "summon_operator"}));
}

// Issue 27: with cameras, the failed pickup's verification names what PSEIKI must see to accept:
// the fixed camera that sees the peg (not the one looking away, though it comes first), the peg,
// and the peg's model edges expected visible at the pickup's pose; without cameras there is none.
TEST(Phase2SeedExample, VerificationNamesTheEdgesACameraMustSee) {
  Scenario scenario = widened();
  scenario.range_scan = RangeScanSensor{{1.0 * kInch, 1.0 * kInch, 1.0 * kInch, 0.2}};
  const auto check_of = [](const Scenario& s) {
    const PlanResult result = plan(s, builtin_domain(), quick_options(1));
    const AnalysedStep& pickup = result.chosen_analysis()->steps.front();
    EXPECT_TRUE(pickup.failed);
    return pickup.verification.at(0).vision;
  };
  EXPECT_FALSE(check_of(scenario).has_value());

  const sensing::Intrinsics intrinsics{
      .fx = 800, .fy = 800, .cx = 320, .cy = 240, .width = 640, .height = 480};
  const Eigen::Vector3d peg = peg_of(scenario).initial_pose.translation();
  scenario.cameras.push_back({.name = "away",
                              .intrinsics = intrinsics,
                              .pose = sensing::look_at(peg + Eigen::Vector3d(0, 0, 1),
                                                       peg + Eigen::Vector3d(0, 0, 2), {0, 1, 0}),
                              .location = {}});
  // A wrist camera (its pose in the gripper frame) is never the one: PSEIKI renders from a world
  // pose. Posed as the overhead one, it would tie and come first.
  scenario.cameras.push_back(
      {.name = "wrist",
       .intrinsics = intrinsics,
       .pose = sensing::look_at(peg + Eigen::Vector3d(0, -0.4, 0.6), peg, {0, 0, 1}),
       .mount = sensing::Mount::kWrist,
       .location = {}});
  scenario.cameras.push_back(
      {.name = "overhead",
       .intrinsics = intrinsics,
       .pose = sensing::look_at(peg + Eigen::Vector3d(0, -0.4, 0.6), peg, {0, 0, 1}),
       .location = {}});
  const std::optional<VisionCheck> check = check_of(scenario);
  ASSERT_TRUE(check.has_value());
  EXPECT_EQ(check->camera, "overhead");
  EXPECT_EQ(check->object, "peg");
  EXPECT_EQ(check->acceptance, sensing::pseiki::MatchOptions{}.acceptance);
  // Some of the peg's edges, each once: hidden-line removal leaves out those facing away.
  const std::size_t model_edges = sensing::object_features(peg_of(scenario).model).edges.size();
  EXPECT_GT(check->edges.size(), 0u);
  EXPECT_LT(check->edges.size(), model_edges);
  std::set<std::string> ids(check->edges.begin(), check->edges.end());
  EXPECT_EQ(ids.size(), check->edges.size());
  for (const std::string& edge : check->edges) {
    ASSERT_EQ(edge.rfind("peg/e", 0), 0u) << edge;
    const int id = std::stoi(edge.substr(5));
    EXPECT_GE(id, 1) << edge;
    EXPECT_LE(static_cast<std::size_t>(id), model_edges) << edge;
  }
}

// Reverse analysis of the sensor: the coarse sensor's failed pickup says by how much the residual
// must shrink; a sensor that much finer makes the range-scan repair it.
TEST(Phase2SeedExample, SensorMarginIsAResidualThatRepairsThePickup) {
  Scenario scenario = widened();
  const RangeScanSensor coarse{{1.0 * kInch, 1.0 * kInch, 1.0 * kInch, 0.2}};
  scenario.range_scan = coarse;
  PlanOptions options = quick_options(1);
  options.analysis.reverse = true;
  const PlanResult result = plan(scenario, builtin_domain(), options);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const AnalysedStep& pickup = result.chosen_analysis()->steps.front();
  ASSERT_TRUE(pickup.failed);
  ASSERT_TRUE(pickup.sensor_scale_needed.has_value());
  const double needed = *pickup.sensor_scale_needed;
  EXPECT_GT(needed, 0.0);
  EXPECT_LT(needed, 1.0) << "the coarse sensor was reported good enough";
  // The 0.5 in to spare along the finger axis bounds the residual: 1 in scaled by s cannot exceed
  // it.
  EXPECT_LT(needed * coarse.residual.dx, 0.5 * kInch);

  const auto& r = coarse.residual;
  scenario.range_scan =
      RangeScanSensor{{r.dx * needed, r.dy * needed, r.dz * needed, r.dtheta * needed}};
  const PlanResult finer = plan(scenario, builtin_domain(), quick_options(1));
  const InstanceAnalysis& repaired = *finer.chosen_analysis();
  EXPECT_EQ(repaired.errors, 0);
  EXPECT_EQ(actions(repaired), (std::vector<std::string>{"range-scan", "pickup", "assemble"}));
}

}  // namespace
}  // namespace spar::planner
