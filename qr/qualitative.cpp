#include "spar/qr/qualitative.hpp"

#include <cmath>
#include <string>

namespace spar::qr {
namespace {

constexpr Potentials kDefPlus{3, 0, 0};
constexpr Potentials kDefZero{0, 3, 0};
constexpr Potentials kDefMinus{0, 0, 3};
constexpr Potentials kAmbiguous{1, 1, 1};

// ---------------------------------------------------------------------------------------------
// The embedded relation tables: our reconstruction of the seed's lost Figure 3, identical to the
// definite rows of data/qr_relation_tables.json (a test checks the agreement, and that
// the `?` rows computed by table_entry() match the corpus's `?` rows).
//
// Row order is + 0 -, entry (i, j) at index 3*i + j; each triple gives the potentials of a
// + / 0 / - result. Definite outcomes follow the qualitative sign algebra (de Kleer & Brown;
// Kuipers' ADD / MULT / MINUS / M+ constraints); the only undecidable sum, + plus -, is (1,1,1).
//
//   sum        b=+        b=0        b=-             product    b=+        b=0        b=-
//   a=+     (3,0,0)    (3,0,0)    (1,1,1)            a=+     (3,0,0)    (0,3,0)    (0,0,3)
//   a=0     (3,0,0)    (0,3,0)    (0,0,3)            a=0     (0,3,0)    (0,3,0)    (0,3,0)
//   a=-     (1,1,1)    (0,0,3)    (0,0,3)            a=-     (0,0,3)    (0,3,0)    (3,0,0)
//
//   input       negative     abs        M+         threshold (ours, not in the corpus)
//   +           (0,0,3)    (3,0,0)    (3,0,0)     (3/2, 0, 3/2)
//   0           (0,3,0)    (0,3,0)    (0,3,0)     (0, 0, 3)
//   -           (3,0,0)    (3,0,0)    (0,0,3)     (0, 0, 3)
//
// Threshold: the output is + when an unknown real exceeded an unknown POSITIVE threshold (seed,
// section 3), - otherwise, never 0. A non-positive input cannot exceed it; a positive one may or
// may not, so its triple splits evenly between + and -.
// ---------------------------------------------------------------------------------------------
const RelationTable kSumTable{2,
                              {kDefPlus, kDefPlus, kAmbiguous, kDefPlus, kDefZero, kDefMinus,
                               kAmbiguous, kDefMinus, kDefMinus}};
const RelationTable kProductTable{
    2,
    {kDefPlus, kDefZero, kDefMinus, kDefZero, kDefZero, kDefZero, kDefMinus, kDefZero, kDefPlus}};
const RelationTable kNegativeTable{1, {kDefMinus, kDefZero, kDefPlus}};
const RelationTable kAbsTable{1, {kDefPlus, kDefZero, kDefPlus}};
const RelationTable kMonotonePlusTable{1, {kDefPlus, kDefZero, kDefMinus}};
const RelationTable kThresholdTable{1, {Potentials{1.5, 0, 1.5}, kDefMinus, kDefMinus}};

// Possibility factors of an argument: 1 where it may match +, 0, -.
Potentials possibility(Sign sign) {
  if (sign == Sign::kUnknown) return {1, 1, 1};
  Potentials factors{0, 0, 0};
  factors[index(sign)] = 1;
  return factors;
}

void check_arity(const RelationTable& table, std::size_t inputs) {
  if (static_cast<int>(inputs) != table.arity) {
    throw QrError("relation table of arity " + std::to_string(table.arity) + " given " +
                  std::to_string(inputs) + " inputs");
  }
}

// The change triple for definite current input values and definite input changes.
Potentials definite_change(Relation relation, std::span<const Sign> values, Sign output,
                           std::span<const Sign> changes) {
  switch (relation) {
    case Relation::kSum:
      return kSumTable.at(changes[0], changes[1]);
    case Relation::kProduct: {
      const Sign first_term = sign_of(kProductTable.at(values[1], changes[0]));
      const Sign second_term = sign_of(kProductTable.at(values[0], changes[1]));
      return kSumTable.at(first_term, second_term);
    }
    case Relation::kNegative:
      return kNegativeTable.at(changes[0]);
    case Relation::kMonotonePlus:
      return kMonotonePlusTable.at(changes[0]);
    case Relation::kAbs:
      if (values[0] == Sign::kZero) return kAbsTable.at(changes[0]);
      return kProductTable.at(values[0], changes[0]);
    case Relation::kThreshold:
      if (output == Sign::kPlus && changes[0] == Sign::kMinus) return {0, 1.5, 1.5};
      if (output == Sign::kMinus && changes[0] == Sign::kPlus) return {1.5, 1.5, 0};
      return kDefZero;
  }
  throw QrError("unknown relation");
}

}  // namespace

char to_char(Sign sign) {
  constexpr char kSymbols[] = {'+', '0', '-', '?'};
  return kSymbols[index(sign)];
}

Sign sign_from_char(char symbol) {
  switch (symbol) {
    case '+':
      return Sign::kPlus;
    case '0':
      return Sign::kZero;
    case '-':
      return Sign::kMinus;
    case '?':
      return Sign::kUnknown;
    default:
      throw QrError(std::string("not a qualitative value: '") + symbol + "' (expected + 0 - ?)");
  }
}

Sign sign_of(double value) {
  if (value > 0) return Sign::kPlus;
  if (value < 0) return Sign::kMinus;
  return Sign::kZero;
}

Sign negate(Sign sign) {
  if (sign == Sign::kPlus) return Sign::kMinus;
  if (sign == Sign::kMinus) return Sign::kPlus;
  return sign;
}

int arity(Relation relation) {
  return relation == Relation::kSum || relation == Relation::kProduct ? 2 : 1;
}

std::string to_string(Relation relation) {
  switch (relation) {
    case Relation::kSum:
      return "sum";
    case Relation::kProduct:
      return "product";
    case Relation::kNegative:
      return "negative";
    case Relation::kAbs:
      return "abs";
    case Relation::kMonotonePlus:
      return "M+";
    case Relation::kThreshold:
      return "threshold";
  }
  return "?";
}

const Potentials& RelationTable::at(Sign first, Sign second) const {
  if (first == Sign::kUnknown || (arity == 2 && second == Sign::kUnknown)) {
    throw QrError("relation tables are indexed by definite values only");
  }
  return entries[arity == 2 ? 3 * index(first) + index(second) : index(first)];
}

bool is_well_formed(const RelationTable& table) {
  if (table.arity < 1 || table.arity > 2) return false;
  if (table.entries.size() != (table.arity == 2 ? 9u : 3u)) return false;
  for (const Potentials& triple : table.entries) {
    if (triple[0] < 0 || triple[1] < 0 || triple[2] < 0) return false;
    if (std::abs(triple[0] + triple[1] + triple[2] - 3.0) > 1e-12) return false;
  }
  return true;
}

const RelationTable& value_table(Relation relation) {
  switch (relation) {
    case Relation::kSum:
      return kSumTable;
    case Relation::kProduct:
      return kProductTable;
    case Relation::kNegative:
      return kNegativeTable;
    case Relation::kAbs:
      return kAbsTable;
    case Relation::kMonotonePlus:
      return kMonotonePlusTable;
    case Relation::kThreshold:
      return kThresholdTable;
  }
  throw QrError("unknown relation");
}

LikelyPotentials likely_potentials(const RelationTable& table, std::span<const Sign> inputs,
                                   Sign result) {
  check_arity(table, inputs.size());
  LikelyPotentials out;
  out.inputs.assign(inputs.size(), Potentials{0, 0, 0});
  const Potentials result_factors = possibility(result);
  const Potentials first_factors = possibility(inputs[0]);
  const Potentials second_factors = table.arity == 2 ? possibility(inputs[1]) : Potentials{1, 0, 0};
  const int columns = table.arity == 2 ? 3 : 1;
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < columns; ++column) {
      const double input_weight = first_factors[row] * second_factors[column];
      const Potentials& triple = table.entries[columns * row + column];
      for (int k = 0; k < 3; ++k) {
        const double weighted = input_weight * result_factors[k] * triple[k];
        out.inputs[0][row] += weighted;
        if (table.arity == 2) out.inputs[1][column] += weighted;
        out.result[k] += weighted;
      }
    }
  }
  return out;
}

