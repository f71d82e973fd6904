#include "spar/geometry/stable_poses.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "spar/geometry/builtin_objects.hpp"

namespace spar::geometry {
namespace {

const StablePose* pose_resting_on(const std::vector<StablePose>& poses,
                                  const Eigen::Vector3d& normal) {
  for (const StablePose& pose : poses)
    if (pose.facet_normal.isApprox(normal, 1e-9)) return &pose;
  return nullptr;
}

TEST(StablePoses, CubeHasSixEachOnOneFace) {
  const ObjectModel cube("cube", make_box({1, 1, 1}));
  const auto poses = stable_poses(cube);
  ASSERT_EQ(poses.size(), 6u);
  std::vector<int> table_faces;
  for (const StablePose& pose : poses) {
    ASSERT_EQ(pose.table_faces.size(), 1u) << pose.label;
    table_faces.push_back(pose.table_faces.front());
    EXPECT_NEAR(pose.margin, 0.5, 1e-12);
    EXPECT_NEAR(pose.tipping_angle, std::numbers::pi / 4, 1e-12);
    EXPECT_TRUE(cube.face(pose.table_faces.front()).normal.isApprox(pose.facet_normal));
  }
  EXPECT_EQ(table_faces, (std::vector<int>{1, 2, 3, 4, 5, 6}));  // ordered by table face
  EXPECT_EQ(poses[0].label, "P1");
}

TEST(StablePoses, TallThinBoxMarginsOrderByRestingFace) {
  // 1 x 2 x 6: lying flat on a 2 x 6 face is most stable, standing on the 1 x 2 end least.
  const ObjectModel box("box", make_box({1, 2, 6}));
  const auto poses = stable_poses(box);
  ASSERT_EQ(poses.size(), 6u);
  for (const double sign : {-1.0, 1.0}) {
    const StablePose* flat = pose_resting_on(poses, {sign, 0, 0});
    const StablePose* side = pose_resting_on(poses, {0, sign, 0});
    const StablePose* end = pose_resting_on(poses, {0, 0, sign});
    ASSERT_TRUE(flat && side && end);
    EXPECT_NEAR(flat->margin, 1.0, 1e-12);
    EXPECT_NEAR(side->margin, 0.5, 1e-12);
    EXPECT_NEAR(end->margin, 0.5, 1e-12);
    EXPECT_NEAR(end->com_height, 3.0, 1e-12);
    EXPECT_GT(flat->tipping_angle, side->tipping_angle);
    EXPECT_GT(side->tipping_angle, end->tipping_angle);
    EXPECT_NEAR(end->tipping_angle, std::atan2(0.5, 3.0), 1e-12);
  }
}

TEST(StablePoses, TriangularPrismHasFive) {
  const std::vector<Eigen::Vector2d> triangle{{0, 0}, {2, 0}, {1, std::sqrt(3.0)}};
  const ObjectModel prism("prism", make_prism(triangle, 3));
  EXPECT_EQ(prism.hull_facets().size(), 5u);
  EXPECT_EQ(stable_poses(prism).size(), 5u);
}

// Independent check: the centre of mass projects inside a triangle iff all its barycentric
// coordinates in the triangle's plane are positive.
bool projects_inside(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& point) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const Eigen::Vector3d p = point - n.dot(point - a) / n.squaredNorm() * n;
  const double wa = (b - p).cross(c - p).dot(n), wb = (c - p).cross(a - p).dot(n),
               wc = (a - p).cross(b - p).dot(n);
  return wa > 0 && wb > 0 && wc > 0;
}

TEST(StablePoses, TetrahedronWithOffCentreMassLosesPoses) {
  // Every pose is stable with uniform density; a mass pulled towards edge AB leaves the face ACD.
  const std::vector<Eigen::Vector3d> corners{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {1, 1, 1}};
  const Eigen::Vector3d heavy = 0.4 * (corners[0] + corners[1]) + 0.1 * (corners[2] + corners[3]);
  const ObjectModel uniform("tet", make_convex_hull(corners));
  const ObjectModel loaded("tet", make_convex_hull(corners), heavy);
  const auto uniform_poses = stable_poses(uniform);
  const auto loaded_poses = stable_poses(loaded);
  ASSERT_EQ(loaded.hull_facets().size(), 4u);
  int expected_loaded = 0, expected_uniform = 0;
  for (int skip = 0; skip < 4; ++skip) {
    std::vector<Eigen::Vector3d> face;
    for (int k = 0; k < 4; ++k)
      if (k != skip) face.push_back(corners[k]);
    const Eigen::Vector3d outward =
        ((face[1] - face[0]).cross(face[2] - face[0]) *
         ((face[1] - face[0]).cross(face[2] - face[0]).dot(face[0] - corners[skip]) > 0 ? 1 : -1))
            .normalized();
    const bool loaded_stable = projects_inside(face[0], face[1], face[2], heavy);
    const bool uniform_stable =
        projects_inside(face[0], face[1], face[2], uniform.center_of_mass());
    expected_loaded += loaded_stable;
    expected_uniform += uniform_stable;
    EXPECT_EQ(pose_resting_on(loaded_poses, outward) != nullptr, loaded_stable) << "face " << skip;
    EXPECT_EQ(pose_resting_on(uniform_poses, outward) != nullptr, uniform_stable)
        << "face " << skip;
  }
  EXPECT_EQ(expected_uniform, 4);
  EXPECT_EQ(expected_loaded, 3);
  EXPECT_EQ(uniform_poses.size(), 4u);
  EXPECT_EQ(loaded_poses.size(), 3u);
  EXPECT_EQ(pose_resting_on(loaded_poses, Eigen::Vector3d(-1, 0, 1).normalized()), nullptr);  // ACD
}

TEST(StablePoses, CentreOfMassOutsideTheHullIsAnError) {
  EXPECT_THROW(ObjectModel("cube", make_box({1, 1, 1}), Eigen::Vector3d(2, 0.5, 0.5)),
               GeometryError);
}

TEST(StablePoses, LShapeRejectsUnstableHullFacets) {
  const ObjectModel l_shape("l", builtin_mesh("l-shape"));
  ASSERT_EQ(l_shape.hull_facets().size(), 7u);
  const auto poses = stable_poses(l_shape);
  EXPECT_EQ(poses.size(), 5u);
  // The centre of mass (1.25, 0.5, 1.75) in is above the 1 in high foot end and beside the 1 in
  // wide top.
  EXPECT_EQ(pose_resting_on(poses, {1, 0, 0}), nullptr);
  EXPECT_EQ(pose_resting_on(poses, {0, 0, 1}), nullptr);
  // The facet across the notch is stable but touches the table only along two edges.
  const StablePose* notch = pose_resting_on(poses, Eigen::Vector3d(4, 0, 3).normalized());
  ASSERT_NE(notch, nullptr);
  EXPECT_TRUE(notch->table_faces.empty());
  EXPECT_EQ(poses.back().id, notch->id);  // poses on no face come last
}

TEST(StablePoses, PoseRestsTheFacetOnTheTable) {
  const ObjectModel box("box", make_box({1, 2, 3}));
  for (const StablePose& pose : stable_poses(box)) {
    const Eigen::Vector3d com = pose.object_to_world * box.center_of_mass();
    EXPECT_NEAR(com.head<2>().norm(), 0, 1e-12);
    EXPECT_NEAR(com.z(), pose.com_height, 1e-12);
    for (const int face : pose.table_faces)
      EXPECT_NEAR((pose.object_to_world * box.face(face).centroid).z(), 0, 1e-12);
  }
}

TEST(StablePoses, QueriesLeaveFreeAndClassify) {
  const ObjectModel cube("cube", make_box({1, 1, 1}));
  const auto poses = stable_poses(cube);
  const int bottom = poses[0].table_faces.front();
  EXPECT_FALSE(pose_leaves_free(poses[0], std::vector<int>{bottom}));
  EXPECT_TRUE(pose_leaves_free(poses[0], std::vector<int>{bottom % 6 + 1}));
  // Sensed orientation: each pose's own rotation, turned about world z, is still that pose.
  for (const StablePose& pose : poses) {
    const Eigen::Matrix3d turned =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        pose.object_to_world.linear();
    EXPECT_EQ(classify_orientation(poses, turned), pose.id);
  }
  const Eigen::Matrix3d tilted =
      Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_EQ(classify_orientation(poses, tilted), std::nullopt);
}

TEST(StablePoses, PosesOnNoFaceAreLabelledByNormalWhateverTheMeshOrder) {
  // The peg lying on its side rests on edges only (eight such poses). Scenario files name poses by
  // label, so the labels must follow the shape, not the hull's facet order: the same mesh with its
  // vertices and triangles listed backwards gives the same normals under the same labels, in
  // ascending (x, y, z) order.
  const Mesh mesh = builtin_mesh("peg");
  Mesh backwards = mesh;
  const int last = static_cast<int>(mesh.vertices.size()) - 1;
  std::reverse(backwards.vertices.begin(), backwards.vertices.end());
  std::reverse(backwards.triangles.begin(), backwards.triangles.end());
  std::reverse(backwards.triangle_names.begin(), backwards.triangle_names.end());
  std::reverse(backwards.triangle_lines.begin(), backwards.triangle_lines.end());
  for (auto& triangle : backwards.triangles)
    for (int& v : triangle) v = last - v;
  const auto no_face_normals = [](const Mesh& m) {
    std::vector<std::pair<std::string, Eigen::Vector3d>> result;
    for (const StablePose& pose : stable_poses(ObjectModel("peg", m)))
      if (pose.table_faces.empty()) result.emplace_back(pose.label, pose.facet_normal);
    return result;
  };
  const auto forwards = no_face_normals(mesh), reversed = no_face_normals(backwards);
  ASSERT_EQ(forwards.size(), 8u);
  ASSERT_EQ(reversed.size(), 8u);
  for (std::size_t i = 0; i < forwards.size(); ++i) {
    EXPECT_EQ(forwards[i].first, reversed[i].first);
    EXPECT_TRUE(forwards[i].second.isApprox(reversed[i].second, 1e-9)) << forwards[i].first;
    if (i > 0) {
      const Eigen::Vector3d& a = forwards[i - 1].second;
      const Eigen::Vector3d& b = forwards[i].second;
      EXPECT_TRUE(std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3))
          << forwards[i - 1].first << " before " << forwards[i].first;
    }
  }
}

