// ReadSequence / WriteSequence: bit-exact round trips in every layout, input resolution
// (directory, glob, file, PC2), frame consistency errors, and atomic, non-destructive writes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <random>
#include <string>

#include "dmc/io.h"
#include "io_test_util.h"
#include "test_support.h"

namespace dmc {
namespace {

using ::testing::ElementsAre;
using testing::ExpectIdentical;
using ::testing::HasSubstr;
using testing::ListNames;
using testing::ScratchDir;
using testing::WriteText;

// 7 vertices (vertex 6 isolated), a repeated-corner triangle and an edge (0,1) shared by three
// triangles, with random finite float bit patterns (denormals, -0, huge and tiny values) so that
// any loss of digits or reordering shows up.
MeshSequence AwkwardSequence(int frames, uint32_t seed = 1) {
  Triangles triangles(5, 3);
  triangles << 0, 1, 2, 0, 0, 1, 1, 0, 3, 0, 1, 4, 5, 4, 3;
  MeshSequence sequence(7, triangles, frames);
  std::mt19937 random(seed);
  float* values = sequence.data();
  for (size_t i = 0; i < sequence.position_value_count(); ++i) {
    float value = 0.0f;
    do {
      const uint32_t bits = random();
      std::memcpy(&value, &bits, 4);
    } while (!std::isfinite(value));
    values[i] = value;
  }
  values[0] = -0.0f;
  values[1] = 1.0e-45f;  // smallest denormal
  values[2] = 0.1f;
  sequence.frame_rate = 24.0;
  return sequence;
}

MeshSequence ReadOrDie(const std::filesystem::path& input, const ReadOptions& options = {}) {
  auto sequence = ReadSequence(input, options);
  EXPECT_TRUE(sequence.ok()) << sequence.status().ToString();
  return sequence.ok() ? std::move(sequence).value() : MeshSequence();
}

class DirectoryRoundTripTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DirectoryRoundTripTest, IsBitExactAndKeepsOrderAndFrameRate) {
  ScratchDir dir;
  const MeshSequence original = AwkwardSequence(3);
  WriteOptions options;
  options.frame_format = GetParam();
  ASSERT_TRUE(WriteSequence(original, dir / "frames", options).ok());
  const std::string ext = "." + GetParam();
  EXPECT_THAT(ListNames(dir / "frames"),
              ElementsAre("frame_0000" + ext, "frame_0001" + ext, "frame_0002" + ext));
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("frames"));  // no staging left behind
  const MeshSequence read = ReadOrDie(dir / "frames");
  ExpectIdentical(original, read);
  EXPECT_EQ(read.frame_rate, 24.0);
  EXPECT_EQ(read.name, "frames");
}

TEST_P(DirectoryRoundTripTest, SingleFileIsBitExact) {
  ScratchDir dir;
  const MeshSequence original = AwkwardSequence(1, 5);
  const auto path = dir / ("one." + GetParam());
  ASSERT_TRUE(WriteSequence(original, path).ok());
  const MeshSequence read = ReadOrDie(path);
  ExpectIdentical(original, read);
  EXPECT_EQ(read.name, "one");
}

INSTANTIATE_TEST_SUITE_P(Formats, DirectoryRoundTripTest, ::testing::Values("obj", "off", "ply"));

TEST(Pc2Test, RoundTripIsBitExactAndWritesTheConnectivityMesh) {
  ScratchDir dir;
  const MeshSequence original = AwkwardSequence(4);
  ASSERT_TRUE(WriteSequence(original, dir / "anim.pc2").ok());
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("anim.obj", "anim.pc2"));
  EXPECT_EQ(std::filesystem::file_size(dir / "anim.pc2"), 32u + 4u * 7u * 12u);
  const MeshSequence read = ReadOrDie(dir / "anim.pc2");
  ExpectIdentical(original, read);
  EXPECT_EQ(read.frame_rate, 24.0);  // scene rate from anim.obj / sampleRate 1
  // The companion mesh holds frame 0.
  const MeshSequence companion = ReadOrDie(dir / "anim.obj");
  EXPECT_EQ(companion.frame(0), original.frame(0));

  ReadOptions first_two;
  first_two.max_frames = 2;
  const MeshSequence head = ReadOrDie(dir / "anim.pc2", first_two);
  ASSERT_EQ(head.frame_count(), 2);
  EXPECT_EQ(head.frame(1), original.frame(1));
}

