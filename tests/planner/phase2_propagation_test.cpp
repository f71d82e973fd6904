// Propagation through a long chain (issue 10): the peg picked up and put down k times between two
// places, then picked up once more. SPAR's trees grow exponentially with the number of actions
// that touch an object; as shared DAG nodes the last pickup's preconditions must grow linearly in
// k. The chain's expressions must also still be the physics: they evaluate to the numeric
// simulation's values (tests/planner/phase2_simulation.hpp) after 100 round trips.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/common/units.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/uncertainty/deciding.hpp"
#include "spar/planner/uncertainty/propagation.hpp"
#include "spar/symbolic/operations.hpp"
#include "tests/planner/phase2_simulation.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

using testing::action_with;

constexpr int kMaxRoundTrips = 100;

// The chain over one object between two places: pickup at A, putdown at B, pickup at B, putdown at
// A, ... Records the DAG size of the pickup preconditions a grasp would have after each round
// trip (k = 0..kMaxRoundTrips), and keeps the full step list.
class Chain : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new WorldModel(
        load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml"));
    const Domain& domain = builtin_domain();
    const int peg = world_->object_index("peg");
    const kinematics::Transform a = world_->scenario().objects[peg].initial_pose;
    const kinematics::Transform b =
        Eigen::Translation3d(0.1, -0.25, 0) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * a;
    Phase2Step grasp{.action = action_with(domain, Effect::kGrasp),
                     .effect = Effect::kGrasp,
                     .object = peg,
                     .grasp = 0};
    Phase2Step release = grasp;
    release.action = action_with(domain, Effect::kRelease);
    release.effect = Effect::kRelease;
    pool_ = new symbolic::ExprPool;
    propagation_ = new Propagation(*world_, domain, *pool_);
    for (int k = 0; k <= kMaxRoundTrips; ++k) {
      const bool at_a = k % 2 == 0;
      grasp.object_pose = at_a ? a : b;
      release.object_pose = at_a ? b : a;
      // The pickup that would come next, on a snapshot.
      Propagation next = *propagation_;
      const std::vector<Precondition> pre = next.step(grasp, static_cast<int>(steps_.size()) + 1);
      std::vector<symbolic::Expr> roots;
      for (const Precondition& p : pre) roots.push_back(p.inequality.expression);
      nodes_.push_back(symbolic::dag_size(roots));
      if (k == kMaxRoundTrips) {
        steps_.push_back(grasp);
        last_ = pre;
        *propagation_ = std::move(next);
        break;
      }
      for (const Phase2Step& step : {grasp, release}) {
        EXPECT_TRUE(propagation_->step(step, static_cast<int>(steps_.size()) + 1).size() ==
                    (step.effect == Effect::kGrasp ? 4u : 0u));
        steps_.push_back(step);
      }
    }
  }
  static void TearDownTestSuite() {
    delete propagation_;
    delete pool_;
    delete world_;
  }

  static WorldModel* world_;
  static symbolic::ExprPool* pool_;
  static Propagation* propagation_;  // after the whole chain and the last pickup
  static std::vector<Phase2Step> steps_;
  static std::vector<std::size_t> nodes_;  // [k]: preconditions' DAG nodes after k round trips
  static std::vector<Precondition> last_;  // the last pickup's preconditions
};
WorldModel* Chain::world_ = nullptr;
symbolic::ExprPool* Chain::pool_ = nullptr;
Propagation* Chain::propagation_ = nullptr;
std::vector<Phase2Step> Chain::steps_;
std::vector<std::size_t> Chain::nodes_;
std::vector<Precondition> Chain::last_;

