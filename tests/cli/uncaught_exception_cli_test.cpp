// The CLI's last line of defence: memory that runs out (std::bad_alloc) is reported as
// resource-limit (exit 22) instead of aborting (exit 134); usage errors stay exit 1.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

TEST(UncaughtExceptionCli, OutOfMemoryIsAResourceLimitError) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves more address space than the limit allows";
#endif
  const auto dir = FreshTempDir("uncaught_exception");
  // 2,000 frames of 200,000 vertices need 4.8 GB; the address space is limited to 600 MB.
  for (const char* json : {"", " --json"}) {
    const std::string command = "ulimit -v 600000 && exec " + std::string(DMC_CLI_PATH) +
                                " synth walker -o " + Quoted(dir / "huge.pc2") +
                                " --frames 2000 --resolution 200000" + json + " >" +
                                Quoted(dir / "out.txt") + " 2>" + Quoted(dir / "err.txt");
    const int raw = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(raw)) << "wait status " << raw;
    EXPECT_EQ(WEXITSTATUS(raw), 22) << json;  // 10 + ErrorCode::kResourceLimit
    std::ifstream err(dir / "err.txt");
    const std::string text((std::istreambuf_iterator<char>(err)), {});
    EXPECT_NE(
        text.find("dmc synth: error: resource-limit: out of memory while running 'dmc synth'"),
        std::string::npos)
        << text;
    if (*json != '\0') {
      std::ifstream out(dir / "out.txt");
      const std::string document((std::istreambuf_iterator<char>(out)), {});
      EXPECT_NE(document.find("\"name\": \"resource-limit\""), std::string::npos) << document;
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "huge.pc2"));
}

TEST(UncaughtExceptionCli, UsageErrorsStayExitOne) {
  for (const char* args : {"", "nosuch", "encode", "encode --no-such-flag x.pc2 -o y.dmc",
                           "encode a.pc2 -o b.dmc --segment-frames banana"}) {
    EXPECT_EQ(RunDmc(args).exit_code, 1) << args;
  }
  EXPECT_EQ(RunDmc("--help").exit_code, 0);
}

}  // namespace
}  // namespace dmc::testing
