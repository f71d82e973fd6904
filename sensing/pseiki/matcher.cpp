#include "spar/sensing/pseiki/matcher.hpp"

#include <algorithm>
#include <cmath>

#include "spar/sensing/error.hpp"
#include "spar/sensing/pseiki/grouper.hpp"
#include "spar/sensing/pseiki/labeler.hpp"
#include "spar/sensing/pseiki/merger.hpp"
#include "spar/sensing/pseiki/splitter.hpp"

namespace spar::sensing::pseiki {
namespace {

constexpr double kSettled = 1e-4;  // belief change below which a round changed nothing

bool any(const kinematics::PoseUncertainty& h) {
  return h.dx > 0 || h.dy > 0 || h.dz > 0 || h.dtheta > 0;
}

// The camera when its pose is uncertain, else the uncertain object whose edges the uncertainty
// moves most; kAutomaticTarget when nothing is uncertain.
int choose_target(const ModelPanel& panel, const ExpectationUncertainty& uncertainty) {
  if (any(uncertainty.camera)) return kCameraTarget;
  int best = kAutomaticTarget;
  double widest = 0;
  for (std::size_t o = 0; o < uncertainty.objects.size(); ++o) {
    if (!any(uncertainty.objects[o])) continue;
    for (const int e : panel.objects()[o].edges) {
      const double offset = panel.edges()[static_cast<std::size_t>(e)].tolerance.offset;
      if (best == kAutomaticTarget || offset > widest) {
        best = static_cast<int>(o);
        widest = offset;
      }
    }
  }
  return best;
}

kinematics::PoseUncertainty prior_of(const ExpectationUncertainty& uncertainty, int target) {
  if (target == kCameraTarget) return uncertainty.camera;
  if (target < 0 || uncertainty.objects.empty()) return {};
  return uncertainty.objects.at(static_cast<std::size_t>(target));
}

// The first correction followed by the second (eq. 2 offsets add: the rotations are about the
// same vertical axis through the same origin).
PoseCorrection chained(const PoseCorrection& first, const PoseCorrection& second,
                       const Eigen::Isometry3d& believed) {
  PoseCorrection out = second;
  out.offset = {first.offset.dx + second.offset.dx, first.offset.dy + second.offset.dy,
                first.offset.dz + second.offset.dz, first.offset.dtheta + second.offset.dtheta};
  out.pose = offset_pose(believed, out.offset);
  out.residual_before_px = first.residual_before_px;
  return out;
}

}  // namespace

Blackboard match(const ModelPanel& model, std::vector<ImageEdgeInput> image,
                 const MatchOptions& options) {
  if (options.rounds < 0) throw SensingError("match: the number of rounds must be >= 0");
  Blackboard board(model, std::move(image), options.detection_probability);
  const Labeler labeler(options.max_candidates);
  const Merger merger;
  const Grouper grouper;
  labeler.label(board);
  if (Splitter().split(board) > 0) labeler.label(board);
  if (merger.merge(board) > 0) labeler.label(board);
  grouper.group(board);
  for (int round = 0; round < options.rounds; ++round) {
    std::vector<std::pair<int, double>> before;
    for (const ImageEdge& edge : board.edges) before.emplace_back(edge.label, edge.belief);
    labeler.update(board);
    const bool merged = merger.merge(board) > 0;
    if (merged) labeler.label(board);
    grouper.group(board);
    bool settled = !merged;
    for (std::size_t e = 0; e < before.size() && settled; ++e)
      settled = board.edges[e].label == before[e].first &&
                std::abs(board.edges[e].belief - before[e].second) < kSettled;
    if (settled) break;
  }
  return board;
}

Verification verify(const Scene& scene, const Camera& camera,
                    const ExpectationUncertainty& uncertainty, std::vector<ImageEdgeInput> image,
                    const MatchOptions& options) {
  if (options.passes < 1 || options.passes > 2)
    throw SensingError("verify: 1 or 2 passes, got " + std::to_string(options.passes));
  const ExpectedSceneOptions panel_options{.supersampling = options.supersampling};
  auto expected = std::make_unique<ModelPanel>(scene, camera, uncertainty, panel_options);
  Blackboard board = match(*expected, image, options);
  const int target =
      options.target == kAutomaticTarget ? choose_target(*expected, uncertainty) : options.target;
  // The poses to correct: the camera's if uncertain, else every uncertain object's.
  std::vector<int> targets;
  if (any(uncertainty.camera)) {
    targets.push_back(kCameraTarget);
  } else {
    for (std::size_t o = 0; o < uncertainty.objects.size(); ++o)
      if (any(uncertainty.objects[o])) targets.push_back(static_cast<int>(o));
  }
  std::vector<PoseCorrection> corrections;
  for (const int t : targets)
    if (auto c = correct_pose(board, t, prior_of(uncertainty, t))) corrections.push_back(*c);
  int passes = 1;

  if (options.passes == 2 && !corrections.empty()) {
    // The expected scene again, at the corrected poses and with their uncertainty after pass 1.
    const auto corrected_pose = [&](int t, const Eigen::Isometry3d& believed) {
      for (const PoseCorrection& c : corrections)
        if (c.target == t) return c.pose;
      return believed;
    };
    Scene corrected;
    for (std::size_t o = 0; o < scene.objects().size(); ++o) {
      const SceneObject& object = scene.objects()[o];
      corrected.add(object.name, *object.model, *object.features,
                    corrected_pose(static_cast<int>(o), object.pose));
    }
    const Camera moved_camera(camera.projection(), camera.intrinsics(),
                              corrected_pose(kCameraTarget, camera.pose()));
    ExpectationUncertainty narrowed = uncertainty;
    for (const PoseCorrection& c : corrections)
      (c.target == kCameraTarget ? narrowed.camera
                                 : narrowed.objects[static_cast<std::size_t>(c.target)]) =
          c.uncertainty;
    auto second_expected =
        std::make_unique<ModelPanel>(corrected, moved_camera, narrowed, panel_options);
    Blackboard second = match(*second_expected, std::move(image), options);
    for (PoseCorrection& c : corrections)
      if (const auto refined = correct_pose(second, c.target, c.uncertainty))
        c = chained(c, *refined,
                    c.target == kCameraTarget
                        ? camera.pose()
                        : scene.objects()[static_cast<std::size_t>(c.target)].pose);
    expected = std::move(second_expected);
    board = std::move(second);
    passes = 2;
  }
  const bool accepted = board.scene.belief >= options.acceptance;
  Verification out{.expected = std::move(expected),
                   .board = std::move(board),
                   .accepted = accepted,
                   .passes = passes,
                   .target = target,
                   .correction = std::nullopt,
                   .corrections = {}};
  if (accepted) {
    out.corrections = std::move(corrections);
    for (const PoseCorrection& c : out.corrections)
      if (c.target == target) out.correction = c;
  }
  return out;
}

}  // namespace spar::sensing::pseiki
