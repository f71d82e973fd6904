// The pose update after an accepted interpretation (survey seed 003, section 4: "Once the
// correspondence between the image elements and model elements is established, it is then
// possible to use camera calibration information to reduce the amount of uncertainty in the
// robot's position and orientation"): a least-squares correction of one pose, an object's or the
// camera's, from the labelled image edges.
//
// Unknowns: the pose's eq. 2 offsets (dx, dy, dz, dtheta), those with a half-width > 0 in the
// prior; the others stay 0. Each labelled edge e (active, belief >= kCorrectionBelief, of the
// corrected object, or of any object when the camera is corrected) gives two residuals: the
// distances of e's end points from the line of its label's model edge projected at the corrected
// pose (end point to line, so partial edges count fully). Cost:
//   sum_i Bel(e_i) huber(r_i) + sum_k (x_k / h_k)^2 sigma_px^2,
// with h_k the half-widths, sigma_px = max(noise, 0.5 px): least squares inside the uncertainty
// box (the scenario's worst-case bound: every step is projected back into it) with a weak prior
// (one standard deviation = the half-width) that only decides directions the edges leave open.
// Huber's function with k = 3 sigma_px keeps a wrong label from dragging the pose. Gauss-Newton
// on iteratively reweighted least squares, Jacobians by central differences, steps halved while
// the cost grows.
// Uncertainty after the verification step: the covariance s^2 (J^T W J + prior)^-1, s^2 =
// max(sigma_px^2, the weighted mean squared residual), as half-widths 3 sqrt(diagonal), never
// above the prior's. The residual reported is the RMS end-point distance, pixels.
//
// Example:
//   const auto correction = correct_pose(board, /*target=*/0, {.dx = 0.01, .dy = 0.01});
//   if (correction) correction->pose;           // the object's corrected pose
//   if (correction) correction->uncertainty.dx; // what remains of dx after the verification
#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "spar/kinematics/uncertain_pose.hpp"
#include "spar/sensing/pseiki/blackboard.hpp"

namespace spar::sensing::pseiki {

inline constexpr double kCorrectionBelief = 0.5;
inline constexpr int kCameraTarget = -1;

struct PoseCorrection {
  int target{kCameraTarget};                              // scene object index, or kCameraTarget
  PoseOffset offset;                                      // from the believed pose
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  // the corrected pose
  double residual_px{0};                      // RMS end-point distance after the correction
  double residual_before_px{0};               // ... at the believed pose
  kinematics::PoseUncertainty uncertainty{};  // after the verification step
  int observations{0};                        // image edges used
};

// Nothing when no component is uncertain or fewer than two edges qualify.
[[nodiscard]] std::optional<PoseCorrection> correct_pose(const Blackboard& board, int target,
                                                         const kinematics::PoseUncertainty& prior);

}  // namespace spar::sensing::pseiki
