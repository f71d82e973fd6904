// geometry::GeometryError: bad geometry or a bad file. The message names the source (file or
// builder) and, where it can, the line of the polygon at fault. Derives from spar::Error
// (common/error.hpp), like every module's error.
//
// Example:
//   try {
//     const Mesh mesh = read_mesh_file("part.off");
//   } catch (const GeometryError& error) {
//     std::cerr << error.what() << '\n';   // "part.off:7: a vertex needs 3 coordinates"
//   }
#pragma once

#include "spar/common/error.hpp"

namespace spar::geometry {

class GeometryError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::geometry
