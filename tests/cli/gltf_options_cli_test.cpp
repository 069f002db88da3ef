// The glTF read options (--gltf-fps, --gltf-mesh, --gltf-animation, --gltf-weld) on every command
// that reads a sequence (issue 12): each command offers the same four options, and they reach
// ReadSequence (frame counts follow the clip length, mesh and animation selection, welding), also
// through encode, convert, metrics (both inputs), edit, laplacian, sweep and view. Given for a
// non-glTF input they draw a warning naming them. The samples are the small ones of ../shared/data
// (CesiumMan, 3273 vertices; Fox, 1728; RobotExpressive, 7214), read at low frame rates to stay
// fast.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "dmc/status.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::CliResult;
using testing::FreshTempDir;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::Quoted;
using testing::RunDmc;

int ExitCode(ErrorCode code) { return 10 + static_cast<int>(code); }

nlohmann::json Json(const CliResult& result) { return nlohmann::json::parse(result.out); }

// The frames ReadSequence samples from a clip whose keys span `seconds`: one at the first key and
// one every 1/fps after it up to the last key.
int PredictedFrames(double seconds, double fps) {
  return static_cast<int>(std::floor(seconds * fps + 1e-9)) + 1;
}

// CesiumMan's keys run from 1/24 s to 2 s (the file's animation sampler inputs).
constexpr double kCesiumSeconds = 2.0 - 1.0 / 24.0;
// Fox's clips: Survey 0..3.4167 s, Walk 0..0.70833 s, Run 0..1.1583 s (sampler inputs).
constexpr double kFoxWalkSeconds = 0.7083333134651184;
constexpr double kFoxRunSeconds = 1.1583333015441895;

TEST(GltfOptionsCliTest, EveryCommandThatReadsASequenceOffersTheFourOptions) {
  for (const std::string command : {"info", "convert", "encode", "metrics", "edit smooth-explicit",
                                    "edit laplacian-edit", "laplacian", "sweep", "view"}) {
    const CliResult help = RunDmc(command + " --help");
    ASSERT_EQ(help.exit_code, 0) << command << ": " << help.err;
    for (const char* option : {"--gltf-fps", "--gltf-mesh", "--gltf-animation", "--gltf-weld"}) {
      EXPECT_THAT(help.out, HasSubstr(option)) << command;
    }
  }
  // One definition: the same check everywhere (a frame rate must be positive).
  for (const std::string command : {"info x.glb", "encode x.glb -o x.dmc", "metrics x.glb y.glb"}) {
    const CliResult zero = RunDmc(command + " --gltf-fps 0");
    EXPECT_EQ(zero.exit_code, 1) << command;  // a usage error
    EXPECT_THAT(zero.err,
                HasSubstr("--gltf-fps: must be a positive number of frames per second, got '0'"))
        << command;
  }
}

TEST(GltfOptionsCliTest, FrameRateSetsTheFrameCountOfInfoAndEncode) {
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  const auto dir = FreshTempDir("gltf_options");
  for (const double fps : {3.0, 6.0}) {
    const std::string rate = " --gltf-fps " + std::to_string(static_cast<int>(fps));
    const CliResult info = RunDmc("info " + Quoted(cesium) + rate + " --json");
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_EQ(Json(info)["frames"], PredictedFrames(kCesiumSeconds, fps)) << fps;
    EXPECT_EQ(Json(info)["frame_rate"], fps);
    EXPECT_EQ(Json(info)["vertices"], 3273);
  }
  // 3 fps: 6 frames, 6 fps: 12 (47/24 s = 1.96 s of keys).
  EXPECT_EQ(PredictedFrames(kCesiumSeconds, 3.0), 6);
  EXPECT_EQ(PredictedFrames(kCesiumSeconds, 6.0), 12);

  const CliResult encoded = RunDmc("encode " + Quoted(cesium) + " -o " + Quoted(dir / "c.dmc") +
                                   " --gltf-fps 4 --no-measure --json");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  EXPECT_EQ(Json(encoded)["frames"], PredictedFrames(kCesiumSeconds, 4.0));
  EXPECT_EQ(Json(encoded)["frames"], 8);
  EXPECT_EQ(Json(encoded)["vertices"], 3273);
  // The stream records the rate it was sampled at.
  const CliResult stream = RunDmc("info " + Quoted(dir / "c.dmc") + " --json");
  ASSERT_EQ(stream.exit_code, 0) << stream.err;
  EXPECT_EQ(Json(stream)["frames"], 8);
  EXPECT_EQ(Json(stream)["frame_rate"], 4.0);
}

