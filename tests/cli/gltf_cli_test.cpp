// glTF through the command line: .glb inputs for info/convert/encode/metrics, `dmc decode -o
// out.glb` in both layouts, and `dmc view`'s loopback server (files served, everything else 404).
#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <thread>

#include "cli/cli_runner.h"
#include "dmc/status.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::FreshTempDir;
using ::testing::HasSubstr;
using testing::Quoted;
using testing::RunDmc;

int ExitCode(ErrorCode code) { return 10 + static_cast<int>(code); }

nlohmann::json Json(const testing::CliResult& result) { return nlohmann::json::parse(result.out); }

// cloth (12 frames, ~400 vertices) encoded: the .dmc path.
std::filesystem::path EncodedCloth(const std::filesystem::path& dir) {
  EXPECT_EQ(
      RunDmc("synth cloth -o " + Quoted(dir / "cloth") + " --frames 12 --resolution 400").exit_code,
      0);
  const auto encoded = RunDmc("encode " + Quoted(dir / "cloth") + " -o " + Quoted(dir / "c.dmc"));
  EXPECT_EQ(encoded.exit_code, 0) << encoded.err;
  return dir / "c.dmc";
}

TEST(GltfCliTest, DecodeWritesAGlbThatReadsBackInBothLayouts) {
  const auto dir = FreshTempDir("gltf");
  const auto stream = EncodedCloth(dir);
  const auto reference = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "frames_out"));
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  for (const std::string layout : {"morph", "frames"}) {
    const auto glb = dir / ("out-" + layout + ".glb");
    const auto decoded = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(glb) +
                                " --glb-layout " + layout + " --json");
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    EXPECT_EQ(Json(decoded)["frames"], 12);
    const auto info = RunDmc("info " + Quoted(glb) + " --json");
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_EQ(Json(info)["frames"], 12) << layout;
    // The GLB holds the decoded frames: no distortion against the decoder's OBJ output beyond
    // the compact encoding's position grid (1/65532 of the largest extent at most).
    const auto metrics =
        RunDmc("metrics " + Quoted(dir / "frames_out") + " " + Quoted(glb) + " --json");
    ASSERT_EQ(metrics.exit_code, 0) << metrics.err;
    EXPECT_LT(Json(metrics)["kg"].get<double>(), 1e-2) << layout;
  }
  const auto bad = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "x.glb") +
                          " --glb-layout sideways");
  EXPECT_EQ(bad.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  EXPECT_THAT(bad.err, HasSubstr("sideways"));
}

TEST(GltfCliTest, DecodeWritesCompactQuantizedOrFloatGlbs) {
  const auto dir = FreshTempDir("gltf");
  const auto stream = EncodedCloth(dir);
  ASSERT_EQ(RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "frames_out")).exit_code, 0);
  std::map<std::string, uintmax_t> sizes;
  for (const std::string encoding : {"compact", "quantized", "float"}) {
    const auto glb = dir / (encoding + ".glb");
    const auto decoded =
        RunDmc("decode " + Quoted(stream) + " -o " + Quoted(glb) + " --glb-encoding " + encoding);
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    sizes[encoding] = std::filesystem::file_size(glb);
    const auto metrics =
        RunDmc("metrics " + Quoted(dir / "frames_out") + " " + Quoted(glb) + " --json");
    ASSERT_EQ(metrics.exit_code, 0) << metrics.err;
    EXPECT_LT(Json(metrics)["kg"].get<double>(), encoding == "float" ? 1e-4 : 1e-2) << encoding;
  }
  EXPECT_LT(sizes["compact"], sizes["quantized"]);
  EXPECT_LT(sizes["quantized"], sizes["float"]);
  // --float is --glb-encoding float; either is pointless, and said to be, for other outputs.
  const auto float_glb =
      RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "f.glb") + " --float");
  ASSERT_EQ(float_glb.exit_code, 0) << float_glb.err;
  EXPECT_EQ(std::filesystem::file_size(dir / "f.glb"), sizes["float"]);
  const auto pc2 = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "x.pc2") + " --float");
  EXPECT_EQ(pc2.exit_code, 0) << pc2.err;
  EXPECT_THAT(pc2.err, HasSubstr("not a .glb"));
  const auto bad =
      RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "x.glb") + " --glb-encoding zip");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.err, HasSubstr("zip"));
}

