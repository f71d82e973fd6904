#include "cli/bound_json.hpp"

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "cli/options.hpp"
#include "spar/common/number.hpp"
#include "spar/reports/build.hpp"
#include "spar/reports/json.hpp"
#include "spar/symbolic/parse.hpp"

namespace spar::cli {

bounds::Relation relation_named(const std::string& text) {
  if (const std::optional<Relation> relation = relation_from_name(text)) return *relation;
  throw UsageError("unknown relation '" + text + "' (use <, <=, >, >=)");
}

nlohmann::ordered_json bound_result_json(const std::string& name, const bounds::Box& box,
                                         const bounds::BoundResult& r, double seconds) {
  return reports::to_json(reports::bound_record(
      box, r, seconds, name.empty() ? std::nullopt : std::optional<std::string>(name)));
}

namespace {

// A record's mistake: the line's error record says it and the batch goes on.
class RecordError : public Error {
 public:
  using Error::Error;
};

// A range end: a JSON number, or a string spar's number reader takes ("1e-310", "-inf" fails as
// every range must be finite).
double range_end(const nlohmann::json& value, const std::string& what) {
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) return read_number(value.get<std::string>(), what);
  throw RecordError(what + " must be a number");
}

const std::string& string_field(const nlohmann::json& object, const char* key) {
  const auto found = object.find(key);
  if (found == object.end()) throw RecordError(std::string("missing \"") + key + "\" string");
  if (!found->is_string()) throw RecordError(std::string("\"") + key + "\" must be a string");
  return found->get_ref<const std::string&>();
}

}  // namespace

nlohmann::ordered_json bound_record(std::string_view line, std::size_t line_number,
                                    const bounds::BoundOptions& options, bool& ok) {
  std::string name;
  try {
    const auto record = nlohmann::json::parse(line);
    if (!record.is_object()) throw RecordError("a record must be a JSON object");
    if (record.contains("name") && record["name"].is_string()) name = record["name"];
    symbolic::ExprPool pool;
    bounds::Box box;
    if (!record.contains("vars") || !record["vars"].is_object()) {
      throw RecordError("missing \"vars\" object");
    }
    for (const auto& [var, range] : record["vars"].items()) {
      if (!range.is_array() || range.size() != 2) {
        throw RecordError("range of '" + var + "' must be [lo, hi]");
      }
      box.add(pool.variable(var), range_end(range[0], "lower bound of '" + var + "'"),
              range_end(range[1], "upper bound of '" + var + "'"));
    }
    const symbolic::Expr f = symbolic::parse(pool, string_field(record, "expr"));
    std::vector<bounds::Constraint> constraints;
    if (record.contains("constraints")) {
      if (!record["constraints"].is_array()) {
        throw RecordError("\"constraints\" must be an array of {\"g\", \"rel\"}");
      }
      for (const auto& c : record["constraints"]) {
        if (!c.is_object()) throw RecordError("a constraint must be an object {\"g\", \"rel\"}");
        constraints.push_back(
            {symbolic::parse(pool, string_field(c, "g")), relation_named(string_field(c, "rel"))});
      }
    }
    const auto start = std::chrono::steady_clock::now();
    const bounds::BoundResult result = bounds::bound(f, box, options, constraints);
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
    return bound_result_json(name, box, result, elapsed.count());
  } catch (const std::exception& error) {
    ok = false;
    nlohmann::ordered_json out;
    out["line"] = line_number;
    out["name"] = name;
    out["error"] = error.what();
    return out;
  }
}

}  // namespace spar::cli
