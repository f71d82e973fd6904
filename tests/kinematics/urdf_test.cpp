// URDF import: what is read (joints, origins, axes, limits, collision geometry, package://
// names, the chain's ends) and one test per class of mistake, each with its message and line.
#include "spar/kinematics/urdf.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "spar/common/units.hpp"
#include "spar/kinematics/robots.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::kinematics {
namespace {

namespace fs = std::filesystem;
using units::kPi;

// A fresh folder per test under the system's temporary folder.
class Urdf : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    folder_ = fs::temp_directory_path() / ("spar_urdf_" + std::string(test->name()));
    fs::remove_all(folder_);
    fs::create_directories(folder_ / "meshes");
    // A closed tetrahedron, 1 unit along each axis.
    write("meshes/tetra.off",
          "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  }
  void TearDown() override { fs::remove_all(folder_); }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path path = folder_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  // A URDF with `links` and `joints` between the <robot> tags.
  fs::path robot(const std::string& body) const {
    return write("robot.urdf",
                 "<?xml version=\"1.0\"?>\n<robot name=\"arm\">\n" + body + "</robot>\n");
  }
  // "<folder>/robot.urdf:<number of the first line containing `text`>"
  std::string line_of(const std::string& text) const {
    std::ifstream in(folder_ / "robot.urdf");
    std::string line;
    for (int number = 1; std::getline(in, line); ++number)
      if (line.find(text) != std::string::npos)
        return (folder_ / "robot.urdf").string() + ":" + std::to_string(number);
    return "<not found>";
  }
  std::string at(const std::string& text) const { return line_of(text) + ":"; }

  fs::path folder_;
};

std::string revolute(const std::string& name, const std::string& parent, const std::string& child,
                     const std::string& extra = "<axis xyz=\"0 0 1\"/>") {
  return "  <joint name=\"" + name + "\" type=\"revolute\">\n    <parent link=\"" + parent +
         "\"/>\n    <child link=\"" + child + "\"/>\n    " + extra +
         "\n    <limit lower=\"-2\" upper=\"2\" effort=\"1\" velocity=\"1\"/>\n  </joint>\n";
}

// base -j-> tip, the tip with one <collision> of `geometry` (on its own line).
std::string tip_colliding_as(const std::string& geometry) {
  return "  <link name=\"base\"/>\n  <link name=\"tip\">\n    <collision><geometry>" + geometry +
         "</geometry></collision>\n  </link>\n" + revolute("j", "base", "tip");
}

// base -shoulder(z)-> upper -elbow(y, at 0.5 up, turned 90 deg about x)-> fore -fixed-> tip.
const char* kArm =
    "  <link name=\"base\"/>\n"
    "  <link name=\"upper\"/>\n"
    "  <link name=\"fore\"/>\n"
    "  <link name=\"tip\"/>\n"
    "  <joint name=\"shoulder\" type=\"revolute\">\n"
    "    <parent link=\"base\"/><child link=\"upper\"/>\n"
    "    <origin xyz=\"0 0 0.1\"/><axis xyz=\"0 0 1\"/>\n"
    "    <limit lower=\"-2\" upper=\"2\" effort=\"1\" velocity=\"1\"/>\n"
    "  </joint>\n"
    "  <joint name=\"elbow\" type=\"continuous\">\n"
    "    <parent link=\"upper\"/><child link=\"fore\"/>\n"
    "    <origin xyz=\"0 0 0.5\" rpy=\"1.5707963267948966 0 0\"/><axis xyz=\"0 1 0\"/>\n"
    "  </joint>\n"
    "  <joint name=\"slide\" type=\"prismatic\">\n"
    "    <parent link=\"fore\"/><child link=\"tip\"/>\n"
    "    <origin xyz=\"0.3 0 0\"/><axis xyz=\"2 0 0\"/>\n"
    "    <limit lower=\"0\" upper=\"0.2\" effort=\"1\" velocity=\"1\"/>\n"
    "  </joint>\n";

TEST_F(Urdf, ReadsJointsOriginsAxesAndLimits) {
  const RobotModel arm = load_urdf(robot(kArm));
  EXPECT_EQ(arm.name(), "arm");
  EXPECT_EQ(arm.base_link(), "base");
  EXPECT_EQ(arm.tip_link(), "tip");
  ASSERT_EQ(arm.dof(), 3u);
  EXPECT_EQ(arm.joints()[0].limits.lower, -2.0);
  EXPECT_EQ(arm.joints()[1].limits.upper, std::numeric_limits<double>::infinity());
  EXPECT_EQ(arm.joints()[2].type, JointType::kPrismatic);
  EXPECT_EQ(arm.joints()[2].axis, Eigen::Vector3d::UnitX());  // normalised
  const std::vector<double> q = {0.4, -0.7, 0.15};
  const Transform expected =
      Eigen::Translation3d(0, 0, 0.1) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
      Eigen::Translation3d(0, 0, 0.5) * Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()) *
      Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()) * Eigen::Translation3d(0.3 + 0.15, 0, 0);
  EXPECT_LT((arm.forward(q).matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(arm.ik_method(), IkMethod::kNumeric);
}

TEST_F(Urdf, ReadsCollisionBoxesCylindersSpheresAndScaledMeshes) {
  const RobotModel arm = load_urdf(robot(
      "  <link name=\"base\">\n"
      "    <collision><origin xyz=\"0 0 0.05\"/><geometry><box size=\"0.2 0.3 0.1\"/></geometry>"
      "</collision>\n"
      "    <collision><geometry><cylinder radius=\"0.05\" length=\"0.4\"/></geometry></collision>\n"
      "  </link>\n"
      "  <link name=\"tip\">\n"
      "    <collision><geometry><sphere radius=\"0.02\"/></geometry></collision>\n"
      "    <collision><geometry><mesh filename=\"meshes/tetra.off\" scale=\"2 3 4\"/></geometry>"
      "</collision>\n"
      "    <visual><geometry><mesh filename=\"meshes/absent.dae\"/></geometry></visual>\n"
      "  </link>\n" +
      revolute("j", "base", "tip")));
  ASSERT_EQ(arm.links().size(), 2u);
  const std::vector<LinkShape>& base = arm.links()[0].collision;
  ASSERT_EQ(base.size(), 2u);
  EXPECT_EQ(base[0].kind, ShapeKind::kBox);
  EXPECT_EQ(base[0].size, Eigen::Vector3d(0.2, 0.3, 0.1));
  EXPECT_EQ(base[0].origin.translation(), Eigen::Vector3d(0, 0, 0.05));
  EXPECT_EQ(base[0].where, line_of("<box"));
  EXPECT_EQ(base[1].kind, ShapeKind::kCylinder);
  EXPECT_EQ(base[1].size, Eigen::Vector3d(0.05, 0.05, 0.4));
  const std::vector<LinkShape>& tip = arm.links()[1].collision;
  ASSERT_EQ(tip.size(), 2u);
  EXPECT_EQ(tip[0].kind, ShapeKind::kSphere);
  EXPECT_EQ(tip[0].size, Eigen::Vector3d::Constant(0.02));
  ASSERT_EQ(tip[1].kind, ShapeKind::kMesh);
  ASSERT_NE(tip[1].mesh, nullptr);
  Eigen::Vector3d largest = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& vertex : tip[1].mesh->vertices) largest = largest.cwiseMax(vertex);
  EXPECT_EQ(largest, Eigen::Vector3d(2, 3, 4));
}

