// The seed's two objects (SPAR's peg-and-block task) and a few test shapes, built in code from
// the seed's inch dimensions (given below in inches) and returned in metres, like everything inside
// spar: each builder works in inches and scales the finished mesh by exactly 0.0254. Each also
// ships as an OFF file under examples/objects/ (written from these builders by `spar object NAME
// --write-off FILE`), so a file and its built-in give the same face ids.
//
// peg:   a 3 x 3 x 1.5 base, origin at the centre of its bottom, with a 0.5 x 0.5 square cross
//        hole along x through the base (centre at z = 0.75); a shaft of 1.5 in across flats as an
//        octagonal prism, 3.5 long, standing on the base along +z. Simplifications: the cylinder is
//        an octagon, the round cross hole is square.
// block: 3.5 x 3 x 3 (x, y, z), origin at the centre of its bottom; a blind 1.6 x 1.6 square hole
//        for the peg, 2 deep, opening on the top (+z) face; a 0.5 x 0.5 square cross hole along y
//        through the block at z = 2, crossing the peg hole. Simplification: both holes are square.
// cube:  a 1 in cube; l-shape: the L of the stable-pose tests (1 in units). Faces still named by
//        their plane carry its inch coordinate: "+z (z=1 in)".
//
// Example:
//   ObjectModel peg = make_builtin_object("peg");    // metres
//   peg.face(7).name;                                 // "base bottom"
//   peg.face_pairs()[0].width / units::kInch;         // 3: the base is 3 in across
//   for (const std::string& name : builtin_object_names()) ...
//   std::string header = builtin_description("peg");  // the OFF file's comment
#pragma once

#include <string>
#include <vector>

#include "spar/geometry/mesh.hpp"
#include "spar/geometry/object.hpp"

namespace spar::geometry {

[[nodiscard]] std::vector<std::string> builtin_object_names();
// The built-in object's mesh, validated. Throws GeometryError for an unknown name (the message
// lists the known ones).
[[nodiscard]] Mesh builtin_mesh(const std::string& name);
// content_digest of the built-in mesh whose validation was recorded (0 for an unknown name):
// builtin_mesh gives a mesh with this digest without validating it again.
[[nodiscard]] std::uint64_t builtin_validated_digest(const std::string& name);
[[nodiscard]] ObjectModel make_builtin_object(const std::string& name);
// The header comment written at the top of the object's OFF file.
[[nodiscard]] std::string builtin_description(const std::string& name);
// `spar object`'s OBJECT argument: an .off / .obj file when `argument` names one (coordinates
// times `metres_per_unit`, the object named after the file's stem), else a built-in (metres).
// GeometryError for a directory, or for neither a file nor a built-in (listing the built-ins).
[[nodiscard]] ObjectModel load_object(const std::string& argument, double metres_per_unit);

}  // namespace spar::geometry
