#include "spar/kinematics/urdf.hpp"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "spar/geometry/mesh_io.hpp"

namespace spar::kinematics {
namespace {

namespace fs = std::filesystem;

// Lines of the elements messages are about (TinyXML counts from 1).
struct Locations {
  int robot{0};
  std::map<std::string, int> links, joints;
  std::map<std::string, std::vector<int>> collisions;  // per link, its <collision> elements
};

Locations locate(const TiXmlElement& robot) {
  Locations where;
  where.robot = robot.Row();
  for (const TiXmlElement* element = robot.FirstChildElement(); element != nullptr;
       element = element->NextSiblingElement()) {
    const char* name = element->Attribute("name");
    if (name == nullptr) continue;
    const std::string tag = element->ValueStr();
    if (tag == "joint") where.joints.emplace(name, element->Row());
    if (tag != "link") continue;
    where.links.emplace(name, element->Row());
    std::vector<int>& collisions = where.collisions[name];
    for (const TiXmlElement* collision = element->FirstChildElement("collision");
         collision != nullptr; collision = collision->NextSiblingElement("collision"))
      collisions.push_back(collision->Row());
  }
  return where;
}

// urdfdom reports through console_bridge; this keeps its messages (and off the terminal) while a
// parse runs. console_bridge's handler is global, hence the lock.
class CapturedLog final : public console_bridge::OutputHandler {
 public:
  CapturedLog() : lock_(mutex()) { console_bridge::useOutputHandler(this); }
  ~CapturedLog() override { console_bridge::restorePreviousOutputHandler(); }
  CapturedLog(const CapturedLog&) = delete;
  CapturedLog& operator=(const CapturedLog&) = delete;

  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_ERROR) return;
    if (!errors_.empty()) errors_ += "; ";
    errors_ += text;
  }
  // Every error urdfdom logged, in order, "; "-separated.
  [[nodiscard]] const std::string& errors() const { return errors_; }

 private:
  static std::mutex& mutex() {
    static std::mutex instance;
    return instance;
  }
  std::lock_guard<std::mutex> lock_;
  std::string errors_;
};

class Importer {
 public:
  Importer(std::string source, fs::path base_dir, const UrdfOptions& options)
      : source_(std::move(source)), base_dir_(std::move(base_dir)), options_(options) {}

  RobotModel import(const std::string& text) {
    TiXmlDocument document;
    document.Parse(text.c_str());
    if (document.Error())
      throw KinematicsError(source_ + ":" + std::to_string(document.ErrorRow()) + ":" +
                            std::to_string(document.ErrorCol()) +
                            ": XML syntax error: " + document.ErrorDesc());
    const TiXmlElement* robot = document.RootElement();
    if (robot == nullptr || robot->ValueStr() != "robot")
      fail(robot == nullptr ? 1 : robot->Row(),
           "not a URDF file: the root element is <" +
               (robot == nullptr ? std::string() : robot->ValueStr()) + ">, expected <robot>");
    where_ = locate(*robot);
    urdf::ModelInterfaceSharedPtr model;
    std::string urdfdom_error;
    {
      CapturedLog log;
      try {
        model = urdf::parseURDF(text);
      } catch (const std::exception& error) {
        urdfdom_error = error.what();
      }
      if (urdfdom_error.empty()) urdfdom_error = log.errors();
    }
    // urdfdom may log an error and carry on without the element (a malformed <collision>): that
    // loses geometry silently, so any error it logs is one.
    if (!model || !urdfdom_error.empty())
      fail(line_of_message(urdfdom_error), "urdfdom: " + urdfdom_error);
    model_ = model;
    check_collision_meshes();
    RobotDescription description = describe();
    try {
      return RobotModel(std::move(description));
    } catch (const KinematicsError& error) {
      fail(where_.robot, error.what());
    }
  }

