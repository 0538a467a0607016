// Running a command as a user's shell would, for the tests of the rccx program: its output (with
// whatever the command line redirects into it) and its exit code, 128 + the signal when one
// ended it.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace rccx::test {

struct ShellRun {
  int exit_code = -1;
  std::string out;
};

/// `command` through /bin/sh; every byte of its standard output.
inline ShellRun run_shell(const std::string& command) {
  ShellRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return run;
}

/// `rccx ARGUMENTS`, its standard error with its output unless `with_stderr` is false.
inline ShellRun rccx_run(const std::string& arguments, bool with_stderr = true) {
  return run_shell(std::string(RCCX_CLI) + " " + arguments +
                   (with_stderr ? " 2>&1" : " 2>/dev/null"));
}

}  // namespace rccx::test
