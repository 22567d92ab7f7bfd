// Running the `simgrass` executable from tests: temporary folders, captured output, one-line
// error checks. Shared by the command-line, replay and robustness suites.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace sg {
namespace fs = std::filesystem;
using nlohmann::json;

/// A fresh temporary folder, removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "simgrass-cli-test-XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& content) const {
    std::ofstream out(path_ / name, std::ios::binary);
    out << content;
    return file(name);
  }

 private:
  fs::path path_;
};

inline std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A file's bytes (empty when it cannot be read), and bytes written over a file.
inline std::vector<uint8_t> readBytes(const std::string& path) {
  const std::string s = readFile(path);
  return std::vector<uint8_t>(s.begin(), s.end());
}
inline void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct CliResult {
  int exitCode = -1;  ///< exit status, or 128 + signal when it was killed
  std::string out, err;
  std::string describe() const {
    return "exit code " + std::to_string(exitCode) + "\n--- stdout ---\n" + out.substr(0, 2000) + "\n--- stderr ---\n" +
           err.substr(0, 2000);
  }
};

/// Runs `simgrass <args>` (args already shell-quoted where needed) with stdout and stderr
/// captured separately, under a 60 s timeout so a hang is a failure rather than a stuck suite.
/// `cwd`: the folder it runs in (default: the test's own).
inline CliResult runCli(const std::string& args, const std::string& cwd = "") {
  TempDir dir;
  const std::string out = dir.file("stdout"), err = dir.file("stderr");
  const std::string cmd = (cwd.empty() ? std::string() : "cd " + quote(cwd) + " && ") + "timeout -k 5 60 " +
                          quote(SIMGRASS_CLI) + " " + args + " </dev/null >" + quote(out) + " 2>" + quote(err);
  const int status = std::system(cmd.c_str());
  CliResult r;
  if (status == -1) {
    r.exitCode = -1;
  } else if (WIFEXITED(status)) {
    r.exitCode = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    r.exitCode = 128 + WTERMSIG(status);
  }
  r.out = readFile(out);
  r.err = readFile(err);
  return r;
}

/// Exactly one line: one newline, at the end, and something before it.
inline testing::AssertionResult isOneLine(const std::string& s) {
  const auto n = std::count(s.begin(), s.end(), '\n');
  if (n == 1 && s.size() > 1 && s.back() == '\n') return testing::AssertionSuccess();
  return testing::AssertionFailure() << "expected exactly one line on stderr, got " << n << " newlines:\n" << s;
}

inline bool isHex16(const std::string& s) {
  return s.size() == 16 && std::all_of(s.begin(), s.end(), [](char c) { return std::isxdigit((unsigned char)c); });
}

inline json parseJson(const CliResult& r) {
  try {
    return json::parse(r.out);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "stdout is not JSON: " << e.what() << "\n" << r.describe();
    return json();
  }
}

}  // namespace sg
