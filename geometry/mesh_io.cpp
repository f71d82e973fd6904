#include "spar/geometry/mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <ostream>
#include <sstream>
#include <vector>

#include "spar/common/input_file.hpp"
#include "spar/common/number.hpp"
#include "spar/common/text.hpp"

namespace spar::geometry {
namespace {

struct Line {
  int number{0};
  std::vector<std::string> tokens;
  std::string comment;  // text after '#', trimmed
};

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

// Non-blank lines split into tokens, comments kept apart. The text must be UTF-8 without control
// characters (common/text.hpp): comments become face names, which reports print.
std::vector<Line> tokenize(const std::string& text, const std::string& source) {
  try {
    check_utf8(text, source);
  } catch (const TextError& error) {
    throw GeometryError(error.what());
  }
  const std::string normalized = normalize_newlines(text);
  if (const auto at = find_control_character(normalized, /*allow_newlines=*/true))
    throw GeometryError(source + ":" + line_column(normalized, *at) + ": control character " +
                        single_quoted(normalized.substr(*at, 1)) + " in a mesh file");
  std::vector<Line> lines;
  std::istringstream stream(normalized);
  std::string raw;
  for (int number = 1; std::getline(stream, raw); ++number) {
    Line line;
    line.number = number;
    const auto hash = raw.find('#');
    if (hash != std::string::npos) {
      line.comment = trim(raw.substr(hash + 1));
      raw.resize(hash);
    }
    std::istringstream words(raw);
    for (std::string word; words >> word;) line.tokens.push_back(word);
    if (!line.tokens.empty()) lines.push_back(std::move(line));
  }
  return lines;
}

std::string at(const std::string& source, const Line& line) {
  return source + ":" + std::to_string(line.number) + ": ";
}

// Coordinates beyond this magnitude are refused: areas and volumes (squares and cubes of
// lengths) and the moments of the volume (fourth powers) must stay far from double overflow.
constexpr double kMaxCoordinate = 1e12;

double to_double(const std::string& token, const std::string& source, const Line& line) {
  const std::optional<double> value = parse_number(token);
  if (!value || std::isnan(*value))
    throw GeometryError(at(source, line) + "expected a number, got " + single_quoted(token));
  if (!(std::abs(*value) <= kMaxCoordinate))
    throw GeometryError(at(source, line) + "coordinate " + single_quoted(token) +
                        " is too large: coordinates must lie within +-" +
                        format_number(kMaxCoordinate) +
                        " (areas, volumes and moments would overflow)");
  return *value;
}

long to_integer(const std::string& token, const std::string& source, const Line& line) {
  long value = 0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc() || end != token.data() + token.size())
    throw GeometryError(at(source, line) + "expected an integer, got " + single_quoted(token));
  return value;
}

Eigen::Vector3d read_point(const Line& line, std::size_t first, const std::string& source) {
  if (line.tokens.size() < first + 3)
    throw GeometryError(at(source, line) + "a vertex needs 3 coordinates");
  return {to_double(line.tokens[first], source, line),
          to_double(line.tokens[first + 1], source, line),
          to_double(line.tokens[first + 2], source, line)};
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

}  // namespace

Mesh parse_off(const std::string& text, const std::string& source) {
  const std::vector<Line> lines = tokenize(text, source);
  if (lines.empty()) throw GeometryError(source + ": empty file: expected an OFF mesh");
  std::size_t cursor = 0;
  std::vector<std::string> counts = lines[0].tokens;
  if (counts[0] == "OFF") {
    counts.erase(counts.begin());
    if (counts.empty()) {
      if (lines.size() < 2) throw GeometryError(at(source, lines[0]) + "missing the counts line");
      counts = lines[++cursor].tokens;
    }
  } else if (std::isalpha(static_cast<unsigned char>(counts[0][0]))) {
    throw GeometryError(at(source, lines[0]) + "unsupported header " + single_quoted(counts[0]) +
                        " (only plain OFF is read)");
  }
  const Line& count_line = lines[cursor++];
  if (counts.size() < 2)
    throw GeometryError(at(source, count_line) + "expected 'vertices faces [edges]' counts");
  const long vertex_count = to_integer(counts[0], source, count_line);
  const long face_count = to_integer(counts[1], source, count_line);
  if (vertex_count < 0 || face_count < 0)
    throw GeometryError(at(source, count_line) + "counts must not be negative");
  const std::size_t remaining = lines.size() - cursor;  // compared one count at a time: no overflow
  if (static_cast<std::size_t>(vertex_count) > remaining ||
      static_cast<std::size_t>(face_count) > remaining - static_cast<std::size_t>(vertex_count))
    throw GeometryError(source + ": file ends early: expected " + std::to_string(vertex_count) +
                        " vertices and " + std::to_string(face_count) + " polygons");
  MeshBuilder builder(source);
  for (long v = 0; v < vertex_count; ++v)
    builder.add_vertex(read_point(lines[cursor++], 0, source));
  for (long f = 0; f < face_count; ++f) {
    const Line& line = lines[cursor++];
    const long n = to_integer(line.tokens[0], source, line);
    if (n < 0 || line.tokens.size() < static_cast<std::size_t>(n) + 1)
      throw GeometryError(at(source, line) + "polygon says " + single_quoted(line.tokens[0]) +
                          " vertices but lists fewer");
    std::vector<int> loop;
    for (long k = 1; k <= n; ++k)
      loop.push_back(static_cast<int>(to_integer(line.tokens[k], source, line)));
    builder.add_polygon(loop, line.comment, line.number);
  }
  if (cursor != lines.size())
    throw GeometryError(at(source, lines[cursor]) + "unexpected data after the last polygon");
  return std::move(builder).build();
}

Mesh parse_obj(const std::string& text, const std::string& source) {
  MeshBuilder builder(source);
  std::string current_name;
  int vertex_count = 0;
  for (const Line& line : tokenize(text, source)) {
    const std::string& keyword = line.tokens[0];
    if (keyword == "v") {
      builder.add_vertex(read_point(line, 1, source));
      ++vertex_count;
    } else if (keyword == "f") {
      std::vector<int> loop;
      for (std::size_t k = 1; k < line.tokens.size(); ++k) {
        const std::string& token = line.tokens[k];
        const long index = to_integer(token.substr(0, token.find('/')), source, line);
        if (index == 0 || index > vertex_count || -index > vertex_count)
          throw GeometryError(at(source, line) + "vertex index " + std::to_string(index) +
                              " is out of range (" + std::to_string(vertex_count) +
                              " vertices so far)");
        loop.push_back(static_cast<int>(index > 0 ? index - 1 : vertex_count + index));
      }
      builder.add_polygon(loop, current_name, line.number);
    } else if (keyword == "g" || keyword == "o") {
      current_name.clear();
      for (std::size_t k = 1; k < line.tokens.size(); ++k)
        current_name += (k > 1 ? " " : "") + line.tokens[k];
    } else if (keyword != "vt" && keyword != "vn" && keyword != "s" && keyword != "usemtl" &&
               keyword != "mtllib" && keyword != "vp") {
      throw GeometryError(at(source, line) + "unknown OBJ statement " + single_quoted(keyword));
    }
  }
  return std::move(builder).build();
}

namespace {

// The file's bytes (through the one input-file reader) and its lower-case extension, one of the
// three formats; `source` is the path as messages print it.
std::pair<std::string, std::string> mesh_file_content(const std::string& path,
                                                      const std::string& source) {
  std::string content;
  try {
    content = read_input_file(path, "mesh file", kMaxMeshFileBytes);
  } catch (const InputError& error) {
    throw GeometryError(error.what());
  }
  const std::string extension = lower(path.substr(std::min(path.size(), path.rfind('.'))));
  if (extension != ".off" && extension != ".obj" && extension != ".stl")
    throw GeometryError(source + ": unknown mesh format " + single_quoted(extension) +
                        " (expected .off, .obj or .stl)");
  return {content, extension};
}

}  // namespace

Mesh read_mesh_file(const std::string& path) {
  const std::string source = printable(path);
  const auto [content, extension] = mesh_file_content(path, source);
  if (extension == ".stl") return parse_stl(content, source);
  return extension == ".off" ? parse_off(content, source) : parse_obj(content, source);
}

Mesh read_triangle_soup(const std::string& path) {
  const std::string source = printable(path);
  const auto [content, extension] = mesh_file_content(path, source);
  if (extension == ".stl") return parse_stl_soup(content, source);
  return extension == ".off" ? parse_off(content, source) : parse_obj(content, source);
}

void write_off(const Mesh& mesh, std::ostream& out, const std::string& header) {
  out << "OFF\n";
  std::istringstream header_lines(header);
  for (std::string line; std::getline(header_lines, line);) out << "# " << line << '\n';
  out << mesh.vertices.size() << ' ' << mesh.triangles.size() << " 0\n";
  out << std::setprecision(17);
  for (const auto& v : mesh.vertices) out << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    out << "3 " << tri[0] << ' ' << tri[1] << ' ' << tri[2];
    if (!mesh.triangle_names[t].empty()) out << " # " << mesh.triangle_names[t];
    out << '\n';
  }
}

}  // namespace spar::geometry
