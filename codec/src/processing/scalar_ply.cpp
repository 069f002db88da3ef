// ASCII PLY with a per-vertex scalar property and colours (the curvature output). The io
// library's PLY writer has no extra vertex properties, and this is the only place that needs one.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "dmc/io.h"
#include "dmc/processing.h"

namespace dmc {

std::array<uint8_t, 3> DivergingColour(double value, double range) {
  // Blue (negative) – white (zero) – red (positive), linear in each half.
  const double t = range > 0.0 && std::isfinite(value) ? std::clamp(value / range, -1.0, 1.0) : 0.0;
  const auto channel = [](double x) {
    return static_cast<uint8_t>(std::lround(std::clamp(x, 0.0, 1.0) * 255.0));
  };
  if (t >= 0.0) return {255, channel(1.0 - t), channel(1.0 - t)};
  return {channel(1.0 + t), channel(1.0 + t), 255};
}

Status WriteScalarPly(const std::filesystem::path& path, const Triangles& triangles,
                      const FramePositionsD& positions, const Eigen::VectorXd& scalars,
                      std::string_view scalar_name) {
  if (scalars.size() != positions.rows()) {
    return InvalidArgumentError(
        fmt::format("{} scalars for {} vertices", scalars.size(), positions.rows()));
  }
  const bool identifier =
      !scalar_name.empty() && std::all_of(scalar_name.begin(), scalar_name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
      });
  if (!identifier) {
    return InvalidArgumentError(
        fmt::format("scalar name '{}' is not a PLY property name", scalar_name));
  }
  // Saturation at the 98th percentile of |value| so a few outliers do not wash out the map.
  std::vector<double> magnitudes;
  magnitudes.reserve(static_cast<size_t>(scalars.size()));
  for (double value : scalars) {
    if (std::isfinite(value)) magnitudes.push_back(std::abs(value));
  }
  double range = 0.0;
  if (!magnitudes.empty()) {
    const size_t k = std::min(magnitudes.size() - 1,
                              static_cast<size_t>(0.98 * static_cast<double>(magnitudes.size())));
    std::nth_element(magnitudes.begin(), magnitudes.begin() + static_cast<std::ptrdiff_t>(k),
                     magnitudes.end());
    range = magnitudes[k];
  }
  std::string text = fmt::format(
      "ply\nformat ascii 1.0\ncomment dmc per-vertex {} (colours: blue < 0 < red, saturating at "
      "|{}| = {})\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
      "property float {}\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      scalar_name, scalar_name, range, positions.rows(), scalar_name, triangles.rows());
  for (Eigen::Index v = 0; v < positions.rows(); ++v) {
    const std::array<uint8_t, 3> colour = DivergingColour(scalars[v], range);
    // {} of a float is its shortest round-trip form.
    fmt::format_to(std::back_inserter(text), "{} {} {} {} {} {} {}\n",
                   static_cast<float>(positions(v, 0)), static_cast<float>(positions(v, 1)),
                   static_cast<float>(positions(v, 2)), static_cast<float>(scalars[v]), colour[0],
                   colour[1], colour[2]);
  }
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    fmt::format_to(std::back_inserter(text), "3 {} {} {}\n", triangles(t, 0), triangles(t, 1),
                   triangles(t, 2));
  }
  return WriteFileAtomically(
      path, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

}  // namespace dmc