TEST_F(Urdf, PackageNamesResolveThroughPackagePathThenRosPackagePath) {
  fs::create_directories(folder_ / "first" / "cell" / "meshes");
  fs::create_directories(folder_ / "second" / "cell" / "meshes");
  fs::copy_file(folder_ / "meshes/tetra.off", folder_ / "second/cell/meshes/tetra.off");
  const std::string uri = "package://cell/meshes/tetra.off";
  EXPECT_EQ(resolve_mesh_uri(uri, folder_, {folder_ / "first", folder_ / "second"}),
            folder_ / "first/cell/meshes/tetra.off");  // the first folder that has the package
  EXPECT_EQ(resolve_mesh_uri(uri, folder_, {folder_ / "second/cell"}),
            folder_ / "second/cell/meshes/tetra.off");  // a folder named like the package
  EXPECT_EQ(resolve_mesh_uri(uri, folder_, {}), fs::path());
  EXPECT_EQ(resolve_mesh_uri("file:///abs/x.stl", folder_, {}), fs::path("/abs/x.stl"));
  EXPECT_EQ(resolve_mesh_uri("meshes/x.stl", folder_, {}), folder_ / "meshes/x.stl");
  const char* saved = std::getenv("ROS_PACKAGE_PATH");
  const std::string saved_value = saved ? saved : "";
  ::setenv("ROS_PACKAGE_PATH", ("/nowhere:" + (folder_ / "second").string()).c_str(), 1);
  EXPECT_EQ(resolve_mesh_uri(uri, folder_, {}), folder_ / "second/cell/meshes/tetra.off");
  const fs::path file = robot(
      "  <link name=\"base\"/>\n  <link name=\"tip\"><collision><geometry>"
      "<mesh filename=\"" +
      uri + "\"/></geometry></collision></link>\n" + revolute("j", "base", "tip"));
  EXPECT_EQ(load_urdf(file).links()[1].collision.size(), 1u);
  if (saved)
    ::setenv("ROS_PACKAGE_PATH", saved_value.c_str(), 1);
  else
    ::unsetenv("ROS_PACKAGE_PATH");
}

