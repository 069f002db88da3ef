// Anchor vertices of a segment: the vertices whose coefficients are coded directly, so that the
// normal equations (L̃ᵀL̃)C = L̃ᵀ[δ; anchors] have a unique solution.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "dmc/encoder.h"
#include "dmc/topology.h"

namespace dmc {

// The anchor count a segment of `vertex_count` vertices and `frame_count` frames asks for:
// EncoderOptions::anchors when set, else 1 % of the vertices (2 % from kLongSegmentFrames
// frames: a long segment's anchors constrain more frames for the same per-segment cost;
// jump-full gained 3.8 points of BD-rate, RD.md "Anchors and steps"), at least 1 and at most
// 1000 (farthest-point sampling costs O(V · anchors), so the cap keeps it linear in V beyond
// 100k vertices).
int RequestedAnchorCount(const EncoderOptions& options, int vertex_count, int frame_count);

// Farthest-point sampling of `count` vertices (clamped to [1, V]) on the segment's mean shape
// (V × 3), starting at vertex 0, then one anchor added to every component that has none (the
// normal matrix is singular otherwise). Ascending indices. The same for any thread count.
std::vector<int32_t> ChooseAnchors(const Eigen::MatrixXd& mean_shape, const MeshTopology& topology,
                                   int count);

}  // namespace dmc
