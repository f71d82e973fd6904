// Fuzz target: the OFF and OBJ readers (geometry/mesh_io.hpp) and what `spar object` computes from
// a mesh they accept. The first byte picks the format (even: OFF, odd: OBJ).
// Property: any text is either refused with spar::Error (GeometryError: file:line and what is
// wrong) or gives an object model, stable poses and grasps; no crash, no other exception, no
// sanitizer report.
#include <cstdint>
#include <string>

#include "spar/common/error.hpp"
#include "spar/geometry/grasps.hpp"
#include "spar/geometry/mesh_io.hpp"
#include "spar/geometry/object.hpp"
#include "spar/geometry/stable_poses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    spar::geometry::Mesh mesh = (data[0] % 2 == 0) ? spar::geometry::parse_off(text, "fuzz.off")
                                                   : spar::geometry::parse_obj(text, "fuzz.obj");
    const spar::geometry::ObjectModel object("fuzz", std::move(mesh));
    (void)spar::geometry::stable_poses(object);
    (void)spar::geometry::compute_grasps(object, {}, {});
  } catch (const spar::Error&) {
    return 0;
  }
  return 0;
}
