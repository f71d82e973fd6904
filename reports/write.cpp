#include "spar/reports/write.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <random>
#include <system_error>
#include <utility>

#include "spar/reports/error.hpp"
#include "spar/reports/html.hpp"
#include "spar/reports/internal/cell_svg.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/markdown.hpp"

namespace spar::reports {
namespace fs = std::filesystem;

std::vector<Format> parse_formats(std::string_view list) {
  std::vector<Format> formats;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string_view word = list.substr(start, comma - start);
    Format format;
    if (word == "json")
      format = Format::kJson;
    else if (word == "md" || word == "markdown")
      format = Format::kMarkdown;
    else if (word == "html")
      format = Format::kHtml;
    else
      throw ReportError("unknown report format '" + std::string(word) +
                        "' (expected a comma-separated list of json, md, html)");
    if (std::find(formats.begin(), formats.end(), format) != formats.end())
      throw ReportError("report format '" + std::string(word) + "' given twice");
    formats.push_back(format);
    start = comma + 1;
  }
  return formats;
}

std::string file_name(Format format) {
  switch (format) {
    case Format::kJson:
      return "report.json";
    case Format::kMarkdown:
      return "report.md";
    case Format::kHtml:
      return "report.html";
  }
  return "report";
}

std::string render(const Report& report, Format format) {
  switch (format) {
    case Format::kJson:
      return to_json(report).dump(2) + "\n";
    case Format::kMarkdown:
      return render_markdown(report);
    case Format::kHtml:
      return render_html(report);
  }
  return {};
}

namespace {

// ---- signals: a report set is replaced whole or not at all ----
//
// While any thread writes a report set, SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGPIPE (those left
// at their default action: Python's or a caller's own handlers are kept) are held: the handler
// notes the signal, the writers see it, discard their temporaries (a set not yet committed keeps
// the old one) or finish the few renames of their commit, and the last writer out re-raises it
// with the default action. With no writer active the signal acts at once, as before.
constexpr int kHeldSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE};
std::atomic<int> active_writers{0};
std::atomic<int> held_signal{0};

void reraise(int signal_number) {
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

extern "C" void hold_signal(int signal_number) {
  // Noted first, then the writers counted: a writer leaving in between sees the note.
  held_signal.store(signal_number);
  if (active_writers.load() == 0) reraise(signal_number);
}

void install_signal_hold() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int signal_number : kHeldSignals) {
      struct sigaction current {};
      if (sigaction(signal_number, nullptr, &current) != 0 || current.sa_handler != SIG_DFL ||
          (current.sa_flags & SA_SIGINFO) != 0)
        continue;
      struct sigaction hold {};
      hold.sa_handler = hold_signal;
      sigemptyset(&hold.sa_mask);
      hold.sa_flags = SA_RESTART;
      sigaction(signal_number, &hold, nullptr);
    }
  });
}

// Counts this thread as a writer for its lifetime; the last writer out re-raises a held signal.
class WriterScope {
 public:
  WriterScope() {
    install_signal_hold();
    ++active_writers;
  }
  ~WriterScope() {
    if (--active_writers == 0)
      if (const int signal_number = held_signal.exchange(0)) reraise(signal_number);
  }
  WriterScope(const WriterScope&) = delete;
  WriterScope& operator=(const WriterScope&) = delete;
  [[nodiscard]] static bool interrupted() { return held_signal.load() != 0; }
};

std::string system_reason(int error) { return std::strerror(error); }

// A name no other file in the folder has: ".report.json.<random>.tmp" (hidden, and never a
// final name).
fs::path unique_name(const fs::path& folder, const std::string& final_name, const char* kind) {
  static std::atomic<std::uint64_t> counter{0};
  static const std::uint64_t seed = std::random_device{}();
  char suffix[40];
  std::snprintf(suffix, sizeof suffix, ".%d-%llx-%llx.%s", static_cast<int>(getpid()),
                static_cast<unsigned long long>(seed),
                static_cast<unsigned long long>(counter.fetch_add(1)), kind);
  return folder / ("." + final_name + suffix);
}

// Creates `path` new (O_EXCL: never an existing file, O_NOFOLLOW: never through a link), with the
// permissions the umask gives, and writes `text` whole. Returns 0 or the errno of the failure.
int write_new_file(const fs::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) return errno;
  std::size_t written = 0;
  int error = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = n < 0 ? errno : EIO;
      break;
    }
    written += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0 && error == 0) error = errno;
  return error;
}

// A set of files written into a folder all or nothing: each to a temporary first, the old files
// kept as hard-link backups, then each renamed into place. On any failure the temporaries and
// backups go and the old set stays (a rename failing half-way renames the replaced ones back).
class FileSet {
 public:
  explicit FileSet(fs::path folder) : folder_(std::move(folder)) {}

