#pragma once
// Runs the real `tightbvh` binary as a user would and captures exit status, stdout and stderr.
// Output goes through files unique to the process and call: CTest runs the discovered tests as
// parallel processes, so fixed file names would let two tests read each other's output.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace tightbvh::test {

struct CliRun {
  int status = -1;  // exit code, -1 if the process did not exit normally
  std::string out;
  std::string err;
};

[[nodiscard]] inline std::filesystem::path cli_path() {
  return std::filesystem::path(TIGHTBVH_BINARY_DIR) / "bin" / "tightbvh";
}

[[nodiscard]] inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// `args` is passed to the shell as is (quote paths with shell_quote where needed).
[[nodiscard]] inline CliRun run_cli(const std::string& args) {
  static int calls = 0;  // per process; the pid separates processes
  const std::string stem = "tightbvh_cli_" + std::to_string(::getpid()) + "_" + std::to_string(++calls);
  const auto out_path = std::filesystem::temp_directory_path() / (stem + ".out");
  const auto err_path = std::filesystem::temp_directory_path() / (stem + ".err");
  const std::string command = shell_quote(cli_path().string()) + " " + args + " >" +
                              shell_quote(out_path.string()) + " 2>" + shell_quote(err_path.string());
  const int raw = std::system(command.c_str());
  const auto slurp = [](const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  CliRun r;
  r.status = (raw != -1 && WIFEXITED(raw)) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out_path);
  r.err = slurp(err_path);
  std::filesystem::remove(out_path);
  std::filesystem::remove(err_path);
  return r;
}

}  // namespace tightbvh::test
