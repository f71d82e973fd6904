// The domain loader (planner/domain.hpp): the built-in templates are SPAR's, the shipped file is
// what is compiled in, a user's added action loads without recompiling, and every mistake in a
// domain file is one DomainError naming file:line:col.
#include "spar/planner/domain.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "spar/planner/error.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::planner {
namespace {

std::string shipped_text() {
  std::ifstream in(std::filesystem::path(SPAR_SOURCE_DIR) / "planner" / "domain.yaml");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(Domain, BuiltInHasSparsTemplates) {
  const Domain& domain = builtin_domain();
  for (const char* name : {"pickup", "putdown", "assemble", "range-scan", "squeeze"})
    EXPECT_NO_THROW((void)domain.action(name)) << name;
  EXPECT_EQ(domain.action("range-scan").kind, ActionKind::kSensing);
  EXPECT_EQ(domain.action("squeeze").kind, ActionKind::kReduction);
  EXPECT_EQ(domain.action("assemble").uncertainty, std::vector<Builder>{Builder::kAssemble});
  // The domain file's effects, typed at load (planner/uncertainty/effects.hpp).
  EXPECT_EQ(domain.action("pickup").effect, Effect::kGrasp);
  EXPECT_EQ(domain.action("putdown").effect, Effect::kRelease);
  EXPECT_EQ(domain.action("assemble").effect, Effect::kInsert);
  EXPECT_EQ(domain.action("range-scan").effect, Effect::kSense);
  EXPECT_EQ(domain.action("squeeze").effect, Effect::kReduce);
  EXPECT_EQ(domain.action("pickup").uncertainty, std::vector<Builder>{Builder::kPickup});
  EXPECT_TRUE(domain.action("putdown").uncertainty.empty());
  // Every verification an action names, and every recovery a verification names, exists.
  for (const ActionTemplate& action : domain.actions)
    for (const std::string& verification : action.verification)
      for (const VerificationOutcome& outcome : domain.verification(verification).outcomes)
        EXPECT_NO_THROW((void)domain.recovery(outcome.recovery)) << outcome.recovery;
  EXPECT_THROW_MESSAGE(domain.action("weld"), "weld");
}

TEST(Domain, TheShippedFileIsWhatIsCompiledIn) {
  const Domain shipped =
      load_domain(std::filesystem::path(SPAR_SOURCE_DIR) / "planner" / "domain.yaml");
  const Domain& built_in = builtin_domain();
  ASSERT_EQ(shipped.actions.size(), built_in.actions.size());
  for (std::size_t i = 0; i < shipped.actions.size(); ++i) {
    EXPECT_EQ(shipped.actions[i].name, built_in.actions[i].name);
    EXPECT_EQ(shipped.actions[i].operational, built_in.actions[i].operational);
    EXPECT_EQ(shipped.actions[i].add, built_in.actions[i].add);
    EXPECT_EQ(shipped.actions[i].del, built_in.actions[i].del);
    EXPECT_EQ(shipped.actions[i].effect, built_in.actions[i].effect);
    EXPECT_EQ(shipped.actions[i].uncertainty, built_in.actions[i].uncertainty);
  }
  EXPECT_EQ(shipped.verifications.size(), built_in.verifications.size());
  EXPECT_EQ(shipped.recoveries.size(), built_in.recoveries.size());
}

TEST(Domain, AnActionAddedToTheFileLoads) {
  std::string text = shipped_text();
  const std::string anchor = "  - name: range-scan\n";
  ASSERT_NE(text.find(anchor), std::string::npos);
  text.insert(text.find(anchor),
              "  - name: touch-probe\n"
              "    effect: sense\n"
              "    parameters: {object: object, position: position(object)}\n"
              "    operational: [\"gripper(empty)\", \"at(object, position)\"]\n"
              "    add: []\n"
              "    delete: []\n\n");
  const Domain domain = parse_domain(text, "mine.yaml");
  EXPECT_EQ(domain.action("touch-probe").kind, ActionKind::kSensing);
  EXPECT_EQ(domain.actions.size(), builtin_domain().actions.size() + 1);
}

// ---- one test per class of mistake, each with file:line:col ----

// A one-action domain whose action has `body` (indented by four spaces, one key a line).
std::string one_action(const std::string& body) {
  return "actions:\n"
         "  - name: poke\n" +
         body;
}

TEST(DomainErrors, YamlSyntax) {
  EXPECT_THROW_MESSAGE(parse_domain("actions: [\n", "d.yaml"),
                       "d.yaml:2:1: YAML syntax error: end of sequence flow not found");
}

TEST(DomainErrors, NestingBeyondYamlCppsLimitIsNamed) {
  const std::string deep = "actions: " + std::string(1000, '[') + std::string(1000, ']') + "\n";
  EXPECT_THROW_MESSAGE(parse_domain(deep, "d.yaml"),
                       "d.yaml:1:2010: YAML syntax error: nested too deeply");
}

TEST(DomainErrors, UnknownTopLevelKey) {
  EXPECT_THROW_MESSAGE(parse_domain("actions: []\nverbs: []\n", "d.yaml"),
                       "d.yaml:2:1: unknown key 'verbs' in the domain file");
}

TEST(DomainErrors, AtomArgumentThatIsNotAParameter) {
  EXPECT_THROW_MESSAGE(
      parse_domain("actions:\n"
                   "  - name: poke\n"
                   "    effect: none\n"
                   "    parameters: {object: object}\n"
                   "    operational: [\"at(object, where)\"]\n"
                   "    add: []\n"
                   "    delete: []\n",
                   "d.yaml"),
      "d.yaml:5:19: 'where' in at(object, where) is not a parameter of action 'poke'");
}

TEST(DomainErrors, UnknownParameterType) {
  EXPECT_THROW_MESSAGE(parse_domain("actions:\n"
                                    "  - name: poke\n"
                                    "    parameters: {object: thing}\n"
                                    "    add: []\n"
                                    "    delete: []\n",
                                    "d.yaml"),
                       "d.yaml:3:26: parameter 'object' has unknown type 'thing'");
}

TEST(DomainErrors, MissingEffect) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    parameters: {object: object}\n"), "d.yaml"),
                       "d.yaml:2:5: action 'poke' needs 'effect' (one of grasp, release, insert, "
                       "sense, reduce, none)");
}

