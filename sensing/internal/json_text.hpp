// JSON input files of the sensing layer (evidence files, PSEIKI's image files): parsing with the
// place of a syntax error, and values shortened for messages.
//
// Example:
//   const nlohmann::json document = parse_json_text(text, "image.json");
//       // throws SensingError "image.json:3:7: JSON syntax error: ..." for broken text
//   shown(document.at("edges"));   // its JSON text, at most 40 characters
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace spar::sensing::internal {

[[nodiscard]] nlohmann::json parse_json_text(std::string_view text, const std::string& source);
[[nodiscard]] std::string shown(const nlohmann::json& value);

}  // namespace spar::sensing::internal
