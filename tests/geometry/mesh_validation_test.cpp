// What validate_closed_mesh and the mesh readers refuse (issue 12): directories, coordinates too
// large to compute with, and meshes that cross themselves; and that the refusal does not touch
// ordinary solids, convex or not.
#include <gtest/gtest.h>

#include <string>

#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/mesh.hpp"
#include "spar/geometry/mesh_io.hpp"
#include "spar/geometry/object.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::geometry {
namespace {

// Two unit cubes in one mesh, the second moved by `offset` along the diagonal.
Mesh two_cubes(double offset) {
  Mesh mesh = make_box({1, 1, 1});
  const Mesh second = make_box({1, 1, 1});
  const int base = static_cast<int>(mesh.vertices.size());
  for (const auto& v : second.vertices)
    mesh.vertices.push_back(v + Eigen::Vector3d::Constant(offset));
  for (std::size_t t = 0; t < second.triangles.size(); ++t) {
    const auto& tri = second.triangles[t];
    mesh.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
    mesh.triangle_names.push_back("second " + second.triangle_names[t]);
    mesh.triangle_lines.push_back(0);
  }
  return mesh;
}

TEST(MeshValidation, OverlappingCubesIntersectThemselves) {
  // Accepted before with volume 2 although the union holds 1.875.
  Mesh mesh = two_cubes(0.5);
  EXPECT_THROW_MESSAGE(validate_closed_mesh(mesh), "the mesh intersects itself");
}

// An object is one solid (issue 22): pieces apart, or touching only at a corner or along an edge,
// are refused with what is wrong, although each piece is closed and none crosses another.
TEST(MeshValidation, SolidsApartOrTouchingAreNotOneObject) {
  Mesh apart = two_cubes(2);
  EXPECT_THROW_MESSAGE(validate_closed_mesh(apart),
                       "<box> (triangle 12): the mesh is more than one solid: this polygon is not "
                       "connected to the one at <box> (triangle 0)");
  Mesh corner = two_cubes(1);  // one shared corner point, welded into one vertex
  EXPECT_THROW_MESSAGE(validate_closed_mesh(corner), "the mesh is more than one solid");
  // Sharing the edge x = y = 1: four triangles run along it.
  Mesh edge = make_box({1, 1, 1});
  const Mesh second = make_box({1, 1, 1});
  const int base = static_cast<int>(edge.vertices.size());
  for (const auto& v : second.vertices) edge.vertices.push_back(v + Eigen::Vector3d(1, 1, 0));
  for (std::size_t t = 0; t < second.triangles.size(); ++t) {
    const auto& tri = second.triangles[t];
    edge.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
    edge.triangle_names.push_back("");
    edge.triangle_lines.push_back(0);
  }
  EXPECT_THROW_MESSAGE(validate_closed_mesh(edge),
                       "triangles (a non-manifold edge: two solids touching along an edge are not "
                       "one object)");
}

TEST(MeshValidation, TheErrorNamesBothPolygonsByFileLine) {
  // Tetrahedron B's apex (0.2, 0.2, 0.5) lies inside tetrahedron A: B's sides pierce A's base.
  const std::string closed =
      "OFF\n8 8 0\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
      "0.2 0.2 -0.5\n0.9 0.2 -0.5\n0.2 0.9 -0.5\n0.2 0.2 0.5\n"
      "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
      "3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n";
  // A's base (line 11) is the first polygon crossed; B's side (4, 5, 7) on line 16 crosses it.
  EXPECT_THROW_MESSAGE((void)parse_off(closed, "pierced.off"),
                       "pierced.off:11: the mesh intersects itself: this polygon crosses the one "
                       "at pierced.off:16");
}

TEST(MeshValidation, NonConvexBuiltInsAreNotSelfIntersecting) {
  for (const std::string& name : builtin_object_names()) {
    EXPECT_NO_THROW((void)make_builtin_object(name)) << name;
  }
}

TEST(MeshIo, DirectoryIsReportedAsSuch) {
  EXPECT_THROW_MESSAGE((void)read_mesh_file(std::string(SPAR_SOURCE_DIR) + "/geometry"),
                       "is a directory, not a mesh file");
}

TEST(MeshIo, HugeCoordinatesAreRefusedWithTheLimit) {
  const std::string off =
      "OFF\n4 4 0\n0 0 0\n1e300 0 0\n0 1 0\n0 0 1\n"
      "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  EXPECT_THROW_MESSAGE((void)parse_off(off, "big.off"),
                       "big.off:4: coordinate '1e300' is too large: coordinates must lie within "
                       "+-1e+12");
}

TEST(MeshIo, CoordinatesAreReadAsSparPrintsThem) {
  // Subnormal and 17-digit coordinates (what write_off prints) are read back exactly.
  const std::string off =
      "OFF\n4 4 0\n4.9406564584124654e-324 0 0\n1 0 0\n0 0.10000000000000001 0\n"
      "0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const Mesh mesh = parse_off(off, "tiny.off");
  EXPECT_EQ(mesh.vertices[0].x(), 4.9406564584124654e-324);
  EXPECT_EQ(mesh.vertices[2].y(), 0.1);
}

}  // namespace
}  // namespace spar::geometry