// A hand-made cache: header fields as given, `samples` x `points` vertices at (s, p, 0).
std::string Pc2Bytes(int32_t points, int32_t samples, float sample_rate, int32_t version = 1,
                     const char* magic = "POINTCACHE2") {
  std::string out(magic, 11);
  out.push_back('\0');
  auto put = [&out](auto value) { out.append(reinterpret_cast<const char*>(&value), 4); };
  put(version);
  put(points);
  put(10.0f);
  put(sample_rate);
  put(samples);
  for (int s = 0; s < samples; ++s) {
    for (int p = 0; p < points; ++p) {
      put(static_cast<float>(s));
      put(static_cast<float>(p));
      put(0.0f);
    }
  }
  return out;
}

constexpr std::string_view kTetrahedronObj =
    "# dmc frame_rate 24\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

TEST(Pc2Test, DerivesTheRateFromSampleSpacingAndUsesAnExplicitConnectivity) {
  ScratchDir dir;
  WriteText(dir / "cache.pc2", Pc2Bytes(4, 3, 0.5f));
  WriteText(dir / "elsewhere" / "tet.obj", kTetrahedronObj);
  ReadOptions options;
  options.connectivity = dir / "elsewhere" / "tet.obj";
  const MeshSequence read = ReadOrDie(dir / "cache.pc2", options);
  ASSERT_EQ(read.frame_count(), 3);
  EXPECT_EQ(read.triangle_count(), 4);
  EXPECT_EQ(read.frame(2)(3, 0), 2.0f);
  EXPECT_EQ(read.frame(2)(3, 1), 3.0f);
  EXPECT_EQ(read.frame_rate, 48.0);  // two samples per scene frame at 24 fps
}

struct Pc2Case {
  std::string bytes;
  bool write_mesh;
  ErrorCode code;
  std::string message;
};

class Pc2ErrorTest : public ::testing::TestWithParam<Pc2Case> {};

TEST_P(Pc2ErrorTest, Fails) {
  ScratchDir dir;
  WriteText(dir / "c.pc2", GetParam().bytes);
  if (GetParam().write_mesh) WriteText(dir / "c.obj", kTetrahedronObj);
  auto read = ReadSequence(dir / "c.pc2");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), GetParam().code) << read.status().ToString();
  EXPECT_THAT(read.status().message(), HasSubstr(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Cases, Pc2ErrorTest,
    ::testing::Values(
        Pc2Case{Pc2Bytes(4, 3, 1.0f).substr(0, 32 + 100), true, ErrorCode::kParseError,
                "declares 3 samples of 4 points (176 bytes) but the file has 132 bytes "
                "(truncated)"},
        Pc2Case{Pc2Bytes(4, 3, 1.0f).substr(0, 20), true, ErrorCode::kParseError,
                "less than the 32-byte PC2 header"},
        Pc2Case{Pc2Bytes(4, 3, 1.0f, 1, "POINTCACHE3"), true, ErrorCode::kParseError,
                "not a PC2 point cache"},
        Pc2Case{Pc2Bytes(4, 3, 1.0f, 2), true, ErrorCode::kUnsupported, "PC2 version 2"},
        Pc2Case{Pc2Bytes(-4, 3, 1.0f), true, ErrorCode::kParseError, "points must be positive"},
        Pc2Case{Pc2Bytes(5, 3, 1.0f), true, ErrorCode::kMismatch,
                "c.pc2: 5 points, but the connectivity mesh"},
        Pc2Case{Pc2Bytes(4, 3, 1.0f), false, ErrorCode::kIoError, "needs a connectivity mesh"}));

TEST(Pc2Test, RejectsNonFiniteSamplesNamingFrameAndVertex) {
  ScratchDir dir;
  std::string bytes = Pc2Bytes(4, 3, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(bytes.data() + 32 + (2 * 4 + 1) * 12 + 4, &nan, 4);  // frame 2, vertex 1, y
  WriteText(dir / "c.pc2", bytes);
  WriteText(dir / "c.obj", kTetrahedronObj);
  auto read = ReadSequence(dir / "c.pc2");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), ErrorCode::kInvalidSequence);
  EXPECT_THAT(read.status().message(), HasSubstr("frame 2 (" + (dir / "c.pc2").string() +
                                                 "), vertex 1: coordinate y is not finite"));
}

