// White-box tests of the generators' building blocks (internal headers of codec/src/synth):
// exact vertex/triangle counts, closed-surface identities and the spherical-harmonic basis.
#include "../../../codec/src/synth/shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../../../codec/src/synth/random.h"
#include "../../../codec/src/synth/spherical_harmonics.h"
#include "dmc/topology.h"

namespace dmc::synth {
namespace {

constexpr double kPi = std::numbers::pi;

// Σ over triangles of the signed tetrahedron volume with the origin, and the total area.
double EnclosedVolume(const RestMesh& mesh) {
  double volume = 0.0;
  for (int t = 0; t < mesh.triangles.rows(); ++t) {
    const Eigen::Vector3d a = mesh.positions.row(mesh.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = mesh.positions.row(mesh.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = mesh.positions.row(mesh.triangles(t, 2)).transpose();
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

TEST(Capsule, CountsTopologyAndVolumeMatchTheFormulas) {
  const double radius = 0.5, length = 2.0;
  const CapsuleLayout layout = LayoutCapsule(radius, length, 0.05);
  const RestMesh capsule = BuildCapsule(radius, length, layout);
  EXPECT_EQ(layout.segments, 63);  // round(2π · 0.5 / 0.05)
  EXPECT_EQ(capsule.vertex_count(), layout.ring_count() * layout.segments + 2);
  EXPECT_EQ(capsule.triangles.rows(), 2 * layout.segments * layout.ring_count());
  const MeshTopology topology = BuildTopology(capsule.triangles, capsule.vertex_count());
  EXPECT_TRUE(topology.is_manifold());
  EXPECT_EQ(topology.euler_characteristic, 2);
  EXPECT_EQ(topology.boundary_edge_count, 0);
  // An inscribed polyhedron: slightly less than the exact capsule volume π r² (L + 4r/3).
  const double exact = kPi * radius * radius * (length + 4.0 * radius / 3.0);
  EXPECT_LT(EnclosedVolume(capsule), exact);
  EXPECT_GT(EnclosedVolume(capsule), 0.99 * exact);
  // Poles first and last, on the axis.
  EXPECT_EQ(capsule.positions.row(0), Eigen::RowVector3d(0, 0, -radius));
  EXPECT_EQ(capsule.positions.row(capsule.vertex_count() - 1),
            Eigen::RowVector3d(0, 0, length + radius));
}

TEST(Capsule, ZeroLengthIsASphereAndCoarseLayoutsKeepTheMinimum) {
  const CapsuleLayout sphere_layout = LayoutCapsule(1.0, 0.0, 0.3);
  EXPECT_EQ(sphere_layout.body_intervals, 0);
  const RestMesh sphere = BuildCapsule(1.0, 0.0, sphere_layout);
  EXPECT_EQ(BuildTopology(sphere.triangles, sphere.vertex_count()).euler_characteristic, 2);
  for (int v = 0; v < sphere.vertex_count(); ++v) {
    EXPECT_NEAR(sphere.positions.row(v).norm(), 1.0, 1e-12);
  }
  const CapsuleLayout coarse = LayoutCapsule(0.01, 1.0, 1.0, 6);
  EXPECT_EQ(coarse.segments, 6);
  EXPECT_EQ(coarse.cap_rings, 0);
  EXPECT_EQ(coarse.body_intervals, 1);
}

TEST(GeodesicSphere, HasTenNSquaredPlusTwoVerticesOnTheUnitSphere) {
  for (int frequency : {1, 2, 5}) {
    const RestMesh sphere = BuildGeodesicSphere(frequency);
    EXPECT_EQ(sphere.vertex_count(), 10 * frequency * frequency + 2);
    EXPECT_EQ(sphere.triangles.rows(), 20 * frequency * frequency);
    const MeshTopology topology = BuildTopology(sphere.triangles, sphere.vertex_count());
    EXPECT_TRUE(topology.is_manifold());
    EXPECT_EQ(topology.euler_characteristic, 2);
    EXPECT_EQ(topology.isolated_vertex_count, 0);
    // The 12 icosahedron corners have 5 neighbours, every other vertex 6.
    int five = 0;
    for (int v = 0; v < sphere.vertex_count(); ++v) {
      EXPECT_NEAR(sphere.positions.row(v).norm(), 1.0, 1e-12);
      five += topology.degree(v) == 5;
      EXPECT_TRUE(topology.degree(v) == 5 || topology.degree(v) == 6);
    }
    EXPECT_EQ(five, 12);
    EXPECT_GT(EnclosedVolume(sphere), 0.0);  // outward orientation
  }
}

TEST(Grid, IsADiskWithAlternatingDiagonalsFacingUp) {
  const RestMesh grid = BuildGrid(4, 3, 3.0, 2.0);
  EXPECT_EQ(grid.vertex_count(), 12);
  EXPECT_EQ(grid.triangles.rows(), 12);
  EXPECT_EQ(grid.positions.row(11), Eigen::RowVector3d(3.0, 2.0, 0.0));
  const MeshTopology topology = BuildTopology(grid.triangles, grid.vertex_count());
  EXPECT_EQ(topology.euler_characteristic, 1);
  EXPECT_EQ(topology.boundary_loop_count, 1);
  EXPECT_EQ(topology.boundary_edge_count, 2 * (3 + 2));
  for (int t = 0; t < grid.triangles.rows(); ++t) {
    const Eigen::Vector3d a = grid.positions.row(grid.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = grid.positions.row(grid.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = grid.positions.row(grid.triangles(t, 2)).transpose();
    EXPECT_NEAR((b - a).cross(c - a).z(), 1.0, 1e-12);  // unit cells: area ½, facing +z
  }
  // Cell (0, 0) is split along v0–v5, its neighbour (1, 0) along v2–v5.
  EXPECT_EQ(grid.triangles.row(0), Eigen::RowVector3i(0, 1, 5));
  EXPECT_EQ(grid.triangles.row(2), Eigen::RowVector3i(1, 2, 5));
}

TEST(FitSpacing, FindsTheCountClosestToTheTarget) {
  // count = round(100 / spacing²): spacing 0.5 gives exactly 400.
  auto count = [](double spacing) {
    return static_cast<int>(std::lround(100.0 / (spacing * spacing)));
  };
  EXPECT_NEAR(FitSpacing(count, 400, 2.0), 0.5, 1e-3);
  // A step function: whatever the start, the closest reachable count wins.
  auto steps = [](double spacing) { return spacing < 1.0 ? 1000 : 10; };
  EXPECT_LT(FitSpacing(steps, 900, 3.0), 1.0);
}

TEST(SphericalHarmonics, AreOrthonormalOverTheSphere) {
  // Quadrature on a fine geodesic sphere: each triangle weighs its spherical area share at the
  // mean of its corner values.
  const RestMesh sphere = BuildGeodesicSphere(24);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(kHarmonicCount, kHarmonicCount);
  double total_area = 0.0;
  for (int t = 0; t < sphere.triangles.rows(); ++t) {
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(kHarmonicCount);
    Eigen::Vector3d corners[3];
    for (int k = 0; k < 3; ++k) {
      corners[k] = sphere.positions.row(sphere.triangles(t, k)).transpose();
      const auto values = RealSphericalHarmonics(corners[k]);
      for (int i = 0; i < kHarmonicCount; ++i) mean[i] += values[i] / 3.0;
    }
    const double area = 0.5 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).norm();
    total_area += area;
    gram += area * mean * mean.transpose();
  }
  gram *= 4.0 * kPi / total_area;  // rescale the polyhedron's area to the sphere's
  EXPECT_TRUE(gram.isApprox(Eigen::MatrixXd::Identity(kHarmonicCount, kHarmonicCount), 1e-2))
      << gram;
  EXPECT_EQ(HarmonicIndex(0, 0), 0);
  EXPECT_EQ(HarmonicIndex(4, 4), kHarmonicCount - 1);
}

TEST(SphericalHarmonics, MatchKnownValuesAtThePole) {
  // At z = 1 only m = 0 survives: Y_l^0(pole) = sqrt((2l + 1) / 4π).
  const auto values = RealSphericalHarmonics(Eigen::Vector3d::UnitZ());
  for (int l = 0; l <= kMaxHarmonicDegree; ++l) {
    for (int m = -l; m <= l; ++m) {
      const double expected = m == 0 ? std::sqrt((2 * l + 1) / (4.0 * kPi)) : 0.0;
      EXPECT_NEAR(values[HarmonicIndex(l, m)], expected, 1e-12) << l << " " << m;
    }
  }
}

TEST(SeededRandom, IsReproducibleAndStreamsDiffer) {
  SeededRandom a(7, 1), b(7, 1), c(7, 2), d(8, 1);
  for (int i = 0; i < 5; ++i) {
    const double value = a.Uniform(-1.0, 1.0);
    EXPECT_EQ(value, b.Uniform(-1.0, 1.0));
    EXPECT_NE(value, c.Uniform(-1.0, 1.0));
    EXPECT_NE(value, d.Uniform(-1.0, 1.0));
    EXPECT_GE(value, -1.0);
    EXPECT_LT(value, 1.0);
  }
  EXPECT_NEAR(a.UnitVector().norm(), 1.0, 1e-12);
}

}  // namespace
}  // namespace dmc::synth
