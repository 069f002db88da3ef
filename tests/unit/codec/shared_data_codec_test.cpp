// Every sequence and animation of ../shared/data (its README: the OBJ sequences, the point
// caches, the Sumner pose archives, every clip of every GLB) encoded with default options and
// decoded (skipped for what is absent): the default encode must not fail on a valid mesh, and
// its KG and STED must be those of a working codec. BrainStem's default encode used to fail
// (issue 21). Labelled slow (about a minute in Release) and skipped under sanitizers, where it
// would take many times that.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/io.h"
#include "test_support.h"
#include "unit/io/io_test_util.h"

namespace dmc {
namespace {

// Bounds a working encode stays far within: on the data here KG is at most 5.3 % (the pose
// archives, whose poses are far apart), STED at most 0.15, the rate at most 5.5 bpfv (the short
// Fox clips).
constexpr double kMaxKg = 10.0;
constexpr double kMaxSted = 0.3;
constexpr double kMaxBpfv = 8.0;

#if DMC_SANITIZER_OWNS_ALLOCATOR
#define DMC_SKIP_UNDER_SANITIZERS() GTEST_SKIP() << "minutes under a sanitizer: Release only"
#else
#define DMC_SKIP_UNDER_SANITIZERS() static_cast<void>(0)
#endif

// Encodes `sequence` with default options, checks the report, then decodes the stream segment by
// segment as a player would and checks the frames.
void ExpectEncodesAndDecodes(const MeshSequence& sequence, const std::string& what) {
  SCOPED_TRACE(what);
  EncodeReport report;
  const StatusOr<std::vector<uint8_t>> stream = Encode(sequence, EncoderOptions(), &report);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();
  ASSERT_TRUE(report.measured) << report.not_measured_reason;
  EXPECT_LT(report.distortion.kg, kMaxKg);
  EXPECT_LT(report.distortion.sted, kMaxSted);
  EXPECT_LT(report.bpfv, kMaxBpfv);
  Decoder decoder;
  ASSERT_TRUE(decoder.Open(*stream).ok());
  ASSERT_EQ(decoder.info().vertex_count, static_cast<uint32_t>(sequence.vertex_count()));
  int frames = 0;
  for (int s = 0; s < decoder.segment_count(); ++s) {
    const StatusOr<MeshSequence> segment = decoder.DecodeSegment(s);
    ASSERT_TRUE(segment.ok()) << "segment " << s << ": " << segment.status().ToString();
    for (int f = 0; f < segment->frame_count(); ++f) {
      ASSERT_TRUE(segment->frame(f).allFinite()) << "segment " << s << " frame " << f;
    }
    frames += segment->frame_count();
  }
  EXPECT_EQ(frames, sequence.frame_count());
  std::printf("%s: %d frames x %d vertices, KG %.3f, STED %.4f, %.3f bpfv, %.1f s\n", what.c_str(),
              sequence.frame_count(), sequence.vertex_count(), report.distortion.kg,
              report.distortion.sted, report.bpfv, report.seconds);
}

// Reads and round-trips each input present; skips when none is.
void RoundTripEach(const std::vector<std::string>& inputs) {
  int present = 0;
  for (const std::string& input : inputs) {
    const std::filesystem::path path = testing::SharedData(input);
    if (path.empty()) continue;
    ++present;
    const StatusOr<MeshSequence> sequence = ReadSequence(path);
    ASSERT_TRUE(sequence.ok()) << input << ": " << sequence.status().ToString();
    ExpectEncodesAndDecodes(*sequence, input);
  }
  if (present == 0) GTEST_SKIP() << "../shared/data is absent";
}

TEST(SharedDataCodec, ObjSequences) {
  DMC_SKIP_UNDER_SANITIZERS();
  RoundTripEach({"horse-gallop", "samba", "crane", "chicken-crossing", "cow", "dance", "jump",
                 "elephant-gallop", "horse-collapse"});
}

TEST(SharedDataCodec, PointCaches) {
  DMC_SKIP_UNDER_SANITIZERS();
  RoundTripEach({"crane-full/crane-full.pc2", "jump-full/jump-full.pc2",
                 "elephant-gallop-full/elephant-gallop-full.pc2"});
}

// Every clip, by index until the reader reports there is no such animation.
TEST(SharedDataCodec, GltfAnimations) {
  DMC_SKIP_UNDER_SANITIZERS();
  int present = 0;
  for (const std::string input :
       {"brainstem/BrainStem.glb", "cesium-man/CesiumMan.glb", "fox/Fox.glb",
        "robot-expressive/RobotExpressive.glb", "threejs-horse-morph/Horse.glb"}) {
    const std::filesystem::path path = testing::SharedData(input);
    if (path.empty()) continue;
    ++present;
    for (int clip = 0;; ++clip) {
      ReadOptions options;
      options.gltf.animation = std::to_string(clip);
      const StatusOr<MeshSequence> sequence = ReadSequence(path, options);
      if (clip > 0 && sequence.status().code() == ErrorCode::kInvalidArgument &&
          sequence.status().message().find("no animation named") != std::string::npos) {
        break;
      }
      ASSERT_TRUE(sequence.ok()) << input << " clip " << clip << ": "
                                 << sequence.status().ToString();
      ExpectEncodesAndDecodes(*sequence, input + " clip " + std::to_string(clip));
    }
  }
  if (present == 0) GTEST_SKIP() << "../shared/data is absent";
}

// Without the fallback's measurement (effort 0) the ddl coding is decode-checked: BrainStem's
// first 210 frames (its first segment) fit weights that, at 2^-7, leave the normal matrix
// singular, and the segment is coded with kirchhoff instead of failing. (At the automatic 2^-8
// of a 210-frame segment the weights decode, so the step is set here.)
TEST(SharedDataCodec, BrainStemWithoutTheFallbackMeasurement) {
  DMC_SKIP_UNDER_SANITIZERS();
  DMC_REQUIRE_SHARED_DATA(path, "brainstem/BrainStem.glb");
  ReadOptions read;
  read.max_frames = 210;
  const StatusOr<MeshSequence> sequence = ReadSequence(path, read);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  EncoderOptions options;
  options.effort = 0;
  options.weight_bits = 7;
  EncodeReport report;
  const StatusOr<std::vector<uint8_t>> stream = Encode(*sequence, options, &report);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();
  ASSERT_TRUE(report.measured);
  EXPECT_EQ(report.segment_operators, std::vector<std::string>{"kirchhoff"});
  EXPECT_LT(report.distortion.kg, kMaxKg);
  EXPECT_TRUE(Decode(*stream).ok());
}

TEST(SharedDataCodec, PoseArchives) {
  DMC_SKIP_UNDER_SANITIZERS();
  int present = 0;
  for (const std::string name : {"cat", "lion"}) {
    const std::filesystem::path archive =
        testing::SharedData(name + "-poses/" + name + "-poses.tgz");
    if (archive.empty()) continue;
    ++present;
    testing::ScratchDir dir;
    const std::string command =
        "tar xzf '" + archive.string() + "' -C '" + dir.path().string() + "'";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    std::filesystem::path poses;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir.path())) {
      if (entry.path().filename() == name + "-reference.obj") poses = entry.path().parent_path();
    }
    ASSERT_FALSE(poses.empty()) << "no " << name << "-reference.obj in " << archive;
    // The reference pose and the nine others (README: ten poses, one connectivity).
    const StatusOr<MeshSequence> sequence = ReadSequence(poses / (name + "-*.obj"));
    ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
    ASSERT_EQ(sequence->frame_count(), 10);
    ExpectEncodesAndDecodes(*sequence, name + " poses");
  }
  if (present == 0) GTEST_SKIP() << "../shared/data is absent";
}

}  // namespace
}  // namespace dmc
