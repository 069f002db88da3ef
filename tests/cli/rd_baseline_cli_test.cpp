// `dmc sweep --baseline FILE` as the rate–distortion yardstick uses it: a sweep's yardstick.csv
// taken as the baseline, a rerun against it (the baseline's own ladder, BD-rate 0), and the
// errors for a sequence the baseline does not hold or holds at another length.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_runner.h"
#include "dmc/status.h"

namespace dmc {
namespace {

using testing::FreshTempDir;
using ::testing::HasSubstr;
using testing::Quoted;
using testing::ReadText;
using testing::RunDmc;

TEST(RdBaselineCli, ARerunAgainstItsOwnBaselineIsZeroOnTheBaselinesLadder) {
  const auto dir = FreshTempDir("rd-baseline");
  const auto walker = dir / "walker";
  const auto made = RunDmc("synth walker -o " + Quoted(walker) + " --frames 6 --resolution 300");
  ASSERT_EQ(made.exit_code, 0) << made.err;

  const auto first = RunDmc("sweep " + Quoted(walker) + " -o " + Quoted(dir / "base") +
                            " --operators tutte --baselines none --ladder 9,7,11");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const std::string csv = ReadText(dir / "base" / "yardstick.csv");
  EXPECT_THAT(csv, HasSubstr("# command: dmc sweep "));
  EXPECT_THAT(csv, HasSubstr("\nsequence,vertices,frames,operator,effort,residual_bits,"));
  EXPECT_THAT(csv, HasSubstr("\nwalker,"));  // named after the input directory
  EXPECT_THAT(csv, HasSubstr(",tutte,2,7,"));
  EXPECT_THAT(csv, HasSubstr(",tutte,2,11,"));
  EXPECT_FALSE(std::filesystem::exists(dir / "base" / "baseline.md"));

  const auto again = RunDmc("sweep " + Quoted(walker) + " -o " + Quoted(dir / "again") +
                            " --operators tutte --baselines none --json --baseline " +
                            Quoted(dir / "base" / "yardstick.csv"));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const nlohmann::json report = nlohmann::json::parse(again.out);
  EXPECT_EQ(report["sequence"], "walker");
  ASSERT_EQ(report["points"].size(), 3u);  // the baseline's three rungs, in increasing order
  EXPECT_EQ(report["points"][0]["residual_bits"], 7.0);
  EXPECT_EQ(report["points"][2]["residual_bits"], 11.0);
  const nlohmann::json& breakdown = report["points"][0]["breakdown"];
  EXPECT_GT(breakdown["residuals"].get<int>(), 0);
  EXPECT_GT(breakdown["connectivity"].get<int>(), 0);
  ASSERT_EQ(report["comparisons"].size(), 1u);
  const nlohmann::json& comparison = report["comparisons"][0];
  EXPECT_EQ(comparison["curve"], "dmc/tutte");
  EXPECT_NEAR(comparison["bd_rate_sted"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(comparison["bd_rate_kg"].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(comparison["targets"].size(), 3u);
  EXPECT_EQ(comparison["current_near"]["bytes"], comparison["baseline_near"]["bytes"]);
  EXPECT_THAT(ReadText(dir / "again" / "baseline.md"),
              HasSubstr("| dmc/tutte | +0.0 % | +0.0 % |"));
}

TEST(RdBaselineCli, ASequenceTheBaselineLacksOrHoldsAtAnotherLengthIsRefused) {
  const auto dir = FreshTempDir("rd-baseline");
  const auto walker = dir / "walker";
  ASSERT_EQ(RunDmc("synth walker -o " + Quoted(walker) + " --frames 4 --resolution 300").exit_code,
            0);
  const auto baseline = dir / "baseline.csv";
  std::ofstream(baseline) << "# commit: 0\n"
                             "sequence,vertices,frames,residual_bits,bpfv,kg,sted\n"
                             "walker,1,999,8,1,1,0.1\n"
                             "walker,1,999,10,2,0.5,0.05\n";
  const std::string common = "sweep " + Quoted(walker) + " -o " + Quoted(dir / "rd") +
                             " --operators tutte --baselines none --baseline " + Quoted(baseline);
  const auto other = RunDmc(common + " --sequence samba");
  EXPECT_EQ(other.exit_code, ExitCodeFor(ErrorCode::kNotFound)) << other.err;
  EXPECT_THAT(other.err, HasSubstr("no sequence 'samba' (it has: walker)"));
  const auto longer = RunDmc(common);
  EXPECT_EQ(longer.exit_code, ExitCodeFor(ErrorCode::kMismatch)) << longer.err;
  EXPECT_THAT(longer.err, HasSubstr("the baseline's 'walker' has 1 vertices x 999 frames"));

  std::ofstream(baseline) << "sequence,frames\nwalker,4\n";
  const auto damaged = RunDmc(common);
  EXPECT_EQ(damaged.exit_code, ExitCodeFor(ErrorCode::kParseError)) << damaged.err;
  EXPECT_THAT(damaged.err, HasSubstr("baseline.csv: yardstick line 1: the header has no "));
}

}  // namespace
}  // namespace dmc
