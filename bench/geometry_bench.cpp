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
// Collision (geometry/collision.hpp): FCL against CGAL's Rigid_triangle_mesh_collision_detection
// on the project's meshes: the built-ins (peg, block, cube, l-shape) and the robots' collision
// STLs in data/robots (UR5, Panda), every pair of them at random relative poses around contact
// (about half the poses intersect), the same poses for both libraries. Rows, in queries per
// second: surface intersection (FCL collide vs CGAL get_all_intersections), intersection with
// inclusion (spar's collide, i.e. FCL distance plus the inside test, vs CGAL
// get_all_intersections_and_inclusions), the same with spar's 1 mm margin (FCL's distance pruned
// at the margin), and distance (FCL; CGAL has no mesh-mesh distance).
//
//   geometry_bench [--quick]
// Prints a table of per-stage times and `ratio <workload> cgal_hull <hull time / our time>` (the
// share of spar's time CGAL's hull alone would take; 1 would be no work beyond the hull), then the
// collision rows with `ratio collide fcl/cgal <FCL queries per second / CGAL's>`.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/STL.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Rigid_triangle_mesh_collision_detection.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "bench/timing.hpp"
#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/collision.hpp"
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

// --- collision: FCL vs CGAL on the same pairs and poses ---

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Detector = CGAL::Rigid_triangle_mesh_collision_detection<SurfaceMesh>;

struct CollisionMesh {
  std::string name;
  Mesh mesh;  // triangle soup, vertices welded
};

std::vector<CollisionMesh> collision_meshes() {
  std::vector<CollisionMesh> meshes;
  for (const std::string& name : spar::geometry::builtin_object_names())
    meshes.push_back({name, spar::geometry::builtin_mesh(name)});
  std::vector<std::filesystem::path> files;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(std::string(SPAR_CORPUS_DIR) + "/robots"))
    if (entry.path().extension() == ".stl") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    // Robot meshes are read as soups (not every one is closed); CGAL welds equal points.
    std::vector<Kernel::Point_3> points;
    std::vector<std::array<int, 3>> triangles;
    std::ifstream in(file, std::ios::binary);
    if (!CGAL::IO::read_STL(in, points, triangles)) continue;
    Mesh mesh;
    mesh.source = file.string();
    for (const auto& p : points) mesh.vertices.emplace_back(p.x(), p.y(), p.z());
    mesh.triangles = triangles;
    mesh.triangle_names.assign(triangles.size(), "");
    mesh.triangle_lines.assign(triangles.size(), 0);
    meshes.push_back(
        {file.parent_path().parent_path().parent_path().filename().string().substr(0, 5) + "/" +
             file.stem().string(),
         std::move(mesh)});
  }
  return meshes;
}

SurfaceMesh to_surface_mesh(const Mesh& mesh) {
  std::vector<Kernel::Point_3> points;
  for (const auto& v : mesh.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::vector<std::size_t>> polygons;
  for (const auto& t : mesh.triangles)
    polygons.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  namespace pmp = CGAL::Polygon_mesh_processing;
  pmp::repair_polygon_soup(points, polygons);
  pmp::orient_polygon_soup(points, polygons);
  SurfaceMesh out;
  pmp::polygon_soup_to_polygon_mesh(points, polygons, out);
  return out;
}

CGAL::Aff_transformation_3<Kernel> to_cgal(const spar::geometry::Pose& pose) {
  const Eigen::Matrix4d m = pose.matrix();
  return {m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1),
          m(1, 2), m(1, 3), m(2, 0), m(2, 1), m(2, 2), m(2, 3)};
}

struct Query {
  int a{0}, b{0};
  spar::geometry::Pose pose_a, pose_b;
};

// The meshes as each library holds them: FCL's BVHs, spar's bodies, CGAL's surface meshes in one
// detector.
struct CollisionShapes {
  std::vector<std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>>> bvhs;
  std::vector<spar::geometry::Body> bodies;
  std::vector<SurfaceMesh> surfaces;
  std::size_t triangles{0};
  Detector detector;

