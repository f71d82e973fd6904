#include "spar/geometry/builtin_objects.hpp"

#include <gtest/gtest.h>

#include "spar/common/units.hpp"
#include "spar/geometry/grasps.hpp"
#include "spar/geometry/mesh_io.hpp"
#include "spar/geometry/stable_poses.hpp"

namespace spar::geometry {
namespace {

constexpr double inch = units::kInch;  // the built-ins are the seed's inch shapes, in metres

std::vector<int> faces_named_prefix(const ObjectModel& object, const std::string& prefix) {
  std::vector<int> ids;
  for (const Face& face : object.faces())
    if (face.name.rfind(prefix, 0) == 0) ids.push_back(face.id);
  return ids;
}

TEST(BuiltinObjects, ExampleFilesMatchTheBuiltins) {
  for (const std::string name : {"peg", "block"}) {
    const ObjectModel built = make_builtin_object(name);
    const ObjectModel loaded(
        name, read_mesh_file(std::string(SPAR_SOURCE_DIR) + "/examples/objects/" + name + ".off"));
    ASSERT_EQ(loaded.faces().size(), built.faces().size()) << name;
    for (const Face& face : built.faces()) {
      EXPECT_EQ(loaded.face(face.id).name, face.name);
      EXPECT_TRUE(loaded.face(face.id).normal.isApprox(face.normal, 1e-12));
      EXPECT_NEAR(loaded.face(face.id).area, face.area, 1e-9 * inch * inch);
    }
    EXPECT_EQ(stable_poses(loaded).size(), stable_poses(built).size()) << name;
    EXPECT_EQ(compute_grasps(loaded, GripperSpec{}, GraspQuantization{}).size(),
              compute_grasps(built, GripperSpec{}, GraspQuantization{}).size())
        << name;
  }
}

// builtin_mesh skips validating a mesh whose digest is the recorded one: that mesh must pass
// validate_closed_mesh from scratch, unchanged (not flipped), and each built-in must have that
// digest (else a builder changed: record its new digest once it validates).
TEST(BuiltinObjects, KnownDigestsAreOfMeshesThatValidate) {
  for (const std::string& name : builtin_object_names()) {
    const Mesh built = builtin_mesh(name);
    const std::uint64_t digest = content_digest(built);
    EXPECT_EQ(digest, builtin_validated_digest(name))
        << name << ": record 0x" << std::hex << digest << " in builtin_validated_digest";
    EXPECT_EQ(built.validated_digest, digest) << name;
    Mesh checked = built;
    checked.validated_digest = 0;
    EXPECT_NO_THROW(validate_closed_mesh(checked)) << name;
    EXPECT_EQ(content_digest(checked), digest) << name << ": validation changed the mesh";
  }
  EXPECT_EQ(builtin_validated_digest("sphere"), 0u);
}

TEST(BuiltinObjects, UnknownNameListsTheKnownOnes) {
  try {
    (void)make_builtin_object("sphere");
    ADD_FAILURE();
  } catch (const GeometryError& error) {
    EXPECT_NE(std::string(error.what()).find("known: peg, block"), std::string::npos);
  }
}

TEST(BuiltinObjects, BlockHasOnePoseForInsertingThePegFromAbove) {
  // SPAR's BP5: the block's mating faces (the peg hole's opening ring and floor) must be off the
  // table and the mating vector (-z in the block frame, into the hole) must point down.
  const ObjectModel block = make_builtin_object("block");
  EXPECT_NEAR(block.volume(),
              (3.5 * 3 * 3 - 1.6 * 1.6 * 2 - 0.5 * 0.5 * (3 - 1.6)) * inch * inch * inch,
              1e-9 * inch * inch * inch);
  const auto poses = stable_poses(block);
  EXPECT_EQ(poses.size(), 6u);
  const std::vector<int> top = faces_named_prefix(block, "top");
  ASSERT_EQ(top.size(), 1u);
  int permitted = 0;
  for (const StablePose& pose : poses) {
    const double down = (pose.object_to_world.linear() * Eigen::Vector3d(0, 0, -1)).z();
    if (pose_leaves_free(pose, top) && down < -0.5) ++permitted;
  }
  EXPECT_EQ(permitted, 1);
}

TEST(BuiltinObjects, PegStandsOnBaseOrShaftButNotOnTheBaseSides) {
  const ObjectModel peg = make_builtin_object("peg");
  const auto poses = stable_poses(peg);
  // The centre of mass is above the 1.5 in high base, so the base's vertical sides are not stable.
  EXPECT_GT(peg.center_of_mass().z(), 1.5 * inch);
  for (const StablePose& pose : poses)
    EXPECT_GT(std::abs(pose.facet_normal.z()), 1e-6) << pose.label;
  bool on_base = false, on_shaft = false;
  for (const StablePose& pose : poses) {
    on_base = on_base || pose.facet_normal.isApprox(Eigen::Vector3d(0, 0, -1));
    on_shaft = on_shaft || pose.facet_normal.isApprox(Eigen::Vector3d(0, 0, 1));
  }
  EXPECT_TRUE(on_base && on_shaft);
  // Grasps across the 3-inch base (W_p = 3 in the seed) exist and fit the 4-inch opening.
  const auto grasps = compute_grasps(peg, GripperSpec{}, GraspQuantization{});
  EXPECT_TRUE(std::any_of(grasps.begin(), grasps.end(), [](const Grasp& g) {
    return std::abs(g.width - 3 * inch) < 1e-9 * inch;
  }));
  EXPECT_TRUE(std::any_of(grasps.begin(), grasps.end(), [](const Grasp& g) {
    return std::abs(g.width - 1.5 * inch) < 1e-9 * inch;
  }));
}

TEST(BuiltinObjects, AreBuiltInMetresFromInchDimensions) {
  const ObjectModel cube = make_builtin_object("cube");
  double largest = 0;
  for (const Eigen::Vector3d& v : cube.mesh().vertices) largest = std::max(largest, v.maxCoeff());
  EXPECT_EQ(largest, 0.0254);  // exactly 1 in
  EXPECT_NEAR(cube.volume(), inch * inch * inch, 1e-12 * inch * inch * inch);
  bool named_in_inches = false;
  for (const Face& face : cube.faces()) named_in_inches |= face.name == "+z (z=1 in)";
  EXPECT_TRUE(named_in_inches);
  // The block is 3.5 in along x: its left and right faces are 0.0889 m apart.
  const ObjectModel block = make_builtin_object("block");
  const auto left = faces_named_prefix(block, "left -x"),
             right = faces_named_prefix(block, "right +x");
  ASSERT_EQ(left.size(), 1u);
  ASSERT_EQ(right.size(), 1u);
  EXPECT_NEAR(block.face(left[0]).offset + block.face(right[0]).offset, 3.5 * inch, 1e-15);
}

}  // namespace
}  // namespace spar::geometry