// A frame file of the tetrahedron moved by `shift` along x.
std::string TetrahedronFrame(int shift, std::string_view faces = "f 1 3 2\nf 1 2 4\nf 2 3 4\n") {
  return "v " + std::to_string(shift) + " 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + std::string(faces);
}

TEST(InputResolutionTest, DirectoryFramesAreInNaturalOrderAndHiddenFilesSkipped) {
  ScratchDir dir;
  for (int n : {10, 2, 1})
    WriteText(dir / ("mesh_" + std::to_string(n) + ".obj"), TetrahedronFrame(n));
  WriteText(dir / ".mesh_0.obj", "garbage");
  WriteText(dir / "notes.txt", "not a frame");
  std::vector<std::pair<int, int>> progress;
  ReadOptions options;
  options.progress = [&progress](int done, int total) { progress.emplace_back(done, total); };
  const MeshSequence read = ReadOrDie(dir.path(), options);
  ASSERT_EQ(read.frame_count(), 3);
  EXPECT_EQ(read.frame(0)(0, 0), 1.0f);
  EXPECT_EQ(read.frame(1)(0, 0), 2.0f);
  EXPECT_EQ(read.frame(2)(0, 0), 10.0f);
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back(), std::make_pair(3, 3));
  for (size_t i = 1; i < progress.size(); ++i) EXPECT_GT(progress[i].first, progress[i - 1].first);

  ReadOptions two;
  two.max_frames = 2;
  EXPECT_EQ(ReadOrDie(dir.path(), two).frame_count(), 2);
}

TEST(InputResolutionTest, NamesTheSequenceAfterItsDirectoryOrFile) {
  ScratchDir dir;
  WriteText(dir / "walk" / "f1.obj", TetrahedronFrame(1));
  EXPECT_EQ(ReadOrDie(dir / "walk").name, "walk");
  EXPECT_EQ(ReadOrDie(dir.path().string() + "/walk/").name, "walk");
  EXPECT_EQ(ReadOrDie(dir / "walk" / ".." / "walk" / ".").name, "walk");
  EXPECT_EQ(ReadOrDie(dir / "walk" / "f*.obj").name, "walk");
  EXPECT_EQ(ReadOrDie(dir / "walk" / "f1.obj").name, "f1");
}

TEST(InputResolutionTest, GlobSelectsMatchingFilesInNaturalOrder) {
  ScratchDir dir;
  for (int n : {10, 2, 1})
    WriteText(dir / ("mesh_" + std::to_string(n) + ".obj"), TetrahedronFrame(n));
  WriteText(dir / "other_5.obj", TetrahedronFrame(5));
  const MeshSequence read = ReadOrDie(dir / "mesh_*.obj");
  ASSERT_EQ(read.frame_count(), 3);
  EXPECT_EQ(read.frame(2)(0, 0), 10.0f);
  EXPECT_EQ(ReadOrDie(dir / "mesh_[12].obj").frame_count(), 2);
  EXPECT_EQ(ReadOrDie(dir.path()).frame_count(), 4);  // the directory takes every frame
}

struct InputCase {
  std::string name;
  std::vector<std::pair<std::string, std::string>> files;  // created in the scratch dir
  std::string input;                                       // relative to the scratch dir
  ErrorCode code;
  std::string message;  // substring; "<dir>" stands for the scratch directory
};

