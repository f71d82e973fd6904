// `spar object FILE|NAME`: an object's faces, stable poses (margins, table faces) and quantized
// grasps (T_G, contact faces, obscured faces, the poses each grasp is usable in), as text or JSON.
// NAME is a built-in object (peg, block, cube, l-shape); FILE is an .off or .obj mesh.
// `--units m|mm|in` (default m) is the length unit of FILE's coordinates, of --max-opening and of
// everything printed; spar works in metres inside. `--approach-step` is in degrees.
// `--write-off FILE` saves the mesh in metres (how examples/objects/*.off were made from the
// built-ins).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "spar/common/units.hpp"
#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/grasps.hpp"
#include "spar/geometry/mesh_io.hpp"
#include "spar/geometry/stable_poses.hpp"

namespace spar::cli {
namespace {

struct ObjectOptions {
  std::string object;
  bool json{false};
  std::string write_off;
  std::string units{"m"};
  std::optional<double> max_opening;  // in `units`; GripperSpec's default (4 in) without it
  double approach_step_degrees{90};
  int positions_per_axis{1};
};

std::string text(const Eigen::Vector3d& v) {
  std::ostringstream out;
  const auto clean = [](double x) { return std::abs(x) < 1e-12 ? 0.0 : x; };
  out << std::setprecision(4) << '(' << clean(v.x()) << ", " << clean(v.y()) << ", " << clean(v.z())
      << ')';
  return out.str();
}

nlohmann::json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// Rows of the 4x4 matrix, its translation divided by `unit` (metres per output unit).
nlohmann::json matrix_json(const Eigen::Isometry3d& transform, double unit) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < 4; ++c)
      row.push_back(transform.matrix()(r, c) / (c == 3 && r < 3 ? unit : 1));
    rows.push_back(row);
  }
  return rows;
}

std::string id_list(const std::vector<int>& ids) {
  std::string out = "[";
  for (std::size_t i = 0; i < ids.size(); ++i) out += (i ? " " : "") + std::to_string(ids[i]);
  return out + "]";
}

// What `spar object` reports: the object, its stable poses and grasps for the gripper, and the
// length unit of the output (metres per unit).
struct ObjectFacts {
  geometry::ObjectModel object;
  std::vector<geometry::StablePose> poses;
  std::vector<geometry::Grasp> grasps;
  geometry::GripperSpec gripper;
  geometry::GraspQuantization quantization;
  double unit{1};

  // Output in the options' unit: lengths, areas and volumes divided by unit, unit^2, unit^3.
  [[nodiscard]] double length(double metres) const { return metres / unit; }
  [[nodiscard]] double area(double square_metres) const { return square_metres / (unit * unit); }
  [[nodiscard]] Eigen::Vector3d point(const Eigen::Vector3d& metres) const { return metres / unit; }
  // The labels of the stable poses the grasp is usable in.
  [[nodiscard]] std::vector<std::string> usable_in(const geometry::Grasp& grasp) const {
    std::vector<std::string> labels;
    for (const auto& pose : poses)
      if (geometry::grasp_usable(grasp, pose, gripper)) labels.push_back(pose.label);
    return labels;
  }
};

nlohmann::json object_json(const ObjectFacts& facts, const ObjectOptions& options) {
  const geometry::ObjectModel& object = facts.object;
  nlohmann::json out;
  out["object"] = object.name();
  out["units"] = options.units;
  out["volume"] = object.volume() / (facts.unit * facts.unit * facts.unit);
  out["center_of_mass"] = vector_json(facts.point(object.center_of_mass()));
  for (const auto& face : object.faces())
    out["faces"].push_back({{"id", face.id},
                            {"name", face.name},
                            {"normal", vector_json(face.normal)},
                            {"offset", facts.length(face.offset)},
                            {"area", facts.area(face.area)}});
  for (const auto& pair : object.face_pairs())
    out["face_pairs"].push_back({{"faces", {pair.face_a, pair.face_b}},
                                 {"width", facts.length(pair.width)},
                                 {"overlap_area", facts.area(pair.overlap_area)}});
  out["hull_facets"] = object.hull_facets().size();
  out["stable_poses"] = nlohmann::json::array();
  for (const auto& pose : facts.poses)
    out["stable_poses"].push_back(
        {{"label", pose.label},
         {"facet_normal", vector_json(pose.facet_normal)},
         {"margin", facts.length(pose.margin)},
         {"tipping_angle", pose.tipping_angle},
         {"com_height", facts.length(pose.com_height)},
         {"table_faces", pose.table_faces},
         {"object_to_world", matrix_json(pose.object_to_world, facts.unit)}});
  out["grasps"] = nlohmann::json::array();
  for (const auto& grasp : facts.grasps)
    out["grasps"].push_back({{"label", grasp.label},
                             {"contact_faces", {grasp.face_plus_y, grasp.face_minus_y}},
                             {"width", facts.length(grasp.width)},
                             {"approach_deg", grasp.approach / units::kDegree},
                             {"position", grasp.position},
                             {"obscured_faces", grasp.obscured_faces},
                             {"T_G", matrix_json(grasp.gripper_in_object, facts.unit)},
                             {"usable_in", facts.usable_in(grasp)}});
  return out;
}

