// `dmc sweep` run as a user would: the four output files with the exact CSV columns, the JSON
// report, and exit codes and messages for bad options.
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
using testing::ReadText;
using testing::RunDmc;

// A small walker written as OBJ frames by `dmc synth`.
std::filesystem::path SmallWalker(const std::filesystem::path& dir) {
  const std::filesystem::path input = dir / "walker";
  const auto made = RunDmc("synth walker -o " + Quoted(input) + " --frames 6 --resolution 300");
  EXPECT_EQ(made.exit_code, 0) << made.err;
  return input;
}

TEST(SweepCliTest, WritesTheCsvThePlotsAndTheSummary) {
  const auto dir = FreshTempDir("sweep");
  const auto input = SmallWalker(dir);
  const auto output = dir / "rd";
  const auto result = RunDmc("sweep " + Quoted(input) + " -o " + Quoted(output) +
                             " --operators tutte --baselines zstd,draco --points 2");
  ASSERT_EQ(result.exit_code, 0) << result.err;

  const std::string csv = ReadText(output / "rd.csv");
  EXPECT_EQ(csv.rfind("codec,operator,rank,basis_bits,residual_bits,anchors,bpfv,kg,sted,"
                      "encode_s,decode_s,coded_as,default_settings\n",
                      0),
            0u);
  // No ddl curve, so no default settings' point.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 + 2 + 2);
  EXPECT_THAT(csv, HasSubstr("\ndmc,tutte,"));
  EXPECT_THAT(csv, HasSubstr("\nzstd,,,,8,,"));
  EXPECT_THAT(csv, HasSubstr("\ndraco,,,,16,,"));
  for (const char* plot : {"rd_sted.svg", "rd_kg.svg"}) {
    const std::string svg = ReadText(output / plot);
    EXPECT_EQ(svg.rfind("<svg", 0), 0u) << plot;
    EXPECT_EQ(std::count(svg.begin(), svg.end(), '\n') > 10, true) << plot;
    EXPECT_THAT(svg, HasSubstr(">dmc/tutte</text>"));
    EXPECT_THAT(svg, HasSubstr(">draco</text>"));
  }
  const std::string summary = ReadText(output / "summary.md");
  EXPECT_THAT(summary, HasSubstr("## Rate needed for a target STED (bpfv)"));
  EXPECT_THAT(summary, HasSubstr("| dmc/tutte |"));
  // The default operator is not swept: its first dmc curve is the anchor, and Draco too.
  EXPECT_THAT(summary, HasSubstr("BD-rate vs dmc/tutte (STED)"));
  EXPECT_THAT(summary, HasSubstr("BD-rate vs draco (STED)"));
  EXPECT_THAT(summary, Not(HasSubstr("Default settings")));
  EXPECT_THAT(summary, HasSubstr("Command: `dmc sweep "));
  // The text report ends with the same rate table and the files written.
  EXPECT_THAT(result.out, HasSubstr("| zstd |"));
  EXPECT_THAT(result.out, HasSubstr("rd_sted.svg"));
}

