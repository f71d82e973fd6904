// PSEIKI end to end (survey seed 003, section 4): the control that schedules the knowledge
// sources on the blackboard, accepts or rejects the whole interpretation by the belief at the top
// of the hierarchy, and corrects the pose an accepted one verifies.
//
// match() is one pass over a model panel:
//   labeler.label -> splitter -> labeler.label (the pieces) -> merger -> labeler.label (merged);
//   then up to `rounds` rounds of: labeler.update (constraint-based, with the doubt that flowed
//   down from the last grouping) -> merger -> labeler.label -> grouper (faces, objects, scene);
//   stopping early when no label changed and no belief moved by 1e-4.
// verify() is what a vision researcher reproducing PSEIKI for self-location does with it, in
// `passes` passes (default 2):
//   pass 1 matches against the expected scene at the believed poses, with tolerances as wide as
//     their uncertainty (expected_scene.hpp); its labels give least-squares corrections of the
//     uncertain poses (pose_correction.hpp): the camera's when it is uncertain (a robot locating
//     itself on a known map), else each uncertain object's from its own edges (verification in a
//     work cell with a fixed camera);
//   pass 2 matches again against the expected scene at the corrected poses, whose tolerances come
//     from the corrections' own uncertainty: misregistration no longer hides a shadow next to an
//     edge, and the splitter sees where model edges end. Its scene belief decides (accepted when
//     >= `acceptance`) and its corrections, added to the first ones, are the result.
// The survey does not say that PSEIKI iterated; it says the belief at the top decides and the
// matches reduce the uncertainty. One pass is `passes = 1`.
// The pose reported as "the" correction: `target` (a scene object index, kCameraTarget) or, by
// default, the camera when its pose is uncertain, else the uncertain object whose edges the
// uncertainty moves most in the image. A rejected interpretation has no correction.
//
// Example:
//   const Verification result = verify(scene, camera, uncertainty, image_edges, {});
//   result.board.scene.belief;                 // the top of the hierarchy
//   if (result.accepted) result.correction->uncertainty;   // the pose's after verification
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "spar/sensing/pseiki/blackboard.hpp"
#include "spar/sensing/pseiki/pose_correction.hpp"

namespace spar::sensing::pseiki {

inline constexpr int kAutomaticTarget = -2;

struct MatchOptions {
  int max_candidates{4};            // labels kept per image edge (labeler.hpp)
  int rounds{6};                    // at most, per pass
  double acceptance{0.5};           // scene belief that accepts the interpretation
  double detection_probability{1};  // of the camera, in (0, 1]
  int passes{2};                    // verify(): 1 or 2
  int target{kAutomaticTarget};     // verify(): the pose to correct
  int supersampling{2};             // of the expected scene's faces
};

// One pass; the blackboard refers to `model`, which must outlive it.
[[nodiscard]] Blackboard match(const ModelPanel& model, std::vector<ImageEdgeInput> image,
                               const MatchOptions& options);

struct Verification {
  std::unique_ptr<ModelPanel> expected;  // the panel the last pass matched against
  Blackboard board;                      // the last pass (refers to *expected)
  bool accepted{false};
  int passes{0};                             // run
  int target{kCameraTarget};                 // the pose reported (kAutomaticTarget: none uncertain)
  std::optional<PoseCorrection> correction;  // accepted only: the target's, from the believed pose
  std::vector<PoseCorrection> corrections;   // accepted only: every pose corrected
};

[[nodiscard]] Verification verify(const Scene& scene, const Camera& camera,
                                  const ExpectationUncertainty& uncertainty,
                                  std::vector<ImageEdgeInput> image, const MatchOptions& options);

}  // namespace spar::sensing::pseiki
