#include "spar/sensing/internal/json_text.hpp"

#include <algorithm>

#include "spar/sensing/error.hpp"

namespace spar::sensing::internal {
namespace {

// "line:col" (1-based) of byte offset `byte` (nlohmann counts from 1 past the offending byte).
std::string line_and_column(std::string_view text, std::size_t byte) {
  const std::size_t end = std::min(byte > 0 ? byte - 1 : 0, text.size());
  int line = 1, column = 1;
  for (std::size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

}  // namespace

nlohmann::json parse_json_text(std::string_view text, const std::string& source) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& error) {
    std::string what = error.what();
    // nlohmann's message "[json.exception.parse_error.101] parse error at line 1, column 2:
    // syntax error ..." keeps only its reason; the place is ours.
    if (const std::size_t colon = what.find(": "); colon != std::string::npos)
      what = what.substr(colon + 2);
    throw SensingError(source + ":" + line_and_column(text, error.byte) +
                       ": JSON syntax error: " + what);
  }
}

std::string shown(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

}  // namespace spar::sensing::internal
