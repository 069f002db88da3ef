// Tests of the built-in synthetic animations through the public API: the generator table, option
// errors, determinism, mesh validity (manifold, oriented, expected topology), vertex budgets and
// smoothness in time.
#include "dmc/synth.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "dmc/io.h"
#include "dmc/topology.h"

namespace dmc {
namespace {

// Topology every generator promises (see synth.h).
struct ExpectedShape {
  std::string_view name;
  int components;
  int boundary_loops;
  int euler_characteristic;
  bool closed;
};
constexpr ExpectedShape kShapes[] = {
    {"twist", 1, 0, 2, true},
    {"cloth", 1, 1, 1, false},
    {"walker", 6, 0, 12, true},
    {"blob", 1, 0, 2, true},
};

MeshSequence MustSynthesize(std::string_view name, const SynthOptions& options) {
  StatusOr<MeshSequence> result = Synthesize(name, options);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  return result.ok() ? std::move(result).value() : MeshSequence();
}

bool SameBytes(const MeshSequence& a, const MeshSequence& b) {
  return a.vertex_count() == b.vertex_count() && a.frame_count() == b.frame_count() &&
         a.triangles() == b.triangles() &&
         std::memcmp(a.data(), b.data(), a.position_value_count() * sizeof(float)) == 0;
}

Eigen::Vector3d Position(const MeshSequence& sequence, int frame, int vertex) {
  return sequence.frame(frame).row(vertex).cast<double>().transpose();
}

double TriangleArea(const MeshSequence& sequence, int frame, int t) {
  const auto& tri = sequence.triangles();
  const Eigen::Vector3d a = Position(sequence, frame, tri(t, 0));
  const Eigen::Vector3d b = Position(sequence, frame, tri(t, 1));
  const Eigen::Vector3d c = Position(sequence, frame, tri(t, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

// Signed volume enclosed by each connected component (positive when normals point outwards).
std::vector<double> ComponentVolumes(const MeshSequence& sequence, const MeshTopology& topology,
                                     int frame) {
  std::vector<double> volumes(topology.component_count, 0.0);
  const auto& tri = sequence.triangles();
  for (int t = 0; t < sequence.triangle_count(); ++t) {
    const Eigen::Vector3d a = Position(sequence, frame, tri(t, 0));
    const Eigen::Vector3d b = Position(sequence, frame, tri(t, 1));
    const Eigen::Vector3d c = Position(sequence, frame, tri(t, 2));
    volumes[topology.component_of_vertex[tri(t, 0)]] += a.dot(b.cross(c)) / 6.0;
  }
  return volumes;
}

// Every directed edge used at most once: neighbouring triangles are consistently oriented.
bool ConsistentlyOriented(const Triangles& triangles) {
  std::set<std::pair<int, int>> directed;
  for (int t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (!directed.insert({triangles(t, k), triangles(t, (k + 1) % 3)}).second) return false;
    }
  }
  return true;
}

// Number of vertices sharing their exact position with another vertex in frame 0.
int DuplicateVertexCount(const MeshSequence& sequence) {
  std::vector<std::array<float, 3>> points(sequence.vertex_count());
  for (int v = 0; v < sequence.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) points[v][k] = sequence.frame(0)(v, k);
  }
  std::sort(points.begin(), points.end());
  return static_cast<int>(points.end() - std::unique(points.begin(), points.end()));
}

// Largest |p(f+1) − 2 p(f) + p(f−1)| over all vertices and frames.
double MaxSecondDifference(const MeshSequence& sequence) {
  double worst = 0.0;
  for (int f = 1; f + 1 < sequence.frame_count(); ++f) {
    // Evaluated into a vector: an `auto` Eigen expression would reference dead temporaries.
    const Eigen::VectorXd acceleration =
        (sequence.frame_d(f + 1) - 2.0 * sequence.frame_d(f) + sequence.frame_d(f - 1))
            .rowwise()
            .norm();
    worst = std::max(worst, acceleration.maxCoeff());
  }
  return worst;
}

// Largest distance a vertex travels away from its frame-0 position.
double MaxDisplacement(const MeshSequence& sequence) {
  double worst = 0.0;
  for (int f = 1; f < sequence.frame_count(); ++f) {
    worst =
        std::max(worst, (sequence.frame_d(f) - sequence.frame_d(0)).rowwise().norm().maxCoeff());
  }
  return worst;
}

TEST(SynthTable, ListsTheFourGeneratorsInOrder) {
  const std::vector<std::string_view> expected = {"twist", "cloth", "walker", "blob"};
  EXPECT_EQ(SynthNames(), expected);
  for (std::string_view name : SynthNames()) EXPECT_FALSE(SynthDescription(name).empty()) << name;
  EXPECT_TRUE(SynthDescription("teapot").empty());
}

TEST(SynthOptionsErrors, UnknownNameIsNotFoundAndListsTheNames) {
  const auto result = Synthesize("teapot", {});
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(result.status().message().find("'teapot'"), std::string::npos);
  EXPECT_NE(result.status().message().find("twist, cloth, walker, blob"), std::string::npos)
      << result.status().message();
}

TEST(SynthOptionsErrors, ImpossibleOptionsNameTheOption) {
  struct Case {
    SynthOptions options;
    const char* option;
  };
  const Case cases[] = {
      {{.frames = 0}, "frames"},
      {{.frames = -3}, "frames"},
      {{.frames = kMaxSynthFrames + 1}, "frames"},
      {{.resolution = kMinSynthResolution - 1}, "resolution"},
      {{.resolution = kMaxSynthResolution + 1}, "resolution"},
      {{.resolution = -1}, "resolution"},
  };
  for (const Case& c : cases) {
    const auto result = Synthesize("blob", c.options);
    ASSERT_FALSE(result.ok()) << c.option;
    EXPECT_EQ(result.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(result.status().message().rfind(c.option, 0), 0u) << result.status().message();
  }
  // The limits themselves are accepted.
  EXPECT_TRUE(Synthesize("cloth", {.frames = 1, .resolution = kMinSynthResolution}).ok());
}

class SynthGeneratorTest : public ::testing::TestWithParam<ExpectedShape> {};

TEST_P(SynthGeneratorTest, SetsNameAndFrameRate) {
  const MeshSequence sequence = MustSynthesize(GetParam().name, {.frames = 7, .resolution = 500});
  EXPECT_EQ(sequence.name, GetParam().name);
  EXPECT_EQ(sequence.frame_rate, 30.0);
  EXPECT_EQ(sequence.frame_count(), 7);
}

TEST_P(SynthGeneratorTest, SameSeedGivesIdenticalBytesAndOtherSeedsOtherMotion) {
  const SynthOptions options{.frames = 12, .resolution = 800, .seed = 42};
  const MeshSequence first = MustSynthesize(GetParam().name, options);
  const MeshSequence again = MustSynthesize(GetParam().name, options);
  EXPECT_TRUE(SameBytes(first, again));

  SynthOptions other_seed = options;
  other_seed.seed = 43;
  const MeshSequence other = MustSynthesize(GetParam().name, other_seed);
  EXPECT_EQ(other.triangles(), first.triangles()) << "connectivity must not depend on the seed";
  ASSERT_EQ(other.position_value_count(), first.position_value_count());
  EXPECT_NE(std::memcmp(other.data(), first.data(), first.position_value_count() * sizeof(float)),
            0);
}

TEST_P(SynthGeneratorTest, ShorterSequenceIsAPrefixOfALongerOne) {
  const MeshSequence shorter = MustSynthesize(GetParam().name, {.frames = 5, .resolution = 600});
  const MeshSequence longer = MustSynthesize(GetParam().name, {.frames = 9, .resolution = 600});
  ASSERT_EQ(shorter.vertex_count(), longer.vertex_count());
  EXPECT_EQ(shorter.triangles(), longer.triangles());
  EXPECT_EQ(
      std::memcmp(shorter.data(), longer.data(), shorter.position_value_count() * sizeof(float)),
      0);
}

// Every size: valid, no degenerate or duplicate geometry, manifold with the promised topology,
// consistently oriented, and the vertex count near the request.
TEST_P(SynthGeneratorTest, ValidManifoldAndNearTheRequestedResolution) {
  const ExpectedShape& shape = GetParam();
  for (int resolution : {500, 5'000, 50'000}) {
    SCOPED_TRACE(resolution);
    const MeshSequence sequence =
        MustSynthesize(shape.name, {.frames = 2, .resolution = resolution});
    // The documented tolerance: ±15% from 500 vertices, ±10% from 1,000.
    const double tolerance = resolution < 1'000 ? 0.15 : 0.10;
    EXPECT_NEAR(static_cast<double>(sequence.vertex_count()) / resolution, 1.0, tolerance);

    ValidationReport report;
    ASSERT_TRUE(ValidateSequence(sequence, &report).ok());
    EXPECT_EQ(report.degenerate_triangles, 0);
    EXPECT_EQ(DuplicateVertexCount(sequence), 0);

    const MeshTopology topology = BuildTopology(sequence.triangles(), sequence.vertex_count());
    EXPECT_TRUE(topology.is_manifold());
    EXPECT_EQ(topology.isolated_vertex_count, 0);
    EXPECT_EQ(topology.component_count, shape.components);
    EXPECT_EQ(topology.boundary_loop_count, shape.boundary_loops);
    EXPECT_EQ(topology.euler_characteristic, shape.euler_characteristic);
    EXPECT_TRUE(ConsistentlyOriented(sequence.triangles()));
    if (shape.closed) {
      for (double volume : ComponentVolumes(sequence, topology, 0)) EXPECT_GT(volume, 0.0);
    }
  }
}

// The requested resolution range's ends stay valid too (minimum samplings kick in at 100).
TEST_P(SynthGeneratorTest, SmallestResolutionIsStillAValidMesh) {
  const MeshSequence sequence = MustSynthesize(GetParam().name, {.frames = 1, .resolution = 100});
  ValidationReport report;
  ASSERT_TRUE(ValidateSequence(sequence, &report).ok());
  EXPECT_EQ(report.degenerate_triangles, 0);
  const MeshTopology topology = BuildTopology(sequence.triangles(), sequence.vertex_count());
  EXPECT_TRUE(topology.is_manifold());
  EXPECT_EQ(topology.euler_characteristic, GetParam().euler_characteristic);
  EXPECT_LT(sequence.vertex_count(), 300);
}

// Smooth, visible motion: accelerations stay a small fraction of the size, the mesh moves by a
// visible amount, no triangle collapses or flips and closed parts keep their volume.
TEST_P(SynthGeneratorTest, MotionIsSmoothVisibleAndFreeOfCollapse) {
  const ExpectedShape& shape = GetParam();
  const MeshSequence sequence = MustSynthesize(shape.name, {.frames = 60, .resolution = 2000});
  const double diagonal = ComputeBoundingBox(sequence).diagonal();
  EXPECT_LT(MaxSecondDifference(sequence), 0.01 * diagonal);
  EXPECT_GT(MaxDisplacement(sequence), 0.05 * diagonal);

  const MeshTopology topology = BuildTopology(sequence.triangles(), sequence.vertex_count());
  const std::vector<double> rest_volumes = ComponentVolumes(sequence, topology, 0);
  double smallest_area_ratio = 1.0;
  for (int f = 0; f < sequence.frame_count(); ++f) {
    for (int t = 0; t < sequence.triangle_count(); ++t) {
      smallest_area_ratio = std::min(smallest_area_ratio,
                                     TriangleArea(sequence, f, t) / TriangleArea(sequence, 0, t));
    }
    if (shape.closed) {
      const std::vector<double> volumes = ComponentVolumes(sequence, topology, f);
      for (size_t c = 0; c < volumes.size(); ++c) {
        EXPECT_GT(volumes[c], 0.0);
        // The blob's volume breathes by design; the others are near-isometric.
        if (shape.name != "blob") {
          EXPECT_NEAR(volumes[c] / rest_volumes[c], 1.0, 0.02) << c;
        }
      }
    }
  }
  EXPECT_GT(smallest_area_ratio, 0.3);
}

INSTANTIATE_TEST_SUITE_P(AllGenerators, SynthGeneratorTest, ::testing::ValuesIn(kShapes),
                         [](const auto& info) { return std::string(info.param.name); });

// The generators' output is what the quickstart writes: it must survive a PC2 round trip bit for
// bit, frame rate included.
TEST(SynthOutput, RoundTripsThroughAPointCache) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("dmc_synth_roundtrip_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const MeshSequence walker = MustSynthesize("walker", {.frames = 4, .resolution = 400});
  ASSERT_TRUE(WriteSequence(walker, dir / "walker.pc2").ok());
  const StatusOr<MeshSequence> read = ReadSequence(dir / "walker.pc2");
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_TRUE(SameBytes(*read, walker));
  EXPECT_EQ(read->frame_rate, 30.0);
}

TEST(SynthCloth, PinnedEdgeStaysStill) {
  const MeshSequence cloth = MustSynthesize("cloth", {.frames = 20, .resolution = 1000});
  int pinned = 0;
  for (int v = 0; v < cloth.vertex_count(); ++v) {
    if (cloth.frame(0)(v, 0) != 0.0f) continue;
    ++pinned;
    for (int f = 1; f < cloth.frame_count(); ++f) {
      EXPECT_EQ(Position(cloth, f, v), Position(cloth, 0, v)) << "vertex " << v << " frame " << f;
    }
  }
  EXPECT_GE(pinned, 10);  // a whole grid column
}

TEST(SynthWalker, HeadMovesRigidlyAndTheFigureWalksForward) {
  const MeshSequence walker = MustSynthesize("walker", {.frames = 30, .resolution = 3000});
  const MeshTopology topology = BuildTopology(walker.triangles(), walker.vertex_count());
  // The head is the component with the highest rest-pose vertex; one bone, so rigid.
  int top = 0;
  for (int v = 0; v < walker.vertex_count(); ++v) {
    if (walker.frame(0)(v, 1) > walker.frame(0)(top, 1)) top = v;
  }
  std::vector<int> head;
  for (int v = 0; v < walker.vertex_count(); ++v) {
    if (topology.component_of_vertex[v] == topology.component_of_vertex[top]) head.push_back(v);
  }
  ASSERT_GT(head.size(), 20u);
  const int last = walker.frame_count() - 1;
  for (size_t i = 1; i < head.size(); i += 7) {
    const double rest = (Position(walker, 0, head[i]) - Position(walker, 0, head[0])).norm();
    const double moved = (Position(walker, last, head[i]) - Position(walker, last, head[0])).norm();
    EXPECT_NEAR(moved, rest, 1e-5);
  }
  // One second of walking at 1–2 m/s: the centroid advances along +z.
  const double advance = walker.frame_d(last).col(2).mean() - walker.frame_d(0).col(2).mean();
  EXPECT_GT(advance, 0.8);
  EXPECT_LT(advance, 2.0);
  // A standing adult: 1.6–1.9 m tall.
  const auto rest = walker.frame_d(0);
  const double height = rest.col(1).maxCoeff() - rest.col(1).minCoeff();
  EXPECT_GT(height, 1.6);
  EXPECT_LT(height, 1.9);
}

TEST(SynthTwist, AxisKeepsItsLengthWhileBending) {
  // Bending maps the axis by arc length and the caps follow the end frames rigidly, so the chord
  // between the poles is at most the rest length (body 4 + two cap radii 0.4), nearly reaches it
  // when the tube passes through straight, and shrinks while it is bent.
  const MeshSequence twist = MustSynthesize("twist", {.frames = 60, .resolution = 2000});
  const int bottom = 0, top = twist.vertex_count() - 1;  // capsule order: poles first and last
  double shortest = 1e9, longest = 0.0;
  for (int f = 0; f < twist.frame_count(); ++f) {
    const double chord = (Position(twist, f, top) - Position(twist, f, bottom)).norm();
    shortest = std::min(shortest, chord);
    longest = std::max(longest, chord);
  }
  EXPECT_LE(longest, 4.8 + 1e-5);
  EXPECT_GT(longest, 4.79);
  EXPECT_LT(shortest, 0.97 * longest);
}

}  // namespace
}  // namespace dmc