TEST(GltfOptionsCliTest, AnimationIsChosenByNameOrIndex) {
  DMC_REQUIRE_SHARED_DATA(fox, "fox/Fox.glb");
  const CliResult walk =
      RunDmc("info " + Quoted(fox) + " --gltf-animation Walk --gltf-fps 10 --json");
  ASSERT_EQ(walk.exit_code, 0) << walk.err;
  EXPECT_EQ(Json(walk)["frames"], PredictedFrames(kFoxWalkSeconds, 10.0));  // 8
  // Index 2 is Run (Survey, Walk, Run in the file).
  const CliResult run = RunDmc("info " + Quoted(fox) + " --gltf-animation 2 --gltf-fps 10 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(Json(run)["frames"], PredictedFrames(kFoxRunSeconds, 10.0));  // 12
  const CliResult missing = RunDmc("info " + Quoted(fox) + " --gltf-animation Moonwalk");
  EXPECT_EQ(missing.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  EXPECT_THAT(missing.err, HasSubstr("'Moonwalk'"));
  EXPECT_THAT(missing.err, HasSubstr("Survey"));  // the clips there are
}

TEST(GltfOptionsCliTest, MeshNameSelectsOneMesh) {
  DMC_REQUIRE_SHARED_DATA(robot, "robot-expressive/RobotExpressive.glb");
  const std::string clip = " --gltf-animation Wave --gltf-fps 10 --max-frames 2 --json";
  const CliResult whole = RunDmc("info " + Quoted(robot) + clip);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  EXPECT_EQ(Json(whole)["vertices"], 7214);  // all 19 primitives (data/README.md)
  EXPECT_EQ(Json(whole)["triangles"], 3237);
  // Mesh "Head": three primitives of 302, 876 and 564 vertices (its POSITION accessors).
  const CliResult head = RunDmc("info " + Quoted(robot) + " --gltf-mesh Head" + clip);
  ASSERT_EQ(head.exit_code, 0) << head.err;
  EXPECT_EQ(Json(head)["vertices"], 302 + 876 + 564);
  EXPECT_EQ(Json(head)["frames"], 2);
}

TEST(GltfOptionsCliTest, UnknownMeshNameIsAnErrorNamingIt) {
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  const auto dir = FreshTempDir("gltf_options");
  for (const std::string& command :
       {"info " + Quoted(cesium), "encode " + Quoted(cesium) + " -o " + Quoted(dir / "x.dmc"),
        "convert " + Quoted(cesium) + " -o " + Quoted(dir / "x.glb")}) {
    const CliResult result = RunDmc(command + " --gltf-mesh Nobody");
    EXPECT_EQ(result.exit_code, ExitCode(ErrorCode::kInvalidArgument)) << command;
    EXPECT_THAT(result.err, HasSubstr("no mesh or node named 'Nobody'")) << command;
    EXPECT_THAT(result.err, HasSubstr("Cesium_Man")) << command;  // the meshes there are
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "x.dmc"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x.glb"));
  // The one mesh by its own name is the whole file.
  const CliResult named =
      RunDmc("info " + Quoted(cesium) + " --gltf-mesh Cesium_Man --gltf-fps 1 --json");
  ASSERT_EQ(named.exit_code, 0) << named.err;
  EXPECT_EQ(Json(named)["vertices"], 3273);
}

TEST(GltfOptionsCliTest, WeldReducesTheVertexCountThroughEveryCommand) {
  DMC_REQUIRE_SHARED_DATA(fox, "fox/Fox.glb");
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  const auto dir = FreshTempDir("gltf_options");
  const std::string clip = " --gltf-animation Walk --gltf-fps 2";  // 2 frames
  const CliResult soup = RunDmc("info " + Quoted(fox) + clip + " --json");
  ASSERT_EQ(soup.exit_code, 0) << soup.err;
  EXPECT_EQ(Json(soup)["vertices"], 1728);  // 576 triangles, 3 own vertices each
  const CliResult welded = RunDmc("info " + Quoted(fox) + clip + " --gltf-weld --json");
  ASSERT_EQ(welded.exit_code, 0) << welded.err;
  const int fox_welded = Json(welded)["vertices"];
  // Shared corners merge: far fewer vertices, the triangles stay (the fox has no seam that
  // collapses a triangle), and the soup's 576 components become one surface.
  EXPECT_LT(fox_welded, 1728 / 2);
  EXPECT_EQ(Json(welded)["triangles"], 576);
  EXPECT_LT(Json(welded)["components"].get<int>(), Json(soup)["components"].get<int>());

  const CliResult cesium_welded =
      RunDmc("info " + Quoted(cesium) + " --gltf-fps 1 --gltf-weld --json");
  ASSERT_EQ(cesium_welded.exit_code, 0) << cesium_welded.err;
  EXPECT_LT(Json(cesium_welded)["vertices"].get<int>(), 3273);  // UV/normal seams

  // convert writes the welded clip; reading it back needs no options (frame rate recorded).
  const auto out = dir / "fox.glb";
  const CliResult converted =
      RunDmc("convert " + Quoted(fox) + " -o " + Quoted(out) + clip + " --gltf-weld --json");
  ASSERT_EQ(converted.exit_code, 0) << converted.err;
  EXPECT_EQ(Json(converted)["vertices"], fox_welded);
  const CliResult back = RunDmc("info " + Quoted(out) + " --json");
  ASSERT_EQ(back.exit_code, 0) << back.err;
  EXPECT_EQ(Json(back)["vertices"], fox_welded);
  EXPECT_EQ(Json(back)["frames"], 2);
  EXPECT_EQ(Json(back)["frame_rate"], 2.0);

  // metrics applies the options to both inputs (else their vertex counts would differ): the
  // welded fox against itself.
  const CliResult metrics =
      RunDmc("metrics " + Quoted(fox) + " " + Quoted(fox) + clip + " --gltf-weld --json");
  ASSERT_EQ(metrics.exit_code, 0) << metrics.err;
  EXPECT_EQ(Json(metrics)["vertices"], fox_welded);
  EXPECT_EQ(Json(metrics)["frames"], 2);
  EXPECT_EQ(Json(metrics)["kg"], 0.0);

  // edit and laplacian see the welded mesh too (one frame at 1 fps).
  const std::string frame = " --gltf-animation Walk --gltf-fps 1 --gltf-weld";
  const CliResult edited = RunDmc("edit smooth-explicit " + Quoted(fox) + frame + " -o " +
                                  Quoted(dir / "smooth.obj") + " --operator tutte --json");
  ASSERT_EQ(edited.exit_code, 0) << edited.err;
  EXPECT_EQ(Json(edited)["vertices"], fox_welded);
  EXPECT_EQ(Json(edited)["input_frames"], 1);
  const CliResult laplacian =
      RunDmc("laplacian " + Quoted(fox) + frame + " --operator tutte --anchors 4 --json");
  ASSERT_EQ(laplacian.exit_code, 0) << laplacian.err;
  EXPECT_EQ(Json(laplacian)["dimension"], fox_welded);
}

TEST(GltfOptionsCliTest, SweepAndViewReadTheirGltfInputWithTheOptions) {
  DMC_REQUIRE_SHARED_DATA(fox, "fox/Fox.glb");
  const auto dir = FreshTempDir("gltf_options");
  const std::string clip = " --gltf-animation Walk --gltf-fps 4 --gltf-weld";  // 3 frames
  const CliResult sweep = RunDmc("sweep " + Quoted(fox) + " -o " + Quoted(dir / "sweep") + clip +
                                 " --operators tutte --baselines none --points 2 --json");
  ASSERT_EQ(sweep.exit_code, 0) << sweep.err;
  EXPECT_EQ(Json(sweep)["frames"], PredictedFrames(kFoxWalkSeconds, 4.0));
  const int welded = Json(sweep)["vertices"];
  EXPECT_LT(welded, 1728 / 2);
  // summary.md's command line reruns the same sweep, so it carries the options.
  std::ifstream summary(dir / "sweep" / "summary.md");
  const std::string text((std::istreambuf_iterator<char>(summary)), {});
  EXPECT_THAT(text, HasSubstr("--gltf-fps 4 --gltf-animation Walk --gltf-weld"));

  // dmc view compares its --original with the decoded stream: only the welded read matches.
  const auto stream = dir / "fox.dmc";
  const CliResult encoded = RunDmc("encode " + Quoted(fox) + " -o " + Quoted(stream) + clip);
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  std::filesystem::create_directories(dir / "viewer");  // a stand-in viewer build
  std::ofstream(dir / "viewer" / "index.html") << "<!doctype html>";
  std::ofstream(dir / "viewer" / "viewer.js") << "";
  const std::string view = "view " + Quoted(stream) + " --original " + Quoted(fox) +
                           " --viewer-dir " + Quoted(dir / "viewer") +
                           " --port 0 --exit-after 0.2 --json --gltf-animation Walk --gltf-fps 4";
  const CliResult unwelded = RunDmc(view);
  EXPECT_EQ(unwelded.exit_code, ExitCode(ErrorCode::kMismatch));
  EXPECT_THAT(unwelded.err, HasSubstr("1728 vs " + std::to_string(welded)));
  const CliResult served = RunDmc(view + " --gltf-weld");
  ASSERT_EQ(served.exit_code, 0) << served.err;
  EXPECT_THAT(Json(served)["url"].get<std::string>(), HasSubstr("http://127.0.0.1:"));
  EXPECT_EQ(Json(served)["frames"], 3);
}

TEST(GltfOptionsCliTest, OptionsGivenForANonGltfInputDrawAWarningNamingThem) {
  const auto dir = FreshTempDir("gltf_options");
  const auto mesh = dir / "tetra.obj";
  std::ofstream(mesh) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                         "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  const CliResult plain = RunDmc("info " + Quoted(mesh));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_THAT(plain.err, Not(HasSubstr("gltf")));
  const CliResult info = RunDmc("info " + Quoted(mesh) + " --gltf-fps 12 --gltf-weld --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;  // harmless: read as without them
  EXPECT_EQ(Json(info)["vertices"], 4);
  EXPECT_THAT(info.err,
              HasSubstr("dmc info: warning: --gltf-fps, --gltf-weld ignored: no .glb/.gltf input"));
  EXPECT_THAT(info.err, HasSubstr("tetra.obj"));
  // metrics warns only when neither input is glTF.
  const CliResult metrics =
      RunDmc("metrics " + Quoted(mesh) + " " + Quoted(mesh) + " --gltf-mesh Head --json");
  ASSERT_EQ(metrics.exit_code, 0) << metrics.err;
  EXPECT_THAT(metrics.err, HasSubstr("dmc metrics: warning: --gltf-mesh ignored"));
  const CliResult convert =
      RunDmc("convert " + Quoted(mesh) + " -o " + Quoted(dir / "t.ply") + " --gltf-animation 1");
  ASSERT_EQ(convert.exit_code, 0) << convert.err;
  EXPECT_THAT(convert.err, HasSubstr("dmc convert: warning: --gltf-animation ignored"));
  // dmc view: the options concern --original; without one they are ignored too.
  std::filesystem::create_directories(dir / "viewer");
  std::ofstream(dir / "viewer" / "index.html") << "<!doctype html>";
  std::ofstream(dir / "viewer" / "viewer.js") << "";
  const CliResult view = RunDmc("view " + Quoted(dir / "missing.dmc") + " --viewer-dir " +
                                Quoted(dir / "viewer") + " --gltf-weld");
  EXPECT_EQ(view.exit_code, ExitCode(ErrorCode::kIoError));  // the stream is missing
  EXPECT_THAT(view.err, HasSubstr("dmc view: warning: --gltf-weld ignored: no .glb/.gltf input\n"));
}

TEST(GltfOptionsCliTest, MixedMetricsInputsTakeTheOptionsWithoutAWarning) {
  DMC_REQUIRE_SHARED_DATA(fox, "fox/Fox.glb");
  const auto dir = FreshTempDir("gltf_options");
  // The welded Walk clip as OBJ frames, measured against the GLB it came from.
  const std::string clip = " --gltf-animation Walk --gltf-fps 2 --gltf-weld";
  const CliResult converted =
      RunDmc("convert " + Quoted(fox) + " -o " + Quoted(dir / "frames") + clip + " --json");
  ASSERT_EQ(converted.exit_code, 0) << converted.err;
  const CliResult metrics =
      RunDmc("metrics " + Quoted(fox) + " " + Quoted(dir / "frames") + clip + " --json");
  ASSERT_EQ(metrics.exit_code, 0) << metrics.err;
  EXPECT_THAT(metrics.err, Not(HasSubstr("ignored")));
  EXPECT_EQ(Json(metrics)["vertices"], Json(converted)["vertices"]);
  // OBJ keeps every float bit (shortest round-trip decimal form).
  EXPECT_EQ(Json(metrics)["kg"], 0.0);
}

}  // namespace
}  // namespace dmc
