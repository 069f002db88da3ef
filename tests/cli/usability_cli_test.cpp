// The command line without surprises: an output path's extension is checked before any work, a
// target given on the command line must be one, -i works like the positional input, and a
// mistyped command or option gets a suggestion.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_runner.h"
#include "dmc/status.h"

namespace dmc {
namespace {

using testing::FreshTempDir;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::Quoted;
using testing::RunDmc;

const int kInvalidArgumentExit = ExitCodeFor(ErrorCode::kInvalidArgument);

// A small synthetic cloth as a .pc2 cache (with its .obj) in `dir`.
std::filesystem::path MakeCloth(const std::filesystem::path& dir) {
  const auto cache = dir / "cloth.pc2";
  const auto made = RunDmc("synth cloth -o " + Quoted(cache) + " --frames 4 --resolution 200");
  EXPECT_EQ(made.exit_code, 0) << made.err;
  return cache;
}

std::filesystem::path MakeStream(const std::filesystem::path& dir) {
  const auto stream = dir / "cloth.dmc";
  const auto encoded = RunDmc("encode " + Quoted(MakeCloth(dir)) + " -o " + Quoted(stream));
  EXPECT_EQ(encoded.exit_code, 0) << encoded.err;
  return stream;
}

TEST(UsabilityCliTest, DecodeRefusesAnUnknownOutputExtensionBeforeDecoding) {
  const auto dir = FreshTempDir("usability");
  const auto stream = MakeStream(dir);
  for (const std::string name : {"out.fbx", "out.usdz"}) {
    const auto result = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / name));
    EXPECT_EQ(result.exit_code, kInvalidArgumentExit) << result.err;
    EXPECT_THAT(result.err, HasSubstr("unknown output extension '" + name.substr(3) + "'"));
    EXPECT_THAT(result.err, HasSubstr(".pc2, .glb, .obj, .off or .ply"));
    EXPECT_FALSE(std::filesystem::exists(dir / name)) << name;
  }
}

TEST(UsabilityCliTest, DirectoriesAreNamedWithoutExtensionOrWithATrailingSlash) {
  const auto dir = FreshTempDir("usability");
  const auto stream = MakeStream(dir);
  const auto plain = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "frames"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_TRUE(std::filesystem::is_directory(dir / "frames"));
  const auto slash = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "take.v2") + "/");
  ASSERT_EQ(slash.exit_code, 0) << slash.err;
  EXPECT_TRUE(std::filesystem::is_directory(dir / "take.v2"));
  // An existing directory may be rewritten whatever its name.
  const auto again = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "take.v2"));
  EXPECT_EQ(again.exit_code, 0) << again.err;
}

TEST(UsabilityCliTest, ConvertAndSynthCheckTheOutputPathFirst) {
  const auto dir = FreshTempDir("usability");
  const auto cache = MakeCloth(dir);
  const auto convert = RunDmc("convert " + Quoted(cache) + " -o " + Quoted(dir / "x.fbx"));
  EXPECT_EQ(convert.exit_code, kInvalidArgumentExit) << convert.err;
  EXPECT_THAT(convert.err, HasSubstr("unknown output extension '.fbx'"));
  const auto synth = RunDmc("synth cloth -o " + Quoted(dir / "y.usdz") + " --frames 2");
  EXPECT_EQ(synth.exit_code, kInvalidArgumentExit) << synth.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.fbx"));
  EXPECT_FALSE(std::filesystem::exists(dir / "y.usdz"));
}

TEST(UsabilityCliTest, AGivenTargetMustBePositive) {
  const auto dir = FreshTempDir("usability");
  const auto cache = MakeCloth(dir);
  const auto out = Quoted(dir / "x.dmc");
  for (const std::string flag : {"--target-bpfv", "--target-sted"}) {
    for (const std::string value : {"0", "-1"}) {
      const auto result =
          RunDmc("encode " + Quoted(cache) + " -o " + out + " " + flag + " " + value);
      EXPECT_EQ(result.exit_code, kInvalidArgumentExit) << flag << " " << value;
      EXPECT_THAT(result.err, HasSubstr(flag + " must be > 0 (got " + value + ")"));
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "x.dmc"));
}

