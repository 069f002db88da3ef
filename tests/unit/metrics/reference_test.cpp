// The library against a direct, obviously-correct transcription of ../shared/docs/metrics.md on
// random small meshes, and the invariances of STED and KG.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "dmc/metrics.h"
#include "metrics_test_util.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::RelativeTolerance;

Eigen::Vector3d Position(const MeshSequence& s, int f, int v) {
  return s.frame(f).row(v).cast<double>().transpose();
}

// The definitions, literally: sets for neighbourhoods, IEEE arithmetic for zero-length edges
// (ed = (0 − l′)/0 is NaN or −inf, and 0·ed is NaN), brute-force diameter, window means summed
// directly. Slow and plain on purpose.
struct NaiveMetrics {
  double kg = 0, sted = 0, sted_s = 0, sted_t = 0, rmse_rel = 0, max_error = 0;
};

NaiveMetrics Naive(const MeshSequence& a, const MeshSequence& b, const StedOptions& options) {
  const int F = a.frame_count(), V = a.vertex_count();
  std::set<std::pair<int, int>> edge_set;
  std::vector<std::set<int>> ring(V);
  for (int t = 0; t < a.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int i = a.triangles()(t, k), j = a.triangles()(t, (k + 1) % 3);
      if (i == j) continue;
      edge_set.insert({std::min(i, j), std::max(i, j)});
      ring[i].insert(j);
      ring[j].insert(i);
    }
  }
  const std::vector<std::pair<int, int>> edges(edge_set.begin(), edge_set.end());
  std::vector<std::vector<int>> neighbourhood(V);
  for (int v = 0; v < V; ++v) {
    std::set<int> reached = {v};
    for (int step = 0; step < options.width; ++step) {
      std::set<int> grown = reached;
      for (int u : reached) grown.insert(ring[u].begin(), ring[u].end());
      reached = grown;
    }
    for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
      if (reached.count(edges[e].first) || reached.count(edges[e].second)) {
        neighbourhood[v].push_back(e);
      }
    }
  }

  NaiveMetrics m;
  double spatial = 0.0;
  for (int f = 0; f < F; ++f) {
    for (int v = 0; v < V; ++v) {
      double sum_l = 0.0, sum_led = 0.0;
      std::vector<double> l, ed;
      for (int e : neighbourhood[v]) {
        const double le = (Position(a, f, edges[e].first) - Position(a, f, edges[e].second)).norm();
        const double lp = (Position(b, f, edges[e].first) - Position(b, f, edges[e].second)).norm();
        l.push_back(le);
        ed.push_back((le - lp) / le);
        sum_l += le;
        sum_led += le * ed.back();
      }
      const double avg = sum_led / sum_l;
      if (std::isnan(avg)) continue;
      double sum_dev = 0.0;
      for (size_t k = 0; k < l.size(); ++k) {
        if (l[k] > 0) sum_dev += l[k] * (ed[k] - avg) * (ed[k] - avg);
      }
      spatial += std::sqrt(sum_dev / sum_l);
    }
  }
  m.sted_s = spatial / (V * F);

  double diameter = 0.0;
  for (int i = 0; i < V; ++i) {
    for (int j = 0; j < V; ++j) {
      diameter = std::max(diameter, (Position(a, 0, i) - Position(a, 0, j)).norm());
    }
  }
  auto te = [&](const MeshSequence& s, int f, int v) {
    const Eigen::Vector3d d = (Position(s, f, v) - Position(s, f - 1, v)) / diameter;
    return std::sqrt(d.squaredNorm() + options.dt * options.dt);
  };
  if (F > 1) {
    double temporal = 0.0;
    for (int f = 1; f < F; ++f) {
      const int first = std::max(1, f - options.window + 1);
      const int last = std::min(F - 1, f + options.window);
      for (int v = 0; v < V; ++v) {
        double speed = 0.0;
        for (int g = first; g <= last; ++g) speed += te(a, g, v);
        speed /= (last - first + 1);
        temporal += std::abs(te(b, f, v) - te(a, f, v)) / speed;
      }
    }
    m.sted_t = temporal / (V * (F - 1.0));
  }
  m.sted = std::sqrt(m.sted_s * m.sted_s + options.c * options.c * m.sted_t * m.sted_t);

  double error = 0.0, spread = 0.0;
  Eigen::Vector3d lo = Position(a, 0, 0), hi = lo;
  for (int f = 0; f < F; ++f) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int v = 0; v < V; ++v) centroid += Position(a, f, v) / V;
    for (int v = 0; v < V; ++v) {
      const double e2 = (Position(a, f, v) - Position(b, f, v)).squaredNorm();
      error += e2;
      m.max_error = std::max(m.max_error, std::sqrt(e2));
      spread += (Position(a, f, v) - centroid).squaredNorm();
      lo = lo.cwiseMin(Position(a, f, v));
      hi = hi.cwiseMax(Position(a, f, v));
    }
  }
  m.kg = 100.0 * std::sqrt(error) / std::sqrt(spread);
  m.rmse_rel = std::sqrt(error / (F * V)) / (hi - lo).norm();
  return m;
}

