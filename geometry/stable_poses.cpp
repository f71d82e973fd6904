#include "spar/geometry/stable_poses.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <tuple>

#include "spar/geometry/internal/convex_hull.hpp"
#include "spar/geometry/internal/polygon2d.hpp"

namespace spar::geometry {

namespace {

// The smallest rotation taking the unit vector `down` to world -z. Eigen's FromTwoVectors loses
// digits when `down` is nearly +z (it takes the angle from 1 + cos, about 1e-8 rad off there);
// the angle from atan2(|sin|, cos) keeps them. Exactly +z has no smallest rotation: Eigen's choice.
Eigen::Matrix3d smallest_turn_down(const Eigen::Vector3d& down) {
  const Eigen::Vector3d axis = down.cross(-Eigen::Vector3d::UnitZ());
  if (axis.norm() == 0)
    return Eigen::Quaterniond::FromTwoVectors(down, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return Eigen::AngleAxisd(std::atan2(axis.norm(), -down.z()), axis.normalized())
      .toRotationMatrix();
}

// The vertices the part's triangles use (an unreferenced vertex is not the body), where it is.
std::vector<Eigen::Vector3d> posed_vertices(const PosedPart& part) {
  const Mesh& mesh = part.model->mesh();
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& triangle : mesh.triangles)
    for (const int v : triangle) used[v] = 1;
  std::vector<Eigen::Vector3d> posed;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v]) posed.push_back(part.pose * mesh.vertices[v]);
  return posed;
}

// The parts' centre of mass, one density for all; nullopt when they have no volume.
std::optional<Eigen::Vector3d> joint_center_of_mass(std::span<const PosedPart> parts) {
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double volume = 0;
  for (const PosedPart& part : parts) {
    weighted += part.model->volume() * (part.pose * part.model->center_of_mass());
    volume += part.model->volume();
  }
  if (volume <= 0) return std::nullopt;
  return weighted / volume;
}

}  // namespace

std::vector<StablePose> stable_poses(const ObjectModel& object) {
  std::vector<StablePose> poses;
  const auto& facets = object.hull_facets();
  for (std::size_t f = 0; f < facets.size(); ++f) {
    const HullFacet& facet = facets[f];
    if (facet.com_inset <= object.tolerance()) continue;
    StablePose pose;
    pose.hull_facet = static_cast<int>(f);
    pose.facet_normal = facet.normal;
    pose.margin = facet.com_inset;
    pose.com_height = facet.com_height;
    pose.tipping_angle = std::atan2(facet.com_inset, facet.com_height);
    pose.table_faces = facet.table_faces;
    // Eigen's rotation, not smallest_turn_down: the seed experiments' reports (golden files)
    // depend on its last digits, and a facet normal nearly +z is a corner case.
    const Eigen::Matrix3d rotation =
        Eigen::Quaterniond::FromTwoVectors(facet.normal, -Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    const Eigen::Vector3d com = object.center_of_mass();
    const Eigen::Vector3d foot = com + facet.com_height * facet.normal;  // on the facet plane
    pose.object_to_world = Eigen::Isometry3d::Identity();
    pose.object_to_world.linear() = rotation;
    pose.object_to_world.translation() = -(rotation * foot);
    poses.push_back(std::move(pose));
  }
  // Labels are how scenario files name poses, so the order depends on the shape only: face ids,
  // then (for poses on no face) the facet normal, never the hull's facet order.
  const auto key = [](const StablePose& p) {
    const auto rounded = [&](int axis) { return std::lround(p.facet_normal[axis] * 1e6); };
    return std::tuple{p.table_faces.empty() ? INT_MAX : p.table_faces.front(), rounded(0),
                      rounded(1), rounded(2), p.hull_facet};
  };
  std::sort(poses.begin(), poses.end(),
            [&](const StablePose& a, const StablePose& b) { return key(a) < key(b); });
  for (std::size_t i = 0; i < poses.size(); ++i) {
    poses[i].id = static_cast<int>(i) + 1;
    poses[i].label =
        std::string(1, 'P').append(std::to_string(i + 1));  // GCC 12 -Wrestrict on "P" + s
  }
  return poses;
}

bool pose_leaves_free(const StablePose& pose, std::span<const int> faces) {
  return std::none_of(faces.begin(), faces.end(), [&](int face) {
    return std::binary_search(pose.table_faces.begin(), pose.table_faces.end(), face);
  });
}

std::optional<int> classify_orientation(const std::vector<StablePose>& poses,
                                        const Eigen::Matrix3d& rotation, double angle_tolerance) {
  const Eigen::Vector3d down_in_object = rotation.transpose() * -Eigen::Vector3d::UnitZ();
  for (const StablePose& pose : poses)
    if (pose.facet_normal.dot(down_in_object) >= std::cos(angle_tolerance)) return pose.id;
  return std::nullopt;
}

std::optional<double> resting_margin(std::span<const PosedPart> parts, double tolerance) {
  std::vector<Eigen::Vector2d> footing;
  for (const PosedPart& part : parts)
    for (const Eigen::Vector3d& world : posed_vertices(part)) {
      if (world.z() < -tolerance) return std::nullopt;
      if (world.z() <= tolerance) footing.push_back(world.head<2>());
    }
  const std::optional<Eigen::Vector3d> center = joint_center_of_mass(parts);
  const internal::Polygon2 hull = internal::convex_hull_2d(std::move(footing));
  if (hull.size() < 3 || !center) return std::nullopt;
  return internal::inset_distance(hull, center->head<2>());
}

std::vector<JointStablePose> joint_stable_poses(std::span<const PosedPart> parts,
                                                double tolerance) {
  std::vector<Eigen::Vector3d> points;
  for (const PosedPart& part : parts)
    for (const Eigen::Vector3d& vertex : posed_vertices(part)) points.push_back(vertex);
  const std::optional<Eigen::Vector3d> center = joint_center_of_mass(parts);
  if (!center) return {};
  std::vector<Eigen::Vector3d> downs;
  for (const auto& t : internal::convex_hull_triangles(points)) {
    const Eigen::Vector3d normal = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
    if (normal.norm() > 0) downs.push_back(normal.normalized());
  }
  const auto before = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::sort(downs.begin(), downs.end(), before);
  std::vector<JointStablePose> poses;
  std::vector<PosedPart> placed(parts.begin(), parts.end());
  std::vector<Eigen::Vector3d> tried;
  for (const Eigen::Vector3d& down : downs) {
    // Coplanar hull triangles give one direction; they need not sort next to each other when a
    // component differs by rounding only, so compare with every direction tried.
    if (std::any_of(tried.begin(), tried.end(),
                    [&](const Eigen::Vector3d& seen) { return (seen - down).norm() < 1e-9; }))
      continue;
    tried.push_back(down);
    Eigen::Isometry3d frame_to_world = Eigen::Isometry3d::Identity();
    frame_to_world.linear() = smallest_turn_down(down);
    double lowest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& point : points)
      lowest = std::min(lowest, (frame_to_world.linear() * point).z());
    const Eigen::Vector3d turned = frame_to_world.linear() * *center;
    frame_to_world.translation() = Eigen::Vector3d(-turned.x(), -turned.y(), -lowest);
    for (std::size_t k = 0; k < parts.size(); ++k) placed[k].pose = frame_to_world * parts[k].pose;
    const std::optional<double> margin = resting_margin(placed, tolerance);
    if (margin && *margin > tolerance) poses.push_back({down, frame_to_world, *margin});
  }
  return poses;
}

}  // namespace spar::geometry