TEST(UsabilityCliTest, DashIGivesTheInputLikeThePositional) {
  const auto dir = FreshTempDir("usability");
  const auto cache = MakeCloth(dir);
  const auto positional = RunDmc("encode " + Quoted(cache) + " -o " + Quoted(dir / "a.dmc"));
  const auto flagged = RunDmc("encode -i " + Quoted(cache) + " -o " + Quoted(dir / "b.dmc"));
  ASSERT_EQ(positional.exit_code, 0) << positional.err;
  ASSERT_EQ(flagged.exit_code, 0) << flagged.err;
  EXPECT_EQ(testing::ReadText(dir / "a.dmc"), testing::ReadText(dir / "b.dmc"));
  const auto info = RunDmc("info --input " + Quoted(dir / "b.dmc"));
  EXPECT_EQ(info.exit_code, 0) << info.err;
  const auto decoded =
      RunDmc("decode -i " + Quoted(dir / "b.dmc") + " -o " + Quoted(dir / "b.pc2"));
  EXPECT_EQ(decoded.exit_code, 0) << decoded.err;
}

// What `dmc encode` reports per segment is what the stream's headers say (`dmc info`): with the
// fallback some segments are coded with another operator, and a kirchhoff segment's step is
// scaled by the mean degree.
TEST(UsabilityCliTest, EncodeReportsEachSegmentAsCoded) {
  const auto dir = FreshTempDir("usability");
  const auto input = dir / "blob.pc2";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(input) + " --frames 12 --resolution 1500").exit_code,
            0);
  const auto stream = dir / "blob.dmc";
  const std::string encode =
      "encode " + Quoted(input) + " -o " + Quoted(stream) + " --segment-frames 2 --ddl-fallback";
  const auto encoded = RunDmc(encode + " --json");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  const auto info = RunDmc("info " + Quoted(stream) + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto reported = nlohmann::json::parse(encoded.out)["segment_details"];
  const auto headers = nlohmann::json::parse(info.out)["segments"];
  ASSERT_EQ(reported.size(), headers.size());
  ASSERT_EQ(reported.size(), 6u);
  bool some_other_operator = false;
  for (size_t s = 0; s < reported.size(); ++s) {
    for (const char* key : {"first_frame", "frames", "operator", "rank", "anchors"}) {
      EXPECT_EQ(reported[s][key], headers[s][key]) << "segment " << s << " " << key;
    }
    EXPECT_DOUBLE_EQ(reported[s]["residual_step"].get<double>(),
                     headers[s]["residual_step"].get<double>())
        << "segment " << s;
    some_other_operator |= reported[s]["operator"] != "ddl";
  }
  ASSERT_TRUE(some_other_operator) << "the fallback coded every segment with ddl: " << reported;
  // The text lists the segments then, each with its own operator and step.
  const auto text = RunDmc(encode);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  for (size_t s = 0; s < reported.size(); ++s) {
    EXPECT_THAT(text.out, HasSubstr("segment " + std::to_string(s) + ", frames ")) << text.out;
  }
  EXPECT_THAT(text.out, HasSubstr(": " + reported[0]["operator"].get<std::string>() + ", rank"));
}

TEST(UsabilityCliTest, TyposGetSuggestions) {
  const auto command = RunDmc("encdoe x.pc2 -o y.dmc");
  EXPECT_EQ(command.exit_code, 1);
  EXPECT_THAT(command.err, HasSubstr("'encdoe' is not a dmc command; did you mean 'encode'?"));
  const auto option = RunDmc("encode x.pc2 -o y.dmc --rnak 3");
  EXPECT_EQ(option.exit_code, 1);
  EXPECT_THAT(option.err, HasSubstr("dmc encode has no option --rnak; did you mean --rank?"));
  const auto with_value = RunDmc("decode x.dmc -o y.glb --glb-layuot=basis");
  EXPECT_THAT(with_value.err, HasSubstr("did you mean --glb-layout?"));
  // Nothing near: no suggestion.
  const auto far = RunDmc("encode x.pc2 -o y.dmc --completely-unknown 3");
  EXPECT_EQ(far.exit_code, 1);
  EXPECT_THAT(far.err, Not(HasSubstr("did you mean")));
}

}  // namespace
}  // namespace dmc
