// Per-axis low-rank morph targets (gltf_motion_basis.h).
#include "io/gltf_motion_basis.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

namespace dmc::io_internal::glb {
namespace {

bool Within(const Eigen::MatrixXd& error, const FitTolerance& tolerance, double share) {
  const double count = static_cast<double>(error.size());
  return error.cwiseAbs().maxCoeff() <= share * tolerance.max &&
         error.squaredNorm() <= count * (share * tolerance.rms) * (share * tolerance.rms);
}

struct QuantizedFit {
  Eigen::MatrixXd values;   // n × R, integers
  Eigen::MatrixXf weights;  // R × m
  bool within = false;
  bool at_floor = false;  // every target already on its finest int16 step
};

// Rounds `directions` (n × R) on steps no finer than `step` (and no finer than int16 allows),
// refits the weights to the rounded targets and measures the whole fit.
QuantizedFit Quantize(const Eigen::MatrixXd& displacements, const Eigen::MatrixXd& directions,
                      double step, const FitTolerance& tolerance) {
  QuantizedFit fit;
  fit.at_floor = true;
  Eigen::MatrixXd values(directions.rows(), directions.cols());
  Eigen::Index kept = 0;
  for (Eigen::Index k = 0; k < directions.cols(); ++k) {
    const double largest = directions.col(k).cwiseAbs().maxCoeff();
    if (!(largest > 0)) continue;  // a direction the block does not move along
    const double floor = largest / tolerance.largest_value;
    if (step > floor) fit.at_floor = false;
    const double target_step = std::max(step, floor);
    if (!(target_step > 0)) continue;
    Eigen::VectorXd rounded = (directions.col(k) / target_step).array().round().matrix();
    if (rounded.cwiseAbs().maxCoeff() == 0) continue;  // below the step everywhere: no target
    values.col(kept++) = rounded;
  }
  fit.values = values.leftCols(kept);
  if (kept == 0) {
    fit.weights.resize(0, displacements.cols());
    fit.within = Within(displacements, tolerance, 1.0);
    return fit;
  }
  // Least squares weights for the rounded targets: they absorb part of the rounding.
  const Eigen::MatrixXd normal = fit.values.transpose() * fit.values;
  const Eigen::MatrixXd weights = normal.ldlt().solve(fit.values.transpose() * displacements);
  fit.weights = weights.cast<float>();
  const Eigen::MatrixXd error = displacements - fit.values * fit.weights.cast<double>();
  fit.within = weights.allFinite() && Within(error, tolerance, 1.0);
  return fit;
}

// The fewest principal directions whose truncation stays within 70 % of the rms tolerance.
Eigen::Index RmsRank(const Eigen::VectorXd& energy_descending, const FitTolerance& tolerance,
                     Eigen::Index n) {
  const Eigen::Index m = energy_descending.size();
  const double budget = 0.49 * tolerance.rms * tolerance.rms * static_cast<double>(n * m);
  double tail = energy_descending.sum();
  Eigen::Index rank = 0;
  while (rank < m && tail > budget) tail -= energy_descending[rank++];
  return rank;
}

Eigen::VectorXd EnergyDescending(const Eigen::MatrixXd& displacements) {
  const Eigen::MatrixXd gram = displacements.transpose() * displacements;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(gram, Eigen::EigenvaluesOnly);
  return eigen.eigenvalues().reverse().cwiseMax(0.0);
}

// One step target per frame of a block (AxisTarget): positions rounded to the lattice, normals by
// NormalSteps, both closed loop from the base.
std::vector<AxisTarget> StepTargets(const std::array<Eigen::MatrixXd, 3>& displacements,
                                    const std::vector<double>& base, int largest_value) {
  const Eigen::Index n = displacements[0].rows(), m = displacements[0].cols();
  const auto values = static_cast<size_t>(3 * n);
  std::vector<int> sum(values);
  for (size_t k = 0; k < values; ++k) {
    sum[k] =
        static_cast<int>(std::lround(largest_value == 127 ? base[k] * 127.0 / 32767.0 : base[k]));
  }
  std::vector<AxisTarget> targets;
  for (Eigen::Index j = 0; j < m; ++j) {
    AxisTarget& target = targets.emplace_back();
    target.axis = -1;
    target.weights.assign(static_cast<size_t>(m), 0.0f);
    std::fill(target.weights.begin() + j, target.weights.end(), 1.0f);
    std::vector<double> frame(values);
    for (Eigen::Index v = 0; v < n; ++v) {
      for (size_t c = 0; c < 3; ++c) {
        const size_t at = 3 * static_cast<size_t>(v) + c;
        frame[at] = base[at] + displacements[c](v, j);
      }
    }
    if (largest_value == 127) {
      std::vector<float> normals(values);
      for (size_t k = 0; k < values; ++k) normals[k] = static_cast<float>(frame[k] / 32767.0);
      const std::vector<int8_t> steps = NormalSteps(normals, sum);
      target.values.assign(steps.begin(), steps.end());
      continue;
    }
    target.values.resize(values);
    for (size_t k = 0; k < values; ++k) {
      const int q = static_cast<int>(std::clamp(std::round(frame[k]), -16383.0, 16383.0));
      target.values[k] = static_cast<int16_t>(std::clamp(q - sum[k], -32767, 32767));
      sum[k] += target.values[k];
    }
  }
  return targets;
}

}  // namespace

std::vector<int8_t> NormalSteps(const std::vector<float>& normals, std::vector<int>& sum) {
  std::vector<int8_t> q(normals.size());
  for (size_t v = 0; v < normals.size() / 3; ++v) {
    double s = 1.0;
    for (size_t c = 0; c < 3; ++c) {
      const double target = 127.0 * normals[3 * v + c];
      const double previous = sum[3 * v + c];
      if (target - previous > 127.0) s = std::min(s, (previous + 127.0) / target);
      if (target - previous < -127.0) s = std::min(s, (previous - 127.0) / target);
    }
    s = std::max(s, 1.0 / 16);
    for (size_t c = 0; c < 3; ++c) {
      const double step = std::round(s * 127.0 * normals[3 * v + c]) - sum[3 * v + c];
      q[3 * v + c] = static_cast<int8_t>(std::clamp(step, -127.0, 127.0));
      sum[3 * v + c] += q[3 * v + c];
    }
  }
  return q;
}

std::vector<AxisTarget> FitAxisTargets(const Eigen::MatrixXd& displacements, int axis,
                                       const FitTolerance& tolerance) {
  const Eigen::Index n = displacements.rows(), m = displacements.cols();
  if (n == 0 || m == 0 || Within(displacements, tolerance, 1.0)) return {};
  // Principal directions in time, largest first.
  const Eigen::MatrixXd gram = displacements.transpose() * displacements;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(gram);
  const Eigen::MatrixXd directions_in_time = eigen.eigenvectors().rowwise().reverse();
  const Eigen::VectorXd energy = eigen.eigenvalues().reverse().cwiseMax(0.0);
  // The fewest directions whose truncation leaves 70 % of the tolerance (the rest is rounding's):
  // the rms from the eigenvalues, then the largest error, measured, growing the rank by a quarter
  // until it fits.
  Eigen::Index rank = RmsRank(energy, tolerance, n);
  const auto truncation_within = [&](Eigen::Index r) {
    const Eigen::MatrixXd kept = directions_in_time.leftCols(r);
    return Within(displacements - (displacements * kept) * kept.transpose(), tolerance, 0.7);
  };
  while (rank < m && !truncation_within(rank)) {
    rank = std::min(m, rank + std::max<Eigen::Index>(1, rank / 4));
  }
  QuantizedFit fit;
  for (;;) {
    const Eigen::MatrixXd directions = displacements * directions_in_time.leftCols(rank);
    // Start where independent rounding errors on R targets spread over m frames would use half
    // the rms budget, then halve until the measured fit is within the tolerance.
    double step = 0.5 * tolerance.rms *
                  std::sqrt(12.0 * static_cast<double>(m) /
                            static_cast<double>(std::max<Eigen::Index>(rank, 1)));
    // Halving from any start reaches the int16 floor well within 64 steps.
    for (int halvings = 0; halvings < 64; ++halvings) {
      fit = Quantize(displacements, directions, step, tolerance);
      if (fit.within || fit.at_floor) break;
      step *= 0.5;
    }
    // int16 cannot hold these directions finely enough: one more direction takes up the rest.
    if (fit.within || rank == m) break;
    rank = std::min(m, rank + std::max<Eigen::Index>(1, rank / 4));
  }
  std::vector<AxisTarget> targets(static_cast<size_t>(fit.values.cols()));
  for (Eigen::Index k = 0; k < fit.values.cols(); ++k) {
    AxisTarget& target = targets[static_cast<size_t>(k)];
    target.axis = axis;
    target.values.resize(static_cast<size_t>(n));
    for (Eigen::Index v = 0; v < n; ++v) {
      target.values[static_cast<size_t>(v)] = static_cast<int16_t>(fit.values(v, k));
    }
    target.weights.resize(static_cast<size_t>(m));
    for (Eigen::Index j = 0; j < m; ++j) target.weights[static_cast<size_t>(j)] = fit.weights(k, j);
  }
  return targets;
}

std::vector<FrameBlock> SplitBlocks(int frame_count, const std::vector<int>& starts,
                                    int max_length) {
  std::vector<FrameBlock> blocks;
  for (int j = 0; j < frame_count; ++j) {
    const bool starts_here = j == 0 || blocks.back().count >= max_length ||
                             std::find(starts.begin(), starts.end(), j) != starts.end();
    if (starts_here) blocks.push_back({j, 0});
    ++blocks.back().count;
  }
  return blocks;
}

std::vector<BlockTarget> FitBlockTargets(const FrameValues& frame, const std::vector<double>& base,
                                         std::span<const FrameBlock> blocks,
                                         const FitTolerance& tolerance) {
  const auto n = static_cast<Eigen::Index>(base.size() / 3);
  std::vector<BlockTarget> out;
  std::vector<double> values(base.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    std::array<Eigen::MatrixXd, 3> displacements;
    for (Eigen::MatrixXd& axis : displacements) axis.resize(n, blocks[b].count);
    for (int k = 0; k < blocks[b].count; ++k) {
      frame(blocks[b].first + k, values);
      for (Eigen::Index v = 0; v < n; ++v) {
        for (size_t c = 0; c < 3; ++c) {
          const size_t at = 3 * static_cast<size_t>(v) + c;
          displacements[c](v, k) = values[at] - base[at];
        }
      }
    }
    Eigen::Index fitted = 0;
    for (const Eigen::MatrixXd& axis : displacements) {
      fitted += RmsRank(EnergyDescending(axis), tolerance, n);
    }
    if (2 * fitted > 3 * static_cast<Eigen::Index>(blocks[b].count)) {
      for (AxisTarget& target : StepTargets(displacements, base, tolerance.largest_value)) {
        out.push_back({static_cast<int>(b), std::move(target)});
      }
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      for (AxisTarget& target :
           FitAxisTargets(displacements[static_cast<size_t>(c)], c, tolerance)) {
        out.push_back({static_cast<int>(b), std::move(target)});
      }
    }
  }
  return out;
}

std::vector<std::vector<float>> TargetWeights(std::span<const BlockTarget> targets,
                                              std::span<const FrameBlock> blocks, int frame_count) {
  std::vector<std::vector<float>> weights(static_cast<size_t>(frame_count),
                                          std::vector<float>(targets.size(), 0.0f));
  for (size_t t = 0; t < targets.size(); ++t) {
    const FrameBlock& block = blocks[static_cast<size_t>(targets[t].block)];
    for (int k = 0; k < block.count; ++k) {
      weights[static_cast<size_t>(block.first + k)][t] =
          targets[t].target.weights[static_cast<size_t>(k)];
    }
  }
  return weights;
}

}  // namespace dmc::io_internal::glb