// --- a subassembly resting as one body ---

Eigen::Isometry3d shifted_by(double x, double y, double z) {
  return Eigen::Isometry3d(Eigen::Translation3d(x, y, z));
}

// The lowest point of `object`'s mesh placed at `pose`.
double lowest_vertex_z(const ObjectModel& object, const Eigen::Isometry3d& pose) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& vertex : object.mesh().vertices)
    lowest = std::min(lowest, (pose * vertex).z());
  return lowest;
}

TEST(RestingMargin, ACubeAloneRestsByItsStablePoseMargin) {
  const ObjectModel cube("cube", make_box({1, 1, 1}));
  const PosedPart alone[] = {{&cube, stable_poses(cube)[0].object_to_world}};
  ASSERT_TRUE(resting_margin(alone, 1e-7).has_value());
  EXPECT_NEAR(*resting_margin(alone, 1e-7), stable_poses(cube)[0].margin, 1e-12);
}

TEST(RestingMargin, TheJointCentreOfMassDecides) {
  // A 4 x 4 x 0.5 plate (volume 8, centre x = 2) with a 1 x 1 post standing on it.
  const ObjectModel plate("plate", make_box({4, 4, 0.5}));
  const ObjectModel short_post("post", make_box({1, 1, 3}));  // volume 3
  const PosedPart inside[] = {{&plate, Eigen::Isometry3d::Identity()},
                              {&short_post, shifted_by(0, 0, 0.5)}};
  // Centre x = (8 * 2 + 3 * 0.5) / 11; the nearest footing edge is x = 0.
  EXPECT_NEAR(resting_margin(inside, 1e-7).value(), 17.5 / 11, 1e-12);
  // A long post beyond the plate's edge (volume 20, centre x = -1.5) pulls the centre to x = -0.5,
  // outside the footing [0, 4] x [0, 4]; the post is above the table, so it adds no footing.
  const ObjectModel long_post("post", make_box({1, 1, 20}));
  const PosedPart overhanging[] = {{&plate, Eigen::Isometry3d::Identity()},
                                   {&long_post, shifted_by(-2, 0, 0.5)}};
  EXPECT_NEAR(resting_margin(overhanging, 1e-7).value(), -0.5, 1e-12);
}

