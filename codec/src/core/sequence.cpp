#include "dmc/sequence.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace dmc {

MeshSequence::MeshSequence(int vertex_count, Triangles triangles, int frame_count)
    : vertex_count_(vertex_count), triangles_(std::move(triangles)) {
  ResizeFrames(frame_count);
}

Status MeshSequence::AppendFrame(const Eigen::Ref<const FramePositions>& positions) {
  if (positions.rows() != vertex_count_) {
    return MismatchError("frame " + std::to_string(frame_count_) + " has " +
                         std::to_string(positions.rows()) + " vertices, expected " +
                         std::to_string(vertex_count_));
  }
  ResizeFrames(frame_count_ + 1);
  frame(frame_count_ - 1) = positions;
  return Status::Ok();
}

void MeshSequence::ResizeFrames(int frame_count) {
  frame_count_ = frame_count;
  positions_.resize(static_cast<size_t>(frame_count) * vertex_count_ * 3, 0.0f);
}

Status CheckFiniteFrames(const float* values, int first_frame, int frame_count, int vertex_count) {
  const size_t per_frame = static_cast<size_t>(vertex_count) * 3;
  const size_t count = per_frame * static_cast<size_t>(frame_count);
  for (size_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) {
      return InvalidSequenceError("frame " + std::to_string(first_frame + i / per_frame) +
                                  ", vertex " + std::to_string((i % per_frame) / 3) +
                                  ": coordinate " + "xyz"[i % 3] + " is not finite");
    }
  }
  return Status::Ok();
}

Status ValidateSequence(const MeshSequence& sequence, ValidationReport* report) {
  const int v_count = sequence.vertex_count();
  if (v_count <= 0) return InvalidSequenceError("the sequence has no vertices");
  if (sequence.triangle_count() <= 0) return InvalidSequenceError("the sequence has no triangles");
  if (sequence.frame_count() < 1) return InvalidSequenceError("the sequence has no frames");
  if (sequence.position_value_count() !=
      static_cast<size_t>(sequence.frame_count()) * v_count * 3) {
    return InvalidSequenceError("position storage does not hold frames x vertices x 3 values");
  }
  const Triangles& tris = sequence.triangles();
  for (int t = 0; t < tris.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t index = tris(t, k);
      if (index < 0 || index >= v_count) {
        return InvalidSequenceError("triangle " + std::to_string(t) + " refers to vertex " +
                                    std::to_string(index) + ", outside [0, " +
                                    std::to_string(v_count) + ")");
      }
    }
  }
  DMC_RETURN_IF_ERROR(CheckFiniteFrames(sequence.data(), 0, sequence.frame_count(), v_count));
  ValidationReport local;
  ValidationReport& out = report ? *report : local;
  const auto first = sequence.frame(0);
  int first_degenerate = -1;
  for (int t = 0; t < tris.rows(); ++t) {
    const int a = tris(t, 0), b = tris(t, 1), c = tris(t, 2);
    bool degenerate = a == b || b == c || a == c;
    if (!degenerate) {
      const Eigen::Vector3d pa = first.row(a).cast<double>().transpose();
      const Eigen::Vector3d pb = first.row(b).cast<double>().transpose();
      const Eigen::Vector3d pc = first.row(c).cast<double>().transpose();
      degenerate = (pb - pa).cross(pc - pa).norm() == 0.0;
    }
    if (degenerate) {
      if (first_degenerate < 0) first_degenerate = t;
      ++out.degenerate_triangles;
    }
  }
  if (out.degenerate_triangles > 0) {
    out.warnings.push_back(std::to_string(out.degenerate_triangles) +
                           " degenerate triangle(s) (repeated index or zero area in frame 0), "
                           "first is triangle " +
                           std::to_string(first_degenerate));
  }
  return Status::Ok();
}

Status CheckComparable(const MeshSequence& a, const MeshSequence& b) {
  if (a.frame_count() != b.frame_count()) {
    return MismatchError("frame counts differ: " + std::to_string(a.frame_count()) + " vs " +
                         std::to_string(b.frame_count()));
  }
  if (a.vertex_count() != b.vertex_count()) {
    return MismatchError("vertex counts differ: " + std::to_string(a.vertex_count()) + " vs " +
                         std::to_string(b.vertex_count()));
  }
  if (a.triangle_count() != b.triangle_count()) {
    return MismatchError("triangle counts differ: " + std::to_string(a.triangle_count()) + " vs " +
                         std::to_string(b.triangle_count()));
  }
  if (a.triangles() == b.triangles()) return Status::Ok();
  // A codec may reorder triangles and rotate their indices: equal sets of oriented triangles
  // describe the same mesh.
  auto canonical = [](const Triangles& tris) {
    std::vector<std::array<int32_t, 3>> out(tris.rows());
    for (Eigen::Index t = 0; t < tris.rows(); ++t) {
      // The smallest of the three rotations (the first smallest index is ambiguous when an
      // index repeats: (2, 3, 2) and (2, 2, 3) are one triangle).
      const std::array<int32_t, 3> tri = {tris(t, 0), tris(t, 1), tris(t, 2)};
      out[t] = std::min({tri, std::array<int32_t, 3>{tri[1], tri[2], tri[0]},
                         std::array<int32_t, 3>{tri[2], tri[0], tri[1]}});
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  const auto set_a = canonical(a.triangles()), set_b = canonical(b.triangles());
  for (size_t t = 0; t < set_a.size(); ++t) {
    if (set_a[t] != set_b[t]) {
      return MismatchError("triangle lists differ: oriented triangle (" +
                           std::to_string(set_a[t][0]) + ", " + std::to_string(set_a[t][1]) + ", " +
                           std::to_string(set_a[t][2]) + ") has no counterpart");
    }
  }
  return Status::Ok();
}

BoundingBox ComputeBoundingBox(const MeshSequence& sequence) {
  BoundingBox box;
  if (sequence.frame_count() == 0 || sequence.vertex_count() == 0) return box;
  box.min.setConstant(std::numeric_limits<double>::infinity());
  box.max.setConstant(-std::numeric_limits<double>::infinity());
  for (int f = 0; f < sequence.frame_count(); ++f) {
    const auto positions = sequence.frame(f);
    box.min = box.min.cwiseMin(positions.colwise().minCoeff().cast<double>().transpose());
    box.max = box.max.cwiseMax(positions.colwise().maxCoeff().cast<double>().transpose());
  }
  return box;
}

}  // namespace dmc