TEST_F(Chain, NodeCountGrowsLinearlyInTheNumberOfRoundTrips) {
  ASSERT_EQ(nodes_.size(), static_cast<std::size_t>(kMaxRoundTrips) + 1);
  for (const int k : {0, 1, 50, 100})  // in the XML report (--gtest_output=xml)
    RecordProperty("nodes_k" + std::to_string(k), static_cast<int>(nodes_[k]));
  // Linear a + b k: doubling k from 50 to 100 adds what going from 0 to 50 added (a quadratic
  // would add three times as much, an exponential incomparably more).
  const double first = static_cast<double>(nodes_[50]) - nodes_[0];
  const double second = static_cast<double>(nodes_[100]) - nodes_[50];
  EXPECT_GT(first, 0.0);
  EXPECT_NEAR(second / first, 1.0, 0.1) << nodes_[0] << ", " << nodes_[50] << ", " << nodes_[100];
  const double ratio = static_cast<double>(nodes_[100]) / nodes_[50];
  EXPECT_GT(ratio, 1.6);
  EXPECT_LT(ratio, 2.1);
  // Every round trip adds a bounded number of nodes: at most twice the average.
  const std::size_t average = (nodes_[kMaxRoundTrips] - nodes_[0]) / kMaxRoundTrips;
  for (int k = 1; k <= kMaxRoundTrips; ++k) {
    EXPECT_GT(nodes_[k], nodes_[k - 1]) << "k = " << k;
    EXPECT_LE(nodes_[k] - nodes_[k - 1], 2 * average + 4) << "k = " << k;
  }
}

TEST_F(Chain, LastPickupStillDependsOnEarlySteps) {
  // A grasp keeps the x and z of the grasp centre's offset (the finger axis and the rotation are
  // reset to the arm's), so the arm errors of early steps reach the last pickup through every
  // putdown in between: the expressions cannot stay small by forgetting.
  ASSERT_EQ(last_.size(), 4u);
  std::vector<symbolic::Expr> roots;
  for (const Precondition& p : last_) roots.push_back(p.inequality.expression);
  std::map<int, int> per_step;
  for (const symbolic::Expr v : symbolic::free_variables(roots)) {
    const std::optional<VariableId> id = propagation_->space().id_of(v);
    ASSERT_TRUE(id.has_value()) << v.name();
    const Provenance& from = propagation_->space().variable(*id).provenance;
    ++per_step[from.source == UncertaintySource::kManipulator ? from.step : 0];
  }
  const int last = static_cast<int>(steps_.size());
  EXPECT_EQ(per_step[last], 3) << "the pickup's own arm error but its dz (along the approach)";
  EXPECT_GT(per_step[last - 1], 0) << "the putdown before it";
  // The x and z of the grasp centre carry the object's earlier error: early steps still count.
  int early = 0;
  for (const auto& [step, count] : per_step) early += step > 0 && step < last / 2 ? count : 0;
  EXPECT_GT(early, 0);
}

TEST_F(Chain, ExpressionsAfterAHundredRoundTripsEvaluateToTheSimulation) {
  const std::vector<SpaceVariable>& variables = propagation_->space().variables();
  std::mt19937_64 random(7);
  for (int sample = 0; sample < 20; ++sample) {
    std::map<std::string, double> values;
    for (const SpaceVariable& v : variables)
      values[v.name] =
          sample == 0 ? v.upper : std::uniform_real_distribution<double>(v.lower, v.upper)(random);
    testing::NumericPlan simulation(*world_, variables, values);
    std::vector<testing::NumericCondition> measured;
    for (std::size_t i = 0; i < steps_.size(); ++i)
      measured = simulation.step(steps_[i], static_cast<int>(i) + 1);
    ASSERT_EQ(measured.size(), last_.size());
    for (std::size_t j = 0; j < last_.size(); ++j) {
      const double value = symbolic::evaluate(last_[j].inequality.expression, values);
      EXPECT_NEAR(value, measured[j].value, 1e-9)
          << last_[j].inequality.name << ", sample " << sample;
    }
  }
}