TEST(DomainErrors, UnknownEffect) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    effect: fly\n"
                                               "    parameters: {object: object}\n"),
                                    "d.yaml"),
                       "d.yaml:3:13: unknown effect 'fly' (known: grasp, release, insert, sense, "
                       "reduce, none)");
}

TEST(DomainErrors, SensorOnAnActionThatDoesNotSense) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    effect: none\n"
                                               "    sensor: camera\n"
                                               "    parameters: {object: object}\n"),
                                    "d.yaml"),
                       "d.yaml:4:13: 'sensor' is for actions with effect sense (action 'poke' has "
                       "effect none)");
}

TEST(DomainErrors, UnknownSensor) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    effect: sense\n"
                                               "    sensor: sonar\n"
                                               "    parameters: {object: object}\n"),
                                    "d.yaml"),
                       "d.yaml:4:13: unknown sensor 'sonar' (known: range_scan, camera)");
}

TEST(DomainErrors, UnknownBuilder) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    effect: none\n"
                                               "    parameters: {object: object}\n"
                                               "    uncertainty: [weld]\n"),
                                    "d.yaml"),
                       "d.yaml:5:19: unknown uncertainty builder 'weld' (known: pickup, squeeze, "
                       "assemble)");
}

TEST(DomainErrors, BuilderListedTwice) {
  EXPECT_THROW_MESSAGE(
      parse_domain(one_action("    effect: grasp\n"
                              "    parameters: {object: object, grasp: grasp(object)}\n"
                              "    uncertainty: [pickup, pickup]\n"),
                   "d.yaml"),
      "d.yaml:5:27: uncertainty builder 'pickup' is listed twice");
}

TEST(DomainErrors, AssembleBuilderNeedsEffectInsert) {
  EXPECT_THROW_MESSAGE(
      parse_domain(one_action("    effect: grasp\n"
                              "    parameters: {object: object, grasp: grasp(object)}\n"
                              "    uncertainty: [assemble]\n"),
                   "d.yaml"),
      "d.yaml:5:19: builder 'assemble' needs effect insert (it checks the held object against the "
      "fixed one) (action 'poke')");
}

TEST(DomainErrors, PickupBuilderNeedsTheObjectOnTheTable) {
  EXPECT_THROW_MESSAGE(
      parse_domain(one_action("    effect: release\n"
                              "    parameters: {object: object, grasp: grasp(object), "
                              "position: placement(object)}\n"
                              "    uncertainty: [pickup]\n"),
                   "d.yaml"),
      "d.yaml:5:19: builder 'pickup' reads the object on the table, but before a step with effect "
      "release it is held (action 'poke')");
}

TEST(DomainErrors, EffectNeedsAGraspParameter) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    effect: grasp\n"
                                               "    parameters: {object: object}\n"),
                                    "d.yaml"),
                       "d.yaml:3:13: effect grasp needs a grasp parameter, grasp(<object>) "
                       "(action 'poke')");
}

TEST(DomainErrors, ReleaseNeedsAPlaceOfTheGraspedObject) {
  EXPECT_THROW_MESSAGE(
      parse_domain(one_action("    effect: release\n"
                              "    parameters: {object: object, grasp: grasp(object)}\n"),
                   "d.yaml"),
      "d.yaml:3:13: effect release needs a position or placement of the grasped object 'object' "
      "(action 'poke')");
}

TEST(DomainErrors, InsertNeedsAPositionOfAnotherObject) {
  EXPECT_THROW_MESSAGE(
      parse_domain(one_action("    effect: insert\n"
                              "    parameters: {object: object, grasp: grasp(object), "
                              "position: position(object)}\n"),
                   "d.yaml"),
      "d.yaml:3:13: effect insert needs a position of the fixed object (another object than the "
      "grasped 'object') (action 'poke')");
}

TEST(DomainErrors, SenseNeedsAnObject) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    effect: sense\n"
                                               "    parameters: {}\n"),
                                    "d.yaml"),
                       "d.yaml:3:13: effect sense needs an object parameter (action 'poke')");
}

TEST(DomainErrors, KindThatDisagreesWithTheEffect) {
  EXPECT_THROW_MESSAGE(parse_domain(one_action("    effect: sense\n"
                                               "    kind: manipulation\n"
                                               "    parameters: {object: object}\n"),
                                    "d.yaml"),
                       "d.yaml:4:11: kind 'manipulation' disagrees with effect sense");
}

TEST(DomainErrors, MissingFileIsNamed) {
  EXPECT_THROW_MESSAGE(load_domain("/nonexistent/domain.yaml"),
                       "/nonexistent/domain.yaml: no such domain file");
}

}  // namespace
}  // namespace spar::planner
