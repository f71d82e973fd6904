// STL object meshes (geometry/mesh_io.hpp: parse_stl on CGAL's STL reader), ASCII and binary;
// triangle soups for robot links' collision meshes.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>

#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/mesh_io.hpp"
#include "spar/geometry/object.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::geometry {
namespace {

const char* const kTetrahedronStl = R"(solid tet
facet normal 0 0 -1
  outer loop
    vertex 0 0 0
    vertex 0 1 0
    vertex 1 0 0
  endloop
endfacet
facet normal 0 -1 0
  outer loop
    vertex 0 0 0
    vertex 1 0 0
    vertex 0 0 1
  endloop
endfacet
facet normal -1 0 0
  outer loop
    vertex 0 0 0
    vertex 0 0 1
    vertex 0 1 0
  endloop
endfacet
facet normal 1 1 1
  outer loop
    vertex 1 0 0
    vertex 0 1 0
    vertex 0 0 1
  endloop
endfacet
endsolid tet
)";

// The binary form of a mesh: 80-byte header, triangle count, then per triangle a normal, three
// corners (little-endian float32) and a 2-byte attribute.
std::string binary_stl(const Mesh& mesh) {
  std::string bytes(80, ' ');
  bytes.replace(0, 11, "binary mesh");
  const auto put = [&](const void* data, std::size_t size) {
    bytes.append(static_cast<const char*>(data), size);
  };
  const std::uint32_t count = static_cast<std::uint32_t>(mesh.triangles.size());
  put(&count, 4);
  for (const auto& triangle : mesh.triangles) {
    const float normal[3] = {0, 0, 0};
    put(normal, sizeof normal);
    for (const int corner : triangle) {
      const Eigen::Vector3d& v = mesh.vertices[corner];
      const float xyz[3] = {static_cast<float>(v.x()), static_cast<float>(v.y()),
                            static_cast<float>(v.z())};
      put(xyz, sizeof xyz);
    }
    const std::uint16_t attribute = 0;
    put(&attribute, 2);
  }
  return bytes;
}

TEST(MeshIoStl, ReadsAsciiStl) {
  const ObjectModel tet("tet", parse_stl(kTetrahedronStl, "tet.stl"));
  EXPECT_EQ(tet.faces().size(), 4u);
  EXPECT_NEAR(tet.volume(), 1.0 / 6, 1e-12);
}

TEST(MeshIoStl, ReadsBinaryStlWeldingCorners) {
  const Mesh cube = make_box({2, 1, 1});  // float-exact coordinates
  const Mesh read = parse_stl(binary_stl(cube), "cube.stl");
  EXPECT_EQ(read.vertices.size(), 8u);  // 36 corners welded into 8 vertices
  const ObjectModel model("cube", read);
  EXPECT_EQ(model.faces().size(), 6u);
  EXPECT_NEAR(model.volume(), 2.0, 1e-12);
}

TEST(MeshIoStl, FileByExtensionAnyCase) {
  const std::string path = ::testing::TempDir() + "/spar_stl_test_cube.STL";
  std::ofstream(path, std::ios::binary) << binary_stl(make_box({1, 1, 1}));
  EXPECT_NEAR(ObjectModel("cube", read_mesh_file(path)).volume(), 1.0, 1e-12);
}

TEST(MeshIoStl, EmptyAndOpenFilesAreErrorsNamingTheFile) {
  EXPECT_THROW_MESSAGE((void)parse_stl("", "empty.stl"),
                       "empty.stl: the STL file has no triangles");
  Mesh cube = make_box({1, 1, 1});
  cube.triangles.pop_back();
  EXPECT_THROW_MESSAGE((void)parse_stl(binary_stl(cube), "open.stl"), "open.stl");
  EXPECT_THROW_MESSAGE((void)parse_stl(binary_stl(cube), "open.stl"), "mesh is not closed");
  std::string bad = kTetrahedronStl;
  bad.replace(bad.find("vertex 0 1 0"), 12, "vertex 0 x 0");
  EXPECT_THROW_MESSAGE((void)parse_stl(bad, "bad.stl"), "bad.stl: not an STL file");
}

TEST(MeshIoStl, TriangleSoupsKeepOpenAndSelfCrossingMeshes) {
  Mesh cube = make_box({1, 1, 1});
  cube.triangles.pop_back();  // open: refused as a solid, read as a soup
  const Mesh soup = parse_stl_soup(binary_stl(cube), "open.stl");
  EXPECT_EQ(soup.triangles.size(), 11u);
  EXPECT_EQ(soup.vertices.size(), 8u);
  // The UR5's forearm crosses itself: a collision mesh, not a solid.
  const std::string forearm = std::string(SPAR_CORPUS_DIR) +
                              "/robots/example-robot-data/robots/ur_description/meshes/ur5/"
                              "collision/forearm.stl";
  EXPECT_THROW_MESSAGE((void)read_mesh_file(forearm), "the mesh intersects itself");
  EXPECT_GT(read_triangle_soup(forearm).triangles.size(), 100u);
  EXPECT_THROW_MESSAGE((void)parse_stl_soup("", "empty.stl"),
                       "empty.stl: the STL file has no triangles");
}

}  // namespace
}  // namespace spar::geometry
