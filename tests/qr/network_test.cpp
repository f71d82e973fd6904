#include "spar/qr/network.hpp"

#include <gtest/gtest.h>

#include "spar/qr/match_strike.hpp"

namespace spar::qr {
namespace {

class MatchNetwork : public ::testing::Test {
 protected:
  void set(double depth, double angle, double gap, std::optional<bool> break_start,
           std::optional<bool> break_strike, std::optional<bool> ignition) {
    net.set_control_value(net.find("digging depth"), depth);
    net.set_control_value(net.find("angle"), angle);
    net.set_control_value(net.find("jumping gap"), gap);
    net.observe_threshold(net.find("break on move to start"), break_start);
    net.observe_threshold(net.find("break on strike"), break_strike);
    net.observe_threshold(net.find("ignition"), ignition);
    net.propagate_values();
  }
  Sign value(const std::string& name) const { return net.node(net.find(name)).value; }

  Network net = match_strike_model().network;
};

TEST_F(MatchNetwork, ForwardValuesAtTheSeedStart) {
  set(8, 20, 20, false, false, false);
  EXPECT_EQ(value("force"), Sign::kPlus);
  EXPECT_EQ(value("heat"), Sign::kPlus);
  EXPECT_EQ(value("-landmark"), Sign::kPlus);
  EXPECT_EQ(value("strike offset"), Sign::kPlus);  // positive angle, negative landmark
  EXPECT_EQ(value("strike moment"), Sign::kPlus);
  EXPECT_EQ(value("ignition"), Sign::kMinus);
}

TEST_F(MatchNetwork, UnobservedThresholdOfPositiveInputIsUnknown) {
  set(8, 20, 20, false, false, std::nullopt);
  EXPECT_EQ(value("ignition"), Sign::kUnknown);
}

// A negative angle against a negative landmark leaves the offset undecided; a break on the strike
// tells backwards that the moment, hence the lever, is positive, but not the offset's sign.
TEST_F(MatchNetwork, BackwardRefinementFromAnObservedBreak) {
  set(12, -10, 20, false, true, std::nullopt);
  EXPECT_EQ(value("strike offset"), Sign::kUnknown);
  EXPECT_EQ(value("strike lever"), Sign::kPlus);
  EXPECT_EQ(value("strike moment"), Sign::kPlus);
}

TEST_F(MatchNetwork, BackwardRefinementResolvesAnUnknownFactor) {
  Network small;
  const int a = small.add_control("a");
  const int b = small.add_constant("b", Sign::kUnknown);
  const int product = small.add_relation(NodeKind::kProduct, "a*b", {a, b});
  const int fired = small.add_threshold("fired", product);
  small.set_control_value(a, -2.0);
  small.observe_threshold(fired, true);
  small.propagate_values();
  EXPECT_EQ(small.node(product).value, Sign::kPlus);  // exceeded a positive threshold
  EXPECT_EQ(small.node(b).value, Sign::kMinus);       // so b must be negative
}

TEST_F(MatchNetwork, ChangesPropagateTowardsEffects) {
  set(8, 20, 20, false, false, false);
  const std::vector<Sign> deeper =
      net.propagate_changes({{net.find("digging depth"), Sign::kPlus}});
  EXPECT_EQ(deeper[net.find("force")], Sign::kPlus);
  EXPECT_EQ(deeper[net.find("heat")], Sign::kPlus);
  EXPECT_EQ(deeper[net.find("strike moment")], Sign::kPlus);
  EXPECT_EQ(deeper[net.find("velocity")], Sign::kZero);
  const std::vector<Sign> lower = net.propagate_changes({{net.find("angle"), Sign::kMinus}});
  EXPECT_EQ(lower[net.find("strike offset")], Sign::kMinus);
  EXPECT_EQ(lower[net.find("strike lever")], Sign::kMinus);
  EXPECT_EQ(lower[net.find("start lever")], Sign::kMinus);
  EXPECT_EQ(lower[net.find("heat")], Sign::kZero);
}

TEST_F(MatchNetwork, CauseChangePotentialsPlanBackwards) {
  set(8, 20, 20, false, false, false);
  const int heat = net.find("heat");
  const std::vector<Sign> steady(net.size(), Sign::kZero);
  // For heat to rise with the velocity steady, force must rise.
  const Potentials force = net.cause_change_potentials(heat, 0, Sign::kPlus, steady);
  EXPECT_GT(force[index(Sign::kPlus)], 0);
  EXPECT_EQ(force[index(Sign::kZero)], 0);
  EXPECT_EQ(force[index(Sign::kMinus)], 0);
}

TEST(Network, RejectsMalformedNodesWithAMessage) {
  Network net;
  const int a = net.add_control("a");
  EXPECT_THROW((void)net.add_relation(NodeKind::kConstant, "c", {a}), QrError);
  try {
    (void)net.add_relation(NodeKind::kSum, "s", {a});
    FAIL() << "expected QrError";
  } catch (const QrError& error) {
    EXPECT_STREQ(error.what(), "node 's': a sum node takes 2 cause(s), got 1");
  }
  try {
    (void)net.add_relation(NodeKind::kAbs, "abs", {7});
    FAIL() << "expected QrError";
  } catch (const QrError& error) {
    EXPECT_STREQ(error.what(), "node 'abs' names a cause that does not exist yet");
  }
  EXPECT_THROW((void)net.add_control("a"), QrError);
}

TEST(Network, AncestorsFollowCauses) {
  const Network net = match_strike_model().network;
  EXPECT_TRUE(net.is_ancestor(net.find("digging depth"), net.find("break on strike")));
  EXPECT_TRUE(net.is_ancestor(net.find("angle"), net.find("break on move to start")));
  EXPECT_FALSE(net.is_ancestor(net.find("jumping gap"), net.find("break on strike")));
  EXPECT_FALSE(net.is_ancestor(net.find("angle"), net.find("ignition")));
}

}  // namespace
}  // namespace spar::qr