class InputErrorTest : public ::testing::TestWithParam<InputCase> {};

TEST_P(InputErrorTest, Fails) {
  ScratchDir dir;
  std::filesystem::create_directories(dir / "empty");
  for (const auto& [name, text] : GetParam().files) WriteText(dir / name, text);
  ReadOptions options;
  options.threads = 2;
  auto read = ReadSequence(dir / GetParam().input, options);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), GetParam().code) << read.status().ToString();
  std::string expected = GetParam().message;
  const size_t at = expected.find("<dir>");
  if (at != std::string::npos) expected.replace(at, 5, dir.path().string());
  EXPECT_THAT(read.status().message(), HasSubstr(expected));
}

INSTANTIATE_TEST_SUITE_P(
    Cases, InputErrorTest,
    ::testing::Values(
        InputCase{"missing",
                  {},
                  "nothing.obj",
                  ErrorCode::kIoError,
                  "cannot open <dir>/nothing.obj: no such file or directory"},
        InputCase{"empty_dir",
                  {},
                  "empty",
                  ErrorCode::kInvalidSequence,
                  "<dir>/empty holds no .obj, .off or .ply frame files"},
        InputCase{"no_match", {}, "f_*.obj", ErrorCode::kIoError, "no file matches <dir>/f_*.obj"},
        InputCase{"mixed",
                  {{"s/a.obj", TetrahedronFrame(0)}, {"s/b.ply", "ply"}},
                  "s",
                  ErrorCode::kInvalidArgument,
                  "<dir>/s mixes mesh formats (a.obj, b.ply)"},
        InputCase{"unknown_ext",
                  {{"x.stl", "solid"}},
                  "x.stl",
                  ErrorCode::kUnsupported,
                  "<dir>/x.stl: unknown input format"},
        InputCase{"vertex_count",
                  {{"s/0.obj", TetrahedronFrame(0)},
                   {"s/1.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 3 2\nf 1 2 3\nf 2 3 1\n"}},
                  "s",
                  ErrorCode::kMismatch,
                  "frame 1 (<dir>/s/1.obj): 3 vertices, expected 4 (as in frame 0)"},
        InputCase{"triangle_count",
                  {{"s/0.obj", TetrahedronFrame(0)},
                   {"s/1.obj", TetrahedronFrame(1, "f 1 3 2\nf 1 2 4\n")}},
                  "s",
                  ErrorCode::kMismatch,
                  "frame 1 (<dir>/s/1.obj): 2 triangles, expected 3 (as in frame 0)"},
        InputCase{"triangles_differ",
                  {{"s/0.obj", TetrahedronFrame(0)},
                   {"s/1.obj", TetrahedronFrame(1)},
                   {"s/2.obj", TetrahedronFrame(2, "f 1 3 2\nf 1 4 2\nf 2 3 4\n")}},
                  "s",
                  ErrorCode::kMismatch,
                  "frame 2 (<dir>/s/2.obj): triangle 1 is (0, 3, 1), frame 0 has (0, 1, 3)"},
        InputCase{"nan_in_later_frame",
                  {{"s/0.obj", TetrahedronFrame(0)},
                   {"s/1.obj",
                    "v 0 0 0\nv 1 0 0\nv 0 inf 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\n"
                    "f 2 3 4\n"}},
                  "s",
                  ErrorCode::kInvalidSequence,
                  "frame 1 (<dir>/s/1.obj), vertex 2: coordinate y is not finite"},
        InputCase{"parse_error_in_later_frame",
                  {{"s/0.obj", TetrahedronFrame(0)}, {"s/1.obj", "v 0 0 0\nv 1 0\n"}},
                  "s",
                  ErrorCode::kParseError,
                  "<dir>/s/1.obj:2: vertex has 2 coordinate(s), expected 3"}),
    [](const auto& info) { return info.param.name; });

