// The rate–distortion yardstick: its CSV read back exactly, the errors of a damaged one, the
// choice of a sequence's curve, and the comparison of a curve with the baseline's on curves whose
// BD-rates are known.
#include "sweep/yardstick.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace dmc::sweep {
namespace {

using ::testing::HasSubstr;

// A curve of `sequence` with rate · STED = 0.02 and rate · KG = 1 (straight lines in log–log),
// every byte count scaled by `scale`, so a scaled curve needs exactly `scale` times the rate at
// every distortion.
std::vector<YardstickRow> Curve(const std::string& sequence, double scale = 1.0) {
  std::vector<YardstickRow> rows;
  for (int k = 0; k < 6; ++k) {
    YardstickRow row;
    row.sequence = sequence;
    row.vertices = 1000;
    row.frames = 40;
    row.operator_name = "ddl";
    row.effort = 2;
    row.residual_bits = 8 + k;
    const double base_bpfv = 0.25 * std::exp2(0.75 * k);
    row.bpfv = scale * base_bpfv;
    row.sted = 0.02 / base_bpfv;
    row.kg = 1.0 / base_bpfv;
    row.rank = 3 + 2 * k;
    row.basis_bits = 10;
    row.segments = 2;
    row.segment_operators = "ddl:1 tutte:1";
    row.residual_bytes = static_cast<uint64_t>(std::lround(scale * 800 * (k + 1)));
    row.basis_bytes = static_cast<uint64_t>(std::lround(scale * 100 * (k + 1)));
    row.connectivity_bytes = 90;
    row.operator_bytes = 5;
    row.anchor_bytes = 3;
    row.mean_bytes = 1;
    row.header_bytes = 1;
    row.bytes = row.residual_bytes + row.basis_bytes + 100;
    rows.push_back(row);
  }
  return rows;
}

TEST(Yardstick, CsvReadsBackExactly) {
  const std::vector<YardstickRow> rows = Curve("crane-full");
  const std::string csv = YardstickCsv({{"commit", "abc123"}, {"tree", "clean"}}, rows);
  EXPECT_EQ(
      csv.rfind("# commit: abc123\n# tree: clean\n" + std::string(kYardstickHeader) + "\n", 0), 0u);
  StatusOr<Yardstick> read = ParseYardstick(csv);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->meta.size(), 2u);
  EXPECT_EQ(read->meta[0].first, "commit");
  EXPECT_EQ(read->meta[0].second, "abc123");
  ASSERT_EQ(read->rows.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const YardstickRow& a = rows[i];
    const YardstickRow& b = read->rows[i];
    EXPECT_EQ(b.sequence, a.sequence);
    EXPECT_EQ(b.vertices, a.vertices);
    EXPECT_EQ(b.frames, a.frames);
    EXPECT_EQ(b.operator_name, a.operator_name);
    EXPECT_EQ(b.effort, a.effort);
    EXPECT_EQ(b.residual_bits, a.residual_bits);
    EXPECT_EQ(b.bpfv, a.bpfv);  // written exactly
    EXPECT_EQ(b.sted, a.sted);
    EXPECT_EQ(b.kg, a.kg);
    EXPECT_EQ(b.rank, a.rank);
    EXPECT_EQ(b.basis_bits, a.basis_bits);
    EXPECT_EQ(b.segments, a.segments);
    EXPECT_EQ(b.segment_operators, a.segment_operators);
    EXPECT_EQ(b.bytes, a.bytes);
    EXPECT_EQ(b.residual_bytes, a.residual_bytes);
    EXPECT_EQ(b.basis_bytes, a.basis_bytes);
    EXPECT_EQ(b.connectivity_bytes, a.connectivity_bytes);
    EXPECT_EQ(b.operator_bytes, a.operator_bytes);
    EXPECT_EQ(b.anchor_bytes, a.anchor_bytes);
    EXPECT_EQ(b.mean_bytes, a.mean_bytes);
    EXPECT_EQ(b.header_bytes, a.header_bytes);
  }
}

TEST(Yardstick, ColumnsAreFoundByNameAndOptionalOnesMayBeAbsent) {
  const std::string csv =
      "sted,extra,frames,sequence,kg,bpfv,vertices,residual_bits\r\n"
      "0.02,x,16,crane,0.5,1.5,10002,10.5\r\n";
  StatusOr<Yardstick> read = ParseYardstick(csv);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->rows.size(), 1u);
  const YardstickRow& row = read->rows[0];
  EXPECT_EQ(row.sequence, "crane");
  EXPECT_EQ(row.vertices, 10002);
  EXPECT_EQ(row.frames, 16);
  EXPECT_EQ(row.residual_bits, 10.5);
  EXPECT_EQ(row.bpfv, 1.5);
  EXPECT_EQ(row.sted, 0.02);
  EXPECT_EQ(row.kg, 0.5);
  EXPECT_EQ(row.bytes, 0u);
  EXPECT_EQ(row.operator_name, "");
}

