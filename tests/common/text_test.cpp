// The text policy of common/text.hpp (issue 22): what is valid UTF-8, where an invalid byte is
// reported, how line ends count, and that printable() makes anything safe to print.
#include "spar/common/text.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <string>
#include <vector>

#include "tests/common/expect_message.hpp"

namespace spar {
namespace {

struct Utf8Case {
  std::string text;
  std::optional<std::size_t> invalid_at;
};

TEST(Utf8, ValidAndInvalidSequences) {
  const std::vector<Utf8Case> cases = {
      {"", std::nullopt},
      {"peg", std::nullopt},
      {"caf\xc3\xa9", std::nullopt},       // é
      {"\xe2\x82\xac 5", std::nullopt},    // €
      {"\xf0\x9f\x94\xa9", std::nullopt},  // U+1F529, four bytes
      {"\xef\xbb\xbfname", std::nullopt},  // a byte-order mark is a character
      {"peg\xff", 3},                      // never in UTF-8
      {"a\x80", 1},                        // a continuation byte alone
      {"\xc0\x80", 0},                     // overlong NUL
      {"\xc1\xbf", 0},                     // overlong
      {"\xe0\x80\x80", 0},                 // overlong three-byte form
      {"\xed\xa0\x80", 0},                 // a UTF-16 surrogate
      {"\xf4\x90\x80\x80", 0},             // past U+10FFFF
      {"ab\xc3", 2},                       // cut short at the end
      {"ab\xe2\x82x", 2},                  // cut short inside
      {"\xf5\x80\x80\x80", 0},             // no such lead byte
  };
  for (const Utf8Case& c : cases) {
    EXPECT_EQ(find_invalid_utf8(c.text), c.invalid_at) << printable(c.text);
    EXPECT_EQ(is_valid_utf8(c.text), !c.invalid_at.has_value()) << printable(c.text);
  }
}

TEST(Utf8, CheckNamesSourceLineAndColumnInCharacters) {
  EXPECT_NO_THROW(check_utf8("name: caf\xc3\xa9\n", "a.yaml"));
  // Line 2; column 7 counts "é" as one character.
  EXPECT_THROW_MESSAGE(check_utf8("a: 1\nb: \xc3\xa9 \xff\n", "a.yaml"),
                       "a.yaml:2:6: invalid UTF-8 (byte 0xff); a.yaml must be UTF-8 text");
  // The source itself may be anything (a path from the file system): printed escaped.
  EXPECT_THROW_MESSAGE(check_utf8("\xfe", "dir\xff/a.yaml"), "dir\\xff/a.yaml:1:1: invalid UTF-8");
}

TEST(LineColumn, EveryKindOfLineEndCounts) {
  EXPECT_EQ(line_column("a\nb\r\nc\rd", 7), "4:1");  // LF, CRLF and CR each end a line
  EXPECT_EQ(line_column("abc", 2), "1:3");
  EXPECT_EQ(line_column("", 0), "1:1");
}

TEST(NormalizeNewlines, CrAndCrLfBecomeLf) {
  EXPECT_EQ(normalize_newlines("a: 1\rb: 2\r"), "a: 1\nb: 2\n");
  EXPECT_EQ(normalize_newlines("a\r\nb\n\rc"), "a\nb\n\nc");
  EXPECT_EQ(normalize_newlines("plain\n"), "plain\n");
}

TEST(Printable, EscapesControlsAndInvalidBytesOnly) {
  EXPECT_EQ(printable("peg\x08lock"), "peg\\x08lock");
  EXPECT_EQ(printable(std::string("a\0b", 3)), "a\\0b");
  EXPECT_EQ(printable("l1\nl2\tx\r\x7f"), "l1\\nl2\\tx\\r\\x7f");
  EXPECT_EQ(printable("caf\xc3\xa9 \xff\xfe"), "caf\xc3\xa9 \\xff\\xfe");
  EXPECT_EQ(printable("back\\slash"), "back\\slash");
}

TEST(Printable, CutsLongTextOnACharacterBoundary) {
  EXPECT_EQ(printable("abcdef", 3), "abc... (6 bytes)");
  EXPECT_EQ(printable("ab\xc3\xa9z", 3), "ab... (5 bytes)");  // é is not cut in two
  EXPECT_EQ(single_quoted("x\ny"), "'x\\ny'");
}

TEST(ControlCharacters, FoundUnlessAllowed) {
  EXPECT_EQ(find_control_character("peg"), std::nullopt);
  EXPECT_EQ(find_control_character("a\tb"), std::nullopt);  // tab is allowed everywhere
  EXPECT_EQ(find_control_character(std::string("pe\0g", 4)), 2u);
  EXPECT_EQ(find_control_character("two\nlines"), 3u);
  EXPECT_EQ(find_control_character("two\nlines\r\n", /*allow_newlines=*/true), std::nullopt);
  EXPECT_EQ(find_control_character("del\x7f"), 3u);
}

// Whatever the bytes, printable() gives valid UTF-8 without control characters: what every
// message and JSON line spar writes relies on.
RC_GTEST_PROP(Printable, AlwaysValidUtf8WithoutControls,
              (const std::vector<unsigned char>& bytes)) {
  const std::string text(bytes.begin(), bytes.end());
  const std::string shown = printable(text, 1 + bytes.size() / 2);
  RC_ASSERT(is_valid_utf8(shown));
  RC_ASSERT(!find_control_character(shown).has_value());
  RC_ASSERT(is_valid_utf8(single_quoted(text)));
}

// Valid UTF-8 passes printable() unchanged when it has no control character.
RC_GTEST_PROP(Printable, KeepsPrintableUtf8, (const std::u32string& code_points)) {
  std::string text;
  for (char32_t c : code_points) {
    c = c % 0x10FFFF;
    if (c < 0x20 || c == 0x7F || (c >= 0xD800 && c <= 0xDFFF)) continue;
    if (c < 0x80) {
      text += static_cast<char>(c);
    } else if (c < 0x800) {
      text += static_cast<char>(0xC0 | (c >> 6));
      text += static_cast<char>(0x80 | (c & 0x3F));
    } else if (c < 0x10000) {
      text += static_cast<char>(0xE0 | (c >> 12));
      text += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      text += static_cast<char>(0x80 | (c & 0x3F));
    } else {
      text += static_cast<char>(0xF0 | (c >> 18));
      text += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
      text += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      text += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  RC_ASSERT(is_valid_utf8(text));
  RC_ASSERT(printable(text) == text);
}

}  // namespace
}  // namespace spar
