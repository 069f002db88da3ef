// PointSetDiameter must equal the brute-force maximum exactly, on clouds chosen to stress the
// pruning: uniform, on a sphere (many near-ties), on a circle and a lattice (exact ties),
// clustered, collinear, duplicated.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "dmc/io.h"
#include "dmc/metrics.h"
#include "test_support.h"

namespace dmc {
namespace {

// The obvious O(n²) definition, with the distance expression documented in metrics.h.
double BruteForceDiameter(const FramePositions& points) {
  double best = 0.0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (Eigen::Index j = i + 1; j < points.rows(); ++j) {
      const double dx = static_cast<double>(points(i, 0)) - points(j, 0);
      const double dy = static_cast<double>(points(i, 1)) - points(j, 1);
      const double dz = static_cast<double>(points(i, 2)) - points(j, 2);
      best = std::max(best, dx * dx + dy * dy + dz * dz);
    }
  }
  return std::sqrt(best);
}

FramePositions UniformCube(int n, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  FramePositions points(n, 3);
  for (int i = 0; i < n; ++i) points.row(i) << u(rng), u(rng), 3.0f * u(rng);
  return points;
}

FramePositions OnSphere(int n, std::mt19937& rng) {
  std::normal_distribution<double> g;
  FramePositions points(n, 3);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d p(g(rng), g(rng), g(rng));
    points.row(i) = (p.normalized() * 5.0).cast<float>().transpose();
  }
  return points;
}

FramePositions OnCircle(int n) {
  FramePositions points(n, 3);
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / n;
    points.row(i) << static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)), 0.f;
  }
  return points;
}

FramePositions Lattice(int side) {
  FramePositions points(side * side * side, 3);
  int i = 0;
  for (int x = 0; x < side; ++x) {
    for (int y = 0; y < side; ++y) {
      for (int z = 0; z < side; ++z) {
        points.row(i++) << static_cast<float>(x), static_cast<float>(y), static_cast<float>(z);
      }
    }
  }
  return points;
}

FramePositions Clusters(int n, std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 0.05f);
  std::uniform_int_distribution<int> which(0, 3);
  const float centres[4][3] = {{0, 0, 0}, {10, 1, 0}, {3, -7, 2}, {5, 5, 5}};
  FramePositions points(n, 3);
  for (int i = 0; i < n; ++i) {
    const int c = which(rng);
    points.row(i) << centres[c][0] + g(rng), centres[c][1] + g(rng), centres[c][2] + g(rng);
  }
  return points;
}

TEST(Diameter, TrivialSizes) {
  EXPECT_EQ(PointSetDiameter(FramePositions(0, 3)), 0.0);
  FramePositions one(1, 3);
  one << 1, 2, 3;
  EXPECT_EQ(PointSetDiameter(one), 0.0);
  FramePositions two(2, 3);
  two << 0, 0, 0, 3, 4, 0;
  EXPECT_EQ(PointSetDiameter(two), 5.0);
  FramePositions same(50, 3);
  same.setConstant(2.5f);
  EXPECT_EQ(PointSetDiameter(same), 0.0);
}

TEST(Diameter, HandComputedShapes) {
  // Unit-cube corners: the space diagonal √3. A segment of 100 points from 0 to 9.9 along x.
  EXPECT_EQ(PointSetDiameter(Lattice(2)), std::sqrt(3.0));
  FramePositions segment(100, 3);
  for (int i = 0; i < 100; ++i) segment.row(i) << 0.1f * static_cast<float>(i), 0.f, 0.f;
  EXPECT_EQ(PointSetDiameter(segment), static_cast<double>(0.1f * 99.0f));
}

TEST(Diameter, EqualsBruteForceOnRandomClouds) {
  std::mt19937 rng(20240611);
  for (int trial = 0; trial < 6; ++trial) {
    for (int n : {3, 9, 17, 100, 1500}) {
      const FramePositions cube = UniformCube(n, rng);
      EXPECT_EQ(PointSetDiameter(cube), BruteForceDiameter(cube)) << "cube n=" << n;
      const FramePositions sphere = OnSphere(n, rng);
      EXPECT_EQ(PointSetDiameter(sphere), BruteForceDiameter(sphere)) << "sphere n=" << n;
      const FramePositions clusters = Clusters(n, rng);
      EXPECT_EQ(PointSetDiameter(clusters), BruteForceDiameter(clusters)) << "clusters n=" << n;
    }
  }
}

TEST(Diameter, EqualsBruteForceOnCurvedSurfacesAwayFromTheOrigin) {
  // Near-spheres (the hard case for the pruning), ellipsoids and small clouds far from the
  // origin, where rounding is relative to the large coordinates rather than to the cloud.
  std::mt19937 rng(99);
  std::normal_distribution<double> g;
  const Eigen::Vector3d stretches[] = {{1, 1, 1}, {1, 1, 1.01}, {0.3, 1.8, 0.5}};
  const Eigen::Vector3d offsets[] = {{0, 0, 0}, {1000, -2000, 500}, {3e4, 0, 0}};
  for (const auto& stretch : stretches) {
    for (const auto& offset : offsets) {
      for (double radius : {1e-3, 1.0, 50.0}) {
        FramePositions points(2000, 3);
        for (int i = 0; i < points.rows(); ++i) {
          const Eigen::Vector3d p = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
          points.row(i) = (radius * p.cwiseProduct(stretch) + offset).cast<float>().transpose();
        }
        EXPECT_EQ(PointSetDiameter(points), BruteForceDiameter(points))
            << "stretch " << stretch.transpose() << " offset " << offset.transpose() << " radius "
            << radius;
      }
    }
  }
}

TEST(Diameter, EqualsBruteForceWithExactTies) {
  for (int n : {4, 64, 1000, 2048}) {
    const FramePositions circle = OnCircle(n);
    EXPECT_EQ(PointSetDiameter(circle), BruteForceDiameter(circle)) << "circle n=" << n;
  }
  for (int side : {3, 5, 11}) {
    const FramePositions lattice = Lattice(side);
    EXPECT_EQ(PointSetDiameter(lattice), BruteForceDiameter(lattice)) << "lattice " << side;
  }
  // Duplicates of a few points.
  std::mt19937 rng(7);
  const FramePositions base = UniformCube(5, rng);
  FramePositions repeated(500, 3);
  for (int i = 0; i < 500; ++i) repeated.row(i) = base.row(i % 5);
  EXPECT_EQ(PointSetDiameter(repeated), BruteForceDiameter(repeated));
}

TEST(Diameter, EqualsBruteForceOnRealMeshes) {
  for (const char* name : {"horse-gallop/0001.obj", "samba/mesh_0000.obj"}) {
    DMC_REQUIRE_SHARED_DATA(path, name);
    const auto sequence = ReadSequence(path);
    ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
    const FramePositions frame = sequence->frame(0);
    EXPECT_EQ(PointSetDiameter(frame), BruteForceDiameter(frame)) << name;
  }
}

}  // namespace
}  // namespace dmc
