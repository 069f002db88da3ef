// Ctrl-C, kill and a closed terminal during `dmc encode` / `dmc decode`: the process dies of the
// signal (so a shell sees 128 + N), no hidden ".NAME.dmc-tmp-PID-N" file or directory is left
// beside the output, and an output that existed before is untouched. Each signal is sent at a
// moment observed in the file system (the temporary has appeared, has grown, holds frames), not
// after a delay, so the test does not depend on the machine's speed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

namespace fs = std::filesystem;

std::vector<char> Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Entries of `dir` whose name holds "dmc-tmp".
std::vector<fs::path> Temporaries(const fs::path& dir) {
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename().string().find("dmc-tmp") != std::string::npos) {
      found.push_back(entry.path());
    }
  }
  return found;
}

// Starts `dmc <args>` with its output discarded.
pid_t Spawn(const std::vector<std::string>& args) {
  std::vector<std::string> argv_strings = {DMC_CLI_PATH};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& arg : argv_strings) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

// Runs `dmc <args>`, sends `signal_number` once `ready(dir)` holds, and returns the wait status.
// Fails the test when the command ends before that moment comes.
int InterruptWhen(const std::vector<std::string>& args, const fs::path& dir,
                  const std::function<bool(const fs::path&)>& ready, int signal_number) {
  const pid_t pid = Spawn(args);
  EXPECT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  int status = 0;
  while (!ready(dir)) {
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      ADD_FAILURE() << "dmc ended (status " << status << ") before the moment to interrupt it";
      return status;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      ADD_FAILURE() << "the moment to interrupt never came";
      return status;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ::kill(pid, signal_number);
  ::waitpid(pid, &status, 0);
  return status;
}

// The first temporary in `dir` holding at least `bytes` bytes (files) or `files` entries
// (directories).
std::function<bool(const fs::path&)> TemporaryWith(uintmax_t bytes, size_t files = 0) {
  return [bytes, files](const fs::path& dir) {
    for (const fs::path& temporary : Temporaries(dir)) {
      std::error_code error;
      if (fs::is_directory(temporary, error)) {
        size_t count = 0;
        for (fs::directory_iterator it(temporary, error), end; !error && it != end;
             it.increment(error)) {
          ++count;
        }
        if (count >= files) return true;
      } else if (const uintmax_t size = fs::file_size(temporary, error); !error && size >= bytes) {
        return true;
      }
    }
    return false;
  };
}

class SignalCleanupCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // FreshTempDir names a directory after the running test, which SetUpTestSuite has not.
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("dmc_test_signal_cleanup_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    // Large enough that encoding and writing the decoded frames take a while, small enough to
    // make quickly: 7,200 vertices x 400 frames (35 MB of PC2).
    const CliResult made =
        RunDmc("synth walker -o " + Quoted(*dir_ / "walk.pc2") + " --frames 400 --resolution 7200");
    ASSERT_EQ(made.exit_code, 0) << made.err;
    const CliResult encoded = RunDmc("encode " + Quoted(*dir_ / "walk.pc2") + " -o " +
                                     Quoted(*dir_ / "walk.dmc") + " --no-measure");
    ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    fs::remove_all(*dir_, ignored);
    delete dir_;
  }
  void SetUp() override {
    out_ = *dir_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(out_);
    fs::create_directories(out_);
  }
  void ExpectKilledBy(int status, int signal_number) {
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number)
        << "wait status " << status << ", expected death by " << strsignal(signal_number);
  }
  static fs::path* dir_;
  fs::path out_;
};
fs::path* SignalCleanupCli::dir_ = nullptr;

TEST_F(SignalCleanupCli, EncodeInterruptedKeepsTheExistingStream) {
  const fs::path stream = out_ / "out.dmc";
  fs::copy_file(*dir_ / "walk.dmc", stream);
  const auto before = Bytes(stream);
  const std::vector<std::string> encode = {"encode", (*dir_ / "walk.pc2").string(), "-o",
                                           stream.string()};
  // As soon as the staged stream exists (before the first segment is written), and once it has
  // grown (segments written).
  ExpectKilledBy(InterruptWhen(encode, out_, TemporaryWith(0), SIGINT), SIGINT);
  EXPECT_TRUE(Temporaries(out_).empty());
  ExpectKilledBy(InterruptWhen(encode, out_, TemporaryWith(1), SIGTERM), SIGTERM);
  EXPECT_TRUE(Temporaries(out_).empty());
  EXPECT_EQ(Bytes(stream), before);
}

TEST_F(SignalCleanupCli, DecodeToPc2InterruptedKeepsTheExistingCacheAndMesh) {
  const fs::path cache = out_ / "out.pc2", mesh = out_ / "out.obj";
  std::ofstream(cache) << "an older cache";
  std::ofstream(mesh) << "an older mesh";
  const std::vector<std::string> decode = {"decode", (*dir_ / "walk.dmc").string(), "-o",
                                           cache.string()};
  ExpectKilledBy(InterruptWhen(decode, out_, TemporaryWith(0), SIGHUP), SIGHUP);
  EXPECT_TRUE(Temporaries(out_).empty());
  // Part way through the frames.
  ExpectKilledBy(InterruptWhen(decode, out_, TemporaryWith(4 << 20), SIGTERM), SIGTERM);
  EXPECT_TRUE(Temporaries(out_).empty());
  EXPECT_EQ(Bytes(cache), std::vector<char>({'a', 'n', ' ', 'o', 'l', 'd', 'e', 'r', ' ', 'c', 'a',
                                             'c', 'h', 'e'}));
  std::ifstream mesh_in(mesh);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(mesh_in), {}), "an older mesh");
}

TEST_F(SignalCleanupCli, DecodeToFramesInterruptedKeepsTheExistingDirectory) {
  const fs::path frames = out_ / "frames";
  fs::create_directories(frames);
  std::ofstream(frames / "frame_0000.obj") << "an older frame";
  const std::vector<std::string> decode = {"decode", (*dir_ / "walk.dmc").string(), "-o",
                                           frames.string()};
  // The staging directory holds a few frame files.
  ExpectKilledBy(InterruptWhen(decode, out_, TemporaryWith(0, 3), SIGINT), SIGINT);
  EXPECT_TRUE(Temporaries(out_).empty());
  ASSERT_EQ(std::distance(fs::directory_iterator(frames), fs::directory_iterator()), 1);
  std::ifstream frame(frames / "frame_0000.obj");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(frame), {}), "an older frame");
}

TEST_F(SignalCleanupCli, AnUninterruptedRunStillReplacesTheOutput) {
  // The handlers change nothing for a run that completes.
  const fs::path cache = out_ / "out.pc2";
  std::ofstream(cache) << "an older cache";
  ASSERT_EQ(RunDmc("decode " + Quoted(*dir_ / "walk.dmc") + " -o " + Quoted(cache)).exit_code, 0);
  EXPECT_GT(fs::file_size(cache), 1000u);
  EXPECT_TRUE(Temporaries(out_).empty());
}

}  // namespace
}  // namespace dmc::testing
