// Runs the built dmc binary for CLI tests and captures exit code, stdout and stderr.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace dmc::testing {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// A fresh, empty directory under the system temp dir, unique per test.
inline std::filesystem::path FreshTempDir(const std::string& tag) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::filesystem::path dir = std::filesystem::temp_directory_path() /
                              ("dmc_test_" + tag + "_" + std::string(info->test_suite_name()) +
                               "_" + std::string(info->name()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// `path` in single quotes for RunDmc's shell command line. Built by appending: the shorter
// `"'" + path.string() + "'"` trips GCC 12's false -Wrestrict positive under -Werror.
inline std::string Quoted(const std::filesystem::path& path) {
  std::string quoted = "'";
  quoted.append(path.string()).push_back('\'');
  return quoted;
}

// The whole file, byte for byte ("" when it cannot be read).
inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs `dmc <args>` through the shell (args are passed verbatim; quote paths with spaces).
inline CliResult RunDmc(const std::string& args) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string stem = "dmc_cli_" + std::to_string(::getpid()) + "_" +
                           std::to_string(reinterpret_cast<uintptr_t>(&args));
  const auto out_path = dir / (stem + ".out");
  const auto err_path = dir / (stem + ".err");
  const std::string command =
      std::string(DMC_CLI_PATH) + " " + args + " >" + out_path.string() + " 2>" + err_path.string();
  const int raw = std::system(command.c_str());
  CliResult result;
  result.exit_code = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = ReadText(out_path);
  result.err = ReadText(err_path);
  std::filesystem::remove(out_path);
  std::filesystem::remove(err_path);
  return result;
}

}  // namespace dmc::testing