// A random mesh: a perturbed grid, a few arbitrary extra triangles (possibly non-manifold), one
// vertex no triangle uses, random smooth motion; the distorted adds noise, and some frames
// collapse an edge in the original or in the distorted.
std::pair<MeshSequence, MeshSequence> RandomPair(std::mt19937& rng) {
  std::uniform_int_distribution<int> side_dist(2, 5), frame_dist(1, 7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const int side = side_dist(rng), F = frame_dist(rng);
  const int grid = side * side, V = grid + 1;  // the last vertex is isolated
  std::vector<std::array<int32_t, 3>> faces;
  for (int y = 0; y + 1 < side; ++y) {
    for (int x = 0; x + 1 < side; ++x) {
      const int v = y * side + x;
      faces.push_back({v, v + 1, v + side + 1});
      faces.push_back({v, v + side + 1, v + side});
    }
  }
  std::uniform_int_distribution<int> any_vertex(0, grid - 1);
  for (int extra = 0; extra < 2; ++extra) {
    faces.push_back({any_vertex(rng), any_vertex(rng), any_vertex(rng)});
  }
  Triangles tris(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t t = 0; t < faces.size(); ++t) {
    tris.row(static_cast<Eigen::Index>(t)) << faces[t][0], faces[t][1], faces[t][2];
  }
  MeshSequence a(V, tris, F), b(V, tris, F);
  const float phase = u(rng);
  for (int f = 0; f < F; ++f) {
    for (int v = 0; v < V; ++v) {
      const float x = static_cast<float>(v % side) + 0.2f * u(rng);
      const float y = static_cast<float>(v / side) + 0.2f * u(rng);
      const float wave = 0.3f * std::sin(0.7f * static_cast<float>(f) + x + phase);
      a.frame(f).row(v) << x + 0.1f * static_cast<float>(f), y, wave;
      b.frame(f).row(v) = a.frame(f).row(v);
      for (int k = 0; k < 3; ++k) b.frame(f)(v, k) += 0.05f * u(rng);
    }
    if (u(rng) > 0.5f) a.frame(f).row(1) = a.frame(f).row(0);     // zero-length edge 01 in A
    if (u(rng) > 0.5f) b.frame(f).row(side) = b.frame(f).row(0);  // in A′
  }
  return {std::move(a), std::move(b)};
}

TEST(MetricsReference, MatchesNaiveTranscriptionOnRandomMeshes) {
  std::mt19937 rng(31337);
  std::uniform_int_distribution<int> width_dist(0, 3);
  const int windows[] = {1, 2, 3, 5, 10};
  const double dts[] = {0.0003, 0.1};
  for (int trial = 0; trial < 60; ++trial) {
    auto [a, b] = RandomPair(rng);
    StedOptions options;
    options.width = width_dist(rng);
    options.window = windows[trial % 5];
    options.dt = dts[trial % 2];
    options.c = trial % 3 == 0 ? 9.144e-5 : 0.5;
    SCOPED_TRACE(::testing::Message()
                 << "trial " << trial << ", F=" << a.frame_count() << ", V=" << a.vertex_count()
                 << ", w=" << options.width << ", s=" << options.window);
    const NaiveMetrics expected = Naive(a, b, options);
    const auto report = MeasureDistortion(a, b, options);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    EXPECT_NEAR(report->sted_s, expected.sted_s, RelativeTolerance(expected.sted_s));
    EXPECT_NEAR(report->sted_t, expected.sted_t, RelativeTolerance(expected.sted_t));
    EXPECT_NEAR(report->sted, expected.sted, RelativeTolerance(expected.sted));
    EXPECT_NEAR(report->kg, expected.kg, RelativeTolerance(expected.kg));
    EXPECT_NEAR(report->rmse_rel, expected.rmse_rel, RelativeTolerance(expected.rmse_rel));
    EXPECT_NEAR(report->max_error, expected.max_error, RelativeTolerance(expected.max_error));
  }
}

// Applies x ↦ scale·R·x + t to every position.
MeshSequence Transformed(const MeshSequence& s, const Eigen::Matrix3d& rotation, double scale,
                         const Eigen::Vector3d& translation) {
  MeshSequence out = s;
  for (int f = 0; f < s.frame_count(); ++f) {
    for (int v = 0; v < s.vertex_count(); ++v) {
      const Eigen::Vector3d p = scale * rotation * Position(s, f, v) + translation;
      out.frame(f).row(v) = p.cast<float>().transpose();
    }
  }
  return out;
}

// A moving, bumpy grid whose coordinates are multiples of 1/1024 in [0, 2], and a noisy copy
// (noise also on that grid), so that the exact transforms below stay exact in float.
std::pair<MeshSequence, MeshSequence> DyadicPair() {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> noise(-20, 20);
  const MeshSequence grid = testing::PlanarGrid(8, 6);
  MeshSequence a = grid, b = grid;
  for (int f = 0; f < a.frame_count(); ++f) {
    for (int v = 0; v < a.vertex_count(); ++v) {
      const float bump = std::round(200.0f * std::sin(0.5f * static_cast<float>(f + v))) / 1024.f;
      a.frame(f)(v, 2) = 1.0f + bump;
      a.frame(f)(v, 0) = std::round(a.frame(f)(v, 0) * 1024.f) / 1024.f;
      a.frame(f)(v, 1) = std::round(a.frame(f)(v, 1) * 1024.f) / 1024.f;
      for (int k = 0; k < 3; ++k) {
        b.frame(f)(v, k) = a.frame(f)(v, k) + static_cast<float>(noise(rng)) / 1024.f;
      }
    }
  }
  return {a, b};
}

TEST(MetricsInvariance, ExactSimilarityLeavesEveryMetricUnchanged) {
  // Axis permutation with sign flips, scale 4, translation (8, −16, 2): exact in float here.
  auto [a, b] = DyadicPair();
  Eigen::Matrix3d permutation;
  permutation << 0, -1, 0, 0, 0, 1, -1, 0, 0;
  const Eigen::Vector3d translation(8, -16, 2);
  const MeshSequence ta = Transformed(a, permutation, 4.0, translation);
  const MeshSequence tb = Transformed(b, permutation, 4.0, translation);
  const auto before = MeasureDistortion(a, b);
  const auto after = MeasureDistortion(ta, tb);
  ASSERT_TRUE(before.ok() && after.ok());
  EXPECT_GT(before->sted_s, 1e-3);
  EXPECT_GT(before->sted_t, 1e-3);
  EXPECT_NEAR(after->sted_s, before->sted_s, RelativeTolerance(before->sted_s));
  EXPECT_NEAR(after->sted_t, before->sted_t, RelativeTolerance(before->sted_t));
  EXPECT_NEAR(after->sted, before->sted, RelativeTolerance(before->sted));
  EXPECT_NEAR(after->kg, before->kg, RelativeTolerance(before->kg));
  EXPECT_NEAR(after->rmse_rel, before->rmse_rel, RelativeTolerance(before->rmse_rel));
  EXPECT_NEAR(after->max_error, 4.0 * before->max_error, RelativeTolerance(before->max_error));
}

TEST(MetricsInvariance, GeneralRigidMotionAndScaleLeaveStedUnchanged) {
  // A generic rotation rounds every coordinate to float, so agreement is to float precision.
  auto [a, b] = DyadicPair();
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const MeshSequence ta = Transformed(a, rotation, 2.5, Eigen::Vector3d(0.3, -1.2, 0.7));
  const MeshSequence tb = Transformed(b, rotation, 2.5, Eigen::Vector3d(0.3, -1.2, 0.7));
  const auto before = Sted(a, b);
  const auto after = Sted(ta, tb);
  ASSERT_TRUE(before.ok() && after.ok());
  EXPECT_NEAR(after->sted_s, before->sted_s, 1e-4 * before->sted_s);
  EXPECT_NEAR(after->sted_t, before->sted_t, 1e-4 * before->sted_t);
  EXPECT_NEAR(after->sted, before->sted, 1e-4 * before->sted);
  // Moving only the distorted is not a common motion: STED_s must see it.
  const MeshSequence scaled_b = Transformed(b, Eigen::Matrix3d::Identity(), 1.5, {0, 0, 0});
  const auto skewed = Sted(a, scaled_b);
  ASSERT_TRUE(skewed.ok());
  EXPECT_GT(std::abs(skewed->sted_s - before->sted_s), 1e-3);
}

}  // namespace
}  // namespace dmc
