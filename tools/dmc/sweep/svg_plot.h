// A small, dependency-free SVG line chart for rate–distortion curves: logarithmic axes with
// 1-2-5 ticks and a light grid, labelled axes, a title, one polyline with markers per series and a
// legend beside the plot. Output is deterministic (same input, same bytes).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace dmc::sweep {

struct PlotSeries {
  std::string label;
  std::vector<std::pair<double, double>> points;  // (x, y); drawn in order of increasing x
  bool dashed = false;                            // e.g. the baselines, to set them apart
};

// One point drawn apart from the curves (a black-outlined diamond with its label beside it and in
// the legend), e.g. what the encoder's default settings give.
struct PlotMark {
  std::string label;
  double x = 0.0;
  double y = 0.0;
};

struct PlotSpec {
  std::string title;
  std::string subtitle;  // smaller second line, e.g. the sequence; may be empty
  std::string x_label;
  std::string y_label;
  bool log_x = true;
  bool log_y = true;
  std::vector<PlotSeries> series;
  std::vector<PlotMark> marks;  // drawn over the series; they count in the axes' ranges
  int width = 960;
  int height = 600;
};

// The SVG document. Points that a log axis cannot show (≤ 0) or that are not finite are skipped;
// a series left with no point still appears in the legend. With no point at all the axes span
// [1, 10]. Text is XML-escaped.
std::string RenderSvgPlot(const PlotSpec& spec);

// Axis ticks over [low, high]: on a log axis the 1, 2, 5 multiples of powers of ten (only the
// powers of ten when the range spans more than four decades), on a linear axis about 6 round
// steps. Exposed for tests.
std::vector<double> AxisTicks(double low, double high, bool log_scale);

}  // namespace dmc::sweep
