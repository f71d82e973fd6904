// `spar bound`'s JSON: a bound result as a JSON object (the bound record of reports/model.hpp,
// the keys Python's spar.bound gives too), and one line of an FPBench-style JSONL corpus read,
// bounded and answered. Kept apart from the command so the JSONL reader can be fuzzed
// on its own (tests/fuzz/bound_jsonl_fuzz.cpp).
//
// A corpus line is {"name": "...", "expr": "...", "vars": {"x": [lo, hi], ...},
// "constraints": [{"g": "...", "rel": "<="}, ...]} ("name" and "constraints" optional). A range
// end is a JSON number or a string spar's number reader takes ("1e-310", "-0.5"). A line that is
// not such a record (invalid JSON or UTF-8, a missing key, a wrong type) or whose bounding fails
// gives {"line": N, "name": ..., "error": "..."} instead of a result: one bad line never stops a
// batch. Non-finite numbers are written as the strings "inf", "-inf", "nan".
//
// Example:
//   bool ok = true;
//   const nlohmann::ordered_json result =
//       bound_record(R"({"expr": "x*x", "vars": {"x": [-1, 2]}})", 1, {}, ok);
//   result["hi"];   // 4
//   std::cout << result.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "spar/bounds/bound.hpp"

namespace spar::cli {

// "<", "<=", ">", ">="; throws UsageError for anything else.
[[nodiscard]] bounds::Relation relation_named(const std::string& text);

// The bound record {"name"?, "lo", "hi", "inner_lo", "inner_hi", "argmin", "argmax", "status",
// "possibly_undefined", "time_limited", "relative_gap", "evaluations", "seconds"} (docs/
// report-schema.md, "The bound record"); `seconds` is the wall-clock time the bound took.
[[nodiscard]] nlohmann::ordered_json bound_result_json(const std::string& name,
                                                       const bounds::Box& box,
                                                       const bounds::BoundResult& result,
                                                       double seconds);

// Bounds one corpus line (`line_number` counts from 1) with `options`; `ok` becomes false when
// the answer is an error record. Never throws for anything in `line`.
[[nodiscard]] nlohmann::ordered_json bound_record(std::string_view line, std::size_t line_number,
                                                  const bounds::BoundOptions& options, bool& ok);

}  // namespace spar::cli
