// Shared helpers of the processing tests.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "dmc/processing.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc::testing {

// Prepares `method` on `mesh` or fails the test.
inline PreparedRun MustPrepare(std::string_view method, const MeshSequence& mesh,
                               const RunOptions& options) {
  StatusOr<PreparedRun> run = Prepare(method, mesh, options);
  EXPECT_TRUE(run.ok()) << method << " with " << options.operator_name << ": "
                        << run.status().ToString();
  return run.ok() ? std::move(run).value() : PreparedRun{};
}

// Applies a prepared per-frame method to `positions` or fails the test.
inline FrameOutput MustApply(const PreparedRun& run, const FramePositionsD& positions,
                             const FrameConstraints* constraints = nullptr) {
  if (run.prepared == nullptr) return {};
  StatusOr<FrameOutput> output = run.prepared->Apply(positions, 0, constraints);
  EXPECT_TRUE(output.ok()) << output.status().ToString();
  return output.ok() ? std::move(output).value() : FrameOutput{};
}

// The value of a measurement, or NaN when absent.
inline double MeasurementValue(const std::vector<Measurement>& measurements,
                               std::string_view name) {
  for (const Measurement& m : measurements) {
    if (m.name == name) return m.value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// An icosphere of radius `radius` whose vertices are pushed radially by uniform noise in
// [−amplitude, amplitude]·radius.
inline MeshSequence NoisySphere(int level, double radius, double amplitude, unsigned seed = 3) {
  MeshSequence sphere = Icosphere(level, radius);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-amplitude, amplitude);
  for (int v = 0; v < sphere.vertex_count(); ++v) {
    sphere.frame(0).row(v) *= static_cast<float>(1.0 + noise(rng));
  }
  return sphere;
}

// Standard deviation of the distance to the centroid, relative to its mean: how far a closed
// mesh is from a sphere (scale invariant, so shrinkage alone does not change it).
inline double RadialRoughness(const FramePositionsD& positions) {
  const Eigen::RowVector3d centre = positions.colwise().mean();
  const Eigen::VectorXd radius = (positions.rowwise() - centre).rowwise().norm();
  const double mean = radius.mean();
  return std::sqrt((radius.array() - mean).square().mean()) / mean;
}

// Signed volume of a closed, consistently oriented triangle mesh.
inline double SignedVolume(const Triangles& triangles, const FramePositionsD& positions) {
  double volume = 0.0;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = positions.row(triangles(t, 0)).transpose();
    const Eigen::Vector3d b = positions.row(triangles(t, 1)).transpose();
    const Eigen::Vector3d c = positions.row(triangles(t, 2)).transpose();
    volume += a.dot(b.cross(c));
  }
  return volume / 6.0;
}

}  // namespace dmc::testing