void print_object(const ObjectFacts& facts, const ObjectOptions& options) {
  const geometry::ObjectModel& object = facts.object;
  std::cout << std::setprecision(4) << "object " << object.name() << " (" << object.mesh().source
            << "), lengths in " << options.units << ": " << object.faces().size()
            << " faces, volume " << object.volume() / (facts.unit * facts.unit * facts.unit)
            << ", centre of mass " << text(facts.point(object.center_of_mass())) << "\n\nfaces:\n";
  for (const auto& face : object.faces())
    std::cout << "  " << std::setw(3) << face.id << "  " << std::left << std::setw(22) << face.name
              << std::right << " normal " << text(face.normal) << "  area " << facts.area(face.area)
              << '\n';
  std::cout << "\nparallel opposite face pairs:\n";
  for (const auto& pair : object.face_pairs())
    std::cout << "  " << pair.face_a << " & " << pair.face_b << "  width "
              << facts.length(pair.width) << "  overlap area " << facts.area(pair.overlap_area)
              << '\n';
  std::cout << "\nstable poses: " << facts.poses.size() << " of " << object.hull_facets().size()
            << " hull facets\n";
  for (const auto& pose : facts.poses)
    std::cout << "  " << pose.label << "  facet normal " << text(pose.facet_normal) << "  margin "
              << facts.length(pose.margin) << "  tipping " << pose.tipping_angle / units::kDegree
              << " deg  table faces " << id_list(pose.table_faces) << '\n';
  for (const auto& facet : object.hull_facets())
    if (facet.com_inset <= object.tolerance())
      std::cout << "  (unstable facet normal " << text(facet.normal) << ": centre of mass projects "
                << facts.length(-facet.com_inset) << " outside)\n";
  std::cout << "\ngrasps: " << facts.grasps.size() << " (approach every "
            << options.approach_step_degrees << " deg, " << facts.quantization.positions_per_axis
            << " position(s) per axis, opening " << facts.length(facts.gripper.max_opening)
            << ")\n";
  for (const auto& grasp : facts.grasps) {
    std::cout << "  " << std::left << std::setw(5) << grasp.label << std::right << "faces +y "
              << grasp.face_plus_y << " -y " << grasp.face_minus_y << "  W "
              << facts.length(grasp.width) << "  approach " << std::setw(3)
              << grasp.approach / units::kDegree << " deg  z "
              << text(grasp.gripper_in_object.linear().col(2)) << "  at "
              << text(facts.point(grasp.gripper_in_object.translation())) << "  obscures "
              << id_list(grasp.obscured_faces) << "  usable in";
    const auto labels = facts.usable_in(grasp);
    if (labels.empty()) std::cout << " none";
    for (const auto& label : labels) std::cout << ' ' << label;
    std::cout << '\n';
  }
}

void run(const ObjectOptions& options) {
  const double unit = metres_per_unit(options.units);
  geometry::GripperSpec gripper;
  if (options.max_opening) {
    gripper.max_opening = *options.max_opening * unit;
    check_limit("--max-opening", "robot.gripper.max_opening", gripper.max_opening,
                {unit, options.units}, format_number(*options.max_opening));
  }
  geometry::GraspQuantization quantization;
  quantization.approach_step = options.approach_step_degrees * units::kDegree;
  check_limit("--approach-step", "grasping.approach_step", quantization.approach_step,
              {units::kDegree, "deg"}, format_number(options.approach_step_degrees));
  quantization.positions_per_axis = options.positions_per_axis;
  check_limit("--positions", "grasping.positions_per_axis", options.positions_per_axis);
  // On a terminal, what a large mesh is at: each step is O(n log n), but seconds at 200k triangles.
  const StatusLine status("spar object");
  status.show("reading the mesh, its faces, convex hull and face pairs");
  geometry::ObjectModel object = geometry::load_object(options.object, unit);
  const bool builtin = !std::filesystem::exists(options.object);
  if (!options.write_off.empty()) {
    write_file(options.write_off, "the mesh", [&](std::ostream& file) {
      geometry::write_off(
          object.mesh(), file,
          builtin ? geometry::builtin_description(options.object) : "spar object " + object.name());
    });
  }
  status.show("stable poses");
  auto poses = geometry::stable_poses(object);
  status.show("grasps");
  auto grasps = geometry::compute_grasps(object, gripper, quantization);
  status.clear();
  const ObjectFacts facts{std::move(object), std::move(poses), std::move(grasps),
                          gripper,           quantization,     unit};
  if (options.json)
    std::cout << object_json(facts, options).dump(2) << '\n';
  else
    print_object(facts, options);
}

}  // namespace

void add_object_command(CLI::App& app) {
  auto options = std::make_shared<ObjectOptions>();
  CLI::App* command = app.add_subcommand(
      "object",
      "Show an object's faces, stable poses and quantized grasps (file or built-in name)");
  command->add_option("object", options->object, "an .off/.obj file, or peg, block, cube, l-shape")
      ->required();
  command->add_flag("--json", options->json, "print JSON");
  command
      ->add_option("--units", options->units, "length unit of FILE and of the output (default m)")
      ->check(CLI::IsMember({"m", "mm", "in"}));
  // The ranges are the scenario keys' (robot.gripper.max_opening, grasping.approach_step and
  // grasping.positions_per_axis in common/limits.hpp), checked once --units is known.
  add_number_option(*command, "--max-opening", options->max_opening,
                    "gripper opening in --units (default 4 in, at most 2 m)",
                    NumberLimits::positive());
  add_number_option(*command, "--approach-step", options->approach_step_degrees,
                    "approach quantization step in degrees about the closing axis, 1 to 360",
                    NumberLimits::positive());
  add_count_option(*command, "--positions", options->positions_per_axis,
                   "contact positions per axis of each face pair's overlap, 1 to 20", 0, 1'000'000);
  command->add_option("--write-off", options->write_off, "also write the mesh as an OFF file");
  command->callback([options] { run(*options); });
}

}  // namespace spar::cli