  explicit CollisionShapes(const std::vector<CollisionMesh>& meshes) {
    for (const CollisionMesh& m : meshes) {
      auto bvh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
      std::vector<fcl::Triangle> tris;
      for (const auto& t : m.mesh.triangles) tris.emplace_back(t[0], t[1], t[2]);
      bvh->beginModel();
      bvh->addSubModel(m.mesh.vertices, tris);
      bvh->endModel();
      bvhs.push_back(bvh);
      bodies.emplace_back(m.name, spar::geometry::CollisionShape(m.mesh));
      surfaces.push_back(to_surface_mesh(m.mesh));
      triangles += m.mesh.triangles.size();
    }
    for (const SurfaceMesh& surface : surfaces) detector.add_mesh(surface);
  }
};

// Random poses of every pair (a mesh with itself included), `per_pair` each: b turned at random,
// its centre within the sum of both bounding radii of a's.
std::vector<Query> random_queries(const std::vector<spar::geometry::Body>& bodies, int per_pair) {
  namespace geo = spar::geometry;
  std::mt19937 random(20261123);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<Query> queries;
  for (std::size_t a = 0; a < bodies.size(); ++a)
    for (std::size_t b = a; b < bodies.size(); ++b)
      for (int k = 0; k < per_pair; ++k) {
        const Eigen::AlignedBox3d box_a = bodies[a].bounds(), box_b = bodies[b].bounds();
        const double reach = (box_a.diagonal().norm() + box_b.diagonal().norm()) / 2;
        Eigen::Vector3d offset(unit(random), unit(random), unit(random));
        offset *= 0.8 * reach / std::max(1.0, offset.norm());
        const Eigen::Quaterniond turn =
            Eigen::Quaterniond(unit(random), unit(random), unit(random), unit(random)).normalized();
        Query q{static_cast<int>(a), static_cast<int>(b), geo::Pose::Identity(),
                geo::Pose::Identity()};
        q.pose_a.translation() = -box_a.center();
        q.pose_b =
            geo::Pose(Eigen::Translation3d(offset) * turn * Eigen::Translation3d(-box_b.center()));
        queries.push_back(q);
      }
  return queries;
}

// Queries per second of each library's collision and distance tests, and where they disagree.
struct CollisionRates {
  double fcl_collide{0}, cgal_collide{0}, spar_collide{0}, spar_collide_margin{0};
  double cgal_inclusions{0}, fcl_distance{0}, spar_distance{0}, checksum{0};
  std::size_t hits{0}, disagreements{0}, self_pairs{0}, within_margin{0};
  std::size_t inclusion_disagreements{0}, inclusions{0};
};

CollisionRates time_queries(CollisionShapes& shapes, const std::vector<Query>& queries,
                            int repeats) {
  namespace geo = spar::geometry;
  const auto& bvhs = shapes.bvhs;
  const auto& bodies = shapes.bodies;
  Detector& detector = shapes.detector;
  CollisionRates out;
  std::vector<char> fcl_hits(queries.size()), cgal_hits(queries.size());
  const auto rate = [&](const auto& query) {
    const double seconds = spar::bench::time_median(repeats, [&] {
      for (std::size_t i = 0; i < queries.size(); ++i) query(i);
    });
    return queries.size() / seconds;
  };
  out.fcl_collide = rate([&](std::size_t i) {
    const Query& q = queries[i];
    fcl::CollisionRequestd request;
    fcl::CollisionResultd result;
    fcl::collide(bvhs[q.a].get(), q.pose_a, bvhs[q.b].get(), q.pose_b, request, result);
    fcl_hits[i] = result.isCollision();
  });
  out.cgal_collide = rate([&](std::size_t i) {
    const Query& q = queries[i];
    detector.set_transformation(q.a, to_cgal(q.pose_a));
    detector.set_transformation(q.b, to_cgal(q.pose_b));
    const std::array<std::size_t, 1> other = {static_cast<std::size_t>(q.b)};
    // A mesh against itself: a second copy is not in the detector, so compare with FCL's own.
    cgal_hits[i] = q.a == q.b ? fcl_hits[i] : !detector.get_all_intersections(q.a, other).empty();
  });
  for (std::size_t i = 0; i < queries.size(); ++i) {
    out.hits += fcl_hits[i];
    out.disagreements += fcl_hits[i] != cgal_hits[i];
    out.self_pairs += queries[i].a == queries[i].b;
  }
  std::vector<char> spar_hits(queries.size()), cgal_inclusion_hits(queries.size());
  out.spar_collide_margin = rate([&](std::size_t i) {
    const Query& q = queries[i];
    out.within_margin += geo::collide({&bodies[q.a], q.pose_a}, {&bodies[q.b], q.pose_b}, 0.001);
  });
  out.spar_collide = rate([&](std::size_t i) {
    const Query& q = queries[i];
    spar_hits[i] = geo::collide({&bodies[q.a], q.pose_a}, {&bodies[q.b], q.pose_b}, 0.0);
  });
  out.cgal_inclusions = rate([&](std::size_t i) {
    const Query& q = queries[i];
    if (q.a == q.b) return;
    detector.set_transformation(q.a, to_cgal(q.pose_a));
    detector.set_transformation(q.b, to_cgal(q.pose_b));
    const std::array<std::size_t, 1> other = {static_cast<std::size_t>(q.b)};
    cgal_inclusion_hits[i] = !detector.get_all_intersections_and_inclusions(q.a, other).empty();
  });
  for (std::size_t i = 0; i < queries.size(); ++i) {
    if (queries[i].a == queries[i].b) continue;
    out.inclusion_disagreements += spar_hits[i] != cgal_inclusion_hits[i];
    out.inclusions += cgal_inclusion_hits[i] && !fcl_hits[i];
  }
  out.fcl_distance = rate([&](std::size_t i) {
    const Query& q = queries[i];
    fcl::DistanceRequestd request;
    fcl::DistanceResultd result;
    out.checksum +=
        fcl::distance(bvhs[q.a].get(), q.pose_a, bvhs[q.b].get(), q.pose_b, request, result);
  });
  out.spar_distance = rate([&](std::size_t i) {
    const Query& q = queries[i];
    out.checksum += geo::proximity({&bodies[q.a], q.pose_a}, {&bodies[q.b], q.pose_b}).distance;
  });
  return out;
}

