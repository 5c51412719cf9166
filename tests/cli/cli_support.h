#pragma once
// Running the cps executable as a user runs it, for the command-line tests (test_cli*.cpp).
// Each test file defines CPS_EXE (the path of the built cps) before including this header.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace cli_test {

/// What one run of cps gave: its exit code (-1 if it did not exit normally, e.g. killed by a
/// signal), and everything it wrote to stdout and to stderr.
struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// The whole content of the file at `p` (empty if it cannot be read), bytes as they are.
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `ENV cps ARGS` with `dir` as the working directory (ENV: shell variable assignments such
/// as "PATH=/x", may be empty). stdout and stderr go to files, so stderr is never a terminal, as
/// in CI. ARGS is passed through the shell: quote what needs quoting.
inline Result run_cps(const std::string& args, const std::filesystem::path& dir,
                      const std::string& env = "") {
  const std::filesystem::path out = dir / "stdout.txt";
  const std::filesystem::path err = dir / "stderr.txt";
  const std::string command = "cd '" + dir.string() + "' && " + env + " '" CPS_EXE "' " + args +
                              " > '" + out.string() + "' 2> '" + err.string() + "'";
  const int status = std::system(command.c_str());
  Result r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

/// An empty folder named `name` in the system's temporary folder (removed first if it exists).
/// Test files use distinct prefixes so that ctest can run them in parallel.
inline std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace cli_test