Sign sign_of(const Potentials& potentials) {
  int nonzero = 0;
  Sign sign = Sign::kUnknown;
  for (Sign candidate : kDefiniteSigns) {
    if (potentials[index(candidate)] > 0) {
      ++nonzero;
      sign = candidate;
    }
  }
  return nonzero == 1 ? sign : Sign::kUnknown;
}

TableEntry table_entry(const RelationTable& table, std::span<const Sign> inputs) {
  const LikelyPotentials raw = likely_potentials(table, inputs, Sign::kUnknown);
  const double total = raw.result[0] + raw.result[1] + raw.result[2];
  TableEntry entry;
  // Each matching definite entry contributes a triple summing to 3, so total / 3 entries matched.
  for (int k = 0; k < 3; ++k) entry.potentials[k] = raw.result[k] * 3.0 / total;
  entry.sign = sign_of(entry.potentials);
  return entry;
}

RelationTable change_table(Relation relation, std::span<const Sign> input_values,
                           Sign output_value) {
  const int n = arity(relation);
  if (static_cast<int>(input_values.size()) != n) {
    throw QrError(to_string(relation) + " takes " + std::to_string(n) + " input values");
  }
  RelationTable table{n, std::vector<Potentials>(n == 2 ? 9 : 3, Potentials{0, 0, 0})};
  // Enumerate the unknown current values (and the threshold's own value) uniformly.
  std::vector<std::vector<Sign>> candidates;
  for (Sign value : input_values) {
    candidates.push_back(value == Sign::kUnknown
                             ? std::vector<Sign>(kDefiniteSigns.begin(), kDefiniteSigns.end())
                             : std::vector<Sign>{value});
  }
  const std::vector<Sign> outputs = output_value == Sign::kPlus || output_value == Sign::kMinus
                                        ? std::vector<Sign>{output_value}
                                        : std::vector<Sign>{Sign::kPlus, Sign::kMinus};
  const std::vector<Sign> second_values = n == 2 ? candidates[1] : std::vector<Sign>{Sign::kPlus};
  double count = 0;
  for (Sign first : candidates[0]) {
    for (Sign second : second_values) {
      for (Sign output : outputs) {
        count += 1;
        const Sign values[] = {first, second};
        for (int entry = 0; entry < static_cast<int>(table.entries.size()); ++entry) {
          const Sign changes[] = {kDefiniteSigns[n == 2 ? entry / 3 : entry],
                                  kDefiniteSigns[entry % 3]};
          const Potentials triple =
              definite_change(relation, std::span(values, n), output, std::span(changes, n));
          for (int k = 0; k < 3; ++k) table.entries[entry][k] += triple[k];
        }
      }
    }
  }
  for (Potentials& triple : table.entries) {
    for (double& value : triple) value /= count;
  }
  return table;
}

LikelyPotentials likely_change_potentials(Relation relation, std::span<const Sign> input_values,
                                          Sign output_value, std::span<const Sign> input_changes,
                                          Sign result_change) {
  return likely_potentials(change_table(relation, input_values, output_value), input_changes,
                           result_change);
}

}  // namespace spar::qr