TEST(Yardstick, DamagedCsvIsAParseErrorNamingLineAndColumn) {
  struct Case {
    std::string text;
    std::string message;
  };
  const std::string header = "sequence,vertices,frames,residual_bits,bpfv,kg,sted\n";
  for (const Case& c : {
           Case{"", "no header line"},
           Case{"# only: comments\n", "no header line"},
           Case{"sequence,vertices,frames,residual_bits,bpfv,kg\n", "no 'sted' column"},
           Case{header + "crane,10002,16,10,1.5,0.5\n", "line 2: 6 fields, the header has 7"},
           Case{header + "crane,10002,16,10,1.5x,0.5,0.02\n", "line 2: column 'bpfv' holds '1.5x'"},
           Case{header + "\n# note\ncrane,many,16,10,1.5,0.5,0.02\n", "line 4: column 'vertices'"},
           Case{header + ",10002,16,10,1.5,0.5,0.02\n", "line 2: empty sequence name"},
       }) {
    StatusOr<Yardstick> read = ParseYardstick(c.text);
    ASSERT_FALSE(read.ok()) << c.text;
    EXPECT_EQ(read.status().code(), ErrorCode::kParseError) << c.text;
    EXPECT_THAT(read.status().message(), HasSubstr(c.message)) << c.text;
  }
}

TEST(Yardstick, BaselineCurveIsTheSequencesRowsWithTheSameShape) {
  Yardstick baseline;
  for (const char* name : {"crane", "crane-full"}) {
    for (const YardstickRow& row : Curve(name)) baseline.rows.push_back(row);
  }
  StatusOr<std::vector<YardstickRow>> curve = BaselineCurve(baseline, "crane-full", 1000, 40);
  ASSERT_TRUE(curve.ok()) << curve.status().ToString();
  ASSERT_EQ(curve->size(), 6u);
  for (const YardstickRow& row : *curve) EXPECT_EQ(row.sequence, "crane-full");

  const StatusOr<std::vector<YardstickRow>> absent = BaselineCurve(baseline, "samba", 1000, 40);
  EXPECT_EQ(absent.status().code(), ErrorCode::kNotFound);
  EXPECT_THAT(absent.status().message(), HasSubstr("no sequence 'samba' (it has: crane, "
                                                   "crane-full)"));

  const StatusOr<std::vector<YardstickRow>> shorter = BaselineCurve(baseline, "crane", 1000, 16);
  EXPECT_EQ(shorter.status().code(), ErrorCode::kMismatch);
  EXPECT_THAT(shorter.status().message(), HasSubstr("1000 vertices x 40 frames, the input "
                                                    "1000 x 16"));

  baseline.rows.back().operator_name = "tutte";
  const StatusOr<std::vector<YardstickRow>> mixed = BaselineCurve(baseline, "crane-full", 1000, 40);
  EXPECT_EQ(mixed.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(mixed.status().message(), HasSubstr("mixes operators 'ddl' and 'tutte'"));
}

TEST(Yardstick, SequenceNameOfDirectoriesGlobsAndFiles) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "dmc-yardstick-crane";
  std::filesystem::create_directories(dir);
  EXPECT_EQ(SequenceNameOf(dir.string()), "dmc-yardstick-crane");
  EXPECT_EQ(SequenceNameOf(dir.string() + "/"), "dmc-yardstick-crane");
  EXPECT_EQ(SequenceNameOf(dir.string() + "/mesh_*.obj"), "dmc-yardstick-crane");
  EXPECT_EQ(SequenceNameOf("/data/crane-full/crane-full.pc2"), "crane-full");
  EXPECT_EQ(SequenceNameOf("Fox.glb"), "Fox");
  std::filesystem::remove_all(dir);
}

TEST(Yardstick, NearestToStedIsNearestInTheLog) {
  std::vector<YardstickRow> rows(3);
  rows[0].sted = 0.04;
  rows[0].bpfv = 1.0;
  rows[1].sted = 0.011;
  rows[1].bpfv = 2.0;
  rows[2].sted = 0.005;
  rows[2].bpfv = 3.0;
  // |ln(0.04 / 0.02)| = 0.69 > |ln(0.011 / 0.02)| = 0.60, though 0.04 is the nearer in value.
  EXPECT_EQ(NearestToSted(rows, 0.02).bpfv, 2.0);
  EXPECT_EQ(NearestToSted(rows, 0.1).bpfv, 1.0);
  rows[1].sted = 0.01;  // 0.04 and 0.01 are equally far from 0.02: the cheaper wins
  EXPECT_EQ(NearestToSted(rows, 0.02).bpfv, 1.0);
}

