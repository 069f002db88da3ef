// The registry of live temporaries (io/file_ops.h) and the signal cleanup built on it (dmc/io.h):
// RemoveTemporaryFiles removes exactly the temporaries still in progress, puts a moved-aside
// output directory back, leaves a forked child's parent alone; the opt-in handlers remove them and
// end the process by the signal; the writers' error paths, exceptions included, leave nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dmc/io.h"
#include "io/file_ops.h"
#include "io/pc2_stream.h"
#include "io_test_util.h"
#include "test_support.h"

namespace dmc {
namespace {

using io_internal::TemporaryPath;
using ::testing::ElementsAre;
using ::testing::IsEmpty;
using testing::ListNames;
using testing::ReadText;
using testing::ScratchDir;
using ::testing::StartsWith;
using testing::WriteText;

TEST(TemporaryFilesTest, NamesAreHiddenSiblingsWithThePid) {
  ScratchDir dir;
  const TemporaryPath first(dir / "out.dmc", TemporaryPath::Kind::kFile);
  const TemporaryPath second(dir / "out.dmc", TemporaryPath::Kind::kFile);
  EXPECT_EQ(first.path().parent_path(), dir.path());
  EXPECT_THAT(first.path().filename().string(),
              StartsWith(".out.dmc.dmc-tmp-" + std::to_string(::getpid()) + "-"));
  EXPECT_NE(first.path(), second.path());
}

TEST(TemporaryFilesTest, RemovesLiveTemporariesOnlyAndTheDestructorCleansUp) {
  ScratchDir dir;
  TemporaryPath file(dir / "a.pc2", TemporaryPath::Kind::kFile);
  WriteText(file.path(), "partial cache");
  TemporaryPath frames(dir / "frames", TemporaryPath::Kind::kDirectory);
  std::filesystem::create_directory(frames.path());
  for (int f = 0; f < 300; ++f) WriteText(frames.path() / ("frame_" + std::to_string(f)), "v");
  // Renamed into place and released: no longer the registry's business.
  TemporaryPath done(dir / "done.obj", TemporaryPath::Kind::kFile);
  WriteText(done.path(), "complete");
  std::filesystem::rename(done.path(), dir / "done.obj");
  done.Release();
  WriteText(dir / "unrelated.txt", "keep");

  RemoveTemporaryFiles();
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("done.obj", "unrelated.txt"));
  EXPECT_EQ(ReadText(dir / "done.obj"), "complete");

  // Still registered until destroyed; destroying what is gone is harmless.
  WriteText(file.path(), "written again after the cleanup");
  { const TemporaryPath gone = std::move(file); }
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("done.obj", "unrelated.txt"));
}

