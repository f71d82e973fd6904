// The one input-file reader (common/input_file.hpp, issue 22): every kind of path that is not a
// regular file of an acceptable size is refused before a byte is parsed, with a message that
// says what the path is; a FIFO never blocks and a device never fills memory.
#include "spar/common/input_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/common/expect_message.hpp"

namespace spar {
namespace {

namespace fs = std::filesystem;

// A fresh scratch folder with one file of each kind.
const fs::path& scratch() {
  static const fs::path dir = [] {
    std::string pattern = (fs::temp_directory_path() / "spar-input-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    const fs::path root(pattern);
    std::ofstream(root / "small.yaml") << "objects: {}\n";
    std::ofstream(root / "big.yaml") << std::string(2000, 'x');
    fs::create_directory(root / "folder.yaml");
    fs::create_symlink(root / "small.yaml", root / "link.yaml");
    fs::create_symlink(root / "nowhere.yaml", root / "dangling.yaml");
    if (mkfifo((root / "fifo.yaml").c_str(), 0600) != 0) throw std::runtime_error("mkfifo failed");
    return root;
  }();
  return dir;
}

TEST(InputFile, ReadsARegularFileOrALinkToOne) {
  EXPECT_EQ(read_input_file(scratch() / "small.yaml", "scenario file", 100), "objects: {}\n");
  EXPECT_EQ(read_input_file(scratch() / "link.yaml", "scenario file", 100), "objects: {}\n");
  EXPECT_EQ(input_file_problem(scratch() / "link.yaml", "scenario file"), "");
}

struct Refusal {
  std::string name;  // in the scratch folder, or an absolute path
  std::string message;
};

TEST(InputFile, RefusesWhatIsNotARegularFileOfAcceptableSize) {
  const std::vector<Refusal> refusals = {
      {"missing.yaml", "missing.yaml: no such scenario file"},
      {"dangling.yaml", "dangling.yaml: is a symbolic link to '"},
      {"folder.yaml", "folder.yaml: is a directory, not a scenario file"},
      {"fifo.yaml", "fifo.yaml: is not a regular file (a FIFO): give a scenario file"},
      {"/dev/zero", "/dev/zero: is not a regular file (a character device): give a scenario file"},
      {"big.yaml", "big.yaml: is larger than 1000 bytes, the limit for a scenario file"},
  };
  for (const Refusal& refusal : refusals) {
    const fs::path path =
        refusal.name.starts_with('/') ? fs::path(refusal.name) : scratch() / refusal.name;
    EXPECT_THROW_MESSAGE(read_input_file(path, "scenario file", 1000), refusal.message);
    if (refusal.name != "big.yaml") {  // the listing does not look at sizes
      EXPECT_NE(input_file_problem(path, "scenario file"), "") << refusal.name;
    }
  }
  EXPECT_THROW_MESSAGE(read_input_file(scratch() / "dangling.yaml", "scenario file", 1000),
                       "nowhere.yaml', which does not exist");
}

TEST(InputFile, LimitsAreWholeMegabytesInMessages) {
  const std::string text(3u << 20, 'x');
  std::ofstream(scratch() / "three_mb.off") << text;
  EXPECT_THROW_MESSAGE(read_input_file(scratch() / "three_mb.off", "mesh file", 2u << 20),
                       "three_mb.off: is larger than 2 MB, the limit for a mesh file");
  EXPECT_EQ(read_input_file(scratch() / "three_mb.off", "mesh file", 3u << 20).size(), 3u << 20);
}

TEST(InputFile, APathThatIsNotUtf8IsShownEscaped) {
  EXPECT_THROW_MESSAGE(read_input_file(scratch() / "bad\xff.yaml", "scenario file", 100),
                       "bad\\xff.yaml: no such scenario file");
}

}  // namespace
}  // namespace spar