  // Writes every (name, text) to a temporary in the folder.
  void stage(const std::vector<std::pair<std::string, std::string>>& files) {
    for (const auto& [name, text] : files) {
      members_.push_back({unique_name(folder_, name, "tmp"), folder_ / name, {}});
      if (const int failure = write_new_file(members_.back().temporary, text))
        fail("cannot write " + members_.back().temporary.string() + ": " + system_reason(failure));
      if (WriterScope::interrupted()) fail("interrupted: the old report is kept");
    }
  }

  // Backups as hard links, so a rename that fails half-way can restore the old set.
  void back_up() {
    for (Member& member : members_) {
      struct stat info {};
      if (::lstat(member.final.c_str(), &info) != 0) continue;
      if (S_ISDIR(info.st_mode))
        fail(member.final.string() + " is a directory, not a report file (the old report is kept)");
      member.backup = unique_name(folder_, member.final.filename().string(), "old");
      if (::link(member.final.c_str(), member.backup.c_str()) != 0) {
        const int failure = errno;
        member.backup.clear();
        fail("cannot keep the old " + member.final.string() +
             " while writing: " + system_reason(failure));
      }
    }
  }

  // The renames (a held signal waits for them), then the backups go.
  void commit() {
    for (Member& member : members_) {
      if (::rename(member.temporary.c_str(), member.final.c_str()) == 0) {
        member.replaced = true;
        continue;
      }
      const int failure = errno;
      for (const Member& done : members_) {
        if (!done.replaced) continue;
        if (done.backup.empty())
          ::unlink(done.final.c_str());
        else
          ::rename(done.backup.c_str(), done.final.c_str());
      }
      fail("cannot rename " + member.temporary.string() + " to " + member.final.string() + ": " +
           system_reason(failure) + " (the old report is kept)");
    }
    for (const Member& member : members_)
      if (!member.backup.empty()) ::unlink(member.backup.c_str());
  }

  // The final path of the i-th file staged.
  [[nodiscard]] const fs::path& final_path(std::size_t i) const { return members_.at(i).final; }

 private:
  struct Member {
    fs::path temporary, final, backup;
    bool replaced{false};
  };
  [[noreturn]] void fail(const std::string& what) const {
    for (const Member& member : members_) {
      ::unlink(member.temporary.c_str());
      if (!member.backup.empty()) ::unlink(member.backup.c_str());
    }
    throw ReportError(what);
  }

  fs::path folder_;
  std::vector<Member> members_;
};

// Removes the files of an older report that this one (`files`) does not have: formats not
// written, and cell views past this report's (all of them without the Markdown).
void remove_stale(const fs::path& folder,
                  const std::vector<std::pair<std::string, std::string>>& files) {
  const auto remove = [&](const std::string& name) {
    for (const auto& file : files)
      if (file.first == name) return;
    const fs::path old = folder / name;
    struct stat info {};
    if (::lstat(old.c_str(), &info) == 0 && !S_ISDIR(info.st_mode)) ::unlink(old.c_str());
  };
  for (const Format format : {Format::kJson, Format::kMarkdown, Format::kHtml})
    remove(file_name(format));
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 9 && name.starts_with("cell-") && name.ends_with(".svg") &&
        name.find_first_not_of("0123456789", 5) == name.size() - 4)
      remove(name);
  }
}

}  // namespace

std::vector<fs::path> write_reports(const Report& report, const fs::path& folder,
                                    const std::vector<Format>& formats) {
  if (folder.empty()) throw ReportError("the report folder is empty: give a folder name");
  // Every file: the formats' (returned), then the cell's views the Markdown links to.
  std::vector<std::pair<std::string, std::string>> files;
  for (const Format format : formats) files.emplace_back(file_name(format), render(report, format));
  const std::size_t reports = files.size();
  if (report.cell && std::find(formats.begin(), formats.end(), Format::kMarkdown) != formats.end())
    for (std::size_t v = 0; v < report.cell->views.size(); ++v)
      files.emplace_back(internal::cell_view_file(v), internal::cell_view_svg(report, v, true));
  std::error_code error;
  fs::create_directories(folder, error);
  if (error)
    throw ReportError("cannot create the report folder " + folder.string() + ": " +
                      error.message());
  const WriterScope writer;
  FileSet set(folder);
  set.stage(files);
  set.back_up();
  set.commit();
  remove_stale(folder, files);
  std::vector<fs::path> finals;
  for (std::size_t i = 0; i < reports; ++i) finals.push_back(set.final_path(i));
  return finals;
}

}  // namespace spar::reports
