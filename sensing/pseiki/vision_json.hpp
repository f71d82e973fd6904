// The JSON forms of `spar vision` (normative; Python's spar.vision_* take and return the same).
//
// image file (input of `spar vision match`, output of `spar vision simulate`):
//   {"edges": [{"id": "e1" or 1, "p0": [u, v], "p1": [u, v]}, ...]}
//   Pixels (u right, v down, sensing/camera.hpp). Ids are strings or whole numbers, distinct, and
//   come back as written. p0 != p1. Other keys are ignored (a simulated image adds "truth" per
//   edge and a top-level "truth" with the true poses; a file made from `vision render` output may
//   keep its "object" and "faces"). At most kMaxImageEdges edges.
// render (`spar vision render --json`), the model panel (expected_scene.hpp):
//   {"camera", "projection", "width", "height",
//    "vertices": [{"id": "v1", "p": [u, v], "edges": [edge ids]}],
//    "edges": [{"id": "block/e5", "object": "block", "faces": ["block/f2", ...], "p0", "p1",
//               "pieces": [[p0, p1], ...], "vertices": [vertex ids], "silhouette",
//               "tolerance": {"angle" (rad), "offset" (px), "margin" (px)}}],
//    "faces": [{"id": "block/f2", "object", "edges": [edge ids], "area" (px)}],
//    "objects": [{"id": "block", "faces": [...], "edges": [...]}]}
//   p0, p1: the visible extent (the first piece's start, the last piece's end).
// match (`spar vision match --json`), the image panel after verification (matcher.hpp):
//   {"camera", "passes",
//    "edges": [{"id", "label": "block/e5" or null, "belief"}] (one per input edge, in input
//              order; "merged_with": [ids] when the merger joined it with others, "pieces":
//              [{"label", "belief", "p0", "p1"}] when the splitter cut it; belief of a null
//              label: the belief that the edge is no model edge),
//    "faces": [{"label": "block/f2", "members": [ids], "belief"}],
//    "objects": [{"label": "block", "belief", "coverage"}],
//    "scene": {"belief", "disbelief", "accepted", "threshold"},
//    "pose_correction": null or {"object" (an object's name, or the camera's), "frame"
//      ("object" or "camera"), "xyz", "rpy" (the correction: eq. 2 offsets, the rotation about
//      z), "pose": {"xyz", "rpy"} (the corrected pose), "residual" (px, RMS), "residual_before"
//      (px), "uncertainty": {"dx", "dy", "dz", "dtheta"} (after the verification), "edges"},
//    "units": {"length", "angle"}}
//   Lengths and angles of poses in the scenario's units (`units`), like spar's reports.
//
// Mistakes in an image file throw SensingError "file: edges[3].p0: expected [u, v] ...", and
// "file:line:col: JSON syntax error: ..." for text that is not JSON.
//
// Example:
//   const ImageFile image = parse_image_json(R"({"edges": [{"id": 1, "p0": [0, 0],
//                                                           "p1": [10, 0]}]})", "inline");
//   const Verification result = verify(scene, camera, uncertainty, image.edges, {});
//   std::cout << match_json(result, image, "front", {}).dump(2);
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "spar/sensing/pseiki/matcher.hpp"
#include "spar/sensing/pseiki/simulate.hpp"

namespace spar::sensing::pseiki {

inline constexpr std::size_t kMaxImageEdges = 100000;

struct ImageFile {
  std::vector<ImageEdgeInput> edges;        // ids as text, for messages
  std::vector<nlohmann::ordered_json> ids;  // as written
};

[[nodiscard]] ImageFile image_file(const nlohmann::json& document, const std::string& source);
[[nodiscard]] ImageFile parse_image_json(std::string_view text, const std::string& source);
// Reads the file (SensingError: "path: cannot read the image file: no such file").
[[nodiscard]] ImageFile load_image_file(const std::filesystem::path& path);

// How poses are shown: the scenario's units.
struct OutputUnits {
  double metres_per_length{1}, radians_per_angle{1};
  std::string length{"m"}, angle{"rad"};
};

[[nodiscard]] nlohmann::ordered_json render_json(const ModelPanel& panel,
                                                 const std::string& camera);
[[nodiscard]] nlohmann::ordered_json match_json(const Verification& result, const ImageFile& image,
                                                const std::string& camera, const OutputUnits& units,
                                                double acceptance = 0.5);
// A simulated image as an image file, with its truth (true poses in `units`).
[[nodiscard]] nlohmann::ordered_json simulated_json(const SimulatedImage& image,
                                                    const Scene& believed, const Camera& camera,
                                                    const std::string& camera_name,
                                                    const OutputUnits& units);

}  // namespace spar::sensing::pseiki
