#include "spar/sensing/pseiki/pose_correction.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <vector>

#include "spar/sensing/error.hpp"

namespace spar::sensing::pseiki {
namespace {

constexpr int kIterations = 30;

struct Observation {
  Segment image;
  Eigen::Vector3d p0, p1;  // the label's model edge, object frame
  int object{0};
  double weight{1};
};

// The four offsets of a parameter vector over the free components.
PoseOffset offset_of(const Eigen::VectorXd& x, const std::vector<int>& free) {
  std::array<double, 4> values{};
  for (std::size_t k = 0; k < free.size(); ++k)
    values[static_cast<std::size_t>(free[k])] = x[static_cast<Eigen::Index>(k)];
  return {values[0], values[1], values[2], values[3]};
}

class Problem {
 public:
  Problem(const Blackboard& board, int target, std::vector<Observation> observations,
          std::vector<int> free)
      : model_(board.model()),
        target_(target),
        observations_(std::move(observations)),
        free_(std::move(free)) {}

  // Residuals at x (two per observation); an edge behind the camera gives zeros.
  [[nodiscard]] Eigen::VectorXd residuals(const Eigen::VectorXd& x) const {
    const PoseOffset offset = offset_of(x, free_);
    const Camera camera = target_ == kCameraTarget
                              ? Camera(model_.camera().projection(), model_.camera().intrinsics(),
                                       offset_pose(model_.camera().pose(), offset))
                              : model_.camera();
    Eigen::VectorXd r(2 * static_cast<Eigen::Index>(observations_.size()));
    for (std::size_t i = 0; i < observations_.size(); ++i) {
      const Observation& o = observations_[i];
      const Eigen::Isometry3d& believed = model_.objects()[static_cast<std::size_t>(o.object)].pose;
      const Eigen::Isometry3d pose = o.object == target_ ? offset_pose(believed, offset) : believed;
      const auto u0 = camera.project(pose * o.p0), u1 = camera.project(pose * o.p1);
      const auto row = static_cast<Eigen::Index>(2 * i);
      if (!u0 || !u1 || (*u1 - *u0).norm() < 1e-9) {
        r[row] = r[row + 1] = 0;
        continue;
      }
      const Eigen::Vector2d d = (*u1 - *u0).normalized();
      const Eigen::Vector2d n(-d.y(), d.x());
      r[row] = n.dot(o.image.p0 - *u0);
      r[row + 1] = n.dot(o.image.p1 - *u0);
    }
    return r;
  }

  [[nodiscard]] Eigen::MatrixXd jacobian(const Eigen::VectorXd& x,
                                         const Eigen::VectorXd& scales) const {
    Eigen::MatrixXd j(2 * static_cast<Eigen::Index>(observations_.size()), x.size());
    for (Eigen::Index k = 0; k < x.size(); ++k) {
      const double h = 1e-6 * scales[k];
      Eigen::VectorXd plus = x, minus = x;
      plus[k] += h;
      minus[k] -= h;
      j.col(k) = (residuals(plus) - residuals(minus)) / (2 * h);
    }
    return j;
  }

  [[nodiscard]] Eigen::VectorXd weights() const {
    Eigen::VectorXd w(2 * static_cast<Eigen::Index>(observations_.size()));
    for (std::size_t i = 0; i < observations_.size(); ++i)
      w[static_cast<Eigen::Index>(2 * i)] = w[static_cast<Eigen::Index>(2 * i + 1)] =
          observations_[i].weight;
    return w;
  }

