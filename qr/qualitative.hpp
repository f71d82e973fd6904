// Qualitative math with likelihood potentials (seeds/000, section 3).
//
// A qualitative value is one of `+ 0 - ?`. A relation table maps each combination of DEFINITE input
// values (+, 0, -) to a triple of likelihood potentials (p+, p0, p-): the relative likelihoods that
// the relation's result is +, 0 or -. Every triple sums to 3, which embodies the seed's assumption
// that each combination of inputs is equally likely. A definite outcome is (3,0,0), (0,3,0) or
// (0,0,3); an outcome the sign algebra cannot decide (e.g. `+` plus `-`) is (1,1,1).
//
// likely_potentials() is the procedure of the seed's Figure 4. Each argument (inputs and result)
// gets three possibility factors (1 where the argument may match +, 0, - and 0 where it cannot; `?`
// gives 1,1,1). Input factors multiply all three triple values of the entries in the corresponding
// rows (first input) and columns (second input); result factors multiply the corresponding triple
// position of every entry. The potentials returned are, for each input, the sums of all weighted
// triple values in each row / column and, for the result, the sums of each weighted triple position
// over all entries. Example (the seed's Figure 4): sum with inputs `+`, `?` and result `+` gives
// first input (7,0,0), second input (3,3,1), result (7,0,0).
//
// The `?` rows of a table are not stored: table_entry() derives them as the result potentials for
// result `?`, normalised back to sum 3 (i.e. averaged over the matching definite entries), which is
// how the corpus reconstruction `qr_relation_tables.json` defines them.
//
// likely_change_potentials() is the same procedure over a CHANGE table: the table relating the
// changes (increase +, steady 0, decrease -) of the inputs to the change of the result, built for
// the current qualitative values of the inputs (see change_table()).
//
// Example:
//   const auto& sum = value_table(Relation::kSum);
//   const Sign in[] = {Sign::kPlus, Sign::kUnknown};
//   LikelyPotentials p = likely_potentials(sum, in, Sign::kPlus);
//   // p.inputs[1] == {3, 3, 1}: the unknown input is most likely + or 0, least likely -.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "spar/qr/error.hpp"

namespace spar::qr {

// The four qualitative values. The definite ones double as indices 0, 1, 2 into a Potentials
// triple.
enum class Sign : std::uint8_t { kPlus = 0, kZero = 1, kMinus = 2, kUnknown = 3 };
inline constexpr std::array<Sign, 3> kDefiniteSigns{Sign::kPlus, Sign::kZero, Sign::kMinus};

[[nodiscard]] char to_char(Sign sign);
// Parses '+', '0', '-' or '?'; throws QrError on anything else.
[[nodiscard]] Sign sign_from_char(char symbol);
// The sign of a real number (exact zero is 0).
[[nodiscard]] Sign sign_of(double value);
// + <-> -, 0 and ? unchanged.
[[nodiscard]] Sign negate(Sign sign);
[[nodiscard]] constexpr int index(Sign sign) { return static_cast<int>(sign); }

// Likelihood potentials for the results (+, 0, -), in that order.
using Potentials = std::array<double, 3>;

// The qualitative relations between a node and its causes. Binary: sum, product; the rest unary.
enum class Relation : std::uint8_t { kSum, kProduct, kNegative, kAbs, kMonotonePlus, kThreshold };
[[nodiscard]] int arity(Relation relation);
[[nodiscard]] std::string to_string(Relation relation);

// A table over definite inputs. Invariant: entries.size() == 3^arity, entry index = 3*i + j for
// inputs (i, j) (or i for unary relations), and every triple is non-negative and sums to 3.
struct RelationTable {
  int arity{1};
  std::vector<Potentials> entries;
  [[nodiscard]] const Potentials& at(Sign first, Sign second = Sign::kPlus) const;
};
// Debug/test helper: true when the invariant above holds.
[[nodiscard]] bool is_well_formed(const RelationTable& table);

// The embedded value tables (the seed's lost Figure 3, as reconstructed; see qualitative.cpp).
[[nodiscard]] const RelationTable& value_table(Relation relation);

// Result of the Figure 4 procedure: one triple per input (indexed by the input's candidate value)
// and one for the result.
struct LikelyPotentials {
  std::vector<Potentials> inputs;
  Potentials result{};
};
[[nodiscard]] LikelyPotentials likely_potentials(const RelationTable& table,
                                                 std::span<const Sign> inputs, Sign result);

// The triple (and sign) of a table row with possibly unknown inputs: the result potentials for a
// `?` result, normalised to sum 3. The sign is definite when only one position is non-zero, else
// `?`.
struct TableEntry {
  Sign sign{Sign::kUnknown};
  Potentials potentials{};
};
[[nodiscard]] TableEntry table_entry(const RelationTable& table, std::span<const Sign> inputs);
// The sign of a triple: the one non-zero position, or `?` when several are non-zero.
[[nodiscard]] Sign sign_of(const Potentials& potentials);

// The change table of `relation` when its inputs currently have `input_values` and the node itself
// has `output_value` (only thresholds look at it). Unknown current values are enumerated over
// + 0 - and averaged (each equally likely). The change rules, for definite current values:
//   sum        d(a+b) = da + db                    (the sum table on the changes)
//   product    d(ab)  = sign(b) da + sign(a) db    (product table, then sum table)
//   negative   d(-a)  = -da;   M+  d(M(a)) = da
//   abs        d|a|   = sign(a) da, and |da| when a = 0
//   threshold  the output is boolean: when it is + it can only stay or fall (a decreasing input
//   gives
//              (0, 3/2, 3/2)), when it is - it can only stay or rise (an increasing input gives
//              (3/2, 3/2, 0)); any other input change leaves it steady.
[[nodiscard]] RelationTable change_table(Relation relation, std::span<const Sign> input_values,
                                         Sign output_value);

// likely_potentials() over change_table(): the seed's likely-change-potentials.
[[nodiscard]] LikelyPotentials likely_change_potentials(Relation relation,
                                                        std::span<const Sign> input_values,
                                                        Sign output_value,
                                                        std::span<const Sign> input_changes,
                                                        Sign result_change);

}  // namespace spar::qr