TEST(GltfCliTest, FpsIsRecordedForInputsWithoutARate) {
  const auto dir = FreshTempDir("gltf");
  ASSERT_EQ(
      RunDmc("synth cloth -o " + Quoted(dir / "cloth") + " --frames 6 --resolution 200").exit_code,
      0);
  const auto encoded =
      RunDmc("encode " + Quoted(dir / "cloth") + " -o " + Quoted(dir / "c.dmc") + " --fps 25");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  const auto info = RunDmc("info " + Quoted(dir / "c.dmc") + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(Json(info)["frame_rate"], 25.0);
  ASSERT_EQ(RunDmc("decode " + Quoted(dir / "c.dmc") + " -o " + Quoted(dir / "c.glb")).exit_code,
            0);
  EXPECT_EQ(Json(RunDmc("info " + Quoted(dir / "c.glb") + " --json"))["frame_rate"], 25.0);
  const auto negative =
      RunDmc("encode " + Quoted(dir / "cloth") + " -o " + Quoted(dir / "n.dmc") + " --fps -3");
  EXPECT_EQ(negative.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  EXPECT_THAT(negative.err, HasSubstr("--fps"));
  // A glTF animation has its own clock: --gltf-fps samples it.
  ASSERT_EQ(RunDmc("convert " + Quoted(dir / "c.glb") + " -o " + Quoted(dir / "g.glb")).exit_code,
            0);
  const auto gltf =
      RunDmc("encode " + Quoted(dir / "g.glb") + " -o " + Quoted(dir / "g.dmc") + " --fps 12");
  EXPECT_EQ(gltf.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  EXPECT_THAT(gltf.err, HasSubstr("--gltf-fps"));
  EXPECT_FALSE(std::filesystem::exists(dir / "g.dmc"));
}

// gltfpack (meshoptimizer's glTF tool) writes EXT_meshopt_compression with quantised attributes
// and filtered animation: such files read like their uncompressed originals.
TEST(GltfCliTest, MeshoptCompressedSamplesRead) {
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  if (std::system("command -v gltfpack >/dev/null 2>&1") != 0) GTEST_SKIP() << "no gltfpack";
  const auto dir = FreshTempDir("gltf");
  ASSERT_EQ(std::system(("gltfpack -i " + Quoted(cesium) + " -o " + Quoted(dir / "cc.glb") +
                         " -cc >/dev/null 2>&1")
                            .c_str()),
            0);
  const auto original = RunDmc("info " + Quoted(cesium) + " --json");
  const auto packed = RunDmc("info " + Quoted(dir / "cc.glb") + " --json");
  ASSERT_EQ(packed.exit_code, 0) << packed.err;
  EXPECT_EQ(Json(packed)["triangles"], Json(original)["triangles"]);
  // gltfpack resamples the clip (at 30 Hz by default), so only its length is comparable.
  EXPECT_NEAR(Json(packed)["frames"].get<double>() / Json(packed)["frame_rate"].get<double>(),
              Json(original)["frames"].get<double>() / Json(original)["frame_rate"].get<double>(),
              0.1);
  const auto encoded = RunDmc("encode " + Quoted(dir / "cc.glb") + " -o " + Quoted(dir / "cc.dmc"));
  EXPECT_EQ(encoded.exit_code, 0) << encoded.err;
}

// A glTF input's scene travels in the stream (format 1.3) and comes back in the decoded GLB: every
// clip with its name, or one with --clip; --no-scene leaves it out on either side.
TEST(GltfCliTest, TheSceneAndEveryClipTravelWithTheStream) {
  DMC_REQUIRE_SHARED_DATA(fox, "fox/Fox.glb");
  const auto dir = FreshTempDir("gltf");
  const auto encoded =
      RunDmc("encode " + Quoted(fox) + " -o " + Quoted(dir / "fox.dmc") + " --json");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  const nlohmann::json report = Json(encoded);
  EXPECT_GT(report["breakdown"]["scene"].get<double>(), 0);
  EXPECT_LT(report["positions_bpfv"].get<double>(), report["bpfv"].get<double>());
  const auto info = RunDmc("info " + Quoted(dir / "fox.dmc") + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(Json(info)["format_version"], "1.3");
  ASSERT_EQ(Json(info)["clips"].size(), 3u);
  EXPECT_EQ(Json(info)["clips"][1]["name"], "Walk");
  const int walk_frames = Json(info)["clips"][1]["frames"];

  ASSERT_EQ(
      RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " + Quoted(dir / "fox.glb")).exit_code, 0);
  const auto glb_info = RunDmc("info " + Quoted(dir / "fox.glb") + " --json");
  ASSERT_EQ(glb_info.exit_code, 0) << glb_info.err;
  ASSERT_EQ(Json(glb_info)["clips"].size(), 3u);
  EXPECT_EQ(Json(glb_info)["clips"][2]["name"], "Run");
  EXPECT_EQ(Json(glb_info)["frames"], Json(info)["frames"]);

  const auto walk = RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " + Quoted(dir / "walk.glb") +
                           " --clip Walk");
  ASSERT_EQ(walk.exit_code, 0) << walk.err;
  const auto walk_info = RunDmc("info " + Quoted(dir / "walk.glb") + " --json");
  ASSERT_EQ(Json(walk_info)["clips"].size(), 1u);
  EXPECT_EQ(Json(walk_info)["frames"], walk_frames);
  const auto unknown =
      RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " + Quoted(dir / "x.glb") + " --clip Swim");
  EXPECT_EQ(unknown.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  EXPECT_THAT(unknown.err, HasSubstr("Survey, Walk, Run"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x.glb"));

  // Without the scene: the motion alone, and a stream of format 1.3 without a scene chunk.
  const auto bare =
      RunDmc("encode " + Quoted(fox) + " -o " + Quoted(dir / "bare.dmc") + " --no-scene --json");
  ASSERT_EQ(bare.exit_code, 0) << bare.err;
  EXPECT_EQ(Json(bare)["breakdown"]["scene"], 0);
  EXPECT_LT(Json(bare)["bytes"].get<double>(), report["bytes"].get<double>());
  const auto no_clip = RunDmc("decode " + Quoted(dir / "bare.dmc") + " -o " +
                              Quoted(dir / "y.glb") + " --clip Walk");
  EXPECT_EQ(no_clip.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  ASSERT_EQ(RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " + Quoted(dir / "motion.glb") +
                   " --no-scene")
                .exit_code,
            0);
  EXPECT_LT(std::filesystem::file_size(dir / "motion.glb"),
            std::filesystem::file_size(dir / "fox.glb"));
  // One segment: its motion alone (the clips span the stream), said on stderr.
  const auto segment = RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " +
                              Quoted(dir / "segment.glb") + " --segment 0");
  ASSERT_EQ(segment.exit_code, 0) << segment.err;
  EXPECT_THAT(segment.err, HasSubstr("without the scene"));
  // Every layout a scene can take, and the frames layout refused with one.
  for (const char* layout : {"basis", "morph"}) {
    const auto out = dir / (std::string(layout) + ".glb");
    ASSERT_EQ(RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " + Quoted(out) + " --glb-layout " +
                     layout)
                  .exit_code,
              0)
        << layout;
    const auto layout_info = RunDmc("info " + Quoted(out) + " --json");
    ASSERT_EQ(Json(layout_info)["clips"].size(), 3u) << layout;
  }
  const auto frames = RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " +
                             Quoted(dir / "frames.glb") + " --glb-layout frames");
  EXPECT_EQ(frames.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  EXPECT_THAT(frames.err, HasSubstr("basis or morph"));
  const auto float_basis = RunDmc("decode " + Quoted(dir / "fox.dmc") + " -o " +
                                  Quoted(dir / "fb.glb") + " --glb-layout basis --float");
  EXPECT_EQ(float_basis.exit_code, ExitCode(ErrorCode::kInvalidArgument));
  EXPECT_THAT(float_basis.err, HasSubstr("quantised targets"));
}

TEST(GltfCliTest, SkinnedSampleIsAnInputLikeAnyOther) {
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  const auto dir = FreshTempDir("gltf");
  const auto info = RunDmc("info " + Quoted(cesium) + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(Json(info)["vertices"], 3273);
  EXPECT_EQ(Json(info)["triangles"], 4672);
  // Keyed at 24 fps from 1/24 s to 2 s: sampled at its key rate, 48 frames.
  EXPECT_EQ(Json(info)["frames"], 48);
  EXPECT_EQ(Json(info)["frame_rate"], 24.0);
  // A short clip as a GLB, then the codec round trip from it and back to GLB.
  const auto clip = dir / "clip.glb";
  ASSERT_EQ(
      RunDmc("convert " + Quoted(cesium) + " -o " + Quoted(clip) + " --max-frames 10").exit_code,
      0);
  const auto encoded = RunDmc("encode " + Quoted(clip) + " -o " + Quoted(dir / "clip.dmc"));
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  const auto decoded =
      RunDmc("decode " + Quoted(dir / "clip.dmc") + " -o " + Quoted(dir / "decoded.glb"));
  ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
  const auto metrics =
      RunDmc("metrics " + Quoted(clip) + " " + Quoted(dir / "decoded.glb") + " --json");
  ASSERT_EQ(metrics.exit_code, 0) << metrics.err;
  EXPECT_EQ(Json(metrics)["frames"], 10);
  EXPECT_GT(Json(metrics)["kg"].get<double>(), 0.0);
  EXPECT_LT(Json(metrics)["kg"].get<double>(), 5.0);
}

TEST(GltfCliTest, BrokenGlbIsAParseError) {
  const auto dir = FreshTempDir("gltf");
  std::ofstream(dir / "broken.glb") << "glTF but not really";
  const auto result = RunDmc("info " + Quoted(dir / "broken.glb"));
  EXPECT_EQ(result.exit_code, ExitCode(ErrorCode::kParseError));
  EXPECT_THAT(result.err, HasSubstr("broken.glb"));
}

// GET `path` from 127.0.0.1:`port`; returns the whole response (status line, headers, body).
std::string HttpGet(int port, const std::string& path) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(s, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    ::close(s);
    return "";
  }
  const std::string request = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
  (void)!::send(s, request.data(), request.size(), 0);
  std::string response;
  char buffer[4096];
  for (ssize_t n; (n = ::recv(s, buffer, sizeof(buffer), 0)) > 0;) {
    response.append(buffer, static_cast<size_t>(n));
  }
  ::close(s);
  return response;
}

TEST(GltfCliTest, ViewServesTheViewerAndDataOnLoopbackOnly) {
  const auto dir = FreshTempDir("gltf");
  const auto stream = EncodedCloth(dir);
  // A stand-in viewer build: the server only needs the two files to exist.
  std::filesystem::create_directories(dir / "viewer");
  std::ofstream(dir / "viewer" / "index.html") << "<!doctype html><title>stub</title>";
  std::ofstream(dir / "viewer" / "viewer.js") << "console.log('stub');";
  const auto out = dir / "view.json";
  const std::string command = std::string(DMC_CLI_PATH) + " view " + Quoted(stream) +
                              " --original " + Quoted(dir / "cloth") + " --viewer-dir " +
                              Quoted(dir / "viewer") + " --port 0 --json --exit-after 20 > " +
                              Quoted(out) + " 2>&1 & echo $! > " + Quoted(dir / "view.pid");
  ASSERT_EQ(std::system(command.c_str()), 0);
  // Stops the server when the test ends, however it ends (it would stop by itself after 20 s).
  struct StopServer {
    std::filesystem::path pid_file;
    ~StopServer() {
      std::ifstream in(pid_file);
      pid_t pid = 0;
      if (in >> pid && pid > 0) ::kill(pid, SIGTERM);
    }
  } stop_server{dir / "view.pid"};
  int port = 0;
  for (int attempt = 0; attempt < 300 && port == 0; ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::ifstream in(out);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    std::smatch match;
    if (std::regex_search(text, match, std::regex(R"(http://127\.0\.0\.1:(\d+)/)"))) {
      port = std::stoi(match[1]);
    }
  }
  ASSERT_GT(port, 0) << "dmc view printed no URL";
  EXPECT_THAT(HttpGet(port, "/"), HasSubstr("<title>stub</title>"));
  const std::string metrics = HttpGet(port, "/data/metrics.json");
  ASSERT_THAT(metrics, HasSubstr("200 OK"));
  const auto json = nlohmann::json::parse(metrics.substr(metrics.find("\r\n\r\n") + 4));
  EXPECT_EQ(json["frames"], 12);
  EXPECT_GT(json["bpfv"].get<double>(), 0.0);
  ASSERT_EQ(json["distortion"]["frames"].size(), 12u);
  // The per-frame KG contributions add up (in squares) to the sequence's KG.
  double sum_of_squares = 0.0;
  for (const auto& frame : json["distortion"]["frames"]) {
    sum_of_squares += frame["kg"].get<double>() * frame["kg"].get<double>();
  }
  EXPECT_NEAR(std::sqrt(sum_of_squares), json["distortion"]["kg"].get<double>(),
              1e-9 + 1e-6 * json["distortion"]["kg"].get<double>());
  EXPECT_THAT(HttpGet(port, "/data/decoded.glb"), HasSubstr("model/gltf-binary"));
  EXPECT_THAT(HttpGet(port, "/data/original.glb"), HasSubstr("200 OK"));
  EXPECT_THAT(HttpGet(port, "/../../etc/passwd"), HasSubstr("404"));
  EXPECT_THAT(HttpGet(port, "/data/"), HasSubstr("404"));
}

TEST(GltfCliTest, ViewWithoutABuiltViewerSaysHowToBuildIt) {
  const auto dir = FreshTempDir("gltf");
  const auto result =
      RunDmc("view " + Quoted(dir / "missing.dmc") + " --viewer-dir " + Quoted(dir / "nowhere"));
  EXPECT_EQ(result.exit_code, ExitCode(ErrorCode::kIoError));
  EXPECT_THAT(result.err, HasSubstr("tools/viewer/build.sh"));
}

}  // namespace
}  // namespace dmc
