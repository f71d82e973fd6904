#include "spar/geometry/mesh.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "spar/geometry/mesh_io.hpp"
#include "spar/geometry/object.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::geometry {
namespace {

const char* const kTetrahedronOff = R"(OFF
# a tetrahedron
4 4 0
0 0 0
1 0 0
0 1 0
0 0 1
3 0 2 1 # bottom
3 0 1 3 # front
3 0 3 2 # left
3 1 2 3 # slanted
)";

TEST(MeshIo, ReadsOffWithNamedPolygons) {
  const Mesh mesh = parse_off(kTetrahedronOff, "tet.off");
  ASSERT_EQ(mesh.triangles.size(), 4u);
  const ObjectModel object("tet", mesh);
  ASSERT_EQ(object.faces().size(), 4u);
  EXPECT_EQ(object.face(1).name, "bottom");
  EXPECT_EQ(object.face(4).name, "slanted");
  EXPECT_NEAR(object.volume(), 1.0 / 6, 1e-12);
  EXPECT_TRUE(object.face(1).normal.isApprox(Eigen::Vector3d(0, 0, -1)));
}

TEST(MeshIo, ReadsObjWithGroupsAndNegativeIndices) {
  const char* obj = R"(v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
g bottom
f 1 3 2
g sides
f 1/1/1 2/2/2 4/4/4
f -4 -1 -2
f 2 3 4
)";
  const ObjectModel object("tet", parse_obj(obj, "tet.obj"));
  EXPECT_EQ(object.faces().size(), 4u);
  EXPECT_EQ(object.face(1).name, "bottom");
  EXPECT_EQ(object.face(2).name, "sides");
}

TEST(MeshIo, BadNumberNamesFileAndLine) {
  std::string text = kTetrahedronOff;
  text.replace(text.find("1 0 0"), 5, "1 x 0");
  EXPECT_THROW_MESSAGE((void)parse_off(text, "tet.off"), "tet.off:5: expected a number, got 'x'");
}

TEST(MeshIo, OutOfRangeIndexNamesLine) {
  std::string text = kTetrahedronOff;
  text.replace(text.find("3 1 2 3"), 7, "3 1 2 9");
  EXPECT_THROW_MESSAGE((void)parse_off(text, "tet.off"),
                       "tet.off:11: vertex index 9 is out of range");
}

TEST(MeshIo, TooFewPolygonsAreRejected) {
  std::string text = kTetrahedronOff;
  text.replace(text.find("4 4 0"), 5, "4 3 0");
  text.erase(text.find("3 1 2 3 # slanted\n"));
  EXPECT_THROW_MESSAGE((void)parse_off(text, "tet.off"), "needs at least 4 triangles");
}

TEST(MeshIo, OpenBoxIsRejectedWithTheEdge) {
  // A cube without its top: five quads, every top edge has one polygon.
  const char* open_box = R"(OFF
8 5 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
)";
  EXPECT_THROW_MESSAGE((void)parse_off(open_box, "open.off"), "mesh is not closed");
  EXPECT_THROW_MESSAGE((void)parse_off(open_box, "open.off"), "open.off:1");  // a polygon line
}

TEST(MeshIo, FlippedPolygonIsInconsistent) {
  std::string text = kTetrahedronOff;
  text.replace(text.find("3 0 1 3"), 7, "3 0 3 1");
  EXPECT_THROW_MESSAGE((void)parse_off(text, "tet.off"), "inconsistently oriented");
}

TEST(MeshIo, InwardMeshIsTurnedOutward) {
  MeshBuilder builder("inward");
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                   Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)})
    builder.add_vertex(p);
  for (const std::array<int, 3>& t :
       {std::array{0, 1, 2}, std::array{0, 3, 1}, std::array{0, 2, 3}, std::array{1, 3, 2}})
    builder.add_polygon(t, "");
  const Mesh mesh = std::move(builder).build();
  EXPECT_NEAR(volume_properties(mesh).volume, 1.0 / 6, 1e-12);
}

