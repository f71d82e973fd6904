// How scenario and domain files become one YAML document, with every refusal at file:line:col:
//   - the text holds at most kMaxYamlFileBytes (common/input_file.hpp);
//   - the text must be UTF-8 (common/text.hpp's policy) and hold no control character but tab and
//     line breaks (YAML's own printable set); "\r\n" and a lone "\r" end lines;
//   - a syntax error is yaml-cpp's own text, except nesting beyond its recursion limit, which
//     yaml-cpp calls "bad file";
//   - the file holds exactly one document: a second one after `---` would be silently dropped by
//     YAML::Load, so it is refused where it starts.
// An empty file (or one holding only comments) gives a null node; the caller says what is missing.
//
// Example:
//   const YAML::Node root = load_yaml_document<DomainError>(text, "my_domain.yaml");
#pragma once

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/yaml.h>

#include <string>
#include <string_view>
#include <vector>

#include "spar/common/input_file.hpp"
#include "spar/common/text.hpp"

namespace spar::planner::internal {

[[nodiscard]] inline std::string yaml_syntax_error(const YAML::Exception& error) {
  if (dynamic_cast<const YAML::DeepRecursion*>(&error) != nullptr)
    return "nested too deeply (a scenario or domain file needs a handful of levels)";
  return error.msg;
}

// "source:line:col" of a yaml-cpp mark (just the source when it has none).
[[nodiscard]] inline std::string yaml_where(const std::string& source, const YAML::Mark& mark) {
  if (mark.is_null()) return source;
  return source + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

// The one document of `raw`; throws Error("source:line:col: ...") otherwise. `source` is printed
// as it is (pass it through printable()).
template <class Error>
[[nodiscard]] YAML::Node load_yaml_document(std::string_view raw, const std::string& source) {
  if (raw.size() > kMaxYamlFileBytes)  // text from Python or a fuzzer, not only from a file
    throw Error(source + ": is larger than " + std::to_string(kMaxYamlFileBytes >> 20) +
                " MB, the limit for a YAML file");
  try {
    check_utf8(raw, source);
  } catch (const TextError& error) {
    throw Error(error.what());
  }
  const std::string text = normalize_newlines(raw);
  if (const auto at = find_control_character(text, /*allow_newlines=*/true))
    throw Error(source + ":" + line_column(text, *at) + ": control character " +
                single_quoted(text.substr(*at, 1)) +
                " in the file: YAML text allows only tab and line breaks (write it as an "
                "escape in a double-quoted string if you mean it)");
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::Exception& error) {
    throw Error(yaml_where(source, error.mark) +
                ": YAML syntax error: " + printable(yaml_syntax_error(error)));
  }
  if (documents.size() > 1)
    throw Error(yaml_where(source, documents[1].Mark()) +
                ": a second YAML document (after '---'): " +
                "the file must hold one document, and the second would be ignored");
  return documents.empty() ? YAML::Node(YAML::NodeType::Null) : documents.front();
}

}  // namespace spar::planner::internal