void collision_section(bool quick) {
  const std::vector<CollisionMesh> meshes = collision_meshes();
  CollisionShapes shapes(meshes);
  const int per_pair = quick ? 4 : 20;
  const std::vector<Query> queries = random_queries(shapes.bodies, per_pair);
  const int repeats = quick ? 2 : 5;
  const CollisionRates r = time_queries(shapes, queries, repeats);
  std::printf(
      "\ncollision: %zu meshes (%zu triangles), %zu pairs x %d poses = %zu queries, "
      "%zu intersecting (FCL), load %s\n",
      meshes.size(), shapes.triangles, queries.size() / per_pair, per_pair, queries.size(), r.hits,
      spar::bench::load_average().c_str());
  std::printf("%-44s %14s\n", "query", "per second");
  std::printf("%-44s %14.0f\n", "FCL collide (surfaces)", r.fcl_collide);
  std::printf("%-44s %14.0f\n", "CGAL get_all_intersections (surfaces)", r.cgal_collide);
  std::printf("%-44s %14.0f\n", "spar collide (FCL collide + inside test)", r.spar_collide);
  std::printf("%-44s %14.0f\n", "spar collide, 1 mm margin (+ FCL distance)",
              r.spar_collide_margin);
  std::printf("%-44s %14.0f\n", "CGAL get_all_intersections_and_inclusions", r.cgal_inclusions);
  std::printf("%-44s %14.0f\n", "FCL distance", r.fcl_distance);
  std::printf("%-44s %14.0f\n", "spar proximity (distance + inside test)", r.spar_distance);
  std::printf("%-44s %14s\n", "CGAL mesh-mesh distance", "none");
  std::printf(
      "disagreements: surfaces %zu of %zu (self pairs %zu not asked of CGAL), "
      "with inclusion %zu (inclusions without surface contact: %zu); within 1 mm: %zu\n",
      r.disagreements, queries.size(), r.self_pairs, r.inclusion_disagreements, r.inclusions,
      r.within_margin / repeats);
  std::printf("ratio collide fcl/cgal %.2f\n", r.fcl_collide / r.cgal_collide);
  std::printf("ratio collide_with_inclusion spar/cgal %.2f\n", r.spar_collide / r.cgal_inclusions);
  std::printf("ratio distance spar/fcl %.2f   (checksum %.3g)\n", r.spar_distance / r.fcl_distance,
              r.checksum);
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
  collision_section(quick);
  return 0;
}
