// `dmc metrics` run as a user would: hand-computed values in JSON, the exact key set, options
// passed through, exit codes and messages for bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "cli/cli_runner.h"
#include "dmc/status.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::FreshTempDir;
using ::testing::HasSubstr;
using testing::Quoted;
using testing::RunDmc;

// One OBJ frame of the tetrahedron (0,0,0), (4,0,0), (0,4,0), (0,0,4) moved by (dx, 0, 0), with
// vertex 0 replaced by `first` when given.
void WriteTetrahedronFrame(const std::filesystem::path& path, int dx, const char* first) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  if (first != nullptr) {
    out << "v " << first << "\n";
  } else {
    out << "v " << dx << " 0 0\n";
  }
  out << "v " << 4 + dx << " 0 0\nv " << dx << " 4 0\nv " << dx << " 0 4\n"
      << "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
}

// The pair of kg_test's tetrahedron: 3 frames moving by (2, 0, 0) per frame; the distorted has
// vertex 0 of frame 0 at (0, 0, −1).
struct TetrahedronPair {
  std::filesystem::path original, distorted;
};
TetrahedronPair WriteTetrahedronPair(const std::filesystem::path& dir, int frames = 3) {
  for (int f = 0; f < frames; ++f) {
    const std::string name = "t_" + std::to_string(f) + ".obj";
    WriteTetrahedronFrame(dir / "original" / name, 2 * f, nullptr);
    WriteTetrahedronFrame(dir / "distorted" / name, 2 * f, f == 0 ? "0 0 -1" : nullptr);
  }
  return {dir / "original", dir / "distorted"};
}

TEST(MetricsCliTest, JsonHoldsExactlyTheDocumentedKeysAndHandComputedValues) {
  const auto pair = WriteTetrahedronPair(FreshTempDir("metrics"));
  const auto result =
      RunDmc("metrics " + Quoted(pair.original) + " " + Quoted(pair.distorted) + " --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  std::set<std::string> keys;
  for (const auto& item : json.items()) keys.insert(item.key());
  EXPECT_EQ(keys, (std::set<std::string>{"kg", "sted", "sted_s", "sted_t", "rmse_rel", "max_error",
                                         "frames", "vertices"}));
  // Worked out in tests/unit/metrics/kg_test.cpp and sted_test.cpp: ‖A − E(A)‖² = 108,
  // ‖A − A′‖² = 1, bounding-box diagonal sqrt(96); D = 4√2 and only vertex 0 of frame 1 has a
  // different temporal edge: sqrt(5/32 + dt²) against sqrt(1/8 + dt²).
  EXPECT_NEAR(json["kg"].get<double>(), 100.0 / std::sqrt(108.0), 1e-12);
  EXPECT_NEAR(json["rmse_rel"].get<double>(), std::sqrt(1.0 / 12.0) / std::sqrt(96.0), 1e-14);
  EXPECT_DOUBLE_EQ(json["max_error"].get<double>(), 1.0);
  const double dt = 0.0003;
  const double te = std::sqrt(0.125 + dt * dt);
  EXPECT_NEAR(json["sted_t"].get<double>(), (std::sqrt(5.0 / 32.0 + dt * dt) - te) / te / 8.0,
              1e-12);
  EXPECT_GT(json["sted_s"].get<double>(), 0.0);
  EXPECT_GE(json["sted"].get<double>(), json["sted_s"].get<double>());
  EXPECT_EQ(json["frames"], 3);
  EXPECT_EQ(json["vertices"], 4);
}

TEST(MetricsCliTest, StedOptionsReachTheMetric) {
  const auto pair = WriteTetrahedronPair(FreshTempDir("metrics"));
  // dt = 0: STED_t = (sqrt(5/32) − sqrt(1/8)) / sqrt(1/8) / 8 = (sqrt(5/4) − 1) / 8; with c = 1,
  // STED = sqrt(STED_s² + STED_t²).
  const auto result = RunDmc("metrics " + Quoted(pair.original) + " " + Quoted(pair.distorted) +
                             " --json --sted-dt 0 --sted-c 1 --sted-window 1 --sted-width 0");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  const double sted_t = (std::sqrt(1.25) - 1.0) / 8.0;
  EXPECT_NEAR(json["sted_t"].get<double>(), sted_t, 1e-12);
  const double sted_s = json["sted_s"].get<double>();
  EXPECT_NEAR(json["sted"].get<double>(), std::sqrt(sted_s * sted_s + sted_t * sted_t), 1e-12);
}

TEST(MetricsCliTest, TextReportNamesEveryMetricAndTheOrderMatters) {
  const auto pair = WriteTetrahedronPair(FreshTempDir("metrics"));
  const auto forward = RunDmc("metrics " + Quoted(pair.original) + " " + Quoted(pair.distorted));
  ASSERT_EQ(forward.exit_code, 0) << forward.err;
  for (const char* label : {"KG error", "STED", "STED_s", "STED_t", "RMSE", "max vertex error"}) {
    EXPECT_THAT(forward.out, HasSubstr(label));
  }
  const auto a = RunDmc("metrics --json " + Quoted(pair.original) + " " + Quoted(pair.distorted));
  const auto b = RunDmc("metrics --json " + Quoted(pair.distorted) + " " + Quoted(pair.original));
  ASSERT_EQ(a.exit_code, 0);
  ASSERT_EQ(b.exit_code, 0);
  EXPECT_NE(nlohmann::json::parse(a.out)["sted"], nlohmann::json::parse(b.out)["sted"]);
}

TEST(MetricsCliTest, MismatchedSequencesFailWithAClearError) {
  const auto dir = FreshTempDir("metrics");
  const auto three = WriteTetrahedronPair(dir / "three", 3);
  const auto two = WriteTetrahedronPair(dir / "two", 2);
  const auto result = RunDmc("metrics " + Quoted(three.original) + " " + Quoted(two.distorted));
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kMismatch));
  EXPECT_THAT(result.err, HasSubstr("dmc metrics: error: mismatch"));
  EXPECT_THAT(result.err, HasSubstr("frame counts differ: 3 vs 2"));
  EXPECT_TRUE(result.out.empty());
  const auto json_result =
      RunDmc("metrics --json " + Quoted(three.original) + " " + Quoted(two.distorted));
  EXPECT_EQ(json_result.exit_code, ExitCodeFor(ErrorCode::kMismatch));
  EXPECT_EQ(nlohmann::json::parse(json_result.out)["error"]["name"], "mismatch");
}

TEST(MetricsCliTest, BadOptionsAndMissingInputsFail) {
  const auto pair = WriteTetrahedronPair(FreshTempDir("metrics"));
  const std::string inputs = Quoted(pair.original) + " " + Quoted(pair.distorted);
  for (const char* option :
       {"--sted-window 0", "--sted-width -1", "--sted-dt -0.1", "--sted-c -1"}) {
    const auto result = RunDmc("metrics " + inputs + " " + option);
    EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kInvalidArgument)) << option;
    EXPECT_THAT(result.err, HasSubstr("invalid-argument")) << option;
  }
  const auto missing = RunDmc("metrics " + Quoted(pair.original) + " " +
                              Quoted(pair.original.parent_path() / "no-such-dir"));
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_THAT(missing.err, HasSubstr("dmc metrics: error:"));
  const auto usage = RunDmc("metrics " + Quoted(pair.original));  // DISTORTED missing
  EXPECT_NE(usage.exit_code, 0);
}

}  // namespace
}  // namespace dmc