TEST_F(Urdf, TheDefaultTipEndsTheLongestChainOfMovingJoints) {
  const fs::path ur5 =
      robot_data_directory() / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf";
  const RobotModel model = load_urdf(ur5, {.package_path = {robot_data_directory()}});
  EXPECT_EQ(model.base_link(), "world");  // the file's root
  EXPECT_EQ(model.tip_link(), "wrist_3_link");
  EXPECT_EQ(model.dof(), 6u);
}

TEST_F(Urdf, TheArmHasTheLinksFixedToItsChainButNotThoseBeyondTheTip) {
  const RobotModel& ur5 = builtin_robot_model("ur5");
  const auto has = [](const RobotModel& robot, const std::string& name) {
    for (const RobotLinkInfo& link : robot.links())
      if (link.name == name) return true;
    return false;
  };
  EXPECT_TRUE(has(ur5, "ee_link"));  // fixed to wrist_3_link beside tool0
  EXPECT_FALSE(has(ur5, "world"));   // above the base
  const RobotModel& panda = builtin_robot_model("panda");
  EXPECT_FALSE(has(panda, "panda_hand"));  // beyond panda_link8: the tool's
  EXPECT_TRUE(has(panda, "panda_link7"));
}

// ---- one test per class of mistake ----

TEST_F(Urdf, UnreadableFile) {
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "absent.urdf"),
                       "absent.urdf: cannot read the URDF file");
}

TEST_F(Urdf, XmlSyntaxErrorHasLineAndColumn) {
  const fs::path file =
      write("robot.urdf", "<robot name=\"arm\">\n  <link name=\"base\">\n</robot>\n");
  EXPECT_THROW_MESSAGE(load_urdf(file), file.string() + ":");
  EXPECT_THROW_MESSAGE(load_urdf(file), "XML syntax error");
}

TEST_F(Urdf, RootMustBeRobot) {
  const fs::path file = write("robot.urdf", "<?xml version=\"1.0\"?>\n<sdf/>\n");
  EXPECT_THROW_MESSAGE(load_urdf(file), file.string() +
                                            ":2: not a URDF file: the root element is <sdf>, "
                                            "expected <robot>");
}

TEST_F(Urdf, WhatUrdfdomRejectsGetsTheLineOfTheJoint) {
  robot(
      "  <link name=\"base\"/>\n  <link name=\"tip\"/>\n"
      "  <joint name=\"hinge\" type=\"swivel\">\n"
      "    <parent link=\"base\"/><child link=\"tip\"/>\n  </joint>\n");
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("name=\"hinge\"") + " urdfdom: Joint [hinge] has no known type [swivel]");
}

