#include "spar/qr/qualitative.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "tests/common/expect_message.hpp"

namespace spar::qr {
namespace {

constexpr Relation kAllRelations[] = {Relation::kSum,          Relation::kProduct,
                                      Relation::kNegative,     Relation::kAbs,
                                      Relation::kMonotonePlus, Relation::kThreshold};
constexpr Sign kAllSigns[] = {Sign::kPlus, Sign::kZero, Sign::kMinus, Sign::kUnknown};

void expect_triple(const Potentials& actual, const Potentials& expected, const std::string& what) {
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(actual[k], expected[k], 1e-12) << what << " position " << k;
}

// Sample reals of a given sign.
std::vector<double> samples(Sign sign) {
  switch (sign) {
    case Sign::kPlus:
      return {0.25, 1.0, 3.0, 7.5};
    case Sign::kZero:
      return {0.0};
    default:
      return {-0.25, -1.0, -3.0, -7.5};
  }
}

double apply(Relation relation, double a, double b) {
  switch (relation) {
    case Relation::kSum:
      return a + b;
    case Relation::kProduct:
      return a * b;
    case Relation::kNegative:
      return -a;
    case Relation::kAbs:
      return std::abs(a);
    case Relation::kMonotonePlus:
      return std::atan(a);  // a monotone increasing function through the origin
    case Relation::kThreshold:
      break;
  }
  return 0;
}

TEST(RelationTables, EveryTripleSumsToThree) {
  for (Relation relation : kAllRelations) {
    EXPECT_TRUE(is_well_formed(value_table(relation))) << to_string(relation);
  }
}

TEST(RelationTables, ChangeTablesSumToThreeForEveryCurrentValue) {
  for (Relation relation : kAllRelations) {
    for (Sign first : kAllSigns) {
      for (Sign second : kAllSigns) {
        for (Sign output : kAllSigns) {
          const Sign values[] = {first, second};
          const RelationTable table =
              change_table(relation, std::span(values, arity(relation)), output);
          EXPECT_TRUE(is_well_formed(table)) << to_string(relation) << " at " << to_char(first)
                                             << to_char(second) << " output " << to_char(output);
        }
      }
    }
  }
}

// The set of result signs a table entry allows must be exactly the set of signs that real
// numbers with the entry's input signs produce.
TEST(RelationTables, SignColumnsAgreeWithRealArithmetic) {
  for (Relation relation : kAllRelations) {
    if (relation == Relation::kThreshold) continue;  // its threshold is unknown; tested below
    const RelationTable& table = value_table(relation);
    for (Sign first : kDefiniteSigns) {
      for (Sign second : kDefiniteSigns) {
        if (table.arity == 1 && second != Sign::kPlus) continue;
        std::set<Sign> produced;
        for (double a : samples(first)) {
          for (double b : samples(second)) produced.insert(sign_of(apply(relation, a, b)));
        }
        const Potentials& triple = table.at(first, second);
        for (Sign result : kDefiniteSigns) {
          EXPECT_EQ(triple[index(result)] > 0, produced.count(result) == 1)
              << to_string(relation) << " (" << to_char(first) << "," << to_char(second)
              << ") result " << to_char(result);
        }
      }
    }
  }
}

TEST(RelationTables, ThresholdNeverZeroAndOnlyPositiveInputsCanExceed) {
  const RelationTable& table = value_table(Relation::kThreshold);
  expect_triple(table.at(Sign::kPlus), {1.5, 0, 1.5}, "threshold(+)");
  expect_triple(table.at(Sign::kZero), {0, 0, 3}, "threshold(0)");
  expect_triple(table.at(Sign::kMinus), {0, 0, 3}, "threshold(-)");
}

// The seed's Figure 4: the sum relation with inputs + and ? and a result of +.
TEST(LikelyPotentials, FigureFourSumExample) {
  const Sign inputs[] = {Sign::kPlus, Sign::kUnknown};
  const LikelyPotentials p = likely_potentials(value_table(Relation::kSum), inputs, Sign::kPlus);
  // Row + of the sum table weighted by result factors (1,0,0): (+,+) 3, (+,0) 3, (+,-) 1.
  expect_triple(p.inputs[0], {7, 0, 0}, "first input");
  expect_triple(p.inputs[1], {3, 3, 1}, "second input");
  expect_triple(p.result, {7, 0, 0}, "result");
}

TEST(LikelyPotentials, UnknownResultWeighsEveryPosition) {
  const Sign inputs[] = {Sign::kMinus, Sign::kUnknown};
  const LikelyPotentials p =
      likely_potentials(value_table(Relation::kProduct), inputs, Sign::kUnknown);
  expect_triple(p.inputs[0], {0, 0, 9}, "first input");
  expect_triple(p.inputs[1], {3, 3, 3}, "second input");
  expect_triple(p.result, {3, 3, 3}, "result");
}

TEST(LikelyPotentials, RejectsWrongNumberOfInputs) {
  const Sign inputs[] = {Sign::kPlus};
  try {
    (void)likely_potentials(value_table(Relation::kSum), inputs, Sign::kPlus);
    FAIL() << "expected QrError";
  } catch (const QrError& error) {
    EXPECT_STREQ(error.what(), "relation table of arity 2 given 1 inputs");
  }
}

TEST(TableEntry, UnknownRowsFollowFromTheProcedure) {
  const Sign plus_unknown[] = {Sign::kPlus, Sign::kUnknown};
  const TableEntry sum = table_entry(value_table(Relation::kSum), plus_unknown);
  EXPECT_EQ(sum.sign, Sign::kUnknown);
  expect_triple(sum.potentials, {7.0 / 3, 1.0 / 3, 1.0 / 3}, "sum(+,?)");
  const Sign zero_unknown[] = {Sign::kZero, Sign::kUnknown};
  const TableEntry product = table_entry(value_table(Relation::kProduct), zero_unknown);
  EXPECT_EQ(product.sign, Sign::kZero);
}

TEST(ChangePotentials, ProductOfPositivesChangesLikeASum) {
  const Sign values[] = {Sign::kPlus, Sign::kPlus};
  const RelationTable table = change_table(Relation::kProduct, values, Sign::kUnknown);
  for (std::size_t entry = 0; entry < 9; ++entry) {
    expect_triple(table.entries[entry], value_table(Relation::kSum).entries[entry],
                  "entry " + std::to_string(entry));
  }
}

TEST(ChangePotentials, AbsOfNegativeValueReversesTheChange) {
  const Sign values[] = {Sign::kMinus};
  const Sign decrease[] = {Sign::kMinus};
  const LikelyPotentials p =
      likely_change_potentials(Relation::kAbs, values, Sign::kPlus, decrease, Sign::kUnknown);
  expect_triple(p.result, {3, 0, 0}, "d|x| for x < 0, dx < 0");
}

TEST(ChangePotentials, FalseThresholdCanOnlyRise) {
  const Sign values[] = {Sign::kPlus};
  const Sign increase[] = {Sign::kPlus};
  const LikelyPotentials p = likely_change_potentials(Relation::kThreshold, values, Sign::kMinus,
                                                      increase, Sign::kUnknown);
  expect_triple(p.result, {1.5, 1.5, 0}, "threshold false, input rising");
}

TEST(Signs, ParseRejectsOtherCharactersWithAMessage) {
  EXPECT_EQ(sign_from_char('-'), Sign::kMinus);
  try {
    (void)sign_from_char('x');
    FAIL() << "expected QrError";
  } catch (const QrError& error) {
    EXPECT_STREQ(error.what(), "not a qualitative value: 'x' (expected + 0 - ?)");
  }
  // One error hierarchy (issue 12): QrError is a spar::Error.
  EXPECT_THROW_MESSAGE(sign_from_char('x'), "not a qualitative value");
}

// ------------------------------------------------------------------------------------------------
// Agreement with the corpus reconstruction of the seed's Figure 3.

double parse_fraction(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return std::stod(text);
  return std::stod(text.substr(0, slash)) / std::stod(text.substr(slash + 1));
}

nlohmann::json load_corpus() {
  std::ifstream file(std::string(SPAR_CORPUS_DIR) + "/qr_relation_tables.json");
  EXPECT_TRUE(file.good()) << "cannot open qr_relation_tables.json in " << SPAR_CORPUS_DIR;
  return nlohmann::json::parse(file);
}

TEST(RelationTables, AgreeWithCorpusReconstructionIncludingUnknownRows) {
  const nlohmann::json corpus = load_corpus();
  const std::pair<const char*, Relation> names[] = {{"sum", Relation::kSum},
                                                    {"product", Relation::kProduct},
                                                    {"negative", Relation::kNegative},
                                                    {"abs", Relation::kAbs},
                                                    {"M+", Relation::kMonotonePlus}};
  int checked = 0;
  for (const auto& [name, relation] : names) {
    ASSERT_TRUE(corpus["tables"].contains(name)) << name;
    const RelationTable& table = value_table(relation);
    for (const auto& [key, entry] : corpus["tables"][name].items()) {
      std::vector<Sign> inputs;
      for (char symbol : key) {
        if (symbol != ',') inputs.push_back(sign_from_char(symbol));
      }
      ASSERT_EQ(static_cast<int>(inputs.size()), table.arity) << name << " " << key;
      Potentials expected{};
      for (int k = 0; k < 3; ++k) {
        expected[k] = parse_fraction(entry["likely_potentials_plus_zero_minus"][k]);
      }
      const std::string what = std::string(name) + " (" + key + ")";
      const TableEntry computed = table_entry(table, inputs);
      expect_triple(computed.potentials, expected, what);
      EXPECT_EQ(to_char(computed.sign), entry["sign"].get<std::string>()[0]) << what;
      const bool definite = std::find(inputs.begin(), inputs.end(), Sign::kUnknown) == inputs.end();
      if (definite) expect_triple(table.at(inputs[0], inputs.back()), expected, what + " embedded");
      ++checked;
    }
  }
  EXPECT_EQ(checked, 16 + 16 + 4 + 4 + 4);
}

}  // namespace
}  // namespace spar::qr
