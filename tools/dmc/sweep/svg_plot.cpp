#include "sweep/svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

namespace dmc::sweep {
namespace {

// Tableau 10: distinct at a glance and readable when printed in grey.
constexpr std::array<std::string_view, 10> kPalette = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2",
                                                       "#59a14f", "#edc948", "#b07aa1", "#ff9da7",
                                                       "#9c755f", "#bab0ac"};

// Relative slack so that values printed as round numbers still count as on a tick.
constexpr double kTickSlack = 1e-9;

std::string Escape(std::string_view text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The largest 1-2-5 value ≤ value (round_up = false) or the smallest ≥ value (true), value > 0.
double NiceLog(double value, bool round_up) {
  const double decade = std::pow(10.0, std::floor(std::log10(value)));
  const double mantissa = value / decade;
  constexpr std::array<double, 4> kSteps = {1.0, 2.0, 5.0, 10.0};
  if (round_up) {
    for (const double step : kSteps) {
      if (step >= mantissa * (1.0 - kTickSlack)) return step * decade;
    }
    return 10.0 * decade;
  }
  double best = 1.0;
  for (const double step : kSteps) {
    if (step <= mantissa * (1.0 + kTickSlack)) best = step;
  }
  return best * decade;
}

// A round step giving about `count` intervals over `span` > 0.
double NiceStep(double span, int count) {
  const double raw = span / count;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double step : {1.0, 2.0, 5.0}) {
    if (step * decade >= raw * (1.0 - kTickSlack)) return step * decade;
  }
  return 10.0 * decade;
}

std::string TickLabel(double value) {
  if (value == 0.0) return "0";
  const double magnitude = std::abs(value);
  if (magnitude >= 1e-4 && magnitude < 1e6) {
    std::string text = fmt::format("{:.6f}", value);
    text.erase(text.find_last_not_of('0') + 1);
    if (text.back() == '.') text.pop_back();
    return text;
  }
  return fmt::format("{:g}", value);
}

struct Axis {
  double low = 1.0, high = 10.0;
  bool log_scale = true;
  double pixel_low = 0.0, pixel_high = 1.0;  // pixel of `low` and of `high`

  double Map(double value) const {
    const double t = log_scale
                         ? (std::log(value) - std::log(low)) / (std::log(high) - std::log(low))
                         : (value - low) / (high - low);
    return pixel_low + t * (pixel_high - pixel_low);
  }
};

// Data range of one coordinate, widened to round values.
Axis MakeAxis(const std::vector<double>& values, bool log_scale) {
  Axis axis;
  axis.log_scale = log_scale;
  if (values.empty()) {
    axis.low = log_scale ? 1.0 : 0.0;
    axis.high = 10.0;
    return axis;
  }
  double low = *std::min_element(values.begin(), values.end());
  double high = *std::max_element(values.begin(), values.end());
  if (log_scale) {
    if (high / low < 1.5) {  // a (nearly) single value: show a little around it
      low /= 1.5;
      high *= 1.5;
    }
    axis.low = NiceLog(low, false);
    axis.high = NiceLog(high, true);
  } else {
    if (high - low <= std::abs(high) * 1e-12) {
      low -= 1.0;
      high += 1.0;
    }
    const double step = NiceStep(high - low, 6);
    axis.low = std::floor(low / step + kTickSlack) * step;
    axis.high = std::ceil(high / step - kTickSlack) * step;
  }
  return axis;
}

bool Drawable(double value, bool log_scale) {
  return std::isfinite(value) && (!log_scale || value > 0.0);
}

}  // namespace