// With the default operator swept, the default settings' point is encoded apart from the ladder:
// the same bytes as `dmc encode`, marked on both plots, listed in rd.csv and the summary; the
// BD-rates are against the ddl curve; each point says which operators it was coded with.
TEST(SweepCliTest, MarksTheDefaultSettingsAndAnchorsOnTheDefaultOperator) {
  const auto dir = FreshTempDir("sweep");
  const auto input = SmallWalker(dir);
  const auto output = dir / "rd";
  const auto result = RunDmc("sweep " + Quoted(input) + " -o " + Quoted(output) +
                             " --operators ddl,tutte --baselines draco --points 2 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json report = nlohmann::json::parse(result.out);
  const nlohmann::json& defaults = report["default_point"];
  ASSERT_TRUE(defaults.is_object()) << result.out;
  const auto encoded =
      RunDmc("encode " + Quoted(input) + " -o " + Quoted(dir / "d.dmc") + " --json");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  const nlohmann::json encode_report = nlohmann::json::parse(encoded.out);
  EXPECT_EQ(defaults["bytes"], encode_report["bytes"]);
  EXPECT_EQ(defaults["operator"], "ddl");
  EXPECT_EQ(report["points"].size(), 2u + 2u + 2u);  // the ladders, not the default point
  for (const nlohmann::json& point : report["points"]) {
    if (point["codec"] == "dmc") {
      EXPECT_FALSE(point["segment_operators"].get<std::string>().empty());
    }
  }
  const std::string csv = ReadText(output / "rd.csv");
  EXPECT_THAT(csv, HasSubstr(",1\n"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 + 2 + 2 + 1);
  for (const char* plot : {"rd_sted.svg", "rd_kg.svg"}) {
    const std::string svg = ReadText(output / plot);
    EXPECT_THAT(svg, HasSubstr("<polygon")) << plot;
    EXPECT_THAT(svg, HasSubstr(">dmc encode defaults (ddl, 10 bits)</text>")) << plot;
  }
  const std::string summary = ReadText(output / "summary.md");
  EXPECT_THAT(summary, HasSubstr("BD-rate vs dmc/ddl (STED)"));
  EXPECT_THAT(summary, HasSubstr("BD-rate vs draco (STED)"));
  EXPECT_THAT(summary, HasSubstr("| dmc/ddl |"));
  EXPECT_THAT(summary, HasSubstr("**Default settings**"));
  EXPECT_THAT(summary, HasSubstr("(default settings)"));
  EXPECT_THAT(summary, HasSubstr("| coded as |"));
}

TEST(SweepCliTest, JsonListsEveryPoint) {
  const auto dir = FreshTempDir("sweep");
  const auto input = SmallWalker(dir);
  const auto result = RunDmc("sweep " + Quoted(input) + " -o " + Quoted(dir / "rd") +
                             " --operators tutte --baselines meshopt --points 3 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json report = nlohmann::json::parse(result.out);
  ASSERT_EQ(report["points"].size(), 6u);
  const nlohmann::json& first = report["points"][0];
  EXPECT_EQ(first["codec"], "dmc");
  EXPECT_EQ(first["operator"], "tutte");
  EXPECT_GT(first["bpfv"].get<double>(), 0.0);
  EXPECT_GT(first["sted"].get<double>(), 0.0);
  const nlohmann::json& last = report["points"][5];
  EXPECT_EQ(last["codec"], "meshopt");
  EXPECT_TRUE(last["operator"].is_null());
  EXPECT_TRUE(last["rank"].is_null());
  EXPECT_EQ(last["residual_bits"], 16);
  EXPECT_EQ(report["vertices"].get<int>() > 0, true);
  EXPECT_TRUE(report["warnings"].empty());
}

TEST(SweepCliTest, BadOptionsFailBeforeReadingWithTheirCode) {
  const auto dir = FreshTempDir("sweep");
  const std::string missing_input = Quoted(dir / "no-such-input");
  const std::string out = " -o " + Quoted(dir / "rd");
  struct Case {
    std::string options;
    ErrorCode code;
    std::string message;
  };
  for (const Case& c : {
           Case{"--baselines gzip", ErrorCode::kInvalidArgument, "unknown baseline 'gzip'"},
           Case{"--points 1", ErrorCode::kInvalidArgument, "--points"},
           Case{"--operators none --baselines none", ErrorCode::kInvalidArgument,
                "nothing to sweep"},
           Case{"--min-baseline-bits 3", ErrorCode::kInvalidArgument, "baseline bits"},
           Case{"--sted-targets 0.01,-1", ErrorCode::kInvalidArgument, "--sted-targets"},
       }) {
    const auto result = RunDmc("sweep " + missing_input + out + " " + c.options);
    EXPECT_EQ(result.exit_code, ExitCodeFor(c.code)) << c.options << ": " << result.err;
    EXPECT_THAT(result.err, HasSubstr(c.message)) << c.options;
  }
}

TEST(SweepCliTest, UnknownOperatorIsNotFound) {
  const auto dir = FreshTempDir("sweep");
  const auto input = SmallWalker(dir);
  const auto result =
      RunDmc("sweep " + Quoted(input) + " -o " + Quoted(dir / "rd") + " --operators tutte,cotang");
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kNotFound)) << result.err;
  EXPECT_THAT(result.err, HasSubstr("cotang"));
}

}  // namespace
}  // namespace dmc
