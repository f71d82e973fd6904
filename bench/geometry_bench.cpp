// geometry: `spar object`'s work (validate the mesh, faces, hull facets, parallel face pairs,
// stable poses, grasps) on generated meshes of growing size, against CGAL's convex hull of the
// same points -- the O(n log n) floor any object model on a hull pays.
//
// Meshes (generated here, so the run needs no files):
//   sphere-N   a UV sphere of N triangles, radius 1 m: bigger than the gripper (0.1016 m), so no
//              grasps: faces, hull facets, face pairs and stable poses only;
//   prism-N    a regular N-gon prism, radius 1 in (0.0254 m), height 1 in: N/2 face pairs the
//              gripper spans, so every stage including grasps runs;
//   ball-N     a UV sphere of N triangles, radius 1 in: every antipodal triangle pair is a grasp.
//
//   geometry_bench [--quick]
// Prints a table of per-stage times and `ratio <workload> cgal_hull <hull time / our time>` (the
// share of spar's time CGAL's hull alone would take; 1 would be no work beyond the hull).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "spar/geometry/grasps.hpp"
#include "spar/geometry/mesh.hpp"
#include "spar/geometry/object.hpp"
#include "spar/geometry/stable_poses.hpp"

namespace {

using spar::geometry::Mesh;
using spar::geometry::MeshBuilder;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// UV sphere: `segments` around, `rings` from pole to pole: 2 * segments * (rings - 1) triangles.
MeshBuilder sphere(int segments, int rings, double radius) {
  MeshBuilder builder("<sphere>");
  const int south = builder.add_vertex({0, 0, -radius});
  for (int i = 1; i < rings; ++i) {
    const double latitude = -std::numbers::pi / 2 + std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double longitude = 2 * std::numbers::pi * j / segments;
      builder.add_vertex({radius * std::cos(latitude) * std::cos(longitude),
                          radius * std::cos(latitude) * std::sin(longitude),
                          radius * std::sin(latitude)});
    }
  }
  const int north = builder.add_vertex({0, 0, radius});
  const auto at = [&](int ring, int j) { return 1 + (ring - 1) * segments + (j % segments); };
  const auto triangle = [&](int a, int b, int c) {
    const int loop[3] = {a, b, c};
    builder.add_polygon(loop, "");
  };
  for (int j = 0; j < segments; ++j) triangle(south, at(1, j + 1), at(1, j));
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      triangle(at(i, j), at(i, j + 1), at(i + 1, j + 1));
      triangle(at(i, j), at(i + 1, j + 1), at(i + 1, j));
    }
  for (int j = 0; j < segments; ++j) triangle(north, at(rings - 1, j), at(rings - 1, j + 1));
  return builder;
}

MeshBuilder prism(int sides, double radius) {
  MeshBuilder builder("<prism>");
  for (const double z : {0.0, radius})
    for (int k = 0; k < sides; ++k) {
      const double angle = 2 * std::numbers::pi * (k + 0.5) / sides;
      builder.add_vertex({radius * std::cos(angle), radius * std::sin(angle), z});
    }
  std::vector<int> bottom, top;
  for (int k = sides - 1; k >= 0; --k) bottom.push_back(k);
  for (int k = 0; k < sides; ++k) top.push_back(sides + k);
  builder.add_polygon(bottom, "bottom");
  builder.add_polygon(top, "top");
  for (int k = 0; k < sides; ++k) {
    const int quad[4] = {k, (k + 1) % sides, sides + (k + 1) % sides, sides + k};
    builder.add_polygon(quad, "side");
  }
  return builder;
}

double cgal_hull_seconds(const Mesh& mesh) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<Kernel::Point_3> points;
  for (const auto& v : mesh.vertices) points.emplace_back(v.x(), v.y(), v.z());
  CGAL::Surface_mesh<Kernel::Point_3> hull;
  const auto start = Clock::now();
  CGAL::convex_hull_3(points.begin(), points.end(), hull);
  const double elapsed = seconds_since(start);
  if (hull.number_of_faces() == 0) std::printf("empty hull?\n");
  return elapsed;
}

void run(const std::string& workload, MeshBuilder builder) {
  auto start = Clock::now();
  Mesh mesh = std::move(builder).build();  // validation: closed, oriented, no self-intersection
  const double validate = seconds_since(start);
  const std::size_t triangles = mesh.triangles.size();
  const double hull = cgal_hull_seconds(mesh);
  start = Clock::now();
  const spar::geometry::ObjectModel object(workload, std::move(mesh));
  const double model = seconds_since(start);
  start = Clock::now();
  const auto poses = spar::geometry::stable_poses(object);
  const double stable = seconds_since(start);
  start = Clock::now();
  const auto grasps = spar::geometry::compute_grasps(object, {}, {});
  const double grasping = seconds_since(start);
  const double total = validate + model + stable + grasping;
  std::printf("%-13s %9zu %8zu %7zu %7zu %9.3f %9.3f %9.3f %9.3f %9.3f %9.4f\n", workload.c_str(),
              triangles, object.faces().size(), poses.size(), grasps.size(), validate, model,
              stable, grasping, total, hull);
  std::printf("ratio %s cgal_hull %.4f\n", workload.c_str(), hull / total);
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  constexpr double kInch = 0.0254;
  std::printf("%-13s %9s %8s %7s %7s %9s %9s %9s %9s %9s %9s\n", "workload", "triangles", "faces",
              "poses", "grasps", "valid s", "model s", "poses s", "grasps s", "total s", "hull s");
  run("sphere-20k", sphere(100, 101, 1.0));
  run("sphere-200k", sphere(400, 251, 1.0));
  run("prism-1000", prism(1000, kInch));
  run("ball-2k", sphere(40, 26, kInch));
  if (!quick) {
    run("sphere-800k", sphere(800, 501, 1.0));
    run("prism-4000", prism(4000, kInch));
    run("ball-8k", sphere(80, 51, kInch));
  }
  return 0;
}