std::vector<double> AxisTicks(double low, double high, bool log_scale) {
  std::vector<double> ticks;
  if (!(high > low)) return ticks;
  if (log_scale) {
    if (!(low > 0.0)) return ticks;
    const bool powers_only = std::log10(high / low) > 4.0;
    for (double decade = std::pow(10.0, std::floor(std::log10(low)));
         decade <= high * (1.0 + kTickSlack); decade *= 10.0) {
      for (const double step : {1.0, 2.0, 5.0}) {
        if (powers_only && step != 1.0) continue;
        const double tick = step * decade;
        if (tick >= low * (1.0 - kTickSlack) && tick <= high * (1.0 + kTickSlack)) {
          ticks.push_back(tick);
        }
      }
    }
    return ticks;
  }
  const double step = NiceStep(high - low, 6);
  for (double tick = std::ceil(low / step - kTickSlack) * step; tick <= high + step * kTickSlack;
       tick += step) {
    ticks.push_back(std::abs(tick) < step * kTickSlack ? 0.0 : tick);
  }
  return ticks;
}

std::string RenderSvgPlot(const PlotSpec& spec) {
  const double width = spec.width, height = spec.height;
  const double left = 86.0, right = width - 230.0, top = spec.subtitle.empty() ? 52.0 : 68.0,
               bottom = height - 62.0;

  std::vector<double> xs, ys;
  for (const PlotSeries& series : spec.series) {
    for (const auto& [x, y] : series.points) {
      if (Drawable(x, spec.log_x) && Drawable(y, spec.log_y)) {
        xs.push_back(x);
        ys.push_back(y);
      }
    }
  }
  for (const PlotMark& mark : spec.marks) {
    if (Drawable(mark.x, spec.log_x) && Drawable(mark.y, spec.log_y)) {
      xs.push_back(mark.x);
      ys.push_back(mark.y);
    }
  }
  Axis x_axis = MakeAxis(xs, spec.log_x);
  Axis y_axis = MakeAxis(ys, spec.log_y);
  x_axis.pixel_low = left;
  x_axis.pixel_high = right;
  y_axis.pixel_low = bottom;
  y_axis.pixel_high = top;

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\" font-family=\"Helvetica, Arial, sans-serif\">\n"
      "<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n",
      spec.width, spec.height);
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"26\" font-size=\"18\" font-weight=\"bold\" "
      "text-anchor=\"middle\">{}</text>\n",
      (left + right) / 2, Escape(spec.title));
  if (!spec.subtitle.empty()) {
    svg += fmt::format(
        "<text x=\"{:.1f}\" y=\"46\" font-size=\"13\" fill=\"#555\" "
        "text-anchor=\"middle\">{}</text>\n",
        (left + right) / 2, Escape(spec.subtitle));
  }

  // Grid and tick labels.
  svg += "<g stroke=\"#e3e3e3\" stroke-width=\"1\">\n";
  const std::vector<double> x_ticks = AxisTicks(x_axis.low, x_axis.high, spec.log_x);
  const std::vector<double> y_ticks = AxisTicks(y_axis.low, y_axis.high, spec.log_y);
  for (const double tick : x_ticks) {
    const double px = x_axis.Map(tick);
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\"/>\n", px,
                       top, bottom);
  }
  for (const double tick : y_ticks) {
    const double py = y_axis.Map(tick);
    svg += fmt::format("<line x1=\"{1:.1f}\" y1=\"{0:.1f}\" x2=\"{2:.1f}\" y2=\"{0:.1f}\"/>\n", py,
                       left, right);
  }
  svg += "</g>\n<g font-size=\"12\" fill=\"#333\">\n";
  for (const double tick : x_ticks) {
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n",
                       x_axis.Map(tick), bottom + 18, TickLabel(tick));
  }
  for (const double tick : y_ticks) {
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", left - 8,
                       y_axis.Map(tick) + 4, TickLabel(tick));
  }
  svg += "</g>\n";
  svg += fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"none\" "
      "stroke=\"#333\" stroke-width=\"1\"/>\n",
      left, top, right - left, bottom - top);
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"14\" text-anchor=\"middle\">{}</text>\n",
      (left + right) / 2, height - 18, Escape(spec.x_label));
  svg += fmt::format(
      "<text x=\"22\" y=\"{0:.1f}\" font-size=\"14\" text-anchor=\"middle\" "
      "transform=\"rotate(-90 22 {0:.1f})\">{1}</text>\n",
      (top + bottom) / 2, Escape(spec.y_label));

  // Curves, clipped to the plot area, then the legend.
  svg += fmt::format(
      "<clipPath id=\"plot-area\"><rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" "
      "height=\"{:.1f}\"/></clipPath>\n<g clip-path=\"url(#plot-area)\">\n",
      left, top, right - left, bottom - top);
  for (size_t s = 0; s < spec.series.size(); ++s) {
    const PlotSeries& series = spec.series[s];
    const std::string_view color = kPalette[s % kPalette.size()];
    std::vector<std::pair<double, double>> points;
    for (const auto& [x, y] : series.points) {
      if (Drawable(x, spec.log_x) && Drawable(y, spec.log_y)) points.emplace_back(x, y);
    }
    std::stable_sort(points.begin(), points.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    if (points.size() > 1) {
      std::string path;
      for (const auto& [x, y] : points) {
        path +=
            fmt::format("{}{:.1f},{:.1f}", path.empty() ? "" : " ", x_axis.Map(x), y_axis.Map(y));
      }
      svg += fmt::format(
          "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"{}/>\n", path,
          color, series.dashed ? " stroke-dasharray=\"7 4\"" : "");
    }
    for (const auto& [x, y] : points) {
      if (series.dashed) {
        svg +=
            fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"7\" height=\"7\" fill=\"{}\"/>\n",
                        x_axis.Map(x) - 3.5, y_axis.Map(y) - 3.5, color);
      } else {
        svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3.5\" fill=\"{}\"/>\n",
                           x_axis.Map(x), y_axis.Map(y), color);
      }
    }
  }
  const auto diamond = [](double x, double y) {
    return fmt::format(
        "<polygon points=\"{:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f}\" "
        "fill=\"white\" stroke=\"black\" stroke-width=\"2\"/>\n",
        x, y - 7, x + 7, y, x, y + 7, x - 7, y);
  };
  for (const PlotMark& mark : spec.marks) {
    if (!Drawable(mark.x, spec.log_x) || !Drawable(mark.y, spec.log_y)) continue;
    const double x = x_axis.Map(mark.x), y = y_axis.Map(mark.y);
    svg += diamond(x, y);
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\">{}</text>\n", x + 10,
                       y - 8, Escape(mark.label));
  }
  svg += "</g>\n<g font-size=\"13\">\n";
  const double legend_x = right + 18;
  for (size_t s = 0; s < spec.series.size(); ++s) {
    const PlotSeries& series = spec.series[s];
    const std::string_view color = kPalette[s % kPalette.size()];
    const double y = top + 10 + 24.0 * static_cast<double>(s);
    svg += fmt::format(
        "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" "
        "stroke-width=\"2\"{}/>\n",
        legend_x, y, legend_x + 30, y, color, series.dashed ? " stroke-dasharray=\"7 4\"" : "");
    if (series.dashed) {
      svg += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"7\" height=\"7\" fill=\"{}\"/>\n",
                         legend_x + 11.5, y - 3.5, color);
    } else {
      svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3.5\" fill=\"{}\"/>\n",
                         legend_x + 15, y, color);
    }
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n", legend_x + 40, y + 4.5,
                       Escape(series.label));
  }
  for (size_t m = 0; m < spec.marks.size(); ++m) {
    const double y = top + 10 + 24.0 * static_cast<double>(spec.series.size() + m);
    svg += diamond(legend_x + 15, y);
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n", legend_x + 40, y + 4.5,
                       Escape(spec.marks[m].label));
  }
  svg += "</g>\n</svg>\n";
  return svg;
}

}  // namespace dmc::sweep
