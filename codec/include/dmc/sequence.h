// MeshSequence: a dynamic mesh — one triangle list shared by every frame, F frames of V positions.
//
// Storage contract:
//  - Triangles are int32, T×3, row-major, counter-clockwise as read; indices are 0-based.
//  - Positions are float32, stored contiguously frame after frame: position (f, v, axis) lives at
//    data()[(f * V + v) * 3 + axis]. Math that needs precision converts to double on the fly.
//  - The sequence does not validate itself on construction; call ValidateSequence() on anything
//    read from outside before trusting it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "dmc/status.h"

namespace dmc {

using Triangles = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using FramePositions = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using FramePositionsD = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

class MeshSequence {
 public:
  MeshSequence() = default;
  // Creates a sequence of `frame_count` frames of `vertex_count` vertices, all at the origin.
  MeshSequence(int vertex_count, Triangles triangles, int frame_count = 0);

  int vertex_count() const { return vertex_count_; }
  int frame_count() const { return frame_count_; }
  int triangle_count() const { return static_cast<int>(triangles_.rows()); }

  const Triangles& triangles() const { return triangles_; }
  Triangles& mutable_triangles() { return triangles_; }

  Eigen::Map<FramePositions> frame(int f) {
    return {positions_.data() + static_cast<size_t>(f) * vertex_count_ * 3, vertex_count_, 3};
  }
  Eigen::Map<const FramePositions> frame(int f) const {
    return {positions_.data() + static_cast<size_t>(f) * vertex_count_ * 3, vertex_count_, 3};
  }
  // Frame f converted to double precision.
  FramePositionsD frame_d(int f) const { return frame(f).cast<double>(); }

  // Appends a frame. Fails with kMismatch (naming the frame) if its vertex count differs.
  Status AppendFrame(const Eigen::Ref<const FramePositions>& positions);
  // Resizes to `frame_count` frames; new frames are zero.
  void ResizeFrames(int frame_count);

  float* data() { return positions_.data(); }
  const float* data() const { return positions_.data(); }
  size_t position_value_count() const { return positions_.size(); }

  std::string name;         // free-form, e.g. the input's base name
  double frame_rate = 0.0;  // frames per second; 0 when unknown

 private:
  int vertex_count_ = 0;
  int frame_count_ = 0;
  Triangles triangles_;
  std::vector<float> positions_;
};

// Findings of ValidateSequence that do not make the sequence unusable.
struct ValidationReport {
  int degenerate_triangles = 0;  // repeated index, or zero area in frame 0
  std::vector<std::string> warnings;
};

// Checks the model invariants and returns the first violation as an error that names the frame,
// vertex or triangle at fault:
//  - kInvalidSequence: no vertices, no triangles, no frames, a triangle index outside [0, V),
//    a non-finite coordinate, storage size inconsistent with V×F.
// Degenerate triangles are not fatal: they are counted and described in `report` (may be null).
Status ValidateSequence(const MeshSequence& sequence, ValidationReport* report = nullptr);

// ValidateSequence's coordinate check on `frame_count` frames stored from `values` (V×3 floats
// each, the MeshSequence layout) whose first is frame `first_frame`: kInvalidSequence
// "frame F, vertex V: coordinate y is not finite" at the first NaN or infinity. For callers that
// hold frames a block at a time (the streaming encoder and measurement).
Status CheckFiniteFrames(const float* values, int first_frame, int frame_count, int vertex_count);

// Fails with kMismatch naming the first difference if `a` and `b` cannot be compared vertex by
// vertex: frame count, vertex count, or triangles. Triangle lists match when they hold the same
// set of oriented triangles (order and rotation of each triangle's indices may differ, as after
// a codec's connectivity coding; orientation may not).
Status CheckComparable(const MeshSequence& a, const MeshSequence& b);

// Axis-aligned bounding box over all frames (double precision).
struct BoundingBox {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  double diagonal() const { return (max - min).norm(); }
};
BoundingBox ComputeBoundingBox(const MeshSequence& sequence);

}  // namespace dmc