TEST(InputResolutionTest, ReportsTheFirstBadFrameWhateverTheThreadTiming) {
  ScratchDir dir;
  for (int f = 0; f < 12; ++f) {
    WriteText(dir / (std::to_string(f) + ".obj"),
              f == 4 || f == 9 ? "v 0 0 0\n" : TetrahedronFrame(f));
  }
  for (int trial = 0; trial < 5; ++trial) {
    ReadOptions options;
    options.threads = 3;
    auto read = ReadSequence(dir.path(), options);
    ASSERT_FALSE(read.ok());
    EXPECT_THAT(read.status().message(), HasSubstr("frame 4 ("));
  }
}

TEST(InputResolutionTest, RejectsNegativeOptions) {
  ReadOptions options;
  options.max_frames = -1;
  EXPECT_EQ(ReadSequence("x.obj", options).status().code(), ErrorCode::kInvalidArgument);
  options.max_frames = 0;
  options.threads = -2;
  EXPECT_EQ(ReadSequence("x.obj", options).status().code(), ErrorCode::kInvalidArgument);
}

TEST(WriteSequenceTest, RejectsImpossibleRequestsWithoutWriting) {
  ScratchDir dir;
  const MeshSequence sequence = AwkwardSequence(2);
  Status status = WriteSequence(sequence, dir / "one.obj");
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("one.obj is a single mesh file but the sequence has 2"));

  WriteOptions stl;
  stl.frame_format = "stl";
  status = WriteSequence(sequence, dir / "frames", stl);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("unknown frame format 'stl'"));

  MeshSequence broken = sequence;
  broken.frame(1)(3, 1) = std::numeric_limits<float>::infinity();
  status = WriteSequence(broken, dir / "frames");
  EXPECT_EQ(status.code(), ErrorCode::kInvalidSequence);
  EXPECT_THAT(status.message(), HasSubstr("frame 1, vertex 3: coordinate y is not finite"));

  WriteText(dir / "a_file", "keep");
  status = WriteSequence(sequence, dir / "a_file");
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("exists and is not a directory"));

  status = WriteSequence(sequence, dir / "no" / "such" / "parent.pc2");
  EXPECT_EQ(status.code(), ErrorCode::kIoError);
  EXPECT_THAT(status.message(),
              HasSubstr("cannot write " + (dir / "no" / "such" / "parent.pc2").string() +
                        ": the directory " + (dir / "no" / "such").string() + " does not exist"));

  EXPECT_THAT(ListNames(dir.path()), ElementsAre("a_file"));
  EXPECT_EQ(testing::ReadText(dir / "a_file"), "keep");
}

TEST(WriteSequenceTest, ReplacesAFrameDirectoryWhollyButNeverAForeignOne) {
  ScratchDir dir;
  ASSERT_TRUE(WriteSequence(AwkwardSequence(3), dir / "out").ok());
  const MeshSequence shorter = AwkwardSequence(2, 9);
  ASSERT_TRUE(WriteSequence(shorter, dir / "out").ok());
  EXPECT_THAT(ListNames(dir / "out"), ElementsAre("frame_0000.obj", "frame_0001.obj"));
  ExpectIdentical(shorter, ReadOrDie(dir / "out"));
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("out"));

  WriteText(dir / "mine" / "thesis.tex", "precious");
  const Status status = WriteSequence(shorter, dir / "mine");
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("refusing to replace " + (dir / "mine").string() +
                                          ": it holds thesis.tex"));
  EXPECT_EQ(testing::ReadText(dir / "mine" / "thesis.tex"), "precious");
}

// Lowers the process's file size limit for its lifetime, so that writes beyond `bytes` fail with
// EFBIG (SIGXFSZ ignored): a real write failure that works even when the tests run as root.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    getrlimit(RLIMIT_FSIZE, &previous_);
    rlimit limited = previous_;
    limited.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limited);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &previous_);
    std::signal(SIGXFSZ, previous_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit previous_{};
  void (*previous_handler_)(int) = nullptr;
};