// Every effect in one script, for every grasp of the peg (approaches from straight down to
// tilted): scan, squeeze, pickup, putdown elsewhere, squeeze there, pickup, insertion into the
// block. Each step's preconditions evaluate to the simulation's values at corners and random
// points of the box, and each has the kind and count the model gives it.
TEST(Propagation, EveryEffectMatchesTheSimulationForEveryGrasp) {
  const WorldModel world(
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml"));
  const Domain& domain = builtin_domain();
  const int peg = world.object_index("peg"), block = world.object_index("block");
  const kinematics::Transform a = world.scenario().objects[peg].initial_pose;
  const kinematics::Transform b =
      Eigen::Translation3d(-0.05, 0.1, 0) * Eigen::AngleAxisd(-1.0, Eigen::Vector3d::UnitZ()) * a;
  const kinematics::Transform block_pose = world.scenario().objects[block].initial_pose;
  const auto& goal = std::get<AssembledGoal>(world.scenario().goals.front());
  const std::size_t grasps = world.object(peg).grasps.size();
  ASSERT_GT(grasps, 4u);
  std::mt19937_64 random(3);
  for (std::size_t g = 0; g < grasps; ++g) {
    SCOPED_TRACE("grasp " + world.object(peg).grasps[g].label);
    const auto make = [&](Effect effect, const kinematics::Transform& pose) {
      Phase2Step step{.action = action_with(domain, effect),
                      .effect = effect,
                      .object = peg,
                      .grasp = static_cast<int>(g),
                      .object_pose = pose};
      if (effect == Effect::kInsert) {
        step.fixed_object = block;
        step.fixed_pose = block_pose;
      }
      return step;
    };
    const std::vector<Phase2Step> script = {make(Effect::kSense, a),
                                            make(Effect::kReduce, a),
                                            make(Effect::kGrasp, a),
                                            make(Effect::kRelease, b),
                                            make(Effect::kReduce, b),
                                            make(Effect::kGrasp, b),
                                            make(Effect::kInsert, block_pose * goal.relative)};
    const std::vector<std::pair<std::string, std::size_t>> expected = {
        {"", 0},        {"squeeze", 4}, {"pickup", 4},  {"", 0},
        {"squeeze", 4}, {"pickup", 4},  {"assemble", 5}};
    symbolic::ExprPool pool;
    Propagation propagation(world, builtin_domain(), pool);
    std::vector<std::vector<Precondition>> built;
    for (std::size_t i = 0; i < script.size(); ++i) {
      built.push_back(propagation.step(script[i], static_cast<int>(i) + 1));
      ASSERT_EQ(built.back().size(), expected[i].second) << "step " << i + 1;
      for (const Precondition& p : built.back()) EXPECT_EQ(to_string(p.kind), expected[i].first);
    }
    const std::vector<SpaceVariable>& variables = propagation.space().variables();
    // The scan moves no arm: it allocates the sensor's four, the others the arm's four each.
    for (const SpaceVariable& v : variables) {
      if (v.provenance.step == 1) {
        EXPECT_EQ(v.provenance.source, UncertaintySource::kSensor) << v.name;
      }
    }
    EXPECT_EQ(variables.size(), 4u * world.object_count() + 4 + 4 * 6);
    for (int sample = 0; sample < 12; ++sample) {
      std::map<std::string, double> values;
      for (const SpaceVariable& v : variables)
        values[v.name] = sample < 2
                             ? (sample == 0 ? v.lower : v.upper)
                             : std::uniform_real_distribution<double>(v.lower, v.upper)(random);
      testing::NumericPlan simulation(world, variables, values);
      for (std::size_t i = 0; i < script.size(); ++i) {
        const std::vector<testing::NumericCondition> measured =
            simulation.step(script[i], static_cast<int>(i) + 1);
        ASSERT_EQ(measured.size(), built[i].size());
        for (std::size_t j = 0; j < measured.size(); ++j) {
          EXPECT_EQ(built[i][j].inequality.relation, measured[j].relation);
          EXPECT_NEAR(built[i][j].inequality.threshold, measured[j].threshold, 1e-12);
          EXPECT_NEAR(symbolic::evaluate(built[i][j].inequality.expression, values),
                      measured[j].value, 1e-9)
              << "step " << i + 1 << " '" << built[i][j].inequality.name << "', sample " << sample;
        }
      }
    }
  }
}

TEST(Propagation, ACopyIsASnapshot) {
  const WorldModel world(
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml"));
  symbolic::ExprPool pool;
  const Propagation original(world, builtin_domain(), pool);
  Propagation copy = original;
  const int peg = world.object_index("peg");
  const Phase2Step grasp{.action = action_with(builtin_domain(), Effect::kGrasp),
                         .effect = Effect::kGrasp,
                         .object = peg,
                         .grasp = 0,
                         .object_pose = world.scenario().objects[peg].initial_pose};
  (void)copy.step(grasp, 1);
  EXPECT_TRUE(copy.held(peg));
  EXPECT_FALSE(original.held(peg));
  EXPECT_TRUE(original.on_table(peg).has_value());
  EXPECT_EQ(original.space().variables().size(), 4u * world.object_count());
  EXPECT_EQ(copy.space().variables().size(), 4u * world.object_count() + 4);
}

TEST(Propagation, StepsThatDoNotFitTheStateAreRefused) {
  const WorldModel world(
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml"));
  const Domain& domain = builtin_domain();
  symbolic::ExprPool pool;
  Propagation propagation(world, domain, pool);
  const int peg = world.object_index("peg");
  Phase2Step release{.action = action_with(domain, Effect::kRelease),
                     .effect = Effect::kRelease,
                     .object = peg,
                     .grasp = 0};
  EXPECT_THROW((void)propagation.step(release, 1), PlanError);
  Phase2Step grasp{.action = action_with(domain, Effect::kGrasp),
                   .effect = Effect::kGrasp,
                   .object = peg,
                   .grasp = 0,
                   .object_pose = world.scenario().objects[peg].initial_pose};
  EXPECT_EQ(propagation.step(grasp, 1).size(), 4u);
  EXPECT_TRUE(propagation.held(peg));
  EXPECT_FALSE(propagation.on_table(peg).has_value());
  try {
    (void)propagation.step(grasp, 2);
    ADD_FAILURE() << "grasping a held object was accepted";
  } catch (const PlanError& error) {
    EXPECT_NE(std::string(error.what()).find("peg on the table"), std::string::npos)
        << error.what();
  }
}

// A scan corrects a component only where the object's error is not already inside the residual's
// box (Propagation::sense): after a putdown the peg's rotation error is the arm's 0.0573 deg, far
// inside the scanner's 1 deg, so the scan keeps it (the same expression), and replaces the others
// by fresh sensor variables over the residual.
TEST(Propagation, AScanCorrectsOnlyTheComponentsItKnowsBetter) {
  const WorldModel world(
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml"));
  const Domain& domain = builtin_domain();
  const int peg = world.object_index("peg");
  const kinematics::Transform a = world.scenario().objects[peg].initial_pose;
  const kinematics::Transform b = Eigen::Translation3d(0.1, -0.25, 0) * a;
  const auto make = [&](Effect effect, const kinematics::Transform& pose) {
    return Phase2Step{.action = action_with(domain, effect),
                      .effect = effect,
                      .object = peg,
                      .grasp = 0,
                      .object_pose = pose};
  };
  symbolic::ExprPool pool;
  Propagation propagation(world, domain, pool);
  (void)propagation.step(make(Effect::kGrasp, a), 1);
  (void)propagation.step(make(Effect::kRelease, b), 2);
  const kinematics::PoseError before = propagation.on_table(peg)->error;
  (void)propagation.step(make(Effect::kSense, b), 3);
  const kinematics::PoseError after = propagation.on_table(peg)->error;
  const kinematics::PoseUncertainty& r = world.scenario().range_scan->residual;
  const symbolic::Expr was[4] = {before.dx, before.dy, before.dz, before.dtheta};
  const symbolic::Expr now[4] = {after.dx, after.dy, after.dz, after.dtheta};
  const double residual[4] = {r.dx, r.dy, r.dz, r.dtheta};
  int kept = 0;
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(to_string(kPoseComponents[i]));
    const bounds::Interval known = natural_enclosures({&was[i], 1}, propagation.space()).front();
    if (known.lo >= -residual[i] && known.hi <= residual[i]) {
      EXPECT_EQ(now[i], was[i]);
      ++kept;
      continue;
    }
    const std::optional<VariableId> id = propagation.space().id_of(now[i]);
    ASSERT_TRUE(id.has_value());
    const SpaceVariable& v = propagation.space().variable(*id);
    EXPECT_EQ(v.provenance.source, UncertaintySource::kSensor);
    EXPECT_EQ(v.provenance.step, 3);
    EXPECT_EQ(v.half_width(), residual[i]);
  }
  EXPECT_EQ(now[3], was[3]) << "the putdown's rotation error was replaced by the wider residual";
  EXPECT_LT(kept, 4);
}

// Reverse analysis of the sensor (set_sensor_scale): a scan's residual is a scale variable times a
// variable over the scenario's residual, so a new scale is new ranges of the same expressions. At
// every scale it encloses exactly the scaled residual, and a scan of an unmoved object fused with
// an earlier reading never exceeds that reading (fusion keeps the smaller half-width).
TEST(Propagation, ScaledResidualsCoverTheScaledBoxAndFusionCapsThem) {
  const WorldModel world(
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml"));
  const Domain& domain = builtin_domain();
  const int peg = world.object_index("peg");
  const double residual_dx = world.scenario().range_scan->residual.dx;
  const Phase2Step scan{.action = action_with(domain, Effect::kSense),
                        .effect = Effect::kSense,
                        .object = peg,
                        .object_pose = world.scenario().objects[peg].initial_pose};
  const auto dx_range = [](const Propagation& state, int object) {
    const symbolic::Expr dx = state.on_table(object)->error.dx;
    bounds::Box box;
    for (const symbolic::Expr v : symbolic::free_variables(dx)) {
      const bounds::Interval range = state.space().range(*state.space().id_of(v));
      box.add(v, range.lo, range.hi);
    }
    const bounds::BoundResult bound = bounds::bound(dx, box);
    return std::pair(bound.lo, bound.hi);
  };
  symbolic::ExprPool pool;
  Propagation scaled(world, domain, pool);
  scaled.set_sensor_scale(1.0);
  (void)scaled.step(scan, 1);
  const symbolic::Expr expression = scaled.on_table(peg)->error.dx;
  for (const double k : {0.0, 0.3, 1.0, 2.5}) {
    scaled.set_sensor_scale(k);
    EXPECT_EQ(scaled.on_table(peg)->error.dx, expression);  // ranges change, not expressions
    const auto [lo, hi] = dx_range(scaled, peg);
    EXPECT_NEAR(lo, -k * residual_dx, 1e-15) << k;
    EXPECT_NEAR(hi, k * residual_dx, 1e-15) << k;
  }
  // An earlier plain reading of the unmoved peg caps a scaled one at its own half-width.
  Propagation fused(world, domain, pool);
  (void)fused.step(scan, 1);
  fused.set_sensor_scale(2.0);
  (void)fused.step(scan, 2);
  EXPECT_NEAR(dx_range(fused, peg).second, residual_dx, 1e-15);
  fused.set_sensor_scale(0.5);
  EXPECT_NEAR(dx_range(fused, peg).second, 0.5 * residual_dx, 1e-15);
  // And a second scaled scan keeps the first one's cap.
  (void)fused.step(scan, 3);
  fused.set_sensor_scale(3.0);
  EXPECT_NEAR(dx_range(fused, peg).second, residual_dx, 1e-15);
}

}  // namespace
}  // namespace spar::planner
