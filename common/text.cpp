#include "spar/common/text.hpp"

#include <array>
#include <cstdint>

namespace spar {
namespace {

// The length of the valid UTF-8 sequence starting at text[i], or 0 when it is invalid
// (RFC 3629's table: the second byte's range depends on the first, which excludes overlong forms,
// surrogates and code points past U+10FFFF).
std::size_t sequence_length(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) -> unsigned {
    return i + k < text.size() ? static_cast<unsigned char>(text[i + k]) : 0x100;
  };
  const auto in = [](unsigned b, unsigned low, unsigned high) { return b >= low && b <= high; };
  const unsigned b0 = byte(0);
  if (b0 < 0x80) return 1;
  std::size_t length = 0;
  unsigned low = 0x80, high = 0xBF;  // the second byte's range
  if (in(b0, 0xC2, 0xDF)) {
    length = 2;
  } else if (in(b0, 0xE0, 0xEF)) {
    length = 3;
    if (b0 == 0xE0) low = 0xA0;
    if (b0 == 0xED) high = 0x9F;
  } else if (in(b0, 0xF0, 0xF4)) {
    length = 4;
    if (b0 == 0xF0) low = 0x90;
    if (b0 == 0xF4) high = 0x8F;
  } else {
    return 0;
  }
  if (!in(byte(1), low, high)) return 0;
  for (std::size_t k = 2; k < length; ++k)
    if (!in(byte(k), 0x80, 0xBF)) return 0;
  return length;
}

bool is_control(unsigned char c) { return c < 0x20 || c == 0x7F; }

std::string hex_byte(unsigned char c) {
  constexpr std::array<char, 16> kDigits{'0', '1', '2', '3', '4', '5', '6', '7',
                                         '8', '9', 'a', 'b', 'c', 'd', 'e', 'f'};
  return {'\\', 'x', kDigits[c >> 4], kDigits[c & 0xF]};
}

}  // namespace

std::optional<std::size_t> find_invalid_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t length = sequence_length(text, i);
    if (length == 0) return i;
    i += length;
  }
  return std::nullopt;
}

std::string line_column(std::string_view text, std::size_t offset) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < offset && i < text.size();) {
    if (text[i] == '\n' || text[i] == '\r') {
      i += (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ? 2 : 1;
      ++line;
      column = 1;
      continue;
    }
    const std::size_t length = sequence_length(text, i);
    i += length == 0 ? 1 : length;
    ++column;
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

void check_utf8(std::string_view text, std::string_view source) {
  const std::optional<std::size_t> at = find_invalid_utf8(text);
  if (!at) return;
  const auto byte = static_cast<unsigned char>(text[*at]);
  throw TextError(printable(source) + ":" + line_column(text, *at) + ": invalid UTF-8 (byte 0x" +
                  hex_byte(byte).substr(2) + "); " + printable(source) + " must be UTF-8 text");
}

std::string normalize_newlines(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\r') {
      out.push_back(text[i]);
      continue;
    }
    out.push_back('\n');
    if (i + 1 < text.size() && text[i + 1] == '\n') ++i;
  }
  return out;
}

std::string printable(std::string_view text, std::size_t max_bytes) {
  std::string out;
  std::size_t i = 0;
  for (; i < text.size() && i < max_bytes;) {
    const std::size_t length = sequence_length(text, i);
    const auto c = static_cast<unsigned char>(text[i]);
    if (length == 0) {
      out += hex_byte(c);
      ++i;
    } else if (length == 1 && is_control(c)) {
      switch (c) {
        case '\n':
          out += "\\n";
          break;
        case '\t':
          out += "\\t";
          break;
        case '\r':
          out += "\\r";
          break;
        case '\0':
          out += "\\0";
          break;
        default:
          out += hex_byte(c);
      }
      ++i;
    } else {
      if (i + length > max_bytes) break;  // never cut a character in two
      out.append(text.substr(i, length));
      i += length;
    }
  }
  if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

std::string single_quoted(std::string_view text, std::size_t max_bytes) {
  std::string out(1, '\'');  // appended piecewise: GCC 12 warns (-Wrestrict) on "'" + text
  out.append(printable(text, max_bytes)).push_back('\'');
  return out;
}

std::optional<std::size_t> find_control_character(std::string_view text, bool allow_newlines) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (!is_control(c) || c == '\t' || (allow_newlines && (c == '\n' || c == '\r'))) continue;
    return i;
  }
  return std::nullopt;
}

}  // namespace spar