TEST(RestingMargin, EveryPartOnTheTableMakesTheFooting) {
  // The plate raised onto a 1 x 1 foot under one corner stands on the foot alone: its centre
  // (2, 2) lies outside the foot's square [0, 1] x [0, 1].
  const ObjectModel plate("plate", make_box({4, 4, 0.5}));
  const ObjectModel foot("foot", make_box({1, 1, 0.5}));
  const PosedPart on_foot[] = {{&plate, shifted_by(0, 0, 0.5)}, {&foot, shifted_by(0, 0, 0)}};
  EXPECT_LT(resting_margin(on_foot, 1e-7).value(), 0);
  // Four feet, one under each corner: the footing is the whole square again.
  const PosedPart on_four[] = {{&plate, shifted_by(0, 0, 0.5)},
                               {&foot, shifted_by(0, 0, 0)},
                               {&foot, shifted_by(3, 0, 0)},
                               {&foot, shifted_by(0, 3, 0)},
                               {&foot, shifted_by(3, 3, 0)}};
  EXPECT_GT(resting_margin(on_four, 1e-7).value(), 1.5);
}

TEST(RestingMargin, EdgesCornersAirAndBelowTheTableDoNotStand) {
  const ObjectModel cube("cube", make_box({1, 1, 1}));
  // On an edge: turned 45 degrees about x, it rests on its edge along x (every other vertex up).
  const Eigen::Isometry3d on_edge(
      Eigen::AngleAxisd(std::numbers::pi / 4, Eigen::Vector3d::UnitX()));
  const PosedPart edge[] = {{&cube, on_edge}};
  EXPECT_FALSE(resting_margin(edge, 1e-7).has_value());
  const PosedPart in_air[] = {{&cube, shifted_by(0, 0, 0.1)}};
  EXPECT_FALSE(resting_margin(in_air, 1e-7).has_value());
  const PosedPart sunk[] = {{&cube, shifted_by(0, 0, -0.1)}};
  EXPECT_FALSE(resting_margin(sunk, 1e-7).has_value());
}

