#include "spar/geometry/builtin_objects.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <regex>
#include <string_view>
#include <utility>

#include "spar/common/units.hpp"
#include "spar/geometry/mesh_io.hpp"

namespace spar::geometry {
namespace {

// Gives the faces the builders named by plane ("+z (z=3)") the names a person would use.
void rename(Mesh& mesh, const std::vector<std::pair<std::string, std::string>>& names) {
  for (std::string& name : mesh.triangle_names)
    for (const auto& [from, to] : names)
      if (name == from) name = to;
}

// The seed gives its objects in inches and so do the builders below; spar works in metres. Every
// vertex is multiplied by 0.0254 (vertices that shared a coordinate still share it, so faces stay
// exactly planar), and the plane coordinates left in face names ("+z (z=1)") are marked as inches.
Mesh inches_to_metres(Mesh mesh) {
  static const std::regex plane(R"(^([+-][xyz]) \(([xyz])=([^)]*)\)$)");
  for (std::string& name : mesh.triangle_names)
    name = std::regex_replace(name, plane, "$1 ($2=$3 in)");
  return scale_mesh(std::move(mesh), units::kInch);
}

// The builders defer validation to builtin_mesh.
Mesh peg_mesh() {
  RectilinearSolid base({-1.5, 1.5}, {-1.5, -0.25, 0.25, 1.5}, {0, 0.5, 1.0, 1.5});
  base.carve({-2, -0.25, 0.5}, {2, 0.25, 1.0});  // the cross hole along x
  Mesh mesh = base.to_mesh("<peg>", MeshCheck::kDeferred);
  // Octagon with flats 1.5 apart: circumradius 0.75 / cos(pi / 8).
  attach_prism(mesh, 1.5, regular_polygon(0.75 / std::cos(std::numbers::pi / 8), 8), 3.5, "shaft",
               MeshCheck::kDeferred);
  rename(mesh, {{"-z (z=0)", "base bottom"},
                {"+z (z=1.5)", "base top"},
                {"-x (x=-1.5)", "base -x"},
                {"+x (x=1.5)", "base +x"},
                {"-y (y=-1.5)", "base -y"},
                {"+y (y=1.5)", "base +y"},
                {"-z (z=1)", "cross hole ceiling"},
                {"+z (z=0.5)", "cross hole floor"},
                {"-y (y=0.25)", "cross hole wall +y"},
                {"+y (y=-0.25)", "cross hole wall -y"}});
  return inches_to_metres(std::move(mesh));
}

Mesh block_mesh() {
  RectilinearSolid block({-1.75, -0.8, -0.25, 0.25, 0.8, 1.75}, {-1.5, -0.8, 0.8, 1.5},
                         {0, 1, 1.75, 2.25, 3});
  block.carve({-0.8, -0.8, 1}, {0.8, 0.8, 4});      // the blind hole for the peg
  block.carve({-0.25, -2, 1.75}, {0.25, 2, 2.25});  // the small cross hole along y
  Mesh mesh = block.to_mesh("<block>", MeshCheck::kDeferred);
  rename(mesh, {{"-z (z=0)", "bottom"},
                {"+z (z=3)", "top"},
                {"-x (x=-1.75)", "left -x"},
                {"+x (x=1.75)", "right +x"},
                {"-y (y=-1.5)", "front -y"},
                {"+y (y=1.5)", "back +y"},
                {"+z (z=1)", "peg hole floor"},
                {"+x (x=-0.8)", "peg hole wall -x"},
                {"-x (x=0.8)", "peg hole wall +x"},
                {"+y (y=-0.8)", "peg hole wall -y"},
                {"-y (y=0.8)", "peg hole wall +y"},
                {"-z (z=2.25)", "cross hole ceiling"},
                {"+z (z=1.75)", "cross hole floor"},
                {"+x (x=-0.25)", "cross hole wall -x"},
                {"-x (x=0.25)", "cross hole wall +x"}});
  return inches_to_metres(std::move(mesh));
}

Mesh l_shape_mesh() {
  // Profile in xz: a 1 x 5 upright at x in [0, 1] and a 3 x 1 foot at x in [1, 4]; 1 deep in y.
  RectilinearSolid l_shape({0, 1, 4}, {0, 1}, {0, 1, 5});
  l_shape.set_filled(1, 0, 1, false);
  return inches_to_metres(l_shape.to_mesh("<l-shape>", MeshCheck::kDeferred));
}

}  // namespace

std::vector<std::string> builtin_object_names() { return {"peg", "block", "cube", "l-shape"}; }

std::uint64_t builtin_validated_digest(const std::string& name) {
  // Recorded from builtin_mesh on Debian 12 x86-64 (GCC and clang give the same bits), each mesh
  // accepted unchanged by validate_closed_mesh from scratch: BuiltinObjects.
  // KnownDigestsAreOfMeshesThatValidate does that again and fails when a builder changes.
  static constexpr std::pair<std::string_view, std::uint64_t> kDigests[] = {
      {"peg", 0xb4fb4d60c7c2f64b},
      {"block", 0x47419db69cf2e325},
      {"cube", 0x2db4a57d3205833d},
      {"l-shape", 0x070770ed24c791f7},
  };
  for (const auto& [builtin, digest] : kDigests)
    if (builtin == name) return digest;
  return 0;
}

Mesh builtin_mesh(const std::string& name) {
  // The builders defer validation; the finished mesh is validated here, once, unless it is bit
  // for bit the one whose validation was recorded: validate_closed_mesh skips a mesh whose
  // validated_digest is its content's, which saves some 2 ms of exact-predicate work per
  // scenario load. Any other (a changed builder, another floating-point environment) is
  // validated as a file's mesh is.
  const auto validated = [&](Mesh mesh) {
    mesh.validated_digest = builtin_validated_digest(name);
    validate_closed_mesh(mesh);
    return mesh;
  };
  if (name == "peg") return validated(peg_mesh());
  if (name == "block") return validated(block_mesh());
  if (name == "cube") return validated(inches_to_metres(make_box({1, 1, 1})));
  if (name == "l-shape") return validated(l_shape_mesh());
  std::string known;
  for (const auto& n : builtin_object_names()) known += (known.empty() ? "" : ", ") + n;
  throw GeometryError("no built-in object '" + name + "' (known: " + known + ")");
}

ObjectModel make_builtin_object(const std::string& name) {
  return ObjectModel(name, builtin_mesh(name));
}

std::string builtin_description(const std::string& name) {
  if (name == "peg")
    return "spar built-in object 'peg' (the seed's peg-and-block task). Coordinates in\n"
           "metres; the dimensions below are inches (1 in = 0.0254 m). Base 3 x 3 x 1.5, origin\n"
           "at the centre of its bottom face, with a 0.5 x 0.5 square cross hole along x through\n"
           "the base (centre z = 0.75). Shaft along +z: 1.5 across flats, 3.5 long.\n"
           "Simplifications: the cylindrical shaft is an octagonal prism and the round cross\n"
           "hole is square. Faces are named in the trailing comments.";
  if (name == "block")
    return "spar built-in object 'block' (the seed's peg-and-block task). Coordinates in\n"
           "metres; the dimensions below are inches (1 in = 0.0254 m). 3.5 x 3 x 3 (x, y, z),\n"
           "origin at the centre of its bottom face. A blind 1.6 x 1.6 square hole for the peg,\n"
           "2 deep, opens on the top (+z) face; a 0.5 x 0.5 square cross hole along y at z = 2\n"
           "crosses it. Simplification: both round holes are square. Faces are named in the\n"
           "trailing comments.";
  if (name == "cube") return "spar built-in object 'cube': a 1 in cube, [0, 0.0254]^3 in metres.";
  if (name == "l-shape")
    return "spar built-in object 'l-shape': an L profile in xz (a 1 x 5 in upright, a 3 x 1 in\n"
           "foot), 1 in deep in y; coordinates in metres. Two of its seven hull facets are not\n"
           "stable.";
  return name;
}

ObjectModel load_object(const std::string& argument, double metres_per_unit) {
  if (std::filesystem::is_directory(argument))
    throw GeometryError(argument +
                        " is a directory: give an .off or .obj file, or a built-in name");
  if (std::filesystem::exists(argument))
    return ObjectModel(std::filesystem::path(argument).stem().string(),
                       read_mesh_file(argument, metres_per_unit));
  const std::vector<std::string> names = builtin_object_names();
  if (std::find(names.begin(), names.end(), argument) != names.end())
    return make_builtin_object(argument);
  std::string known;
  for (const std::string& name : names) known += (known.empty() ? "" : ", ") + name;
  throw GeometryError(argument + ": no such file, nor a built-in object (" + known + ")");
}

}  // namespace spar::geometry
