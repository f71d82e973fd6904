#include "spar/sensing/camera.hpp"

#include <cmath>
#include <string>

#include "spar/common/number.hpp"
#include "spar/sensing/error.hpp"

namespace spar::sensing {

const char* to_string(Projection projection) {
  return projection == Projection::kPinhole ? "pinhole" : "orthographic";
}

Camera::Camera(Projection projection, const Intrinsics& intrinsics, const Eigen::Isometry3d& pose)
    : projection_(projection), intrinsics_(intrinsics), pose_(pose) {
  const auto positive = [](double value, const char* name) {
    if (!(std::isfinite(value) && value > 0))
      throw SensingError(std::string("camera intrinsics: ") + name +
                         " must be a positive number, got " + format_number(value));
  };
  positive(intrinsics.fx, "fx");
  positive(intrinsics.fy, "fy");
  for (const auto& [value, name] : {std::pair{intrinsics.cx, "cx"}, std::pair{intrinsics.cy, "cy"}})
    if (!std::isfinite(value))
      throw SensingError(std::string("camera intrinsics: ") + name + " must be finite, got " +
                         format_number(value));
  for (const auto& [value, name] :
       {std::pair{intrinsics.width, "width"}, std::pair{intrinsics.height, "height"}})
    if (value < 1 || value > kMaxImageSide)
      throw SensingError(std::string("camera intrinsics: ") + name + " must be 1 to " +
                         std::to_string(kMaxImageSide) + " pixels, got " + std::to_string(value));
  const Eigen::Matrix3d rotation = pose.linear();
  if (!pose.matrix().allFinite() ||
      !(rotation.transpose() * rotation).isApprox(Eigen::Matrix3d::Identity(), 1e-9) ||
      !(rotation.determinant() > 0))
    throw SensingError("camera pose: not a rigid transform");
  world_to_camera_ = pose.inverse(Eigen::Isometry);
}

Camera Camera::orthographic_view(const Eigen::Vector3d& toward_viewer,
                                 const Eigen::Vector3d& centre, double radius, int pixels) {
  const Eigen::Vector3d direction = toward_viewer.normalized();
  const Eigen::Vector3d up =
      std::abs(direction.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  // The image plane sits a diameter in front of the centre, so every point of the sphere has
  // z > 0; the sphere's diameter spans the image.
  const Eigen::Isometry3d pose = look_at(centre + 2 * radius * direction, centre, up);
  const double scale = pixels / (2 * radius);
  return Camera(Projection::kOrthographic,
                {.fx = scale,
                 .fy = scale,
                 .cx = pixels / 2.0,
                 .cy = pixels / 2.0,
                 .width = pixels,
                 .height = pixels},
                pose);
}

std::optional<Eigen::Vector2d> Camera::project(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d camera = to_camera(world);
  if (camera.z() < near_depth()) return std::nullopt;
  return project_camera(camera);
}

Eigen::Vector2d Camera::project_camera(const Eigen::Vector3d& camera) const {
  if (projection_ == Projection::kPinhole)
    return {intrinsics_.fx * camera.x() / camera.z() + intrinsics_.cx,
            intrinsics_.fy * camera.y() / camera.z() + intrinsics_.cy};
  return {intrinsics_.fx * camera.x() + intrinsics_.cx,
          intrinsics_.fy * camera.y() + intrinsics_.cy};
}

Eigen::Vector3d Camera::toward_viewer(const Eigen::Vector3d& world) const {
  if (projection_ == Projection::kOrthographic) return -pose_.linear().col(2);
  return (pose_.translation() - world).normalized();
}

Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                          const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d down = -(up - up.dot(z) * z);
  if (!(down.norm() > 1e-12) || !z.allFinite())
    throw SensingError("look_at: the eye is at the target, or `up` is parallel to the view");
  const Eigen::Vector3d y = down.normalized();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = y.cross(z);
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = eye;
  return pose;
}

}  // namespace spar::sensing
