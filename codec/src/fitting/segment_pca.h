// Trajectory PCA of one segment (CODDYAC): each vertex's trajectory over the segment's F frames
// is a 3F vector (x0, y0, z0, x1, ...); the mean trajectory over vertices is subtracted and the
// principal trajectories are the eigenvectors of the 3F×3F Gram matrix XcᵀXc — cheap because
// 3F ≪ V, and exact (no iterative truncation). The encoder's PCA, and the routines the public
// ComputeTrajectoryPca (dmc/pca.h) is built on: the double overloads run the same double sums as
// the float ones on the same values.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "dmc/sequence.h"

namespace dmc {

// V × 3F trajectories of frames [first_frame, first_frame + frame_count), kept in float32: they
// are the input's own values, so nothing is lost, and the encoder holds half the memory of a
// double copy. Everything computed from them is computed in double. With a non-empty `relabel`,
// row i holds input vertex relabel[i] (the codec's vertex order).
using SegmentTrajectories = Eigen::MatrixXf;
SegmentTrajectories GatherTrajectories(const MeshSequence& sequence, int first_frame,
                                       int frame_count, const std::vector<int32_t>& relabel = {});

// Stores one frame (V × 3 floats, the MeshSequence layout) as columns 3f, 3f + 1, 3f + 2 of
// `trajectories`, relabelled as GatherTrajectories does: the encoder fills a segment's
// trajectories frame by frame from its FrameSource with it (GatherTrajectories serves the tests
// and benchmarks that start from a MeshSequence, with the same values).
void StoreFrame(const float* positions, int frame_in_segment, const std::vector<int32_t>& relabel,
                SegmentTrajectories& trajectories);

struct SegmentPca {
  Eigen::VectorXd mean;          // 3F: mean over vertices of the trajectories
  Eigen::VectorXd eigenvalues;   // descending, ≥ 0: squared singular values of the centred data
  Eigen::MatrixXd eigenvectors;  // 3F × 3F, columns in the order of eigenvalues
};

// Deterministic for any thread count (sums run over fixed row blocks, added in block order).
SegmentPca ComputeSegmentPca(const SegmentTrajectories& trajectories);
SegmentPca ComputeSegmentPca(const Eigen::MatrixXd& trajectories);

// The 3F mean over vertices, as ComputeSegmentPca computes it.
Eigen::VectorXd MeanTrajectory(const Eigen::MatrixXd& trajectories);

// (X − 1·meanᵀ)·basis, V × r, in double over fixed row blocks.
Eigen::MatrixXd ProjectTrajectories(const SegmentTrajectories& trajectories,
                                    const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis);
Eigen::MatrixXd ProjectTrajectories(const Eigen::MatrixXd& trajectories,
                                    const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis);

// The mean shape over the segment's frames, V × 3.
Eigen::MatrixXd MeanShape(const SegmentTrajectories& trajectories);

}  // namespace dmc