 private:
  const ModelPanel& model_;
  int target_;
  std::vector<Observation> observations_;
  std::vector<int> free_;
};

double huber_weight(double r, double k) { return std::abs(r) <= k ? 1.0 : k / std::abs(r); }

double rms(const Eigen::VectorXd& r) {
  return r.size() ? std::sqrt(r.squaredNorm() / static_cast<double>(r.size())) : 0.0;
}

// The labelled edges a correction of `target` uses: active, believed at kCorrectionBelief or
// more, of the target object (of any object for the camera).
std::vector<Observation> observations_of(const Blackboard& board, int target) {
  const ModelPanel& model = board.model();
  std::vector<Observation> observations;
  for (const ImageEdge& edge : board.edges) {
    if (!edge.active || edge.label < 0 || edge.belief < kCorrectionBelief) continue;
    const PanelEdge& panel = model.edges()[static_cast<std::size_t>(edge.label)];
    if (target != kCameraTarget && panel.object != target) continue;
    observations.push_back({.image = edge.segment,
                            .p0 = panel.p0,
                            .p1 = panel.p1,
                            .object = panel.object,
                            .weight = edge.belief});
  }
  return observations;
}

// The header's robust least squares over the free components: the offsets `x`, and the normal
// matrix and robust weights of the last iteration (the covariance's).
struct RobustFit {
  Eigen::VectorXd x, robust_weights;
  Eigen::MatrixXd normal;
};

RobustFit robust_fit(const Problem& problem, const Eigen::VectorXd& scales,
                     const Eigen::VectorXd& prior_precision, double huber_k) {
  const Eigen::VectorXd belief_weights = problem.weights();
  const auto cost = [&](const Eigen::VectorXd& x) {
    const Eigen::VectorXd r = problem.residuals(x);
    double total = 0;
    for (Eigen::Index i = 0; i < r.size(); ++i) {
      const double a = std::abs(r[i]);
      total += belief_weights[i] * (a <= huber_k ? 0.5 * a * a : huber_k * (a - 0.5 * huber_k));
    }
    return total + 0.5 * x.cwiseProduct(x).dot(prior_precision);
  };
  const Eigen::Index n = scales.size();
  RobustFit fit{.x = Eigen::VectorXd::Zero(n), .robust_weights = {}, .normal = {}};
  Eigen::VectorXd& x = fit.x;
  for (int iteration = 0; iteration < kIterations; ++iteration) {
    const Eigen::VectorXd r = problem.residuals(x);
    const Eigen::MatrixXd j = problem.jacobian(x, scales);
    fit.robust_weights = belief_weights;
    for (Eigen::Index i = 0; i < r.size(); ++i)
      fit.robust_weights[i] *= huber_weight(r[i], huber_k);
    fit.normal = j.transpose() * fit.robust_weights.asDiagonal() * j;
    fit.normal.diagonal() += prior_precision;
    const Eigen::VectorXd gradient =
        j.transpose() * fit.robust_weights.asDiagonal() * r + prior_precision.cwiseProduct(x);
    // The step, kept inside the box.
    Eigen::VectorXd step =
        (x - fit.normal.ldlt().solve(gradient)).cwiseMax(-scales).cwiseMin(scales) - x;
    const double before = cost(x);
    while (cost(x + step) > before && step.cwiseQuotient(scales).cwiseAbs().maxCoeff() > 1e-9)
      step *= 0.5;
    x += step;
    if (step.cwiseQuotient(scales).cwiseAbs().maxCoeff() < 1e-7) break;
  }
  return fit;
}

// The half-widths after the verification step: 3 sqrt(diagonal) of s^2 (J^T W J + prior)^-1,
// s^2 = max(sigma_px^2, the robust weights' mean squared residual `after`), never above the
// prior's `half_widths`.
kinematics::PoseUncertainty remaining_uncertainty(const RobustFit& fit,
                                                  const Eigen::VectorXd& after, double sigma_px,
                                                  std::array<double, 4> half_widths,
                                                  const std::vector<int>& free) {
  double weighted = 0, total = 0;
  for (Eigen::Index i = 0; i < after.size(); ++i) {
    weighted += fit.robust_weights[i] * after[i] * after[i];
    total += fit.robust_weights[i];
  }
  const double s2 = std::max(sigma_px * sigma_px, total > 0 ? weighted / total : 0.0);
  const Eigen::MatrixXd covariance = s2 * fit.normal.inverse();
  for (Eigen::Index k = 0; k < covariance.rows(); ++k) {
    auto& value = half_widths[static_cast<std::size_t>(free[static_cast<std::size_t>(k)])];
    value = std::min(value, 3 * std::sqrt(std::max(0.0, covariance(k, k))));
  }
  return {half_widths[0], half_widths[1], half_widths[2], half_widths[3]};
}

}  // namespace

std::optional<PoseCorrection> correct_pose(const Blackboard& board, int target,
                                           const kinematics::PoseUncertainty& prior) {
  const ModelPanel& model = board.model();
  if (target != kCameraTarget && (target < 0 || target >= static_cast<int>(model.objects().size())))
    throw SensingError("pose correction: no object " + std::to_string(target));
  const std::array<double, 4> half_widths = {prior.dx, prior.dy, prior.dz, prior.dtheta};
  std::vector<int> free;
  for (int k = 0; k < 4; ++k)
    if (half_widths[static_cast<std::size_t>(k)] > 0) free.push_back(k);
  if (free.empty()) return std::nullopt;
  std::vector<Observation> observations = observations_of(board, target);
  if (observations.size() < 2) return std::nullopt;
  const auto used = static_cast<int>(observations.size());
  const Problem problem(board, target, std::move(observations), free);

  const auto n = static_cast<Eigen::Index>(free.size());
  const double sigma_px = std::max(model.uncertainty().noise_px, 0.5);
  Eigen::VectorXd scales(n), prior_precision(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    scales[k] = half_widths[static_cast<std::size_t>(free[static_cast<std::size_t>(k)])];
    prior_precision[k] = sigma_px * sigma_px / (scales[k] * scales[k]);
  }
  const RobustFit fit = robust_fit(problem, scales, prior_precision, 3 * sigma_px);

  PoseCorrection out;
  out.target = target;
  out.offset = offset_of(fit.x, free);
  out.pose =
      offset_pose(target == kCameraTarget ? model.camera().pose()
                                          : model.objects()[static_cast<std::size_t>(target)].pose,
                  out.offset);
  const Eigen::VectorXd after = problem.residuals(fit.x);
  out.residual_px = rms(after);
  out.residual_before_px = rms(problem.residuals(Eigen::VectorXd::Zero(n)));
  out.observations = used;
  out.uncertainty = remaining_uncertainty(fit, after, sigma_px, half_widths, free);
  return out;
}

}  // namespace spar::sensing::pseiki
