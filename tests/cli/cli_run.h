#ifndef RMHB_TESTS_CLI_CLI_RUN_H_
#define RMHB_TESTS_CLI_CLI_RUN_H_

// Runs the rmhb binary (RMHB_CLI, set by CMake) as a script would.

#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace rmhb::cli_test {

struct CliRun {
  int code;
  std::string out;
};

// Runs a shell command, returns its exit code and standard output.
inline CliRun Capture(const std::string& cmd) {
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), pipe)) out.append(buf.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// stdout and stderr together, as a user sees them.
inline CliRun Cli(const std::string& args) { return Capture(std::string(RMHB_CLI) + " " + args + " 2>&1"); }

// stdout only: it must be a JSON document.
inline nlohmann::json Json(const std::string& args) {
  return nlohmann::json::parse(Capture(std::string(RMHB_CLI) + " " + args).out);
}

}  // namespace rmhb::cli_test

#endif  // RMHB_TESTS_CLI_CLI_RUN_H_
