// Camera verification as a phase-2 sensing operation (issue 27; planner/uncertainty/repair.hpp):
// a fixed camera with a `residual` verifies an object where it sees it well enough, its residual
// replaces the object's pose error, two verifications before the object moves are fused, and a
// camera without a residual repairs nothing. examples/peg_block_camera_verify.yaml is seed figure
// 15 without a range scanner, with an overhead and a front camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "spar/common/units.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/uncertainty/propagation.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

using testing::example;

int action_named(const Domain& domain, const std::string& name) {
  for (std::size_t a = 0; a < domain.actions.size(); ++a)
    if (domain.actions[a].name == name) return static_cast<int>(a);
  ADD_FAILURE() << "no action " << name;
  return -1;
}

TEST(Phase2Camera, TheBuiltInDomainVerifiesWithACamera) {
  const ActionTemplate& look = builtin_domain().action("camera-verify");
  EXPECT_EQ(look.effect, Effect::kSense);
  EXPECT_TRUE(look.camera);
  EXPECT_FALSE(builtin_domain().action("range-scan").camera);
}

TEST(Phase2Camera, CamerasVerifyBothPartsAndTheInsertionHolds) {
  const PlanResult result =
      plan(example("peg_block_camera_verify"), builtin_domain(), testing::quick_options(2));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const InstanceAnalysis& analysis = *result.chosen_analysis();
  EXPECT_EQ(analysis.errors, 0);
  std::set<int> verified;
  for (const AnalysedStep& step : analysis.steps) {
    if (!step.inserted) {
      for (const PreconditionResult& p : step.preconditions)
        EXPECT_EQ(p.verdict, bounds::Verdict::kSatisfied) << p.inequality.name;
      continue;
    }
    EXPECT_EQ(step.action, "camera-verify");
    EXPECT_EQ(step.step.effect, Effect::kSense);
    ASSERT_GE(step.step.camera, 0);
    ASSERT_TRUE(step.camera_verification.has_value());
    EXPECT_EQ(step.camera_verification->camera,
              result.world.scenario().cameras[static_cast<std::size_t>(step.step.camera)].name);
    EXPECT_GE(step.camera_verification->edges.size(), 3U);
    verified.insert(step.step.object);
    EXPECT_FALSE(analysis.repairs.at(static_cast<std::size_t>(step.step.repair)).turned.empty());
  }
  EXPECT_EQ(verified.size(), 2U);  // the block and the peg
}

TEST(Phase2Camera, ACameraWithoutAResidualRepairsNothing) {
  Scenario scenario = example("peg_block_camera_verify");
  for (CameraSensor& camera : scenario.cameras) camera.residual.reset();
  const PlanResult result = plan(scenario, builtin_domain(), testing::quick_options(2));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const InstanceAnalysis& analysis = *result.chosen_analysis();
  EXPECT_GT(analysis.errors, 0);
  EXPECT_TRUE(std::none_of(analysis.steps.begin(), analysis.steps.end(),
                           [](const AnalysedStep& step) { return step.inserted; }));
}

// Two verifications before the object moves: per component the smaller residual (overhead: 0.02,
// 0.02, 0.11 in, 1 deg; front: 0.02, 0.11, 0.02 in, 5.5 deg).
TEST(Phase2Camera, TwoCamerasVerificationsAreFused) {
  const Scenario scenario = example("peg_block_camera_verify");
  const WorldModel world(scenario);
  symbolic::ExprPool pool;
  Propagation propagation(world, builtin_domain(), pool);
  const int block = 0;
  ASSERT_EQ(scenario.objects[block].name, "block");
  Phase2Step look{.action = action_named(builtin_domain(), "camera-verify"),
                  .effect = Effect::kSense,
                  .object = block,
                  .camera = 0,
                  .object_pose = scenario.objects[block].initial_pose};
  (void)propagation.step(look, 1);
  look.camera = 1;
  (void)propagation.step(look, 2);
  const kinematics::PoseError& error = propagation.on_table(block)->error;
  const UncertaintySpace& space = propagation.space();
  const auto half_width = [&](const symbolic::Expr& component) {
    const std::optional<VariableId> id = space.id_of(component);
    EXPECT_TRUE(id.has_value());
    EXPECT_EQ(space.variable(*id).provenance.source, UncertaintySource::kSensor);
    return id ? space.variable(*id).half_width() : -1.0;
  };
  const double in = units::kInch, deg = units::kPi / 180;
  EXPECT_NEAR(half_width(error.dx), 0.02 * in, 1e-15);
  EXPECT_NEAR(half_width(error.dy), 0.02 * in, 1e-15);
  EXPECT_NEAR(half_width(error.dz), 0.02 * in, 1e-15);
  EXPECT_NEAR(half_width(error.dtheta), 1 * deg, 1e-15);
}

}  // namespace
}  // namespace spar::planner