TEST_F(Urdf, MalformedCollisionUrdfdomWouldDropIsAnError) {
  robot(tip_colliding_as("<box size=\"1 1\"/>"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("name=\"tip\"") +
                           " urdfdom: Parser found 2 elements but 3 expected "
                           "while parsing vector [1 1]; Could not parse "
                           "collision element for Link [tip]");
}

TEST_F(Urdf, JointToAMissingLinkIsRejected) {
  robot("  <link name=\"base\"/>\n" + revolute("j", "base", "nowhere"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("name=\"j\"") +
                           " urdfdom: Failed to build tree: child link [nowhere] of joint [j] "
                           "not found");
}

TEST_F(Urdf, FloatingJointOnTheChain) {
  robot(
      "  <link name=\"base\"/>\n  <link name=\"tip\"/>\n"
      "  <joint name=\"free\" type=\"floating\">\n"
      "    <parent link=\"base\"/><child link=\"tip\"/>\n  </joint>\n");
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf", {.tip = "tip"}),
                       at("name=\"free\"") +
                           " joint 'free' is floating or planar: a chain takes revolute, "
                           "continuous, prismatic and fixed joints");
}

TEST_F(Urdf, MimicJointOnTheChain) {
  robot("  <link name=\"base\"/>\n  <link name=\"mid\"/>\n  <link name=\"tip\"/>\n" +
        revolute("a", "base", "mid") +
        revolute("b", "mid", "tip", "<axis xyz=\"0 0 1\"/><mimic joint=\"a\"/>"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("name=\"b\"") +
                           " joint 'b' mimics 'a': a chain's joints must move "
                           "independently");
}

TEST_F(Urdf, LimitsOutOfOrder) {
  robot(
      "  <link name=\"base\"/>\n  <link name=\"tip\"/>\n"
      "  <joint name=\"j\" type=\"revolute\">\n"
      "    <parent link=\"base\"/><child link=\"tip\"/><axis xyz=\"0 0 1\"/>\n"
      "    <limit lower=\"1\" upper=\"-1\" effort=\"1\" velocity=\"1\"/>\n  </joint>\n");
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("name=\"j\"") +
                           " joint 'j': limits [1.000000, -1.000000] are not a "
                           "finite interval with lower <= upper");
}

TEST_F(Urdf, ZeroAxis) {
  robot("  <link name=\"base\"/>\n  <link name=\"tip\"/>\n" +
        revolute("j", "base", "tip", "<axis xyz=\"0 0 0\"/>"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"), " joint 'j' has a zero axis");
}

TEST_F(Urdf, UnknownBaseOrTipLink) {
  robot(kArm);
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf", {.tip = "hand"}),
                       at("<robot") + " no link 'hand' for the tip; links: base, fore, tip, upper");
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf", {.base = "floor"}),
                       " no link 'floor' for the base");
}

TEST_F(Urdf, TipNotBelowTheBase) {
  robot(kArm);
  EXPECT_THROW_MESSAGE(
      load_urdf(folder_ / "robot.urdf", {.base = "fore", .tip = "upper"}),
      at("name=\"upper\"") + " the tip link 'upper' is not below the base link 'fore'");
}

TEST_F(Urdf, SeveralEndsOfTheLongestChainNeedATip) {
  robot("  <link name=\"base\"/>\n  <link name=\"left\"/>\n  <link name=\"right\"/>\n" +
        revolute("a", "base", "left") + revolute("b", "base", "right"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       "several links end the longest chain below 'base' (left, right): name "
                       "the tip link (--tip or robot.tip)");
  EXPECT_EQ(load_urdf(folder_ / "robot.urdf", {.tip = "right"}).tip_link(), "right");
}

TEST_F(Urdf, MissingCollisionMeshNamesTheFileAndLine) {
  robot(
      "  <link name=\"base\"/>\n  <link name=\"tip\">\n"
      "    <visual><geometry><mesh filename=\"meshes/absent.dae\"/></geometry></visual>\n"
      "    <collision>\n      <geometry><mesh filename=\"meshes/absent.stl\"/></geometry>\n"
      "    </collision>\n  </link>\n" +
      revolute("j", "base", "tip"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("<collision>") +
                           " link 'tip': collision mesh 'meshes/absent.stl' not "
                           "found (" +
                           (folder_ / "meshes/absent.stl").string());
}

TEST_F(Urdf, MissingCollisionMeshOffTheArmIsAnErrorToo) {
  robot(
      "  <link name=\"base\"/>\n  <link name=\"tip\"/>\n"
      "  <link name=\"hand\"><collision><geometry><mesh filename=\"gone.stl\"/></geometry>"
      "</collision></link>\n" +
      revolute("j", "base", "tip") +
      "  <joint name=\"mount\" type=\"fixed\"><parent link=\"tip\"/><child link=\"hand\"/>"
      "</joint>\n");
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf", {.tip = "tip"}),
                       at("name=\"hand\"") + " link 'hand': collision mesh 'gone.stl' not found");
}

TEST_F(Urdf, UnknownPackage) {
  robot(tip_colliding_as("<mesh filename=\"package://nopackage/m.stl\"/>"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("<collision>") +
                           " link 'tip': collision mesh 'package://nopackage/m.stl': package "
                           "'nopackage' is on no folder of robot.package_path or "
                           "ROS_PACKAGE_PATH");
}

TEST_F(Urdf, UnsupportedMeshFormat) {
  write("meshes/part.dae", "<COLLADA/>");
  robot(tip_colliding_as("<mesh filename=\"meshes/part.dae\"/>"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("<collision>") +
                           " link 'tip': collision mesh 'meshes/part.dae': spar "
                           "reads STL, OBJ and OFF meshes, not .dae");
}

TEST_F(Urdf, BadMeshFile) {
  write("meshes/broken.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n");
  robot(tip_colliding_as("<mesh filename=\"meshes/broken.off\"/>"));
  EXPECT_THROW_MESSAGE(load_urdf(folder_ / "robot.urdf"),
                       at("<collision>") + " link 'tip': bad collision mesh ");
}

TEST_F(Urdf, ShapeWithoutSize) {
  robot(tip_colliding_as("<sphere radius=\"0\"/>"));
  EXPECT_THROW_MESSAGE(
      load_urdf(folder_ / "robot.urdf"),
      at("<collision>") + " link 'tip': a collision box, cylinder or sphere needs sizes > 0");
}

TEST_F(Urdf, UnknownRobotName) {
  EXPECT_THROW_MESSAGE(load_robot("kuka"),
                       "unknown robot 'kuka'; built-in robots: puma560, puma762, ur5, panda; or "
                       "the path of a URDF file");
  EXPECT_THROW_MESSAGE(load_robot("puma560", {.tip = "wrist"}),
                       "robot 'puma560' is a DH table: its base is link0 and its tip is flange");
}

}  // namespace
}  // namespace spar::kinematics
