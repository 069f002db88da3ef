// Reading and writing time-varying meshes and centres files.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "dmc/tvm.h"
#include "unit/tvm/tvm_fixtures.h"

namespace dmc::tvm {
namespace {

using ::testing::HasSubstr;

std::filesystem::path FreshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("dmc_tvm_io_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(CentresFileTest, RoundTripIsBitExact) {
  CentreTrajectories centres;
  for (int f = 0; f < 3; ++f) {
    FramePositionsD frame(4, 3);
    for (int i = 0; i < 4; ++i) frame.row(i) << 0.1 * i + f, 1.0 / 3.0 * f - i, -1e-300 * i;
    centres.positions.push_back(frame);
  }
  const auto path = FreshDir("centres") / "centres.txt";
  ASSERT_TRUE(WriteCentres(centres, path).ok());
  const auto read = ReadCentres(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->frame_count(), 3);
  ASSERT_EQ(read->centre_count(), 4);
  for (int f = 0; f < 3; ++f) EXPECT_EQ(read->positions[f], centres.positions[f]) << f;
}

TEST(CentresFileTest, LayoutIsOneTrajectoryPerLineCentreMajor) {
  const auto parsed = ParseCentres(
      "dmc-centres 1  # magic and version\n2 2\n"
      "0 0 0  1 1 1\n"
      "5 5 5  6 6 6\n");
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  EXPECT_EQ(parsed->position(0, 1), Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(parsed->position(1, 0), Eigen::Vector3d(5, 5, 5));
}

TEST(CentresFileTest, MalformedFilesAreParseErrorsNamingTheLine) {
  const auto wrong_magic = ParseCentres("centres 1\n1 1\n0 0 0\n");
  EXPECT_EQ(wrong_magic.status().code(), ErrorCode::kParseError);
  const auto short_file = ParseCentres("dmc-centres 1\n2 1\n0 0 0\n1 1\n");
  EXPECT_EQ(short_file.status().code(), ErrorCode::kParseError);
  EXPECT_THAT(short_file.status().message(), HasSubstr("5 coordinates for 2 centres x 1 frames"));
  const auto bad_token = ParseCentres("dmc-centres 1\n1 1\n0 x 0\n");
  EXPECT_EQ(bad_token.status().code(), ErrorCode::kParseError);
  EXPECT_THAT(bad_token.status().message(), HasSubstr("line 3"));
  const auto not_finite = ParseCentres("dmc-centres 1\n1 1\n0 inf 0\n");
  EXPECT_EQ(not_finite.status().code(), ErrorCode::kParseError);
  const auto no_centres = ParseCentres("dmc-centres 1\n0 3\n");
  EXPECT_EQ(no_centres.status().code(), ErrorCode::kParseError);
}

TEST(TvmFilesTest, FramesWithTheirOwnConnectivityRoundTrip) {
  TimeVaryingMesh mesh;
  mesh.frame_rate = 25.0;
  mesh.frames.push_back(testing::UvSphere({0, 0, 0}, 1.0, 6, 8));
  mesh.frames.push_back(testing::UvSphere({1, 0, 0}, 0.5, 9, 11));
  const auto dir = FreshDir("roundtrip") / "seq";
  ASSERT_TRUE(WriteTimeVaryingMesh(mesh, dir, "ply").ok());
  EXPECT_TRUE(std::filesystem::exists(dir / "frame_0001.ply"));
  const auto read = ReadTimeVaryingMesh(dir);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->frame_count(), 2);
  EXPECT_EQ(read->name, "seq");
  EXPECT_EQ(read->frame_rate, 25.0);
  for (int f = 0; f < 2; ++f) {
    EXPECT_EQ(read->frames[f].triangles, mesh.frames[f].triangles);
    // Frames are stored as float32.
    EXPECT_EQ(read->frames[f].positions, mesh.frames[f].positions.cast<float>().cast<double>());
  }
}

TEST(TvmFilesTest, RewritingReplacesStaleFramesButNeverForeignFiles) {
  TimeVaryingMesh mesh;
  for (int f = 0; f < 3; ++f) mesh.frames.push_back(testing::UvSphere({0, 0, 0}, 1.0, 4, 5 + f));
  const auto dir = FreshDir("rewrite") / "seq";
  ASSERT_TRUE(WriteTimeVaryingMesh(mesh, dir).ok());
  mesh.frames.pop_back();
  ASSERT_TRUE(WriteTimeVaryingMesh(mesh, dir).ok());
  EXPECT_FALSE(std::filesystem::exists(dir / "frame_0002.obj"));
  std::ofstream(dir / "notes.md") << "mine";
  const Status refused = WriteTimeVaryingMesh(mesh, dir);
  EXPECT_EQ(refused.code(), ErrorCode::kIoError);
  EXPECT_THAT(refused.message(), HasSubstr("notes.md"));
  EXPECT_TRUE(std::filesystem::exists(dir / "notes.md"));
}

TEST(TvmFilesTest, BadInputsNameTheFault) {
  const auto empty = FreshDir("empty");
  EXPECT_EQ(ReadTimeVaryingMesh(empty).status().code(), ErrorCode::kInvalidSequence);
  const auto bad = FreshDir("bad");
  std::ofstream(bad / "a.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(bad / "b.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";
  const auto read = ReadTimeVaryingMesh(bad);
  EXPECT_FALSE(read.ok());
  EXPECT_THAT(read.status().message(), HasSubstr("b.obj"));

  TimeVaryingMesh mesh;
  mesh.frames.push_back(testing::UvSphere({0, 0, 0}, 1.0, 4, 5));
  mesh.frames[0].triangles(2, 1) = 999;
  const Status invalid = ValidateTimeVaryingMesh(mesh);
  EXPECT_EQ(invalid.code(), ErrorCode::kInvalidSequence);
  EXPECT_THAT(invalid.message(), HasSubstr("frame 0, triangle 2: index 999"));
}

}  // namespace
}  // namespace dmc::tvm
