// What `dmc sweep` writes: the exact CSV columns, empty fields for baselines, the summary's
// interpolated rates and BD-rates on hand-made points.
#include "sweep/report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace dmc::sweep {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

RdPoint DmcPoint(const std::string& op, double bpfv, double sted, double kg) {
  RdPoint point;
  point.codec = "dmc";
  point.operator_name = op;
  point.rank = 12;
  point.basis_bits = 10;
  point.residual_bits = 9.5;
  point.anchors = 100;
  point.bpfv = bpfv;
  point.sted = sted;
  point.kg = kg;
  point.encode_s = 1.25;
  point.decode_s = 0.125;
  return point;
}

RdPoint BaselinePoint(const std::string& codec, int bits, double bpfv, double sted, double kg,
                      double decode_s) {
  RdPoint point;
  point.codec = codec;
  point.residual_bits = bits;
  point.bpfv = bpfv;
  point.sted = sted;
  point.kg = kg;
  point.encode_s = 0.5;
  point.decode_s = decode_s;
  return point;
}

// tutte: rate · STED = 0.1 and rate · KG = 2; ddl needs 80 % of tutte's rate everywhere; draco
// is far dearer and decodes 4 times slower.
std::vector<RdPoint> HandMadePoints() {
  return {DmcPoint("tutte", 1.0, 0.1, 2.0),
          DmcPoint("tutte", 4.0, 0.025, 0.5),
          DmcPoint("tutte", 10.0, 0.01, 0.2),
          DmcPoint("ddl", 0.8, 0.1, 2.0),
          DmcPoint("ddl", 3.2, 0.025, 0.5),
          DmcPoint("ddl", 8.0, 0.01, 0.2),
          BaselinePoint("draco", 8, 8.0, 0.1, 1.0, 0.5),
          BaselinePoint("draco", 12, 16.0, 0.01, 0.1, 0.5)};
}

