// The domain file drives phase 2 (issue 24): an action's `effect:` and `uncertainty:` builders are
// all phase 2 knows about it. A user's `lift` (effect grasp, builders [pickup]) gets exactly the
// pickup preconditions; a pickup whose builder list is deleted gets none.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "tests/common/replaced.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

using testing::peg_pickup;

std::string shipped_text() {
  std::ifstream in(std::filesystem::path(SPAR_SOURCE_DIR) / "planner" / "domain.yaml");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

using test_support::replaced;

const AnalysedStep* first_step(const InstanceAnalysis& analysis, const std::string& action) {
  for (const AnalysedStep& step : analysis.steps)
    if (step.action == action) return &step;
  return nullptr;
}

TEST(Phase2Domain, AUsersLiftActionGetsThePickupPreconditions) {
  // The shipped pickup renamed: the user's own action, known to phase 2 only through its effect
  // and builders.
  const Domain mine = parse_domain(replaced(shipped_text(), "  - name: pickup\n    effect: grasp\n",
                                            "  - name: lift\n    effect: grasp\n"),
                                   "mine.yaml");
  ASSERT_EQ(mine.action("lift").effect, Effect::kGrasp);
  const PlanResult built_in = plan(peg_pickup(), builtin_domain(), testing::quick_options(2));
  const PlanResult with_lift = plan(peg_pickup(), mine, testing::quick_options(2));
  ASSERT_TRUE(with_lift.planned()) << with_lift.family.reason;
  const AnalysedStep* lift = first_step(*with_lift.chosen_analysis(), "lift");
  const AnalysedStep* pickup = first_step(*built_in.chosen_analysis(), "pickup");
  ASSERT_NE(lift, nullptr);
  ASSERT_NE(pickup, nullptr);
  EXPECT_EQ(lift->step.effect, Effect::kGrasp);
  ASSERT_EQ(lift->preconditions.size(), 4u);
  ASSERT_EQ(pickup->preconditions.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(lift->preconditions[i].kind, Builder::kPickup);
    EXPECT_EQ(lift->preconditions[i].inequality.name, pickup->preconditions[i].inequality.name);
    EXPECT_EQ(lift->preconditions[i].verdict, pickup->preconditions[i].verdict);
    EXPECT_DOUBLE_EQ(lift->preconditions[i].bound.lo, pickup->preconditions[i].bound.lo);
  }
  // The assembly after it sees the peg as held by the lift.
  const AnalysedStep* assemble = first_step(*with_lift.chosen_analysis(), "assemble");
  ASSERT_NE(assemble, nullptr);
  EXPECT_FALSE(assemble->preconditions.empty());
}

TEST(Phase2Domain, APickupWithoutBuildersHasNoPreconditions) {
  const Domain mine =
      parse_domain(replaced(shipped_text(), "    uncertainty: [pickup]\n", ""), "mine.yaml");
  const PlanResult result = plan(peg_pickup(), mine, testing::quick_options(2));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const AnalysedStep* pickup = first_step(*result.chosen_analysis(), "pickup");
  ASSERT_NE(pickup, nullptr);
  EXPECT_EQ(pickup->step.effect, Effect::kGrasp);
  EXPECT_TRUE(pickup->preconditions.empty());
  const AnalysedStep* assemble = first_step(*result.chosen_analysis(), "assemble");
  ASSERT_NE(assemble, nullptr);
  EXPECT_FALSE(assemble->preconditions.empty()) << "the assembly keeps its own builder";
}

TEST(Phase2Domain, TheEffectNotThePredicatesSaysWhatAStepDoes) {
  // A putdown declared `effect: none` leaves the object held as far as phase 2 is concerned,
  // whatever its add list says: the next grasp of it is refused.
  const Domain mine =
      parse_domain(replaced(shipped_text(), "  - name: putdown\n    effect: release\n",
                            "  - name: putdown\n    effect: none\n"),
                   "mine.yaml");
  const WorldModel world(peg_pickup());
  const int peg = world.object_index("peg");
  const auto action = [&](const char* name) {
    for (std::size_t a = 0; a < mine.actions.size(); ++a)
      if (mine.actions[a].name == name) return static_cast<int>(a);
    return -1;
  };
  symbolic::ExprPool pool;
  Propagation propagation(world, mine, pool);
  const kinematics::Transform at = world.scenario().objects[peg].initial_pose;
  const Phase2Step grasp{.action = action("pickup"),
                         .effect = Effect::kGrasp,
                         .object = peg,
                         .grasp = 0,
                         .object_pose = at};
  Phase2Step release = grasp;
  release.action = action("putdown");
  release.effect = mine.actions[release.action].effect;
  (void)propagation.step(grasp, 1);
  (void)propagation.step(release, 2);
  EXPECT_TRUE(propagation.held(peg));
  try {
    (void)propagation.step(grasp, 3);
    ADD_FAILURE() << "grasping a held peg was accepted";
  } catch (const PlanError& error) {
    EXPECT_STREQ(error.what(),
                 "step 3 (pickup, effect grasp) needs peg on the table, but it is held; do the "
                 "effects in mine.yaml fit what its actions do?");
  }
}

// A user's lift declared `effect: none`: phase 2 never sees the peg picked up, and the refusal
// names the step, its action and effect, and the domain file to look at.
TEST(Phase2Domain, AnEffectThatDoesNotFitThePlanIsRefusedNamingTheDomain) {
  const Domain mine = parse_domain(replaced(shipped_text(), "  - name: pickup\n    effect: grasp\n",
                                            "  - name: lift\n    effect: none\n"),
                                   "mine.yaml");
  try {
    (void)plan(peg_pickup(), mine, testing::quick_options(2));
    ADD_FAILURE() << "inserting a peg no step grasped was accepted";
  } catch (const PlanError& error) {
    EXPECT_STREQ(error.what(),
                 "step 2 (assemble, effect insert) inserts an object it does not hold; do the "
                 "effects in mine.yaml fit what its actions do?");
  }
}

}  // namespace
}  // namespace spar::planner