 private:
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw KinematicsError(source_ + ":" + std::to_string(line) + ": " + what);
  }
  int joint_line(const std::string& joint) const {
    const auto found = where_.joints.find(joint);
    return found == where_.joints.end() ? where_.robot : found->second;
  }
  int link_line(const std::string& link) const {
    const auto found = where_.links.find(link);
    return found == where_.links.end() ? where_.robot : found->second;
  }
  int collision_line(const std::string& link, std::size_t index) const {
    const auto found = where_.collisions.find(link);
    if (found == where_.collisions.end() || index >= found->second.size()) return link_line(link);
    return found->second[index];
  }
  // urdfdom names what it rejects in brackets ("Joint [elbow] has no type"): the first bracketed
  // name of a joint or link gives the line; otherwise the <robot> element's.
  int line_of_message(const std::string& message) const {
    std::size_t open = message.find('[');
    while (open != std::string::npos) {
      const std::size_t close = message.find(']', open);
      if (close == std::string::npos) break;
      const std::string name = message.substr(open + 1, close - open - 1);
      if (where_.joints.contains(name)) return where_.joints.at(name);
      if (where_.links.contains(name)) return where_.links.at(name);
      open = message.find('[', close);
    }
    return where_.robot;
  }

  std::string link_names() const {
    std::string names;
    for (const auto& [name, link] : model_->links_) names += (names.empty() ? "" : ", ") + name;
    return names;
  }

  // Every collision mesh the file names exists, wherever its link is.
  void check_collision_meshes() {
    for (const auto& [name, link] : model_->links_)
      for (std::size_t i = 0; i < link->collision_array.size(); ++i) {
        const urdf::CollisionSharedPtr& collision = link->collision_array[i];
        if (!collision || !collision->geometry || collision->geometry->type != urdf::Geometry::MESH)
          continue;
        const auto& mesh = static_cast<const urdf::Mesh&>(*collision->geometry);
        (void)mesh_file(mesh.filename, name, i);
      }
  }

  fs::path mesh_file(const std::string& uri, const std::string& link, std::size_t index) const {
    const fs::path file = resolve_mesh_uri(uri, base_dir_, options_.package_path);
    const int line = collision_line(link, index);
    if (file.empty())
      fail(line, "link '" + link + "': collision mesh '" + uri + "': package '" +
                     uri.substr(10, uri.find('/', 10) - 10) +
                     "' is on no folder of robot.package_path or ROS_PACKAGE_PATH");
    std::error_code error;
    if (!fs::is_regular_file(file, error))
      fail(line,
           "link '" + link + "': collision mesh '" + uri + "' not found (" + file.string() + ")");
    return file;
  }

  // The base and tip links, checked.
  std::pair<urdf::LinkConstSharedPtr, urdf::LinkConstSharedPtr> ends() const {
    urdf::LinkConstSharedPtr base = model_->getRoot();
    if (!options_.base.empty()) {
      base = model_->getLink(options_.base);
      if (!base)
        fail(where_.robot, "no link '" + options_.base + "' for the base; links: " + link_names());
    }
    if (!options_.tip.empty()) {
      urdf::LinkConstSharedPtr tip = model_->getLink(options_.tip);
      if (!tip)
        fail(where_.robot, "no link '" + options_.tip + "' for the tip; links: " + link_names());
      return {base, tip};
    }
    // The child links of the last moving joints of the longest paths of moving joints below the
    // base.
    int best = 0;
    std::vector<std::string> ends;
    std::vector<std::pair<urdf::LinkConstSharedPtr, int>> stack = {{base, 0}};
    while (!stack.empty()) {
      const auto [link, moving] = stack.back();
      stack.pop_back();
      for (const urdf::JointSharedPtr& joint : link->child_joints) {
        const int count = moving + (joint->type == urdf::Joint::FIXED ? 0 : 1);
        if (joint->type != urdf::Joint::FIXED && count >= best) {
          if (count > best) ends.clear();
          best = count;
          ends.push_back(joint->child_link_name);
        }
        stack.emplace_back(model_->getLink(joint->child_link_name), count);
      }
    }
    if (ends.empty()) fail(where_.robot, "no joint moves below the base link '" + base->name + "'");
    if (ends.size() > 1) {
      std::sort(ends.begin(), ends.end());
      std::string listed;
      for (const std::string& name : ends) listed += (listed.empty() ? "" : ", ") + name;
      fail(where_.robot, "several links end the longest chain below '" + base->name + "' (" +
                             listed + "): name the tip link (--tip or robot.tip)");
    }
    return {base, model_->getLink(ends.front())};
  }

  RobotJoint joint_of(const urdf::Joint& joint) const {
    const int line = joint_line(joint.name);
    RobotJoint result{.name = joint.name,
                      .type = JointType::kFixed,
                      .parent_link = joint.parent_link_name,
                      .child_link = joint.child_link_name,
                      .origin = transform_of(joint.parent_to_joint_origin_transform),
                      .axis = {joint.axis.x, joint.axis.y, joint.axis.z},
                      .limits = {}};
    switch (joint.type) {
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
        result.type = JointType::kRevolute;
        break;
      case urdf::Joint::PRISMATIC:
        result.type = JointType::kPrismatic;
        break;
      case urdf::Joint::FIXED:
        return result;
      default:
        fail(line, "joint '" + joint.name +
                       "' is floating or planar: a chain takes revolute, continuous, prismatic "
                       "and fixed joints");
    }
    if (joint.mimic)
      fail(line, "joint '" + joint.name + "' mimics '" + joint.mimic->joint_name +
                     "': a chain's joints must move independently");
    if (!(result.axis.norm() > 1e-12) || !result.axis.allFinite())
      fail(line, "joint '" + joint.name + "' has a zero axis");
    if (joint.type == urdf::Joint::CONTINUOUS) {
      result.limits = {-std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::infinity()};
    } else {
      if (!joint.limits) fail(line, "joint '" + joint.name + "' has no <limit>");
      result.limits = {joint.limits->lower, joint.limits->upper};
      if (!std::isfinite(result.limits.lower) || !std::isfinite(result.limits.upper) ||
          result.limits.lower > result.limits.upper)
        fail(line, "joint '" + joint.name + "': limits [" + std::to_string(result.limits.lower) +
                       ", " + std::to_string(result.limits.upper) +
                       "] are not a finite interval with lower <= upper");
    }
    return result;
  }

  static Transform transform_of(const urdf::Pose& pose) {
    Transform transform = Transform::Identity();
    transform.linear() =
        Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
            .normalized()
            .toRotationMatrix();
    transform.translation() << pose.position.x, pose.position.y, pose.position.z;
    return transform;
  }

  RobotLink link_of(const urdf::Link& link) {
    RobotLink result{.name = link.name, .collision = {}};
    for (std::size_t i = 0; i < link.collision_array.size(); ++i) {
      const urdf::CollisionSharedPtr& collision = link.collision_array[i];
      if (!collision || !collision->geometry) continue;
      const std::string where = source_ + ":" + std::to_string(collision_line(link.name, i));
      LinkShape shape{.kind = ShapeKind::kBox,
                      .origin = transform_of(collision->origin),
                      .size = Eigen::Vector3d::Zero(),
                      .mesh = nullptr,
                      .where = where};
      const urdf::Geometry& geometry = *collision->geometry;
      switch (geometry.type) {
        case urdf::Geometry::BOX: {
          const auto& box = static_cast<const urdf::Box&>(geometry);
          shape.size << box.dim.x, box.dim.y, box.dim.z;
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
          shape.kind = ShapeKind::kCylinder;
          shape.size << cylinder.radius, cylinder.radius, cylinder.length;
          break;
        }
        case urdf::Geometry::SPHERE: {
          const auto& sphere = static_cast<const urdf::Sphere&>(geometry);
          shape.kind = ShapeKind::kSphere;
          shape.size.setConstant(sphere.radius);
          break;
        }
        case urdf::Geometry::MESH: {
          const auto& mesh = static_cast<const urdf::Mesh&>(geometry);
          shape.kind = ShapeKind::kMesh;
          shape.mesh = load_mesh(mesh, link.name, i);
          break;
        }
      }
      if (shape.kind != ShapeKind::kMesh && !(shape.size.minCoeff() > 0.0))
        fail(collision_line(link.name, i),
             "link '" + link.name + "': a collision box, cylinder or sphere needs sizes > 0");
      result.collision.push_back(std::move(shape));
    }
    return result;
  }

  std::shared_ptr<const geometry::Mesh> load_mesh(const urdf::Mesh& mesh, const std::string& link,
                                                  std::size_t index) {
    const fs::path file = mesh_file(mesh.filename, link, index);
    std::string extension = file.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const int line = collision_line(link, index);
    if (extension != ".stl" && extension != ".obj" && extension != ".off")
      fail(line, "link '" + link + "': collision mesh '" + mesh.filename +
                     "': spar reads STL, OBJ and OFF meshes, not " + extension);
    const Eigen::Vector3d scale(mesh.scale.x, mesh.scale.y, mesh.scale.z);
    if (!(scale.minCoeff() > 0.0) || !scale.allFinite())
      fail(line, "link '" + link + "': mesh scale must be positive");
    std::ostringstream key;
    key << file.string() << '|' << scale.transpose();
    if (const auto cached = meshes_.find(key.str()); cached != meshes_.end()) return cached->second;
    geometry::Mesh loaded;
    try {
      loaded = geometry::read_triangle_soup(file.string());
    } catch (const geometry::GeometryError& error) {
      fail(line, "link '" + link + "': bad collision mesh " + file.string() + ": " + error.what());
    }
    for (Eigen::Vector3d& vertex : loaded.vertices) vertex = vertex.cwiseProduct(scale);
    auto shared = std::make_shared<const geometry::Mesh>(std::move(loaded));
    meshes_.emplace(key.str(), shared);
    return shared;
  }

  RobotDescription describe() {
    const auto [base, tip] = ends();
    // The path tip -> base through parent joints.
    std::vector<urdf::JointConstSharedPtr> path;
    for (urdf::LinkConstSharedPtr link = tip; link->name != base->name;) {
      const urdf::JointConstSharedPtr joint = link->parent_joint;
      if (!joint)
        fail(link_line(tip->name),
             "the tip link '" + tip->name + "' is not below the base link '" + base->name + "'");
      path.push_back(joint);
      link = model_->getLink(joint->parent_link_name);
    }
    std::reverse(path.begin(), path.end());
    RobotDescription description{.name = model_->getName(),
                                 .source = source_,
                                 .base_link = base->name,
                                 .tip_link = tip->name,
                                 .chain = {},
                                 .attachments = {},
                                 .links = {},
                                 .dh = nullptr};
    std::set<std::string> arm = {base->name};
    for (const urdf::JointConstSharedPtr& joint : path) {
      description.chain.push_back(joint_of(*joint));
      arm.insert(joint->child_link_name);
    }
    // Links fixed to the chain (not below the tip), found breadth first.
    std::vector<std::string> queue(arm.begin(), arm.end());
    std::erase(queue, tip->name);
    while (!queue.empty()) {
      const urdf::LinkConstSharedPtr link = model_->getLink(queue.back());
      queue.pop_back();
      for (const urdf::JointSharedPtr& joint : link->child_joints) {
        if (arm.contains(joint->child_link_name) || joint->type != urdf::Joint::FIXED) continue;
        description.attachments.push_back(joint_of(*joint));
        arm.insert(joint->child_link_name);
        queue.push_back(joint->child_link_name);
      }
    }
    for (const std::string& name : arm) {
      RobotLink link = link_of(*model_->getLink(name));
      if (!link.collision.empty()) description.links.push_back(std::move(link));
    }
    return description;
  }

  std::string source_;
  fs::path base_dir_;
  const UrdfOptions& options_;
  Locations where_;
  urdf::ModelInterfaceSharedPtr model_;
  std::map<std::string, std::shared_ptr<const geometry::Mesh>> meshes_;
};

