// Cameras: where a sensor looks from and how a world point maps to a pixel. Shared by the
// simulated sensors (sensors.hpp), the aspects (aspects.hpp) and PSEIKI's expected-scene renderer.
//
// Camera frame (the ROS optical / OpenCV convention): +z is the viewing direction, +x is right and
// +y is down in the image. `pose` is the camera frame in the world: world = pose * camera point.
// Image: pixel (i, j) covers [i, i + 1) x [j, j + 1) with its centre at (i + 0.5, j + 0.5); the
// image is [0, width) x [0, height).
// Pinhole: camera point (x, y, z) with z >= kNearPlane maps to u = fx x / z + cx, v = fy y / z + cy
//   (fx, fy, cx, cy in pixels); nearer points are not imaged (clipped).
// Orthographic: u = fx x + cx, v = fy y + cy with fx, fy in pixels per metre; points with z >= 0
//   (in front of the image plane) are imaged.
// Invariants (the constructor throws SensingError otherwise): fx, fy finite and > 0; cx, cy
// finite; 1 <= width, height <= kMaxImageSide; the pose is rigid.
//
// Example:
//   const Camera top(Projection::kPinhole, {.fx = 500, .fy = 500, .cx = 320, .cy = 240,
//                                           .width = 640, .height = 480},
//                    look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}));
//   top.project({0.1, 0, 0});                  // (370, 240): 0.1 m right of the centre, 1 m away
//   top.toward_viewer({0, 0, 0});               // (0, 0, 1)
#pragma once

#include <Eigen/Geometry>
#include <optional>

namespace spar::sensing {

inline constexpr int kMaxImageSide = 16384;
inline constexpr double kNearPlane = 1e-3;  // metres in front of a pinhole that are imaged

enum class Projection { kPinhole, kOrthographic };
[[nodiscard]] const char* to_string(Projection projection);  // "pinhole", "orthographic"

struct Intrinsics {
  double fx{0}, fy{0};  // pixels (pinhole) or pixels per metre (orthographic)
  double cx{0}, cy{0};  // pixels
  int width{0}, height{0};
};

class Camera {
 public:
  Camera(Projection projection, const Intrinsics& intrinsics, const Eigen::Isometry3d& pose);

  // An orthographic camera that sees the sphere (centre, radius) from direction `toward_viewer`
  // (unit, from the centre to the viewer), the sphere filling `pixels` x `pixels`. The image's
  // up direction is the projection of world z (or world y when looking along z).
  [[nodiscard]] static Camera orthographic_view(const Eigen::Vector3d& toward_viewer,
                                                const Eigen::Vector3d& centre, double radius,
                                                int pixels);

  [[nodiscard]] Projection projection() const { return projection_; }
  [[nodiscard]] const Intrinsics& intrinsics() const { return intrinsics_; }
  [[nodiscard]] const Eigen::Isometry3d& pose() const { return pose_; }
  [[nodiscard]] Eigen::Vector3d to_camera(const Eigen::Vector3d& world) const {
    return world_to_camera_ * world;
  }
  // The pixel coordinates of a world point, or nullopt when it is not in front of the camera.
  // The point may fall outside the image.
  [[nodiscard]] std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& world) const;
  // Pixel coordinates of a camera-frame point in front of the camera (no check).
  [[nodiscard]] Eigen::Vector2d project_camera(const Eigen::Vector3d& camera) const;
  // Unit direction from a world point toward the viewer: to the pinhole, or -z of an orthographic
  // camera.
  [[nodiscard]] Eigen::Vector3d toward_viewer(const Eigen::Vector3d& world) const;
  // A surface with this outward normal at this point is turned toward the camera (strictly).
  [[nodiscard]] bool faces_camera(const Eigen::Vector3d& world,
                                  const Eigen::Vector3d& normal) const {
    return normal.dot(toward_viewer(world)) > 0;
  }
  // The camera-frame depth below which nothing is imaged: kNearPlane or 0.
  [[nodiscard]] double near_depth() const {
    return projection_ == Projection::kPinhole ? kNearPlane : 0.0;
  }

 private:
  Projection projection_;
  Intrinsics intrinsics_;
  Eigen::Isometry3d pose_;
  Eigen::Isometry3d world_to_camera_;
};

// The camera pose at `eye` looking at `target`, image up toward `up` (not parallel to the view).
[[nodiscard]] Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                                        const Eigen::Vector3d& up);

}  // namespace spar::sensing