TEST(JointStablePoses, OnePartRestsAsItsStablePoses) {
  for (const ObjectModel& object :
       {ObjectModel("box", make_box({1, 2, 6})), make_builtin_object("l-shape")}) {
    const std::vector<StablePose> own = stable_poses(object);
    const PosedPart alone[] = {{&object, Eigen::Isometry3d::Identity()}};
    const std::vector<JointStablePose> joint = joint_stable_poses(alone, object.tolerance());
    ASSERT_EQ(joint.size(), own.size()) << object.name();
    for (const JointStablePose& pose : joint) {
      const auto same = std::find_if(own.begin(), own.end(), [&](const StablePose& stable) {
        return stable.facet_normal.isApprox(pose.down, 1e-9);
      });
      ASSERT_NE(same, own.end()) << object.name() << " down " << pose.down.transpose();
      EXPECT_TRUE(pose.frame_to_world.isApprox(same->object_to_world, 1e-9)) << same->label;
      EXPECT_NEAR(pose.margin, same->margin, 1e-9) << same->label;
    }
  }
}

TEST(JointStablePoses, TwoPartsRestWhereNeitherDoesAlone) {
  // The plate with the long post beyond its edge (RestingMargin.TheJointCentreOfMassDecides):
  // flat on the plate the centre lies outside the footing, but the pair rests tilted on the
  // plate's upper far edge (x = 4, z = 0.5) and the post's top edge (x = -1, z = 20.5): the hull
  // facet through both has the normal (20, 0, 5) / |.|, and neither part rests so alone.
  const ObjectModel plate("plate", make_box({4, 4, 0.5}));
  const ObjectModel long_post("post", make_box({1, 1, 20}));
  const PosedPart joined[] = {{&plate, Eigen::Isometry3d::Identity()},
                              {&long_post, shifted_by(-2, 0, 0.5)}};
  const std::vector<JointStablePose> poses = joint_stable_poses(joined, 1e-7);
  ASSERT_FALSE(poses.empty());
  const Eigen::Vector3d tilted = Eigen::Vector3d(4, 0, 1).normalized();
  bool found = false;
  for (const JointStablePose& pose : poses) {
    EXPECT_FALSE(pose.down.isApprox(-Eigen::Vector3d::UnitZ(), 1e-9));
    const PosedPart placed[] = {{&plate, pose.frame_to_world},
                                {&long_post, pose.frame_to_world * joined[1].pose}};
    EXPECT_NEAR(resting_margin(placed, 1e-7).value(), pose.margin, 1e-12);
    EXPECT_GT(pose.margin, 1e-7);
    if (!pose.down.isApprox(tilted, 1e-9)) continue;
    found = true;
    // Both parts touch the table, each along one edge.
    EXPECT_NEAR(lowest_vertex_z(plate, pose.frame_to_world), 0, 1e-12);
    EXPECT_NEAR(lowest_vertex_z(long_post, pose.frame_to_world * joined[1].pose), 0, 1e-12);
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace spar::geometry
