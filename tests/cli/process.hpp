// Running the built `spar` as a user does, for the CLI tests: run_process starts a program with
// stdin from /dev/null and stdout and stderr going to files, and kills it after a time limit, so a
// hang is a failure, not a stuck test. read_file / write_text are the tests' file helpers.
//
// Example:
//   const Outcome outcome = run_process({SPAR_BINARY, "simplify", "x+x"}, out, err, 30);
//   EXPECT_EQ(outcome.exit_status, 0);
//   EXPECT_EQ(read_file(out), "2*x\n");
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace spar::cli_test {

struct Outcome {
  int exit_status{-1};  // -1: killed by a signal or by the time limit
  std::string what;     // how it ended when it did not exit
  std::string out, err;
};

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Runs `arguments` (the program first), stdin from /dev/null, stdout to `stdout_file` and stderr to
// `stderr_file`; kills it after `seconds`. Fills exit_status / what (not out and err).
inline Outcome run_process(std::vector<std::string> arguments, const std::string& stdout_file,
                           const std::string& stderr_file, int seconds) {
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdout_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderr_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  Outcome outcome;
  if (spawned != 0) {
    outcome.what = "could not start " + arguments.front();
    return outcome;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      outcome.what = "still running after " + std::to_string(seconds) + " s (killed)";
      return outcome;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (WIFEXITED(status)) {
    outcome.exit_status = WEXITSTATUS(status);
  } else {
    outcome.what = "killed by signal " + std::to_string(WTERMSIG(status));
  }
  return outcome;
}

}  // namespace spar::cli_test
