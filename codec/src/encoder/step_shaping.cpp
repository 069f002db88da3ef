#include "encoder/step_shaping.h"

#include <algorithm>
#include <cmath>

#include "bitstream/syntax.h"

namespace dmc {
namespace {

// The encoder keeps the factors within [1/4, 4]: beyond, a region's error would dwarf or be
// dwarfed by its neighbours'. The format allows format::kMaxStepExponent.
constexpr int kLargestExponent = 2 * format::kStepExponentsPerOctave;

}  // namespace

double AutomaticStepShapingStrength(double log_spread) {
  return std::clamp((log_spread - 0.25) / 0.35, 0.0, 1.0);
}

std::vector<int8_t> ChooseStepExponents(const Eigen::MatrixXd& mean_shape,
                                        const MeshTopology& topology,
                                        std::span<const int32_t> anchors, double strength) {
  std::vector<int8_t> exponents(anchors.size(), 0);
  if (strength == 0.0 || anchors.empty()) return exponents;
  const int v_count = topology.vertex_count;
  std::vector<double> length(v_count, 0.0);
  std::vector<int> edges(v_count, 0);
  for (const auto& [i, j] : topology.edges) {
    const double l = (mean_shape.row(i) - mean_shape.row(j)).norm();
    length[i] += l;
    length[j] += l;
    ++edges[i];
    ++edges[j];
  }
  // log2 of each usable vertex's mean edge length, NaN for the others.
  std::vector<double> log_length(v_count, std::nan(""));
  double sum = 0.0;
  int used = 0;
  for (int v = 0; v < v_count; ++v) {
    const double mean = edges[v] > 0 ? length[v] / edges[v] : 0.0;
    if (mean > 0.0 && std::isfinite(mean)) {
      log_length[v] = std::log2(mean);
      sum += log_length[v];
      ++used;
    }
  }
  if (used == 0) return exponents;
  const double log_mean = sum / used;
  if (strength < 0.0) {
    double squares = 0.0;
    for (const double x : log_length) {
      if (!std::isnan(x)) squares += (x - log_mean) * (x - log_mean);
    }
    strength = AutomaticStepShapingStrength(std::sqrt(squares / used) * std::log(2.0));
    if (strength == 0.0) return exponents;
  }
  const std::vector<int32_t> owner = format::AnchorRegions(topology, anchors);
  std::vector<double> region_sum(anchors.size(), 0.0);
  std::vector<int> region_count(anchors.size(), 0);
  for (int v = 0; v < v_count; ++v) {
    if (owner[v] < 0 || std::isnan(log_length[v])) continue;
    region_sum[owner[v]] += log_length[v] - log_mean;
    ++region_count[owner[v]];
  }
  for (size_t a = 0; a < anchors.size(); ++a) {
    if (region_count[a] == 0) continue;
    const double e =
        std::round(format::kStepExponentsPerOctave * strength * region_sum[a] / region_count[a]);
    exponents[a] = static_cast<int8_t>(std::clamp(e, static_cast<double>(-kLargestExponent),
                                                  static_cast<double>(kLargestExponent)));
  }
  return exponents;
}

}  // namespace dmc