TEST(TemporaryFilesTest, AnExceptionUnwindingPastATemporaryRemovesIt) {
  ScratchDir dir;
  try {
    const TemporaryPath temporary(dir / "out.glb", TemporaryPath::Kind::kFile);
    WriteText(temporary.path(), "half");
    throw std::runtime_error("an allocation failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_THAT(ListNames(dir.path()), IsEmpty());
}

TEST(TemporaryFilesTest, AMovedAsideOutputIsPutBackOrRemovedOnceReplaced) {
  ScratchDir dir;
  const auto output = dir / "frames";
  WriteText(output / "frame_0000.obj", "old");
  {
    // Interrupted between moving the old output aside and renaming the new one in.
    TemporaryPath previous(output, TemporaryPath::Kind::kMovedAside);
    std::filesystem::rename(output, previous.path());
    RemoveTemporaryFiles();
    EXPECT_THAT(ListNames(dir.path()), ElementsAre("frames"));
    EXPECT_EQ(ReadText(output / "frame_0000.obj"), "old");
  }
  {
    // Interrupted after the new output is in: the old one goes.
    TemporaryPath staging(output, TemporaryPath::Kind::kDirectory);
    WriteText(staging.path() / "frame_0000.obj", "new");
    TemporaryPath previous(output, TemporaryPath::Kind::kMovedAside);
    std::filesystem::rename(output, previous.path());
    std::filesystem::rename(staging.path(), output);
    staging.Release();
    RemoveTemporaryFiles();
    EXPECT_THAT(ListNames(dir.path()), ElementsAre("frames"));
    EXPECT_EQ(ReadText(output / "frame_0000.obj"), "new");
    previous.Release();
  }
}

TEST(TemporaryFilesTest, BeyondTheRegistryTemporariesAreStillRemovedByTheirOwners) {
  ScratchDir dir;
  {
    std::vector<TemporaryPath> many;
    for (int i = 0; i < 70; ++i) {
      many.emplace_back(dir / ("out" + std::to_string(i)), TemporaryPath::Kind::kFile);
      WriteText(many.back().path(), "x");
    }
    RemoveTemporaryFiles();
    EXPECT_EQ(ListNames(dir.path()).size(), 6u);  // the registry tracks 64 at once
  }
  EXPECT_THAT(ListNames(dir.path()), IsEmpty());
}

// Death tests fork: the child runs the statement, the parent checks how it ended.
TEST(TemporaryFilesDeathTest, AForkedChildLeavesItsParentsTemporaries) {
  ScratchDir dir;
  const TemporaryPath parents(dir / "out.dmc", TemporaryPath::Kind::kFile);
  WriteText(parents.path(), "the parent's");
  EXPECT_EXIT(
      {
        RemoveTemporaryFiles();
        std::_Exit(std::filesystem::exists(parents.path()) ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
  EXPECT_TRUE(std::filesystem::exists(parents.path()));
}

TEST(TemporaryFilesDeathTest, InstalledHandlersRemoveTemporariesAndDieOfTheSignal) {
  ScratchDir dir;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    EXPECT_EXIT(
        {
          if (!InstallTemporaryFileCleanupOnSignals().ok()) std::_Exit(2);
          // Installing again must not make the handler its own "previous" disposition.
          if (!InstallTemporaryFileCleanupOnSignals().ok()) std::_Exit(2);
          const TemporaryPath file(dir / "out.pc2", TemporaryPath::Kind::kFile);
          WriteText(file.path(), "partial");
          const TemporaryPath frames(dir / "frames", TemporaryPath::Kind::kDirectory);
          WriteText(frames.path() / "frame_0000.obj", "v 0 0 0");
          std::raise(signal_number);
          std::_Exit(3);  // not reached: the re-raised signal ends the process
        },
        ::testing::KilledBySignal(signal_number), "");
    EXPECT_THAT(ListNames(dir.path()), IsEmpty()) << strsignal(signal_number);
  }
}

TEST(TemporaryFilesDeathTest, AnIgnoredSignalStaysIgnored) {
  ScratchDir dir;
  EXPECT_EXIT(
      {
        std::signal(SIGHUP, SIG_IGN);  // as under nohup
        if (!InstallTemporaryFileCleanupOnSignals().ok()) std::_Exit(2);
        const TemporaryPath file(dir / "out.dmc", TemporaryPath::Kind::kFile);
        WriteText(file.path(), "partial");
        std::raise(SIGHUP);
        std::_Exit(std::filesystem::exists(file.path()) ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

TEST(TemporaryFilesTest, FailedWritersLeaveNoTemporary) {
  ScratchDir dir;
  const MeshSequence sequence = testing::PlanarGrid(4, 3);
  // The cache's mesh cannot replace a directory: the staged cache and mesh both go.
  std::filesystem::create_directory(dir / "anim.obj");
  EXPECT_EQ(WriteSequence(sequence, dir / "anim.pc2").code(), ErrorCode::kIoError);
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("anim.obj"));
  EXPECT_THAT(ListNames(dir / "anim.obj"), IsEmpty());

  // The streaming writer stopped part way (a non-finite frame, or dropped before Commit).
  std::vector<float> frame(static_cast<size_t>(sequence.vertex_count()) * 3, 0.5f);
  {
    StatusOr<io_internal::Pc2PairWriter> writer = io_internal::Pc2PairWriter::Create(
        dir / "stream.pc2", sequence.vertex_count(), 3, sequence.triangles(), 0.0);
    ASSERT_TRUE(writer.ok()) << writer.status().ToString();
    ASSERT_TRUE(writer->AppendFrames(frame.data(), 1).ok());
    frame[4] = std::numeric_limits<float>::infinity();
    EXPECT_EQ(writer->AppendFrames(frame.data(), 1).code(), ErrorCode::kInvalidSequence);
    EXPECT_EQ(writer->Commit().code(), ErrorCode::kInvalidArgument);  // frames missing
  }
  {
    StatusOr<io_internal::StagedFile> file = io_internal::StagedFile::Create(dir / "s.dmc");
    ASSERT_TRUE(file.ok());
    ASSERT_TRUE(file->Append(std::vector<uint8_t>(100, 7)).ok());
  }
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("anim.obj"));
}

}  // namespace
}  // namespace dmc