TEST(Yardstick, CurveAgainstItselfIsZeroAndScaledCurvesGiveTheirScale) {
  const std::vector<YardstickRow> baseline = Curve("cow");
  const BaselineComparison same = CompareWithBaseline(baseline, baseline, {0.01, 0.02}, 0.02);
  EXPECT_EQ(same.curve, "dmc/ddl");
  ASSERT_TRUE(same.bd_rate_sted && same.bd_rate_kg);
  EXPECT_NEAR(*same.bd_rate_sted, 0.0, 1e-9);
  EXPECT_NEAR(*same.bd_rate_kg, 0.0, 1e-9);

  // 10 % fewer bytes at every distortion: exactly −10 %.
  const BaselineComparison fewer =
      CompareWithBaseline(baseline, Curve("cow", 0.9), {0.01, 0.02}, 0.02);
  ASSERT_TRUE(fewer.bd_rate_sted && fewer.bd_rate_kg);
  EXPECT_NEAR(*fewer.bd_rate_sted, -10.0, 1e-6);
  EXPECT_NEAR(*fewer.bd_rate_kg, -10.0, 1e-6);
  // A baseline that needed 10 % more than the new curve: 1/1.1 − 1 = −9.09 %.
  const BaselineComparison cheaper =
      CompareWithBaseline(Curve("cow", 1.1), baseline, {0.01, 0.02}, 0.02);
  ASSERT_TRUE(cheaper.bd_rate_sted);
  EXPECT_NEAR(*cheaper.bd_rate_sted, -100.0 / 11.0, 1e-6);

  // Rates at the targets, on the exact line rate = 0.02 / STED.
  ASSERT_EQ(fewer.targets.size(), 2u);
  EXPECT_EQ(fewer.targets[0].sted, 0.01);
  EXPECT_EQ(fewer.targets[0].baseline.kind, RateAtTarget::Kind::kInterpolated);
  EXPECT_NEAR(fewer.targets[0].baseline.rate, 2.0, 1e-9);
  EXPECT_NEAR(fewer.targets[0].current.rate, 1.8, 1e-9);
  EXPECT_NEAR(fewer.targets[1].current.rate, 0.9, 1e-9);
  // The breakdown points: STED 0.0168 (k = 3) is nearer 0.02 in the log than 0.0283 (k = 2).
  EXPECT_EQ(fewer.baseline_near.residual_bits, 11);
  EXPECT_EQ(fewer.current_near.residual_bits, 11);
  EXPECT_EQ(fewer.current_near.residual_bytes, 2880u);
}

TEST(Yardstick, ComparisonMarkdownShowsRatesAndShares) {
  const std::vector<YardstickRow> baseline = Curve("dance");
  const std::string md = ComparisonMarkdown(
      "dance", {CompareWithBaseline(baseline, Curve("dance", 0.9), {0.01, 0.02, 0.05}, 0.02)},
      0.02);
  EXPECT_THAT(md, HasSubstr("## Against the baseline's `dance`"));
  EXPECT_THAT(md, HasSubstr("| bpfv @ STED 0.01 (baseline) |"));
  EXPECT_THAT(md, HasSubstr("| dmc/ddl | -10.0 % | -10.0 % | 1.8 (2) | 0.9 (1) | 0.36 (0.4) |"));
  // residuals 2880 of 2880 + 360 + 100 = 3340 bytes, basis 360.
  EXPECT_THAT(md, HasSubstr("| dmc/ddl | current | 11 | 0.01682 | 1.07 | 9 | 86.2 | 10.8 |"));
}

TEST(Yardstick, RowsKeepOnlyTheDmcPoints) {
  RdPoint dmc_point;
  dmc_point.codec = "dmc";
  dmc_point.operator_name = "ddl";
  dmc_point.residual_bits = 11;
  dmc_point.bytes = 100;
  dmc_point.residual_bytes = 70;
  dmc_point.segment_operators = "ddl:2";
  RdPoint draco;
  draco.codec = "draco";
  const std::vector<YardstickRow> rows = YardstickRows("horse", 8431, 48, 2, {dmc_point, draco});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].sequence, "horse");
  EXPECT_EQ(rows[0].vertices, 8431);
  EXPECT_EQ(rows[0].frames, 48);
  EXPECT_EQ(rows[0].effort, 2);
  EXPECT_EQ(rows[0].residual_bits, 11);
  EXPECT_EQ(rows[0].residual_bytes, 70u);
  EXPECT_EQ(rows[0].segment_operators, "ddl:2");
}

}  // namespace
}  // namespace dmc::sweep
