// The least-squares pose correction (sensing/pseiki/pose_correction.hpp): with exact
// correspondences it recovers the true offset of the object or the camera, its residual drops to
// nothing, and the uncertainty left is less than the prior's.
#include "spar/sensing/pseiki/pose_correction.hpp"

#include <gtest/gtest.h>

#include "spar/sensing/render.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/sensing/pseiki/scenes.hpp"

namespace spar::sensing::pseiki {
namespace {

// The image of the scene with object `moved` (or the camera, for kCameraTarget) at `offset` from
// its believed pose, every edge labelled with its true panel edge at belief 0.9.
Blackboard exact_image(const ModelPanel& panel, const testing::TestScene& test, int moved,
                       const PoseOffset& offset) {
  Scene truth;
  for (std::size_t o = 0; o < test.scene.objects().size(); ++o) {
    const SceneObject& object = test.scene.objects()[o];
    truth.add(object.name, *object.model, *object.features,
              static_cast<int>(o) == moved ? offset_pose(object.pose, offset) : object.pose);
  }
  const Camera camera = moved == kCameraTarget
                            ? Camera(test.camera.projection(), test.camera.intrinsics(),
                                     offset_pose(test.camera.pose(), offset))
                            : test.camera;
  std::vector<ImageEdgeInput> image;
  std::vector<int> labels;
  for (const EdgeView& view : render(truth, camera, {.faces = false}).edges) {
    const int label = panel.edge_index(truth.objects()[static_cast<std::size_t>(view.object)].name +
                                       "/e" + std::to_string(view.edge));
    if (label < 0 || (view.u1 - view.u0).norm() < 3) continue;
    image.push_back({std::string("e").append(std::to_string(image.size())), {view.u0, view.u1}});
    labels.push_back(label);
  }
  Blackboard board(panel, image, 1.0);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    board.edges[i].label = labels[i];
    board.edges[i].belief = 0.9;
  }
  return board;
}

TEST(PoseCorrection, RecoversAnObjectsOffset) {
  const testing::TestScene test = testing::two_boxes();
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  const PoseOffset truth{.dx = 0.003, .dy = -0.002, .dz = 0, .dtheta = 0.01};
  const Blackboard board = exact_image(panel, test, 0, truth);
  const auto correction = correct_pose(board, 0, test.uncertainty.objects[0]);
  ASSERT_TRUE(correction.has_value());
  EXPECT_NEAR(correction->offset.dx, truth.dx, 2e-4);
  EXPECT_NEAR(correction->offset.dy, truth.dy, 2e-4);
  EXPECT_EQ(correction->offset.dz, 0);  // not uncertain: not estimated
  EXPECT_NEAR(correction->offset.dtheta, truth.dtheta, 2e-3);
  EXPECT_LT(correction->residual_px, 0.1);
  EXPECT_GT(correction->residual_before_px, 1.0);
  EXPECT_TRUE(
      correction->pose.isApprox(offset_pose(test.scene.objects()[0].pose, correction->offset)));
  EXPECT_LT(correction->uncertainty.dx, test.uncertainty.objects[0].dx);
  EXPECT_LT(correction->uncertainty.dtheta, test.uncertainty.objects[0].dtheta);
  EXPECT_EQ(correction->uncertainty.dz, 0);
}

// A mobile robot's camera: its pose is what is uncertain and corrected, from every object's edges.
TEST(PoseCorrection, RecoversTheCamerasOffset) {
  testing::TestScene test = testing::two_boxes();
  test.uncertainty.objects.assign(2, {});
  test.uncertainty.camera = {.dx = 0.01, .dy = 0.01, .dz = 0, .dtheta = 0.02};
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  const PoseOffset truth{.dx = -0.006, .dy = 0.004, .dz = 0, .dtheta = -0.012};
  const Blackboard board = exact_image(panel, test, kCameraTarget, truth);
  const auto correction = correct_pose(board, kCameraTarget, test.uncertainty.camera);
  ASSERT_TRUE(correction.has_value());
  EXPECT_NEAR(correction->offset.dx, truth.dx, 3e-4);
  EXPECT_NEAR(correction->offset.dy, truth.dy, 3e-4);
  EXPECT_NEAR(correction->offset.dtheta, truth.dtheta, 1e-3);
  EXPECT_LT(correction->residual_px, 0.1);
}

TEST(PoseCorrection, NothingToCorrectWithoutUncertaintyOrEdges) {
  const testing::TestScene test = testing::two_boxes();
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  const Blackboard board = exact_image(panel, test, 0, {});
  EXPECT_FALSE(correct_pose(board, 0, {}).has_value());
  const Blackboard empty(panel, {}, 1.0);
  EXPECT_FALSE(correct_pose(empty, 0, test.uncertainty.objects[0]).has_value());
  EXPECT_THROW_MESSAGE(correct_pose(board, 7, test.uncertainty.objects[0]),
                       "pose correction: no object 7");
}

}  // namespace
}  // namespace spar::sensing::pseiki