std::vector<fs::path> split_path_list(const char* list) {
  std::vector<fs::path> folders;
  if (list == nullptr) return folders;
  std::string text(list);
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t colon = text.find(':', start);
    const std::string folder =
        text.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (!folder.empty()) folders.emplace_back(folder);
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return folders;
}

}  // namespace

fs::path resolve_mesh_uri(std::string_view uri, const fs::path& base_dir,
                          const std::vector<fs::path>& package_path) {
  constexpr std::string_view kPackage = "package://", kFile = "file://";
  if (uri.starts_with(kFile)) return fs::path(uri.substr(kFile.size()));
  if (!uri.starts_with(kPackage)) return (base_dir / fs::path(uri)).lexically_normal();
  const std::string_view rest = uri.substr(kPackage.size());
  const std::size_t slash = rest.find('/');
  const std::string package(rest.substr(0, slash));
  const fs::path inside(slash == std::string_view::npos ? std::string_view()
                                                        : rest.substr(slash + 1));
  std::vector<fs::path> folders = package_path;
  for (const fs::path& folder : split_path_list(std::getenv("ROS_PACKAGE_PATH")))
    folders.push_back(folder);
  std::error_code error;
  for (const fs::path& folder : folders) {
    if (fs::is_directory(folder / package, error))
      return (folder / package / inside).lexically_normal();
    if (folder.lexically_normal().filename() == package && fs::is_directory(folder, error))
      return (folder / inside).lexically_normal();
  }
  return {};
}

RobotModel parse_urdf(const std::string& text, const std::string& source, const fs::path& base_dir,
                      const UrdfOptions& options) {
  return Importer(source, base_dir, options).import(text);
}

RobotModel load_urdf(const fs::path& path, const UrdfOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw KinematicsError(path.string() + ": cannot read the URDF file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_urdf(text.str(), path.string(), path.parent_path(), options);
}

}  // namespace spar::kinematics
