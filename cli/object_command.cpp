// `spar object FILE|NAME`: an object's faces, stable poses (margins, table faces) and quantized
// grasps (T_G, contact faces, obscured faces, the poses each grasp is usable in), as text or JSON.
// NAME is a built-in object (peg, block, cube, l-shape); FILE is an .off or .obj mesh.
// `--write-off FILE` saves the mesh (how examples/objects/*.off were made from the built-ins).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "cli/commands.hpp"
#include "geometry/builtin_objects.hpp"
#include "geometry/grasps.hpp"
#include "geometry/mesh_io.hpp"
#include "geometry/stable_poses.hpp"

namespace spar::cli {
namespace {

using geometry::GeometryError;

struct ObjectOptions {
  std::string object;
  bool json{false};
  std::string write_off;
  geometry::GripperSpec gripper;
  geometry::GraspQuantization quantization;
};

std::string text(const Eigen::Vector3d& v) {
  std::ostringstream out;
  const auto clean = [](double x) { return std::abs(x) < 1e-12 ? 0.0 : x; };
  out << std::setprecision(4) << '(' << clean(v.x()) << ", " << clean(v.y()) << ", " << clean(v.z())
      << ')';
  return out.str();
}

nlohmann::json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json matrix_json(const Eigen::Isometry3d& transform) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < 4; ++c) row.push_back(transform.matrix()(r, c));
    rows.push_back(row);
  }
  return rows;
}

std::string id_list(const std::vector<int>& ids) {
  std::string out = "[";
  for (std::size_t i = 0; i < ids.size(); ++i) out += (i ? " " : "") + std::to_string(ids[i]);
  return out + "]";
}

geometry::ObjectModel load_object(const std::string& argument, std::string& builtin_name) {
  if (std::filesystem::exists(argument)) {
    const std::string name = std::filesystem::path(argument).stem().string();
    return geometry::ObjectModel(name, geometry::read_mesh_file(argument));
  }
  const auto names = geometry::builtin_object_names();
  if (std::find(names.begin(), names.end(), argument) != names.end()) {
    builtin_name = argument;
    return geometry::make_builtin_object(argument);
  }
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw GeometryError(argument + ": no such file, nor a built-in object (" + known + ")");
}

void run(const ObjectOptions& options) {
  std::string builtin_name;
  const geometry::ObjectModel object = load_object(options.object, builtin_name);
  if (!options.write_off.empty()) {
    std::ofstream file(options.write_off);
    if (!file) throw GeometryError(options.write_off + ": cannot write the file");
    geometry::write_off(object.mesh(), file,
                        builtin_name.empty() ? "spar object " + object.name()
                                             : geometry::builtin_description(builtin_name));
  }
  const auto poses = geometry::stable_poses(object);
  const auto grasps = geometry::compute_grasps(object, options.gripper, options.quantization);
  const auto usable_in = [&](const geometry::Grasp& grasp) {
    std::vector<std::string> labels;
    for (const auto& pose : poses)
      if (geometry::grasp_usable(grasp, pose, options.gripper)) labels.push_back(pose.label);
    return labels;
  };

  if (options.json) {
    nlohmann::json out;
    out["object"] = object.name();
    out["volume"] = object.volume();
    out["center_of_mass"] = vector_json(object.center_of_mass());
    for (const auto& face : object.faces())
      out["faces"].push_back({{"id", face.id},
                              {"name", face.name},
                              {"normal", vector_json(face.normal)},
                              {"offset", face.offset},
                              {"area", face.area}});
    for (const auto& pair : object.face_pairs())
      out["face_pairs"].push_back({{"faces", {pair.face_a, pair.face_b}},
                                   {"width", pair.width},
                                   {"overlap_area", pair.overlap_area}});
    out["hull_facets"] = object.hull_facets().size();
    out["stable_poses"] = nlohmann::json::array();
    for (const auto& pose : poses)
      out["stable_poses"].push_back({{"label", pose.label},
                                     {"facet_normal", vector_json(pose.facet_normal)},
                                     {"margin", pose.margin},
                                     {"tipping_angle", pose.tipping_angle},
                                     {"com_height", pose.com_height},
                                     {"table_faces", pose.table_faces},
                                     {"object_to_world", matrix_json(pose.object_to_world)}});
    out["grasps"] = nlohmann::json::array();
    for (const auto& grasp : grasps)
      out["grasps"].push_back({{"label", grasp.label},
                               {"contact_faces", {grasp.face_plus_y, grasp.face_minus_y}},
                               {"width", grasp.width},
                               {"approach_deg", grasp.approach_deg},
                               {"position", grasp.position},
                               {"obscured_faces", grasp.obscured_faces},
                               {"T_G", matrix_json(grasp.gripper_in_object)},
                               {"usable_in", usable_in(grasp)}});
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << std::setprecision(4) << "object " << object.name() << " (" << object.mesh().source
            << "): " << object.faces().size() << " faces, volume " << object.volume()
            << ", centre of mass " << text(object.center_of_mass()) << "\n\nfaces:\n";
  for (const auto& face : object.faces())
    std::cout << "  " << std::setw(3) << face.id << "  " << std::left << std::setw(22) << face.name
              << std::right << " normal " << text(face.normal) << "  area " << face.area << '\n';
  std::cout << "\nparallel opposite face pairs:\n";
  for (const auto& pair : object.face_pairs())
    std::cout << "  " << pair.face_a << " & " << pair.face_b << "  width " << pair.width
              << "  overlap area " << pair.overlap_area << '\n';
  std::cout << "\nstable poses: " << poses.size() << " of " << object.hull_facets().size()
            << " hull facets\n";
  for (const auto& pose : poses)
    std::cout << "  " << pose.label << "  facet normal " << text(pose.facet_normal) << "  margin "
              << pose.margin << "  tipping " << pose.tipping_angle * 180 / std::numbers::pi
              << " deg  table faces " << id_list(pose.table_faces) << '\n';
  for (const auto& facet : object.hull_facets())
    if (facet.com_inset <= object.tolerance())
      std::cout << "  (unstable facet normal " << text(facet.normal) << ": centre of mass projects "
                << -facet.com_inset << " outside)\n";
  std::cout << "\ngrasps: " << grasps.size() << " (approach every "
            << options.quantization.approach_step_deg << " deg, "
            << options.quantization.positions_per_axis << " position(s) per axis, opening "
            << options.gripper.max_opening << ")\n";
  for (const auto& grasp : grasps) {
    std::cout << "  " << std::left << std::setw(5) << grasp.label << std::right << "faces +y "
              << grasp.face_plus_y << " -y " << grasp.face_minus_y << "  W " << grasp.width
              << "  approach " << std::setw(3) << grasp.approach_deg << " deg  z "
              << text(grasp.gripper_in_object.linear().col(2)) << "  at "
              << text(grasp.gripper_in_object.translation()) << "  obscures "
              << id_list(grasp.obscured_faces) << "  usable in";
    const auto labels = usable_in(grasp);
    if (labels.empty()) std::cout << " none";
    for (const auto& label : labels) std::cout << ' ' << label;
    std::cout << '\n';
  }
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
  command->add_option("--max-opening", options->gripper.max_opening, "gripper opening (default 4)");
  command->add_option("--approach-step", options->quantization.approach_step_deg,
                      "approach quantization step in degrees about the closing axis (default 90)");
  command->add_option("--positions", options->quantization.positions_per_axis,
                      "contact positions per axis of each face pair's overlap (default 1)");
  command->add_option("--write-off", options->write_off, "also write the mesh as an OFF file");
  command->callback([options] { run(*options); });
}

}  // namespace spar::cli
