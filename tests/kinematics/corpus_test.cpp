// The built-in robots against data/puma560.json: DH tables, every FK vector (to 1e-9)
// and every listed IK solution (found, with the same label and the same joint-limit verdict).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "spar/kinematics/ik.hpp"
#include "spar/kinematics/puma.hpp"

namespace spar::kinematics {
namespace {

const nlohmann::json& corpus() {
  static const nlohmann::json document = [] {
    std::ifstream file(std::string(SPAR_CORPUS_DIR) + "/puma560.json");
    if (!file) throw std::runtime_error("cannot open the corpus puma560.json");
    return nlohmann::json::parse(file);
  }();
  return document;
}

Eigen::Matrix4d matrix_from_json(const nlohmann::json& rows) {
  Eigen::Matrix4d matrix;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) matrix(row, col) = rows.at(row).at(col).get<double>();
  return matrix;
}

std::vector<double> vector_from_json(const nlohmann::json& values) {
  return values.get<std::vector<double>>();
}

double angle_distance(double a, double b) { return std::abs(wrap_angle(a - b)); }

class CorpusRobot : public ::testing::TestWithParam<std::string> {
 protected:
  const nlohmann::json& entry() const { return corpus().at(GetParam()); }
  const DhChain& robot() const { return builtin_robot(GetParam()); }
};

TEST(CorpusConvention, IsStandardDh) {
  // Our DhChain implements exactly this convention; if the corpus changed it, the tables would not
  // be comparable.
  EXPECT_EQ(corpus().at("convention").get<std::string>(),
            "standard (distal) Denavit-Hartenberg: A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)");
}

TEST_P(CorpusRobot, BuiltInTableMatchesCorpus) {
  const nlohmann::json& table = entry().at("dh");
  ASSERT_EQ(table.size(), robot().size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    SCOPED_TRACE("joint " + std::to_string(i + 1));
    const nlohmann::json& row = table.at(i);
    const DhJoint& joint = robot().joint(i);
    EXPECT_EQ(row.at("type").get<std::string>(), "revolute");
    EXPECT_NEAR(joint.d, row.at("d").get<double>(), 1e-12);
    EXPECT_NEAR(joint.a, row.at("a").get<double>(), 1e-12);
    EXPECT_NEAR(joint.alpha, row.at("alpha").get<double>(), 1e-12);
    EXPECT_NEAR(joint.offset, row.at("offset").get<double>(), 1e-12);
    EXPECT_NEAR(joint.limits.lower, row.at("qlim_rad").at(0).get<double>(), 1e-12);
    EXPECT_NEAR(joint.limits.upper, row.at("qlim_rad").at(1).get<double>(), 1e-12);
  }
}

TEST_P(CorpusRobot, EveryFkVectorMatchesTo1e9) {
  for (const nlohmann::json& vector : entry().at("fk_vectors")) {
    SCOPED_TRACE(vector.at("name").get<std::string>());
    const Transform pose = robot().forward(vector_from_json(vector.at("q")));
    const double error = (pose.matrix() - matrix_from_json(vector.at("T"))).cwiseAbs().maxCoeff();
    EXPECT_LT(error, 1e-9);
  }
}

TEST_P(CorpusRobot, EveryListedIkSolutionIsFoundWithItsLabelAndLimitVerdict) {
  const PumaIk solver(robot());
  const nlohmann::json& vectors = entry().at("ik_vectors");
  ASSERT_FALSE(vectors.empty());
  for (const nlohmann::json& vector : vectors) {
    SCOPED_TRACE(vector.at("name").get<std::string>());
    Transform pose;
    pose.matrix() = matrix_from_json(vector.at("T"));
    const IkResult result = solver.solve(pose);
    ASSERT_TRUE(result.solved());
    EXPECT_EQ(result.singularities, kNoSingularity);
    for (const nlohmann::json& expected : vector.at("solutions")) {
      const std::string label = expected.at("config").get<std::string>();
      SCOPED_TRACE(label);
      const IkSolution& solution = result.solution(ArmConfiguration::from_label(label));
      const std::vector<double> q = vector_from_json(expected.at("q"));
      for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_LT(angle_distance(solution.q[static_cast<Eigen::Index>(i)], q[i]), 1e-8)
            << "joint " << i + 1;
      }
      EXPECT_EQ(solution.within_limits, expected.at("within_limits").get<bool>());
      const Transform reached = robot().forward(std::span<const double>(solution.q.data(), 6));
      EXPECT_LT((reached.matrix() - pose.matrix()).cwiseAbs().maxCoeff(), 1e-9);
    }
    // The generating joint vector is among the solutions (mod 2 pi).
    const std::vector<double> generating = vector_from_json(vector.at("q_generating"));
    bool found = false;
    for (const IkSolution& solution : result.solutions) {
      bool same = true;
      for (std::size_t i = 0; i < 6; ++i)
        same &= angle_distance(solution.q[static_cast<Eigen::Index>(i)], generating[i]) < 1e-8;
      found |= same;
    }
    EXPECT_EQ(found, vector.at("generating_q_found_among_solutions").get<bool>());
  }
}

INSTANTIATE_TEST_SUITE_P(BuiltInRobots, CorpusRobot, ::testing::Values("puma560", "puma762"));

TEST(Puma560, NamedConfigurationsMatchCorpus) {
  // The corpus's named configurations are the toolbox's; our FK of qn agrees with the value
  // printed in the toolbox documentation (to the 5e-5 the corpus states).
  const nlohmann::json& puma = corpus().at("puma560");
  const std::vector<double> qn = vector_from_json(puma.at("named_configurations").at("qn"));
  const Transform pose = puma560().forward(qn);
  const double error =
      (pose.matrix() - matrix_from_json(puma.at("published_check").at("T"))).cwiseAbs().maxCoeff();
  EXPECT_LT(error, puma.at("published_check").at("matches_our_fk_to").get<double>());
}

TEST(Puma560, ToolboxQnHasOnlyRdnAndRdfWithinLimits) {
  // Corpus note: q3 = pi is outside the model's own +-135 degree limit; reachability must be
  // decided per configuration.
  const std::vector<double> qn =
      vector_from_json(corpus().at("puma560").at("named_configurations").at("qn"));
  EXPECT_FALSE(puma560().within_limits(qn));
  const IkResult result = PumaIk(puma560()).solve(puma560().forward(qn));
  ASSERT_TRUE(result.solved());
  std::vector<std::string> in_limits;
  for (const IkSolution& solution : result.solutions)
    if (solution.within_limits) in_limits.push_back(solution.configuration.label());
  EXPECT_EQ(in_limits, (std::vector<std::string>{"rdn", "rdf"}));
}

}  // namespace
}  // namespace spar::kinematics
