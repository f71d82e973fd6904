// Text that comes from outside spar: one policy for its encoding, and how it is echoed.
//
// The policy (CONTRIBUTING.md, "Text and encodings"):
//   - Text spar reads -- scenario, domain, mesh and batch-list files, JSONL records, expressions
//     and names given on the command line or from Python -- must be UTF-8. Invalid UTF-8 is
//     refused where it is read, as `source:line:col: invalid UTF-8 (byte 0xff)`, so no
//     string taken from such text ever reaches a report, a JSON line or a Python str.
//   - Names spar does not read from text -- file paths from the command line, a folder or a list
//     -- are echoed through `printable`, which escapes invalid bytes and control characters as
//     \xNN (and \n, \t, \r, \0), so every message and every JSON line spar writes is valid UTF-8
//     and no terminal is sent raw control bytes.
//   - Line ends: "\r\n" and a lone "\r" (old Mac files) both end a line; `normalize_newlines`
//     turns them into "\n" before a parser sees the text, so line numbers count all three.
//
// Column numbers count characters (code points) from 1, as editors do.
//
// Example:
//   check_utf8("name: caf\xc3\xa9", "a.yaml");      // fine: é is two bytes of UTF-8
//   check_utf8("name: peg\xff", "a.yaml");          // throws "a.yaml:1:10: invalid UTF-8 ..."
//   printable("peg\x08lock\xff");                   // "peg\\x08lock\\xff"
//   normalize_newlines("a: 1\rb: 2\r");             // "a: 1\nb: 2\n"
//   single_quoted("x\ny");                                 // "'x\\ny'"
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "spar/common/error.hpp"

namespace spar {

// Text that breaks the encoding policy; the message names the source, line and column.
class TextError : public Error {
 public:
  using Error::Error;
};

// Where the first invalid UTF-8 sequence starts (a byte offset), or nothing when `text` is valid
// UTF-8 (overlong forms, surrogates and code points past U+10FFFF are invalid, as in RFC 3629).
[[nodiscard]] std::optional<std::size_t> find_invalid_utf8(std::string_view text);
[[nodiscard]] inline bool is_valid_utf8(std::string_view text) {
  return !find_invalid_utf8(text).has_value();
}

// Throws TextError "<source>:<line>:<col>: invalid UTF-8 (byte 0xNN); <source> must be UTF-8
// text" at the first invalid sequence.
void check_utf8(std::string_view text, std::string_view source);

// "line:col" (1-based; columns in code points) of byte `offset` in `text`; "\r\n" and "\r" end a
// line too.
[[nodiscard]] std::string line_column(std::string_view text, std::size_t offset);

// `text` with "\r\n" and lone "\r" turned into "\n".
[[nodiscard]] std::string normalize_newlines(std::string_view text);

// `text` safe to print: valid UTF-8 is kept except control characters (U+0000-U+001F, U+007F),
// which become \n, \t, \r, \0 or \xNN; every byte of an invalid sequence becomes \xNN. With
// `max_bytes`, a longer text is cut (on a character boundary) and ends in "... (N bytes)".
[[nodiscard]] std::string printable(std::string_view text,
                                    std::size_t max_bytes = static_cast<std::size_t>(-1));
// printable(text, max_bytes) in single quotes: how messages quote what the user wrote.
[[nodiscard]] std::string single_quoted(std::string_view text, std::size_t max_bytes = 80);

// Does `text` hold a control character (U+0000-U+001F other than tab, U+007F)? Names and
// one-line texts must not: a NUL or a backspace in a name prints as something else.
[[nodiscard]] std::optional<std::size_t> find_control_character(std::string_view text,
                                                                bool allow_newlines = false);

}  // namespace spar
