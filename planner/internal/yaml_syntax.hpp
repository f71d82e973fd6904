// How scenario and domain files become one YAML document, with every refusal at file:line:col:
//   - the text holds at most kMaxYamlFileBytes (common/input_file.hpp);
//   - the text must be UTF-8 (common/text.hpp's policy) and hold no control character but tab and
//     line breaks (YAML's own printable set); "\r\n" and a lone "\r" end lines;
//   - a syntax error is yaml-cpp's own text, except nesting beyond its recursion limit, which
//     yaml-cpp calls "bad file";
//   - the file holds exactly one document: a second one after `---` would be silently dropped by
//     YAML::Load, so it is refused where it starts;
//   - a token no node can start with (a ',' outside [ ] and { }) is refused where it stands.
//     yaml-cpp 0.7 (Debian 12) emits a null node for it without consuming it, so its
//     YAML::LoadAll loops forever, growing (jbeder/yaml-cpp#1040, fixed upstream after 0.8 by
//     #1319). Hence the documents are counted by a parser that runs at most kDocumentsLooked
//     times, and only then is the one document built by YAML::Load (one parse: cannot loop).
// An empty file (or one holding only comments) gives a null node; the caller says what is missing.
//
// Example:
//   const YAML::Node root = load_yaml_document<DomainError>(text, "my_domain.yaml");
#pragma once

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/yaml.h>

#include <sstream>
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

// Where each document starts, as yaml-cpp's parser reports it; nothing else is kept.
class DocumentStarts final : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> starts;

  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

// Three documents are enough to tell one document, a second one, and a parser stuck on a token
// (two documents starting at the same place: nothing was consumed in between).
inline constexpr int kDocumentsLooked = 3;

// Why the parser stopped at `mark` without consuming anything.
[[nodiscard]] inline std::string stuck_token_message(const std::string& text,
                                                     const YAML::Mark& mark) {
  const auto at = static_cast<std::size_t>(mark.pos);
  if (at < text.size() && text[at] == ',')
    return "',' cannot start a value (a ',' separates items inside [ ] or { } only)";
  return "a value cannot start here";
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
  DocumentStarts documents;
  YAML::Node root;
  try {
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    for (int i = 0; i < kDocumentsLooked && parser.HandleNextDocument(documents); ++i) {
    }
    const std::vector<YAML::Mark>& starts = documents.starts;
    for (std::size_t i = 1; i < starts.size(); ++i)
      if (starts[i].pos == starts[i - 1].pos)
        throw Error(yaml_where(source, starts[i]) +
                    ": YAML syntax error: " + stuck_token_message(text, starts[i]));
    if (starts.size() > 1)
      throw Error(yaml_where(source, starts[1]) + ": a second YAML document (after '---'): " +
                  "the file must hold one document, and the second would be ignored");
    root = YAML::Load(text);
  } catch (const YAML::Exception& error) {
    throw Error(yaml_where(source, error.mark) +
                ": YAML syntax error: " + printable(yaml_syntax_error(error)));
  }
  return root.IsDefined() ? root : YAML::Node(YAML::NodeType::Null);
}

}  // namespace spar::planner::internal
