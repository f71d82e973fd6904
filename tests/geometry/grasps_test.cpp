#include "spar/geometry/grasps.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "spar/common/units.hpp"
#include "spar/geometry/builtin_objects.hpp"

namespace spar::geometry {
namespace {

// Lengths are in metres; the test shapes are sized in inches, like the default gripper.
constexpr double in = units::kInch;

// Is `point` on face `id`: in its plane and inside one of its triangles?
bool on_face(const ObjectModel& object, int id, const Eigen::Vector3d& point) {
  const Face& face = object.face(id);
  if (std::abs(face.normal.dot(point) - face.offset) > object.tolerance()) return false;
  for (const int t : face.triangles) {
    const auto& tri = object.mesh().triangles[t];
    const Eigen::Vector3d a = object.mesh().vertices[tri[0]], b = object.mesh().vertices[tri[1]],
                          c = object.mesh().vertices[tri[2]];
    const double area_tolerance = -1e-12 * in * in;
    if ((b - a).cross(point - a).dot(face.normal) >= area_tolerance &&
        (c - b).cross(point - b).dot(face.normal) >= area_tolerance &&
        (a - c).cross(point - c).dot(face.normal) >= area_tolerance)
      return true;
  }
  return false;
}

int face_named(const ObjectModel& object, const std::string& name) {
  for (const Face& face : object.faces())
    if (face.name == name) return face.id;
  return 0;
}

TEST(Grasps, CubeHasFourApproachesForEachOfThreePairs) {
  const ObjectModel cube = make_builtin_object("cube");  // 1 in
  const auto grasps = compute_grasps(cube, GripperSpec{}, GraspQuantization{});
  ASSERT_EQ(grasps.size(), 12u);
  std::set<std::pair<int, int>> pairs;
  for (const Grasp& grasp : grasps) {
    pairs.insert({grasp.face_plus_y, grasp.face_minus_y});
    EXPECT_NEAR(grasp.width, 1 * in, 1e-12 * in);
    EXPECT_TRUE(
        grasp.gripper_in_object.translation().isApprox(Eigen::Vector3d(0.5, 0.5, 0.5) * in));
  }
  EXPECT_EQ(pairs.size(), 3u);
  EXPECT_NEAR(grasps[3].approach, 270 * units::kDegree, 1e-12);
  EXPECT_EQ(grasps[11].label, "G12");
}

TEST(Grasps, FingersAtPlusMinusHalfWidthTouchTheContactFaces) {
  const ObjectModel block = make_builtin_object("block");
  for (const Grasp& grasp : compute_grasps(block, GripperSpec{}, GraspQuantization{})) {
    const Eigen::Isometry3d& tg = grasp.gripper_in_object;
    EXPECT_TRUE(on_face(block, grasp.face_plus_y, tg * Eigen::Vector3d(0, grasp.width / 2, 0)))
        << grasp.label;
    EXPECT_TRUE(on_face(block, grasp.face_minus_y, tg * Eigen::Vector3d(0, -grasp.width / 2, 0)))
        << grasp.label;
    EXPECT_TRUE(tg.linear().col(1).isApprox(block.face(grasp.face_plus_y).normal));
    EXPECT_TRUE((tg.linear().transpose() * tg.linear()).isIdentity(1e-12));
    EXPECT_NEAR(tg.linear().determinant(), 1, 1e-12);
  }
}

TEST(Grasps, CentroidInAHoleMovesTheContactOntoTheFaces) {
  // The block's top face is a ring around the peg hole, so top/bottom grasps cannot sit at the
  // overlap's centroid (the hole's axis).
  const ObjectModel block = make_builtin_object("block");
  const int top = face_named(block, "top");
  ASSERT_NE(top, 0);
  bool found = false;
  for (const Grasp& grasp : compute_grasps(block, GripperSpec{}, GraspQuantization{}))
    if (grasp.face_plus_y == top || grasp.face_minus_y == top) {
      found = true;
      const Eigen::Vector3d centre = grasp.gripper_in_object.translation();
      EXPECT_GT(std::max(std::abs(centre.x()), std::abs(centre.y())), (0.8 - 1e-9) * in)
          << grasp.label;
    }
  EXPECT_TRUE(found);
}

TEST(Grasps, TopApproachObscuresTheTopFace) {
  const ObjectModel cube = make_builtin_object("cube");
  const int top = face_named(cube, "+z (z=1 in)");
  ASSERT_NE(top, 0);
  for (const Grasp& grasp : compute_grasps(cube, GripperSpec{}, GraspQuantization{})) {
    const bool from_above =
        grasp.gripper_in_object.linear().col(2).isApprox(Eigen::Vector3d(0, 0, -1));
    const bool contact = grasp.face_plus_y == top || grasp.face_minus_y == top;
    const bool obscures_top = !grasp_leaves_free(grasp, std::vector<int>{top});
    EXPECT_EQ(obscures_top, from_above || contact) << grasp.label;
    EXPECT_FALSE(grasp_leaves_free(grasp, std::vector<int>{grasp.face_plus_y}));
  }
}

TEST(Grasps, UsabilityInAPoseGivesTheReason) {
  const ObjectModel cube = make_builtin_object("cube");
  const auto poses = stable_poses(cube);
  const StablePose& on_bottom = poses[face_named(cube, "-z (z=0 in)") - 1];
  ASSERT_EQ(on_bottom.table_faces, std::vector<int>{face_named(cube, "-z (z=0 in)")});
  const GripperSpec gripper;
  std::map<GraspUsability, int> count;
  for (const Grasp& grasp : compute_grasps(cube, gripper, GraspQuantization{})) {
    const GraspUsability usability = grasp_usability(grasp, on_bottom, gripper);
    ++count[usability];
    const Eigen::Vector3d approach =
        (on_bottom.object_to_world * grasp.gripper_in_object).linear().col(2);
    if (usability == GraspUsability::usable) {
      EXPECT_TRUE(approach.isApprox(Eigen::Vector3d(0, 0, -1)));
    }
  }
  // 4 grasps on the vertical pair (top/bottom) touch the table; of the 8 others, 2 come from
  // above (usable), 2 from below, and 4 from the side, where the 1.5 in wide palm hits the
  // table.
  EXPECT_EQ(count[GraspUsability::contact_face_on_table], 4);
  EXPECT_EQ(count[GraspUsability::usable], 2);
  EXPECT_EQ(count[GraspUsability::approach_outside_cone], 2);
  EXPECT_EQ(count[GraspUsability::gripper_below_table], 4);
  GripperSpec narrow = gripper;
  narrow.palm_width = 0.5 * in;
  narrow.finger_width = 0.5 * in;
  int usable_narrow = 0;
  for (const Grasp& grasp : compute_grasps(cube, narrow, GraspQuantization{}))
    usable_narrow += grasp_usable(grasp, on_bottom, narrow);
  EXPECT_EQ(usable_narrow, 6);  // a narrow gripper can also grasp from the side
}

TEST(Grasps, QuantizationIsConfigurable) {
  const ObjectModel cube = make_builtin_object("cube");
  GraspQuantization fine;
  fine.approach_step = 45 * units::kDegree;
  EXPECT_EQ(compute_grasps(cube, GripperSpec{}, fine).size(), 24u);
  fine.positions_per_axis = 2;
  const auto grasps = compute_grasps(cube, GripperSpec{}, fine);
  EXPECT_EQ(grasps.size(), 96u);  // 3 pairs x 4 positions x 8 approaches
  for (const Grasp& grasp : grasps)
    EXPECT_NEAR(
        (grasp.gripper_in_object.translation() - Eigen::Vector3d(0.5, 0.5, 0.5) * in).norm(),
        std::sqrt(2.0) / 4 * in, 1e-9 * in);
  fine.approach_step = 0;
  EXPECT_THROW((void)compute_grasps(cube, GripperSpec{}, fine), GeometryError);
  fine.approach_step = 360;  // degrees where radians are due
  EXPECT_THROW((void)compute_grasps(cube, GripperSpec{}, fine), GeometryError);
}

TEST(Grasps, PairsWiderThanTheOpeningAreSkipped) {
  const ObjectModel bar("bar", make_box(Eigen::Vector3d(5, 1, 2) * in));
  GripperSpec long_fingers;  // long enough that the palm never reaches the bar
  long_fingers.finger_length = 10 * in;
  const auto grasps = compute_grasps(bar, long_fingers, GraspQuantization{});
  EXPECT_EQ(grasps.size(), 8u);
  for (const Grasp& grasp : grasps) EXPECT_LT(grasp.width, 4 * in);
  long_fingers.max_opening = 6 * in;
  EXPECT_EQ(compute_grasps(bar, long_fingers, GraspQuantization{}).size(), 12u);
}

TEST(Grasps, GraspsWhoseGripperWouldEnterTheObjectAreDropped) {
  // Pinching the bar's 1 in wide faces at its middle while approaching along its 5 in long x axis
  // puts the palm (1.75 to 2.75 in behind the contact) inside the bar: those two approaches are
  // dropped.
  const ObjectModel bar("bar", make_box(Eigen::Vector3d(5, 1, 2) * in));
  const auto grasps = compute_grasps(bar, GripperSpec{}, GraspQuantization{});
  EXPECT_EQ(grasps.size(), 4u);
  for (const Grasp& grasp : grasps) {
    const Eigen::Vector3d approach = grasp.gripper_in_object.linear().col(2);
    EXPECT_LT(std::abs(approach.x()), 1e-9) << grasp.label;
  }
}

TEST(Grasps, FacesInsideHolesAreNotContacts) {
  // The peg's outer -y side and the cross hole's wall behind it are parallel, opposite and 1.25
  // in apart, but a finger could only reach the wall from inside the hole.
  const ObjectModel peg = make_builtin_object("peg");
  const int wall = face_named(peg, "cross hole wall -y");
  ASSERT_NE(wall, 0);
  for (const Grasp& grasp : compute_grasps(peg, GripperSpec{}, GraspQuantization{}))
    EXPECT_TRUE(grasp.face_plus_y != wall && grasp.face_minus_y != wall) << grasp.label;
}

// The labels and transforms of two grasp lists, for comparing them.
std::vector<std::pair<std::string, Eigen::Matrix4d>> labelled_transforms(
    const std::vector<Grasp>& grasps) {
  std::vector<std::pair<std::string, Eigen::Matrix4d>> out;
  for (const Grasp& grasp : grasps) out.emplace_back(grasp.label, grasp.gripper_in_object.matrix());
  return out;
}

TEST(Grasps, RememberedListsAreTheComputedOnesForExactlyTheSameInputs) {
  const ObjectModel bar("bar", make_box(Eigen::Vector3d(5, 1, 2) * in));
  const auto first = remembered_grasps(bar, GripperSpec{}, GraspQuantization{});
  EXPECT_EQ(labelled_transforms(*first),
            labelled_transforms(compute_grasps(bar, GripperSpec{}, GraspQuantization{})));
  // Another object with the same mesh shares the list.
  const ObjectModel twin("twin", make_box(Eigen::Vector3d(5, 1, 2) * in));
  EXPECT_EQ(remembered_grasps(twin, GripperSpec{}, GraspQuantization{}), first);
  // Any difference in the gripper, the quantization or a vertex is another list.
  GripperSpec wider;
  wider.max_opening = 6 * in;
  const auto wide = remembered_grasps(bar, wider, GraspQuantization{});
  EXPECT_NE(wide, first);
  EXPECT_EQ(wide->size(), compute_grasps(bar, wider, GraspQuantization{}).size());
  EXPECT_NE(wide->size(), first->size());
  GraspQuantization finer;
  finer.approach_step = 45 * units::kDegree;
  EXPECT_EQ(labelled_transforms(*remembered_grasps(bar, GripperSpec{}, finer)),
            labelled_transforms(compute_grasps(bar, GripperSpec{}, finer)));
  const ObjectModel longer("longer", make_box(Eigen::Vector3d(5 + 1e-9, 1, 2) * in));
  const auto moved = remembered_grasps(longer, GripperSpec{}, GraspQuantization{});
  EXPECT_NE(moved, first);
  EXPECT_EQ(labelled_transforms(*moved),
            labelled_transforms(compute_grasps(longer, GripperSpec{}, GraspQuantization{})));
  // An invalid quantization is an error every time, never a remembered list.
  GraspQuantization invalid;
  invalid.positions_per_axis = 0;
  EXPECT_THROW((void)remembered_grasps(bar, GripperSpec{}, invalid), GeometryError);
  EXPECT_THROW((void)remembered_grasps(bar, GripperSpec{}, invalid), GeometryError);
}

TEST(Grasps, RememberedListsAreBoundedAndRecomputedAfterEviction) {
  const ObjectModel cube = make_builtin_object("cube");
  const auto kept = remembered_grasps(cube, GripperSpec{}, GraspQuantization{});
  // More new inputs than the cache holds push the cube's list out; asking again recomputes it
  // (a new list, equal to the old one).
  for (std::size_t i = 0; i <= kRememberedGraspLists; ++i) {
    GripperSpec gripper;
    gripper.palm_width = (2 + 0.01 * static_cast<double>(i)) * in;  // never the default
    (void)remembered_grasps(cube, gripper, GraspQuantization{});
  }
  const auto again = remembered_grasps(cube, GripperSpec{}, GraspQuantization{});
  EXPECT_NE(again, kept);
  EXPECT_EQ(labelled_transforms(*again), labelled_transforms(*kept));
}

}  // namespace
}  // namespace spar::geometry