TEST(AtomicWriteTest, WritesReplacesAndKeepsPermissions) {
  ScratchDir dir;
  const std::string first = "first version";
  const std::string second = "second";
  auto bytes = [](const std::string& text) {
    return std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size());
  };
  ASSERT_TRUE(WriteFileAtomically(dir / "f.bin", bytes(first)).ok());
  EXPECT_EQ(testing::ReadText(dir / "f.bin"), first);
  ASSERT_EQ(::chmod((dir / "f.bin").c_str(), 0640), 0);
  ASSERT_TRUE(WriteFileAtomically(dir / "f.bin", bytes(second)).ok());
  EXPECT_EQ(testing::ReadText(dir / "f.bin"), second);
  struct stat info {};
  ASSERT_EQ(::stat((dir / "f.bin").c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0640u);
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("f.bin"));
}

TEST(AtomicWriteTest, AFailedWriteLeavesTheExistingFileUntouched) {
  ScratchDir dir;
  const std::string original = "the existing output";
  WriteText(dir / "out.dmc", original);
  const std::vector<uint8_t> big(1 << 16, 0xAB);
  Status status;
  {
    FileSizeLimit limit(4096);
    status = WriteFileAtomically(dir / "out.dmc", big);
  }
  EXPECT_EQ(status.code(), ErrorCode::kIoError);
  EXPECT_THAT(status.message(), HasSubstr("cannot write"));
  EXPECT_EQ(testing::ReadText(dir / "out.dmc"), original);
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("out.dmc"));  // temporary removed
}

TEST(AtomicWriteTest, AFailedSequenceWriteLeavesExistingOutputsUntouched) {
  ScratchDir dir;
  const MeshSequence small = AwkwardSequence(2);
  ASSERT_TRUE(WriteSequence(small, dir / "frames").ok());
  ASSERT_TRUE(WriteSequence(small, dir / "anim.pc2").ok());
  const std::string old_frame = testing::ReadText(dir / "frames" / "frame_0001.obj");
  const std::string old_cache = testing::ReadText(dir / "anim.pc2");
  const std::string old_mesh = testing::ReadText(dir / "anim.obj");

  const MeshSequence large = testing::PlanarGrid(40, 3);  // each frame file is ~60 kB
  Status frames_status, cache_status;
  {
    FileSizeLimit limit(8192);
    frames_status = WriteSequence(large, dir / "frames");
    cache_status = WriteSequence(large, dir / "anim.pc2");
  }
  EXPECT_EQ(frames_status.code(), ErrorCode::kIoError) << frames_status.ToString();
  EXPECT_EQ(cache_status.code(), ErrorCode::kIoError) << cache_status.ToString();
  EXPECT_EQ(testing::ReadText(dir / "frames" / "frame_0001.obj"), old_frame);
  EXPECT_EQ(testing::ReadText(dir / "anim.pc2"), old_cache);
  EXPECT_EQ(testing::ReadText(dir / "anim.obj"), old_mesh);
  EXPECT_THAT(ListNames(dir.path()), ElementsAre("anim.obj", "anim.pc2", "frames"));
  EXPECT_THAT(ListNames(dir / "frames"), ElementsAre("frame_0000.obj", "frame_0001.obj"));
}

TEST(AtomicWriteTest, AReadOnlyDirectoryFailsCleanly) {
  if (::geteuid() == 0) GTEST_SKIP() << "root ignores directory permissions";
  ScratchDir dir;
  WriteText(dir / "locked" / "out.bin", "old");
  ASSERT_EQ(::chmod((dir / "locked").c_str(), 0555), 0);
  const std::vector<uint8_t> bytes = {1, 2, 3};
  const Status status = WriteFileAtomically(dir / "locked" / "out.bin", bytes);
  ::chmod((dir / "locked").c_str(), 0755);
  EXPECT_EQ(status.code(), ErrorCode::kIoError);
  EXPECT_EQ(testing::ReadText(dir / "locked" / "out.bin"), "old");
}

}  // namespace
}  // namespace dmc