TEST(RdCsv, HasExactlyTheDocumentedColumnsAndEmptyFieldsForBaselines) {
  RdPoint defaults = DmcPoint("ddl", 2.0, 0.05, 1.0);
  defaults.residual_bits = 10;
  defaults.segment_operators = "tutte:1";
  const std::string csv = RdCsv(HandMadePoints(), defaults);
  EXPECT_EQ(csv.rfind("codec,operator,rank,basis_bits,residual_bits,anchors,bpfv,kg,sted,"
                      "encode_s,decode_s,coded_as,default_settings\n",
                      0),
            0u);
  EXPECT_THAT(csv, HasSubstr("\ndmc,tutte,12,10,9.5,100,4,0.5,0.025,1.2500,0.1250,,0\n"));
  EXPECT_THAT(csv, HasSubstr("\ndraco,,,,8,,8,1,0.1,0.5000,0.5000,,0\n"));
  EXPECT_THAT(csv, HasSubstr("\ndmc,ddl,12,10,10,100,2,1,0.05,1.2500,0.1250,tutte:1,1\n"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 8 + 1);
}

TEST(CurveNames, KeepTheSweepOrder) {
  EXPECT_EQ(CurveNames(HandMadePoints()),
            (std::vector<std::string>{"dmc/tutte", "dmc/ddl", "draco"}));
}

TEST(RdPlot, OneSeriesPerCurveWithBaselinesDashed) {
  const PlotSpec kg = RdPlot(HandMadePoints(), RdMetric::kKg, "samba");
  ASSERT_EQ(kg.series.size(), 3u);
  EXPECT_FALSE(kg.series[0].dashed);
  EXPECT_TRUE(kg.series[2].dashed);
  EXPECT_EQ(kg.series[1].points[2], (std::pair<double, double>{8.0, 0.2}));
  EXPECT_THAT(kg.y_label, HasSubstr("KG"));
  EXPECT_EQ(kg.subtitle, "samba");
  EXPECT_TRUE(kg.marks.empty());
  RdPoint defaults = DmcPoint("ddl", 2.0, 0.05, 1.0);
  defaults.residual_bits = 10;
  const PlotSpec sted = RdPlot(HandMadePoints(), RdMetric::kSted, "samba", defaults);
  ASSERT_EQ(sted.marks.size(), 1u);
  EXPECT_EQ(sted.marks[0].label, "dmc encode defaults (ddl, 10 bits)");
  EXPECT_EQ(sted.marks[0].x, 2.0);
  EXPECT_EQ(sted.marks[0].y, 0.05);
}

TEST(SummaryMarkdown, InterpolatesTargetsAndComputesBdRates) {
  SummaryContext context;
  context.input = "samba";
  context.vertices = 1000;
  context.frames = 10;
  context.sted_targets = {0.05, 0.2, 0.005};
  context.warnings = {"dmc/cotan skipped: unsupported: not yet"};
  const std::string md = SummaryMarkdown(HandMadePoints(), context);
  // tutte at STED 0.05: rate = 0.1 / 0.05 = 2; 0.2 is met by the cheapest point; 0.005 by none.
  // BD-rates against ddl (the default operator: tutte needs 1.25× its rate) and against draco.
  EXPECT_THAT(md, HasSubstr("| dmc/tutte | 2 | ≤ 1 | > 10 | +25.0 % | +25.0 % |"));
  EXPECT_THAT(md, HasSubstr("| dmc/ddl | 1.6 | ≤ 0.8 | > 8 | 0 (anchor) | 0 (anchor) |"));
  EXPECT_THAT(md, HasSubstr("| draco | 9.86 | ≤ 8 | > 16 | +347.2 % | +184.9 % | 0 (anchor) | "
                            "0 (anchor) |"));
  EXPECT_THAT(md, HasSubstr("BD-rate vs dmc/ddl (STED) | BD-rate vs dmc/ddl (KG) | BD-rate vs "
                            "draco (STED) | BD-rate vs draco (KG) |"));
  // draco: rate ∝ STED^(−log 2 / log 10) between its two points; 0.05 → 8 · 2^(log10 2) = 9.86.
  EXPECT_THAT(md, HasSubstr("| draco | 9.86 |"));
  // Speed: dmc decodes in 0.125 s, draco in 0.5 s: 4× faster; 10 000 vertex-frames / 0.125 s.
  EXPECT_THAT(md, HasSubstr("| dmc/tutte | 1.250 | 0.125 | 8e+04 | 4.00× |"));
  EXPECT_THAT(md, HasSubstr("- dmc/cotan skipped: unsupported: not yet"));
  EXPECT_THAT(md, HasSubstr("| draco |  |  |  |  | 12 |  | 16 | 0.1 | 0.01 | 0.500 | 0.500 |"));
  EXPECT_THAT(md, Not(HasSubstr("Default settings")));
}

TEST(SummaryMarkdown, WithoutTheDefaultOperatorTheFirstDmcCurveIsTheAnchor) {
  std::vector<RdPoint> points = HandMadePoints();
  std::erase_if(points, [](const RdPoint& p) { return p.operator_name == "ddl"; });
  const std::string md = SummaryMarkdown(points, SummaryContext());
  EXPECT_THAT(md, HasSubstr("BD-rate vs dmc/tutte (STED)"));
  EXPECT_THAT(md, HasSubstr("| dmc/tutte | 10 | 5 | 2 | 0 (anchor) | 0 (anchor) |"));
}

TEST(SummaryMarkdown, NoBdRateColumnsWithoutAnyAnchorCurve) {
  std::vector<RdPoint> points = HandMadePoints();
  std::erase_if(points, [](const RdPoint& p) { return p.codec == "dmc" || p.codec == "draco"; });
  points.push_back(BaselinePoint("zstd", 8, 8.0, 0.1, 1.0, 0.5));
  points.push_back(BaselinePoint("zstd", 12, 16.0, 0.01, 0.1, 0.5));
  const std::string md = SummaryMarkdown(points, SummaryContext());
  EXPECT_THAT(md, Not(HasSubstr("BD-rate vs")));
  EXPECT_THAT(md, HasSubstr("| zstd | 16 | 13 | 9.86 |\n"));
}

TEST(SummaryMarkdown, ListsTheDefaultSettingsPoint) {
  SummaryContext context;
  RdPoint defaults = DmcPoint("ddl", 2.0, 0.05, 1.0);
  defaults.residual_bits = 10;
  defaults.rank = 7;
  defaults.segment_operators = "tutte:1";
  context.default_point = defaults;
  const std::string md = SummaryMarkdown(HandMadePoints(), context);
  EXPECT_THAT(md, HasSubstr("**Default settings** (`dmc encode` with no rate option: operator ddl, "
                            "10 residual bits, effort 2; the diamond on the plots): 2 bpfv, KG 1, "
                            "STED 0.05, rank 7, coded as tutte:1."));
  EXPECT_THAT(md, HasSubstr("| dmc | ddl (default settings) | tutte:1 | 7 |"));
}

}  // namespace
}  // namespace dmc::sweep
