#include "encoder/basis_writer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>

#include "bitstream/syntax.h"
#include "encoder/range_encoder.h"

namespace dmc::syntax {

namespace {

// Column k's samples quantised to `levels`, by axis then frame.
std::vector<std::vector<int64_t>> QuantiseColumn(const Eigen::MatrixXd& basis, int k, int frames,
                                                 int64_t levels) {
  std::vector<std::vector<int64_t>> samples(3, std::vector<int64_t>(frames));
  for (int axis = 0; axis < 3; ++axis) {
    for (int f = 0; f < frames; ++f) {
      const double value = std::clamp(basis(3 * f + axis, k), -1.0, 1.0);
      samples[axis][f] = std::llround(value * static_cast<double>(levels));
    }
  }
  return samples;
}

}  // namespace

std::vector<uint8_t> WriteBasis(const Eigen::MatrixXd& basis, const format::SegmentHeader& header,
                                Eigen::MatrixXd* decoded) {
  const int frames = static_cast<int>(header.frame_count);
  const int rank = static_cast<int>(header.rank);
  const int64_t levels = (int64_t{1} << (header.basis_bits - 1)) - 1;
  decoded->resize(3 * frames, rank);
  if (rank == 0) return {};
  RangeEncoder encoder;
  auto contexts = std::make_unique<format::BasisContexts>();
  for (int k = 0; k < rank; ++k) {
    const int g = std::min(k, format::kBasisColumnGroups - 1);
    // Quantise all samples, then pick the predictor with the smaller total |residual|.
    const auto samples = QuantiseColumn(basis, k, frames, levels);
    int64_t cost_first = 0, cost_second = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const auto& s = samples[axis];
      for (int f = 2; f < frames; ++f) {
        cost_first += std::llabs(s[f] - s[f - 1]);
        cost_second += std::llabs(s[f] - 2 * s[f - 1] + s[f - 2]);
      }
    }
    const bool second_order = cost_second < cost_first;
    encoder.EncodeBit(contexts->second_order[g], second_order ? 1 : 0);
    for (int axis = 0; axis < 3; ++axis) {
      const auto& s = samples[axis];
      for (int f = 0; f < frames; ++f) {
        int64_t prediction = 0;
        if (f == 1 || (f >= 2 && !second_order)) prediction = s[f - 1];
        if (f >= 2 && second_order) prediction = 2 * s[f - 1] - s[f - 2];
        encoder.EncodeSigned(f == 0 ? contexts->first[g] : contexts->delta[g], s[f] - prediction);
        (*decoded)(3 * f + axis, k) = static_cast<double>(s[f]) / static_cast<double>(levels);
      }
    }
  }
  return encoder.Finish();
}

std::vector<uint8_t> WriteBasis(const Eigen::MatrixXd& basis, const format::SegmentHeader& header,
                                std::span<const uint8_t> depths, Eigen::MatrixXd* decoded) {
  const int frames = static_cast<int>(header.frame_count);
  const int rank = static_cast<int>(header.rank);
  decoded->resize(3 * frames, rank);
  if (rank == 0) return {};
  RangeEncoder encoder;
  auto contexts = std::make_unique<format::BasisContexts>();
  int previous_depth = header.basis_bits;
  for (int k = 0; k < rank; ++k) {
    const int depth = depths[k];
    encoder.EncodeSigned(contexts->depth, depth - previous_depth);
    previous_depth = depth;
    const int g = format::BasisContextGroup(k, depth);
    const int64_t levels = (int64_t{1} << (depth - 1)) - 1;
    const auto samples = QuantiseColumn(basis, k, frames, levels);
    // The predictor with the smallest total |residual| (ties: the lower order).
    int64_t cost[format::kBasisPredictors] = {};
    for (int axis = 0; axis < 3; ++axis) {
      const auto& s = samples[axis];
      for (int f = 0; f < frames; ++f) {
        for (int mode = 0; mode < format::kBasisPredictors; ++mode) {
          cost[mode] += std::llabs(s[f] - format::PredictBasisSample(mode, s.data(), f));
        }
      }
    }
    int mode = 0;
    for (int m = 1; m < format::kBasisPredictors; ++m) {
      if (cost[m] < cost[mode]) mode = m;
    }
    format::EncodeBasisPredictor(
        *contexts, g, mode, [&](AdaptiveBit& bit, int value) { encoder.EncodeBit(bit, value); });
    for (int axis = 0; axis < 3; ++axis) {
      const auto& s = samples[axis];
      for (int f = 0; f < frames; ++f) {
        const int64_t prediction = format::PredictBasisSample(mode, s.data(), f);
        encoder.EncodeSigned(f == 0 ? contexts->first[g] : contexts->delta[g], s[f] - prediction);
        (*decoded)(3 * f + axis, k) = static_cast<double>(s[f]) / static_cast<double>(levels);
      }
    }
  }
  return encoder.Finish();
}

std::vector<uint8_t> ChooseBasisDepths(std::span<const double> eigenvalues, int rank,
                                       int vertex_count, double residual_step, int max_bits) {
  const double share = kBasisErrorShare;
  std::vector<uint8_t> depths(rank, static_cast<uint8_t>(max_bits));
  for (int k = 0; k < rank; ++k) {
    // levels >= sqrt(λ_k / (share · V)) / Δ.
    const double wanted =
        std::sqrt(std::max(eigenvalues[k], 0.0) / (share * std::max(vertex_count, 1))) /
        residual_step;
    int bits = max_bits;
    if (wanted < 0x1p20) {
      const auto levels = static_cast<uint64_t>(std::ceil(wanted));
      bits = 1 + std::bit_width(levels);
    }
    depths[k] = static_cast<uint8_t>(std::clamp(bits, format::kMinBasisBits, max_bits));
  }
  return depths;
}

}  // namespace dmc::syntax
