// The one reader of spar's input files: scenario, domain, mesh and batch-list files, JSONL corpora
// and any other file a command or a loader is given. Every input file goes through
// read_input_file, so each refuses the same things the same way, before a byte is parsed:
//   - a path that does not exist, or a symbolic link whose target does not ("... which does not
//     exist");
//   - a directory ("is a directory, not a scenario file");
//   - anything but a regular file: a FIFO (which would block), a device such as /dev/zero (which
//     never ends), a socket ("is not a regular file (a FIFO)");
//   - a file larger than the caller's limit ("is larger than 1 MB, the limit for a scenario
//     file"); the limit also holds if the file grows while it is read.
// The file is opened once (O_NONBLOCK, so opening a FIFO cannot block) and checked through that
// descriptor, so a path swapped between the check and the read is still refused. The bytes are
// returned as they are: the caller applies the text policy of common/text.hpp (check_utf8,
// normalize_newlines) when the file is text.
//
// A loader that has its own error type (planner::ScenarioError, geometry::GeometryError, ...)
// catches InputError and rethrows its message as that type, so callers see one error per module.
//
// Example:
//   const std::string text =
//       read_input_file("examples/peg_block_face_up.yaml", "scenario file", kMaxYamlFileBytes);
//   read_input_file("/dev/zero", "domain file", kMaxYamlFileBytes);
//       // throws "/dev/zero: is not a regular file (a character device): give a domain file"
//   read_input_file("big.off", "mesh file", kMaxMeshFileBytes);   // a larger limit for meshes
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "spar/common/error.hpp"

namespace spar {

// An input file that cannot be read, or is not a regular file of an acceptable size.
class InputError : public Error {
 public:
  using Error::Error;
};

// Batch lists and JSON(L) inputs: text read line by line.
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{16} << 20;  // 16 MB
// Scenario and domain files: yaml-cpp holds about 250 bytes per node, so 1 MB of dense YAML
// ("[1,1,1,...]") takes 250 MB; a scenario with the most objects and places the limits of
// common/limits.hpp allow is well under 100 KB.
inline constexpr std::size_t kMaxYamlFileBytes = std::size_t{1} << 20;  // 1 MB
// Mesh files: a 200k-triangle OFF is about 12 MB.
inline constexpr std::size_t kMaxMeshFileBytes = std::size_t{64} << 20;  // 64 MB

// The whole content of `path`, a regular file of at most `max_bytes` bytes. `what` names the kind
// of file in messages ("scenario file", "mesh file"). Throws InputError "<path>: <reason>" (the
// path through printable(), common/text.hpp).
[[nodiscard]] std::string read_input_file(const std::filesystem::path& path, std::string_view what,
                                          std::size_t max_bytes);

// Why `path` cannot be read as a `what` ("is a directory, not a scenario file"), or "" when it is
// a regular file (or a link to one). For listing inputs without reading them: a batch folder's
// entries get a record each, readable or not.
[[nodiscard]] std::string input_file_problem(const std::filesystem::path& path,
                                             std::string_view what);

}  // namespace spar
