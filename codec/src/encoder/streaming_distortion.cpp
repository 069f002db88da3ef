#include "encoder/streaming_distortion.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace dmc {
namespace {

// Vertices per block of the temporal part: src/metrics/sted.cpp's kTemporalBlock. The blocks fix
// the order of the additions, so they must be the same blocks.
constexpr int kTemporalBlock = 256;

double EdgeLength(const float* positions, int32_t i, int32_t j) {
  const double dx = static_cast<double>(positions[3 * i]) - positions[3 * j];
  const double dy = static_cast<double>(positions[3 * i + 1]) - positions[3 * j + 1];
  const double dz = static_cast<double>(positions[3 * i + 2]) - positions[3 * j + 2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

struct SpatialScratch {
  std::vector<double> length;
  std::vector<double> relative_difference;
};

// Σ_v dev(v) of one frame, as sted.cpp's SpatialFrameSum forms it.
double SpatialFrameSum(const metrics_internal::StedReference& reference, const float* original,
                       const float* distorted, SpatialScratch& scratch) {
  const auto& edges = reference.edges;
  const int edge_count = static_cast<int>(edges.size());
  scratch.length.resize(edge_count);
  scratch.relative_difference.resize(edge_count);
  for (int e = 0; e < edge_count; ++e) {
    const double l = EdgeLength(original, edges[e][0], edges[e][1]);
    const double l_distorted = EdgeLength(distorted, edges[e][0], edges[e][1]);
    scratch.length[e] = l;
    scratch.relative_difference[e] =
        l > 0.0 ? (l - l_distorted) / l : std::numeric_limits<double>::quiet_NaN();
  }
  const auto& offsets = reference.neighbourhoods.offsets;
  const auto& indices = reference.neighbourhoods.edge_indices;
  const int vertex_count = static_cast<int>(offsets.size()) - 1;
  double frame_sum = 0.0;
  for (int v = 0; v < vertex_count; ++v) {
    const int32_t* begin = indices.data() + offsets[v];
    const int32_t* end = indices.data() + offsets[v + 1];
    double length_sum = 0.0;
    double weighted_sum = 0.0;
    for (const int32_t* e = begin; e != end; ++e) {
      length_sum += scratch.length[*e];
      weighted_sum += scratch.length[*e] * scratch.relative_difference[*e];
    }
    const double average = weighted_sum / length_sum;
    if (std::isnan(average)) continue;  // zero-length edge in N(v), or N(v) empty: contributes 0
    double deviation_sum = 0.0;
    for (const int32_t* e = begin; e != end; ++e) {
      const double l = scratch.length[*e];
      if (l > 0.0) {
        const double centred = scratch.relative_difference[*e] - average;
        deviation_sum += l * centred * centred;
      }
    }
    frame_sum += std::sqrt(deviation_sum / length_sum);
  }
  return frame_sum;
}

// te = sqrt(‖(current − previous) / D‖² + dt²) of one vertex.
inline double TemporalEdgeLength(const float* current, const float* previous, double diameter,
                                 double dt) {
  const double x = (static_cast<double>(current[0]) - previous[0]) / diameter;
  const double y = (static_cast<double>(current[1]) - previous[1]) / diameter;
  const double z = (static_cast<double>(current[2]) - previous[2]) / diameter;
  return std::sqrt(x * x + y * y + z * z + dt * dt);
}

}  // namespace

StatusOr<StreamingDistortion> StreamingDistortion::Create(const Triangles& triangles,
                                                          int vertex_count, int frame_count,
                                                          const float* frame0,
                                                          const StedOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateStedOptions(options));
  if (vertex_count <= 0 || frame_count <= 0) {
    return InvalidSequenceError("the sequence has no vertices or no frames");
  }
  // PrepareSted on frame 0 alone gives exactly what it gives on the whole original: the edges,
  // the neighbourhoods and D depend on the triangles and frame 0 only. (With one frame it does
  // not check D > 0; FinishOriginal does.)
  MeshSequence first_frame(vertex_count, triangles, 1);
  std::copy_n(frame0, static_cast<size_t>(vertex_count) * 3, first_frame.data());
  StreamingDistortion meter;
  DMC_ASSIGN_OR_RETURN(meter.sted_, metrics_internal::PrepareSted(first_frame, options));
  meter.vertex_count_ = vertex_count;
  meter.frame_count_ = frame_count;
  meter.window_ = std::min<int64_t>(options.window, frame_count);
  meter.temporal_block_sums_.assign((vertex_count + kTemporalBlock - 1) / kTemporalBlock, 0.0);
  meter.box_.min.setConstant(std::numeric_limits<double>::infinity());
  meter.box_.max.setConstant(-std::numeric_limits<double>::infinity());
  return meter;
}

void StreamingDistortion::AddOriginalFrame(const float* data) {
  const Eigen::Map<const FramePositions> positions(data, vertex_count_, 3);
  // kg.cpp's PrepareKg: centroid first, then squared deviations, per frame.
  double centroid[3] = {0.0, 0.0, 0.0};
  for (int v = 0; v < vertex_count_; ++v) {
    for (int k = 0; k < 3; ++k) centroid[k] += positions(v, k);
  }
  for (double& coordinate : centroid) coordinate /= vertex_count_;
  double sum = 0.0;
  for (int v = 0; v < vertex_count_; ++v) {
    for (int k = 0; k < 3; ++k) {
      const double deviation = positions(v, k) - centroid[k];
      sum += deviation * deviation;
    }
  }
  centroid_deviation_squared_ += sum;
  box_.min = box_.min.cwiseMin(positions.colwise().minCoeff().cast<double>().transpose());
  box_.max = box_.max.cwiseMax(positions.colwise().maxCoeff().cast<double>().transpose());
  ++original_frames_seen_;
}

Status StreamingDistortion::FinishOriginal() {
  if (original_frames_seen_ != frame_count_) {
    return InternalError("StreamingDistortion: " + std::to_string(original_frames_seen_) + " of " +
                         std::to_string(frame_count_) + " original frames seen");
  }
  if (frame_count_ > 1 && !(sted_.diameter > 0.0)) {
    return InvalidSequenceError(
        "STED_t is undefined: frame 0 of the original is a single point (diameter D = 0)");
  }
  if (!(centroid_deviation_squared_ > 0.0)) {
    return InvalidSequenceError(
        "KG error is undefined: every frame of the original is a single point (||A - E(A)|| = 0)");
  }
  return Status::Ok();
}

std::pair<int, int> StreamingDistortion::OriginalWindow(int first, int count) const {
  const int reach = static_cast<int>(window_);
  return {std::max(0, first - reach), std::min(frame_count_, first + count + reach)};
}

Status StreamingDistortion::AddSegment(int first, int count, const float* original,
                                       const float* decoded) {
  if (first != next_frame_ || count <= 0 || count > frame_count_ - first) {
    return InvalidArgumentError("StreamingDistortion: segment [" + std::to_string(first) + ", " +
                                std::to_string(first + count) + ") out of order (next frame " +
                                std::to_string(next_frame_) + ")");
  }
  const size_t frame_stride = static_cast<size_t>(vertex_count_) * 3;
  for (size_t i = 0; i < static_cast<size_t>(count) * frame_stride; ++i) {
    if (!std::isfinite(decoded[i])) {
      return InvalidSequenceError("distorted: frame " + std::to_string(first + i / frame_stride) +
                                  ", vertex " + std::to_string((i % frame_stride) / 3) +
                                  ": coordinate " + "xyz"[i % 3] + " is not finite");
    }
  }
  const int window_first = OriginalWindow(first, count).first;
  // original_frame(f): frame f of the original, for f in the window.
  auto original_frame = [&](int64_t f) {
    return original + static_cast<size_t>(f - window_first) * frame_stride;
  };
  auto decoded_frame = [&](int64_t f) {
    return f < first ? previous_decoded_.data()
                     : decoded + static_cast<size_t>(f - first) * frame_stride;
  };

  // Spatial part and vertex errors: per frame, added in frame order.
  std::vector<double> spatial(count), squared(count), largest(count);
  tbb::enumerable_thread_specific<SpatialScratch> scratches;
  tbb::parallel_for(tbb::blocked_range<int>(0, count), [&](const tbb::blocked_range<int>& range) {
    SpatialScratch& scratch = scratches.local();
    for (int i = range.begin(); i < range.end(); ++i) {
      const float* a = original_frame(first + i);
      const float* b = decoded_frame(first + i);
      spatial[i] = SpatialFrameSum(sted_, a, b, scratch);
      double sum = 0.0, most = 0.0;
      for (int v = 0; v < vertex_count_; ++v) {
        const double dx = static_cast<double>(a[3 * v]) - b[3 * v];
        const double dy = static_cast<double>(a[3 * v + 1]) - b[3 * v + 1];
        const double dz = static_cast<double>(a[3 * v + 2]) - b[3 * v + 2];
        const double value = dx * dx + dy * dy + dz * dz;
        sum += value;
        most = std::max(most, value);
      }
      squared[i] = sum;
      largest[i] = most;
    }
  });
  for (int i = 0; i < count; ++i) {
    spatial_total_ += spatial[i];
    squared_error_sum_ += squared[i];
    largest_squared_error_ = std::max(largest_squared_error_, largest[i]);
  }

  // Temporal part: frames f >= 1 of the segment, per vertex block, each block continuing its sum.
  const int64_t frames = frame_count_;
  const int64_t t_first = std::max(first, 1), t_end = first + count;
  if (frames > 1 && t_first < t_end) {
    const double diameter = sted_.diameter;
    const double dt = sted_.options.dt;
    // te of the original is needed for frames [g_low, g_high] (each uses the frame before it).
    const int64_t g_low = std::max<int64_t>(1, t_first - window_ + 1);
    const int64_t g_high = std::min<int64_t>(frames - 1, t_end - 1 + window_);
    const int block_count = static_cast<int>(temporal_block_sums_.size());
    tbb::enumerable_thread_specific<std::vector<double>> te_caches;
    tbb::parallel_for(
        tbb::blocked_range<int>(0, block_count, 1), [&](const tbb::blocked_range<int>& range) {
          std::vector<double>& te = te_caches.local();
          for (int b = range.begin(); b < range.end(); ++b) {
            const int v_begin = b * kTemporalBlock;
            const int v_end = std::min(vertex_count_, v_begin + kTemporalBlock);
            const int block = v_end - v_begin;
            te.resize(static_cast<size_t>(g_high - g_low + 1) * block);
            auto te_of = [&](int64_t g) {
              return te.data() + static_cast<size_t>(g - g_low) * block;
            };
            for (int64_t g = g_low; g <= g_high; ++g) {
              const float* current = original_frame(g);
              const float* previous = original_frame(g - 1);
              double* row = te_of(g);
              for (int v = v_begin; v < v_end; ++v) {
                row[v - v_begin] =
                    TemporalEdgeLength(current + 3 * v, previous + 3 * v, diameter, dt);
              }
            }
            double block_sum = temporal_block_sums_[b];
            for (int64_t f = t_first; f < t_end; ++f) {
              const int64_t window_low = std::max<int64_t>(1, f - window_ + 1);
              const int64_t window_high = std::min<int64_t>(frames - 1, f + window_);
              const double window_frames = static_cast<double>(window_high - window_low + 1);
              const double* te_now = te_of(f);
              const float* current = decoded_frame(f);
              const float* previous = decoded_frame(f - 1);
              for (int v = v_begin; v < v_end; ++v) {
                double speed_sum = 0.0;
                for (int64_t g = window_low; g <= window_high; ++g)
                  speed_sum += te_of(g)[v - v_begin];
                const double local_speed = speed_sum / window_frames;
                const double te_distorted =
                    TemporalEdgeLength(current + 3 * v, previous + 3 * v, diameter, dt);
                const double term = std::abs(te_distorted - te_now[v - v_begin]) / local_speed;
                if (!std::isnan(term)) block_sum += term;
              }
            }
            temporal_block_sums_[b] = block_sum;
          }
        });
  }

  previous_decoded_.assign(decoded_frame(t_end - 1), decoded_frame(t_end - 1) + frame_stride);
  next_frame_ = first + count;
  return Status::Ok();
}

StatusOr<DistortionReport> StreamingDistortion::Report() const {
  if (next_frame_ != frame_count_) {
    return InternalError("StreamingDistortion: " + std::to_string(next_frame_) + " of " +
                         std::to_string(frame_count_) + " frames measured");
  }
  // distortion.cpp's DistortionMeter::Measure and sted.cpp's ComputeSted, term for term.
  StedResult sted;
  sted.sted_s = spatial_total_ / (static_cast<double>(vertex_count_) * frame_count_);
  if (frame_count_ > 1) {
    const double temporal_total =
        std::accumulate(temporal_block_sums_.begin(), temporal_block_sums_.end(), 0.0);
    sted.sted_t = temporal_total / (static_cast<double>(vertex_count_) * (frame_count_ - 1));
  }
  const double c = sted_.options.c;
  sted.sted = std::sqrt(sted.sted_s * sted.sted_s + c * c * sted.sted_t * sted.sted_t);
  const double value_count = static_cast<double>(frame_count_) * static_cast<double>(vertex_count_);
  DistortionReport report;
  report.kg = 100.0 * std::sqrt(squared_error_sum_) / std::sqrt(centroid_deviation_squared_);
  report.sted = sted.sted;
  report.sted_s = sted.sted_s;
  report.sted_t = sted.sted_t;
  report.rmse_rel = std::sqrt(squared_error_sum_ / value_count) / box_.diagonal();
  report.max_error = std::sqrt(largest_squared_error_);
  report.frames = frame_count_;
  report.vertices = vertex_count_;
  return report;
}

}  // namespace dmc
