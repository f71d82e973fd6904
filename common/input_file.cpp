#include "spar/common/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

#include "spar/common/text.hpp"

namespace spar {
namespace {

namespace fs = std::filesystem;

std::string kind_of(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a file";
}

// "16 MB" (limits are whole megabytes), else "1000 bytes".
std::string size_text(std::size_t bytes) {
  if (bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MB";
  return std::to_string(bytes) + " bytes";
}

// The reason an `lstat`-able path failed to open with ENOENT: a dangling symbolic link, or none.
std::string missing(const fs::path& path, std::string_view what) {
  struct stat link {};
  if (::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
    std::error_code error;
    const fs::path target = fs::read_symlink(path, error);
    return "is a symbolic link to " + single_quoted(target.string(), 4096) +
           ", which does not exist";
  }
  return "no such " + std::string(what);
}

// Why a file with this status is not acceptable, or "".
std::string status_problem(const struct stat& status, std::string_view what,
                           std::size_t max_bytes) {
  if (S_ISDIR(status.st_mode)) return "is a directory, not a " + std::string(what);
  if (!S_ISREG(status.st_mode))
    return "is not a regular file (" + kind_of(status.st_mode) + "): give a " + std::string(what);
  if (static_cast<std::uintmax_t>(status.st_size) > max_bytes)
    return "is larger than " + size_text(max_bytes) + ", the limit for a " + std::string(what);
  return "";
}

// Closes the descriptor however the read ends.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string read_input_file(const fs::path& path, std::string_view what, std::size_t max_bytes) {
  const auto fail = [&](const std::string& reason) {
    throw InputError(printable(path.string()) + ": " + reason);
  };
  const Descriptor file(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (file.get() < 0) {
    const int error = errno;
    if (error == ENOENT) fail(missing(path, what));
    fail("cannot read the " + std::string(what) + ": " + std::strerror(error));
  }
  struct stat status {};
  if (::fstat(file.get(), &status) != 0)
    fail("cannot read the " + std::string(what) + ": " + std::strerror(errno));
  if (const std::string problem = status_problem(status, what, max_bytes); !problem.empty())
    fail(problem);
  std::string content;
  content.reserve(static_cast<std::size_t>(status.st_size));
  char buffer[1 << 16];
  while (true) {
    const ssize_t got = ::read(file.get(), buffer, sizeof buffer);
    if (got == 0) break;
    if (got < 0) {
      if (errno == EINTR) continue;
      fail("cannot read the " + std::string(what) + ": " + std::strerror(errno));
    }
    if (content.size() + static_cast<std::size_t>(got) > max_bytes)
      fail("is larger than " + size_text(max_bytes) + ", the limit for a " + std::string(what));
    content.append(buffer, static_cast<std::size_t>(got));
  }
  return content;
}

std::string input_file_problem(const fs::path& path, std::string_view what) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    if (errno == ENOENT) return missing(path, what);
    return "cannot read the " + std::string(what) + ": " + std::strerror(errno);
  }
  return status_problem(status, what, static_cast<std::size_t>(-1));
}

}  // namespace spar