TEST(MeshIo, FlatMeshIsDegenerate) {
  // A tetrahedron's connectivity on four coplanar points: closed, consistent, but flat.
  MeshBuilder builder("flat");
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                   Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 1, 0)})
    builder.add_vertex(p);
  for (const std::array<int, 3>& t :
       {std::array{0, 2, 1}, std::array{0, 1, 3}, std::array{0, 3, 2}, std::array{1, 2, 3}})
    builder.add_polygon(t, "");
  EXPECT_THROW_MESSAGE((void)std::move(builder).build(), "encloses no volume");
}

TEST(MeshIo, ZeroAreaTriangleNamesLine) {
  std::string text = kTetrahedronOff;
  text.replace(text.find("0 0 1\n"), 6, "2 0 0\n");  // vertex 3 now on the line of 0 and 1
  EXPECT_THROW_MESSAGE((void)parse_off(text, "tet.off"), "tet.off:9: degenerate triangle");
}

TEST(MeshIo, NonConvexPolygonIsRejected) {
  MeshBuilder builder("dart");
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0),
                                   Eigen::Vector3d(1, 0.2, 0), Eigen::Vector3d(1, 2, 0)})
    builder.add_vertex(p);
  const std::array loop{0, 1, 2, 3};
  EXPECT_THROW_MESSAGE(builder.add_polygon(loop, "", 7), "dart:7: polygon is not convex");
}

TEST(MeshIo, MissingFileAndUnknownExtension) {
  EXPECT_THROW_MESSAGE((void)read_mesh_file("/nonexistent/thing.off"),
                       "/nonexistent/thing.off: no such mesh file");
  EXPECT_THROW_MESSAGE((void)read_mesh_file(SPAR_SOURCE_DIR "/README.md"),
                       "unknown mesh format '.md' (expected .off, .obj or .stl)");
}

TEST(MeshIo, WriteThenReadKeepsFacesAndNames) {
  const ObjectModel original("box", make_box({1, 2, 3}));
  std::ostringstream text;
  write_off(original.mesh(), text, "a box\nsecond line");
  const ObjectModel copy("box", parse_off(text.str(), "box.off"));
  ASSERT_EQ(copy.faces().size(), original.faces().size());
  for (const Face& face : original.faces()) {
    EXPECT_EQ(copy.face(face.id).name, face.name);
    EXPECT_TRUE(copy.face(face.id).normal.isApprox(face.normal));
  }
}

TEST(RectilinearSolid, SlottedBlockMergesCoplanarQuadsIntoFaces) {
  // 3 x 1 x 2 cells with the top middle cell removed: a block with a slot across y.
  RectilinearSolid solid({0, 1, 2, 3}, {0, 1}, {0, 1, 2});
  solid.set_filled(1, 0, 1, false);
  const ObjectModel object("slotted", solid.to_mesh());
  // bottom, two tops, slot floor, two slot walls, two ends, front and back (each one face).
  EXPECT_EQ(object.faces().size(), 10u);
  EXPECT_NEAR(object.volume(), 5.0, 1e-12);
  int front_faces = 0;
  for (const Face& face : object.faces())
    if (face.normal.isApprox(Eigen::Vector3d(0, -1, 0))) {
      ++front_faces;
      EXPECT_NEAR(face.area, 5.0, 1e-12);  // the U-shaped front is one face
    }
  EXPECT_EQ(front_faces, 1);
}

TEST(RectilinearSolid, EdgeTouchingCellsAreNonManifold) {
  RectilinearSolid solid({0, 1, 2}, {0, 1}, {0, 1, 2});
  solid.set_filled(1, 0, 0, false);
  solid.set_filled(0, 0, 1, false);
  EXPECT_THROW_MESSAGE((void)solid.to_mesh(), "non-manifold");
}

}  // namespace
}  // namespace spar::geometry
