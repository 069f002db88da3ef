// The SVG plot: ticks on round values, one polyline per series placed where the axes say, the
// legend escaped, points a log axis cannot show skipped.
#include "sweep/svg_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>
#include <vector>

namespace dmc::sweep {
namespace {

int Count(const std::string& text, const std::string& what) {
  int count = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++count;
  }
  return count;
}

TEST(AxisTicks, LogAxesTickOneTwoFive) {
  EXPECT_EQ(AxisTicks(0.1, 50.0, true),
            (std::vector<double>{0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0}));
  EXPECT_EQ(AxisTicks(0.2, 0.5, true), (std::vector<double>{0.2, 0.5}));
}

TEST(AxisTicks, WideLogAxesTickPowersOfTenOnly) {
  EXPECT_EQ(AxisTicks(1e-4, 10.0, true), (std::vector<double>{1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0}));
}

TEST(AxisTicks, LinearAxesTickRoundSteps) {
  const std::vector<double> ticks = AxisTicks(0.0, 1.0, false);
  ASSERT_EQ(ticks.size(), 6u);
  for (size_t i = 0; i < ticks.size(); ++i) EXPECT_NEAR(ticks[i], 0.2 * i, 1e-12);
}

TEST(RenderSvgPlot, DrawsEverySeriesAtItsAxisPosition) {
  PlotSpec spec;
  spec.title = "RD";
  spec.x_label = "bpfv";
  spec.y_label = "STED";
  spec.series = {{"dmc/tutte", {{0.5, 0.1}, {5.0, 0.01}}, false},
                 {"draco", {{10.0, 0.1}, {20.0, 0.02}, {-1.0, 0.5}}, true}};
  const std::string svg = RenderSvgPlot(spec);
  ASSERT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(Count(svg, "<polyline"), 2);
  EXPECT_EQ(Count(svg, "<circle"), 2 + 1);           // dmc's two markers and its legend marker
  EXPECT_EQ(Count(svg, "<rect x="), 2 + 1 + 1 + 1);  // draco's markers, legend, frame, clip
  EXPECT_EQ(Count(svg, "stroke-dasharray"), 2);      // draco's curve and its legend line
  EXPECT_NE(svg.find(">dmc/tutte</text>"), std::string::npos);
  EXPECT_NE(svg.find(">bpfv</text>"), std::string::npos);

  // The x axis spans the round range [0.5, 20] over the plot's pixels [86, 730] (960 − 230), log
  // scale: x = 5 sits at 86 + 644 · log(10) / log(40).
  const std::regex circle("<circle cx=\"([0-9.]+)\" cy=\"([0-9.]+)\"");
  std::vector<double> xs;
  for (std::sregex_iterator it(svg.begin(), svg.end(), circle), end; it != end; ++it) {
    xs.push_back(std::stod((*it)[1]));
  }
  ASSERT_GE(xs.size(), 2u);
  EXPECT_NEAR(xs[0], 86.0, 0.06);
  EXPECT_NEAR(xs[1], 86.0 + 644.0 * std::log(10.0) / std::log(40.0), 0.06);
}

TEST(RenderSvgPlot, EscapesTextAndSurvivesEmptySeries) {
  PlotSpec spec;
  spec.title = "a < b & \"c\"";
  spec.series = {{"<none>", {}, false}};
  const std::string svg = RenderSvgPlot(spec);
  EXPECT_NE(svg.find("a &lt; b &amp; &quot;c&quot;"), std::string::npos);
  EXPECT_NE(svg.find("&lt;none&gt;"), std::string::npos);
  EXPECT_EQ(svg.find("<none>"), std::string::npos);
  EXPECT_EQ(Count(svg, "<polyline"), 0);
}

}  // namespace
}  // namespace dmc::sweep
