// A small JSON Schema validator for the tests: the subset docs/report-schema.md uses (type, enum,
// properties, required, additionalProperties (false or a schema), items, minItems, maxItems,
// anyOf, $ref to "#/$defs/<name>"). It records the path of every member it validates ("a.b[].c",
// "*" for a member matched by an additionalProperties schema), so tests can compare the fields a
// report produces with the fields the schema and the document list.
//
// Example:
//   const JsonSchema schema(nlohmann::json::parse(text));
//   std::set<std::string> produced;
//   const std::vector<std::string> errors = schema.validate(report, produced);
//   EXPECT_TRUE(errors.empty()) << errors.front();
#pragma once

#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace spar::reports::testing {

class JsonSchema {
 public:
  explicit JsonSchema(nlohmann::json schema) : root_(std::move(schema)) {}

  // Violations as "path: what is wrong"; `seen` gains the path of every member validated.
  [[nodiscard]] std::vector<std::string> validate(const nlohmann::ordered_json& value,
                                                  std::set<std::string>& seen) const {
    std::vector<std::string> errors;
    check(root_, value, "", errors, &seen);
    return errors;
  }

  // Every member path the schema declares (through $ref and anyOf).
  [[nodiscard]] std::set<std::string> paths() const {
    std::set<std::string> out;
    collect(root_, "", out, 0);
    return out;
  }

 private:
  const nlohmann::json& resolve(const nlohmann::json& schema) const {
    if (!schema.contains("$ref")) return schema;
    const std::string reference = schema["$ref"];
    const std::string prefix = "#/$defs/";
    if (reference.rfind(prefix, 0) != 0) throw std::runtime_error("unsupported $ref " + reference);
    return root_.at("$defs").at(reference.substr(prefix.size()));
  }

  static bool has_type(const nlohmann::ordered_json& value, const std::string& type) {
    if (type == "object") return value.is_object();
    if (type == "array") return value.is_array();
    if (type == "string") return value.is_string();
    if (type == "boolean") return value.is_boolean();
    if (type == "null") return value.is_null();
    if (type == "integer") return value.is_number_integer();
    if (type == "number") return value.is_number();
    throw std::runtime_error("unsupported type " + type);
  }

  static std::string member(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  void check(const nlohmann::json& raw, const nlohmann::ordered_json& value,
             const std::string& path, std::vector<std::string>& errors,
             std::set<std::string>* seen) const {
    const nlohmann::json& schema = resolve(raw);
    const std::string where = path.empty() ? "(root)" : path;
    if (schema.contains("anyOf")) {
      // The first alternative without errors wins and records its paths; if none matches, the
      // errors of the closest one (fewest errors) are reported.
      std::vector<std::string> closest;
      bool closest_wrong_type = true;
      for (const nlohmann::json& alternative : schema["anyOf"]) {
        std::vector<std::string> trial;
        check(alternative, value, path, trial, nullptr);
        if (trial.empty()) {
          check(alternative, value, path, trial, seen);
          return;
        }
        const bool wrong_type =
            trial.size() == 1 && trial[0].find(": expected type") != std::string::npos;
        if (closest.empty() || (closest_wrong_type && !wrong_type) ||
            (!wrong_type && trial.size() < closest.size())) {
          closest = trial;
          closest_wrong_type = wrong_type;
        }
      }
      errors.insert(errors.end(), closest.begin(), closest.end());
      return;
    }
    if (schema.contains("type")) {
      bool ok = false;
      if (schema["type"].is_array()) {
        for (const auto& type : schema["type"]) ok = ok || has_type(value, type);
      } else {
        ok = has_type(value, schema["type"]);
      }
      if (!ok) {
        errors.push_back(where + ": expected type " + schema["type"].dump() + ", got " +
                         value.dump().substr(0, 60));
        return;
      }
    }
    if (schema.contains("enum")) {
      bool found = false;
      for (const auto& allowed : schema["enum"])
        found = found || nlohmann::ordered_json(allowed) == value;
      if (!found)
        errors.push_back(where + ": " + value.dump() + " not in " + schema["enum"].dump());
    }
    if (value.is_object()) {
      for (const auto& required : schema.value("required", nlohmann::json::array()))
        if (!value.contains(required.get<std::string>()))
          errors.push_back(where + ": missing required member " + required.get<std::string>());
      const nlohmann::json properties = schema.value("properties", nlohmann::json::object());
      for (const auto& [key, item] : value.items()) {
        if (properties.contains(key)) {
          if (seen) seen->insert(member(path, key));
          check(properties[key], item, member(path, key), errors, seen);
        } else if (schema.contains("additionalProperties") &&
                   schema["additionalProperties"].is_object()) {
          if (seen) seen->insert(member(path, "*"));
          check(schema["additionalProperties"], item, member(path, "*"), errors, seen);
        } else if (schema.value("additionalProperties", true) == false) {
          errors.push_back(where + ": undocumented member " + key);
        }
      }
    }
    if (value.is_array()) {
      if (schema.contains("minItems") && value.size() < schema["minItems"].get<std::size_t>())
        errors.push_back(where + ": fewer than " + schema["minItems"].dump() + " items");
      if (schema.contains("maxItems") && value.size() > schema["maxItems"].get<std::size_t>())
        errors.push_back(where + ": more than " + schema["maxItems"].dump() + " items");
      if (schema.contains("items"))
        for (const auto& item : value) check(schema["items"], item, path + "[]", errors, seen);
    }
  }

  void collect(const nlohmann::json& raw, const std::string& path, std::set<std::string>& out,
               int depth) const {
    if (depth > 32) return;
    const nlohmann::json& schema = resolve(raw);
    for (const auto& alternative : schema.value("anyOf", nlohmann::json::array()))
      collect(alternative, path, out, depth + 1);
    const nlohmann::json properties = schema.value("properties", nlohmann::json::object());
    for (const auto& [key, item] : properties.items()) {
      out.insert(member(path, key));
      collect(item, member(path, key), out, depth + 1);
    }
    if (schema.contains("additionalProperties") && schema["additionalProperties"].is_object()) {
      out.insert(member(path, "*"));
      collect(schema["additionalProperties"], member(path, "*"), out, depth + 1);
    }
    if (schema.contains("items")) collect(schema["items"], path + "[]", out, depth + 1);
  }

  nlohmann::json root_;
};

}  // namespace spar::reports::testing
