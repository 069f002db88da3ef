// Connectivity coding: every method round-trips the oriented triangle set (and the vertex order
// when it must), Draco-unfriendly meshes fall back to the indexed method, and damaged payloads
// are errors, never crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "decoder/connectivity_decoder.h"
#include "dmc/io.h"
#include "dmc/topology.h"
#include "encoder/connectivity_encoder.h"
#include "entropy/byte_io.h"
#include "test_support.h"

namespace dmc {
namespace {

using connectivity::LabelPredictor;
using connectivity::PredictionKind;

constexpr std::array<ConnectivityCoding, 3> kAllMethods = {
    ConnectivityCoding::kIndexed, ConnectivityCoding::kDracoWithVertexOrder,
    ConnectivityCoding::kDracoReordered};

Triangles FromList(const std::vector<std::array<int32_t, 3>>& list) {
  Triangles triangles(static_cast<Eigen::Index>(list.size()), 3);
  for (size_t t = 0; t < list.size(); ++t) {
    triangles.row(static_cast<Eigen::Index>(t)) << list[t][0], list[t][1], list[t][2];
  }
  return triangles;
}

// Sorted triangles, each rotated to start at its smallest index (orientation kept).
std::vector<std::array<int32_t, 3>> OrientedSet(const Triangles& triangles) {
  std::vector<std::array<int32_t, 3>> set;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    std::array<int32_t, 3> tri = {triangles(t, 0), triangles(t, 1), triangles(t, 2)};
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    set.push_back(tri);
  }
  std::sort(set.begin(), set.end());
  return set;
}

struct TestMesh {
  Triangles triangles;
  int vertex_count = 0;
};

// A closed UV sphere: poles 0 and V-1, consistently oriented.
TestMesh Sphere(int rings, int segments) {
  const int vertex_count = 2 + (rings - 1) * segments;
  const int south = vertex_count - 1;
  auto ring = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  std::vector<std::array<int32_t, 3>> list;
  for (int s = 0; s < segments; ++s) {
    list.push_back({0, ring(1, s), ring(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      list.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      list.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
    list.push_back({ring(rings - 1, s), south, ring(rings - 1, s + 1)});
  }
  return {FromList(list), vertex_count};
}

// Relabels vertices with a random permutation, shuffles triangle order and rotates each
// triangle's indices: the same oriented mesh with an order Draco's traversal cannot guess.
TestMesh Scramble(const TestMesh& mesh, unsigned seed) {
  const Triangles& triangles = mesh.triangles;
  const int vertex_count = mesh.vertex_count;
  std::mt19937 random(seed);
  std::vector<int32_t> label(vertex_count);
  std::iota(label.begin(), label.end(), 0);
  std::shuffle(label.begin(), label.end(), random);
  std::vector<Eigen::Index> order(static_cast<size_t>(triangles.rows()));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), random);
  Triangles out(triangles.rows(), 3);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const int shift = static_cast<int>(random() % 3);
    for (int k = 0; k < 3; ++k) out(t, k) = label[triangles(order[t], (k + shift) % 3)];
  }
  return {out, vertex_count};
}

// Two disjoint pieces (a grid and a tetrahedron) plus a lone triangle: three components.
TestMesh ThreeComponents() {
  const MeshSequence grid = testing::PlanarGrid(5);
  const MeshSequence tetra = testing::Tetrahedron();
  const int offset = grid.vertex_count();
  Triangles triangles(grid.triangle_count() + tetra.triangle_count() + 1, 3);
  triangles.topRows(grid.triangle_count()) = grid.triangles();
  triangles.middleRows(grid.triangle_count(), tetra.triangle_count()) =
      tetra.triangles().array() + offset;
  const int lone = offset + tetra.vertex_count();
  triangles.bottomRows(1) << lone, lone + 1, lone + 2;
  return {triangles, lone + 3};
}

// Checks everything a code promises about itself, and that it decodes to the input.
void ExpectRoundTrip(const ConnectivityCode& code, const Triangles& input, int vertex_count) {
  StatusOr<Triangles> decoded = DecodeConnectivity(code.payload, vertex_count, input.rows());
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_EQ(*decoded, code.triangles) << "ConnectivityCode::triangles is not what decodes";
  switch (code.method()) {
    case ConnectivityCoding::kIndexed:
      EXPECT_TRUE(code.vertex_order.empty());
      EXPECT_EQ(*decoded, input);  // order-preserving down to triangle order
      break;
    case ConnectivityCoding::kDracoWithVertexOrder:
      EXPECT_TRUE(code.vertex_order.empty());
      EXPECT_EQ(OrientedSet(*decoded), OrientedSet(input));
      break;
    case ConnectivityCoding::kDracoReordered: {
      ASSERT_EQ(static_cast<int>(code.vertex_order.size()), vertex_count);
      std::vector<int32_t> sorted = code.vertex_order;
      std::sort(sorted.begin(), sorted.end());
      for (int v = 0; v < vertex_count; ++v) ASSERT_EQ(sorted[v], v) << "not a permutation";
      Triangles in_input_labels = *decoded;
      for (Eigen::Index t = 0; t < in_input_labels.rows(); ++t) {
        for (int k = 0; k < 3; ++k) {
          in_input_labels(t, k) = code.vertex_order[in_input_labels(t, k)];
        }
      }
      EXPECT_EQ(OrientedSet(in_input_labels), OrientedSet(input));
      break;
    }
  }
}

void ExpectAllMethodsRoundTrip(const TestMesh& mesh) {
  const Triangles& triangles = mesh.triangles;
  const int vertex_count = mesh.vertex_count;
  for (const ConnectivityCoding method : kAllMethods) {
    SCOPED_TRACE(static_cast<int>(method));
    StatusOr<ConnectivityCode> code = EncodeConnectivityWithMethod(triangles, vertex_count, method);
    ASSERT_TRUE(code.ok()) << code.status().ToString();
    EXPECT_EQ(code->method(), method);
    ExpectRoundTrip(*code, triangles, vertex_count);
  }
}

TEST(Connectivity, SphereRoundTripsWithEveryMethod) {
  ExpectAllMethodsRoundTrip(Scramble(Sphere(12, 16), 1));
}

TEST(Connectivity, GridWithBoundaryRoundTripsWithEveryMethod) {
  const MeshSequence grid = testing::PlanarGrid(9);
  const TestMesh mesh = {grid.triangles(), grid.vertex_count()};
  ExpectAllMethodsRoundTrip(mesh);
  ExpectAllMethodsRoundTrip(Scramble(mesh, 2));
}

TEST(Connectivity, SeveralComponentsRoundTripWithEveryMethod) {
  const TestMesh mesh = ThreeComponents();
  ExpectAllMethodsRoundTrip(mesh);
  ExpectAllMethodsRoundTrip(Scramble(mesh, 3));
}

// Draco drops isolated vertices and splits the vertices of a non-manifold edge: its methods must
// refuse such meshes, and the automatic choice must fall back to the indexed method.
void ExpectOnlyIndexedWorks(const Triangles& triangles, int vertex_count) {
  for (const ConnectivityCoding method :
       {ConnectivityCoding::kDracoWithVertexOrder, ConnectivityCoding::kDracoReordered}) {
    const StatusOr<ConnectivityCode> code =
        EncodeConnectivityWithMethod(triangles, vertex_count, method);
    ASSERT_FALSE(code.ok());
    EXPECT_EQ(code.status().code(), ErrorCode::kUnsupported) << code.status().ToString();
  }
  for (const bool allow_reorder : {false, true}) {
    StatusOr<ConnectivityCode> code = EncodeConnectivity(triangles, vertex_count, allow_reorder);
    ASSERT_TRUE(code.ok()) << code.status().ToString();
    EXPECT_EQ(code->method(), ConnectivityCoding::kIndexed);
    ExpectRoundTrip(*code, triangles, vertex_count);
  }
}

TEST(Connectivity, IsolatedVertexFallsBackToIndexed) {
  const MeshSequence grid = testing::PlanarGrid(8);
  ExpectOnlyIndexedWorks(grid.triangles(), grid.vertex_count() + 1);  // last vertex unused
}

TEST(Connectivity, NonManifoldEdgeFallsBackToIndexed) {
  // A 6x6 grid plus a fin: a third triangle on the interior edge (7, 14) of the grid.
  const MeshSequence grid = testing::PlanarGrid(6);
  Triangles triangles(grid.triangle_count() + 1, 3);
  triangles.topRows(grid.triangle_count()) = grid.triangles();
  triangles.bottomRows(1) << 7, 14, grid.vertex_count();
  const MeshTopology topology = BuildTopology(triangles, grid.vertex_count() + 1);
  ASSERT_EQ(topology.non_manifold_edge_count, 1);
  ExpectOnlyIndexedWorks(triangles, grid.vertex_count() + 1);
}

TEST(Connectivity, DegenerateTriangleFallsBackToIndexed) {
  const MeshSequence grid = testing::PlanarGrid(6);
  Triangles triangles(grid.triangle_count() + 1, 3);
  triangles.topRows(grid.triangle_count()) = grid.triangles();
  triangles.bottomRows(1) << 3, 3, 9;
  ExpectOnlyIndexedWorks(triangles, grid.vertex_count());
}

TEST(Connectivity, AutomaticChoiceIsTheSmallestAllowedMethod) {
  const TestMesh mesh = Scramble(Sphere(20, 24), 4);
  const Triangles& sphere = mesh.triangles;
  const int v_count = mesh.vertex_count;
  size_t sizes[3];
  for (const ConnectivityCoding method : kAllMethods) {
    sizes[static_cast<int>(method)] =
        EncodeConnectivityWithMethod(sphere, v_count, method)->payload.size();
  }
  // Edgebreaker plus labels beats ~25 bits per triangle; dropping the labels beats both.
  EXPECT_LT(sizes[1], sizes[0]);
  EXPECT_LT(sizes[2], sizes[1]);

  StatusOr<ConnectivityCode> kept = EncodeConnectivity(sphere, v_count, false);
  ASSERT_TRUE(kept.ok()) << kept.status().ToString();
  EXPECT_EQ(kept->method(), ConnectivityCoding::kDracoWithVertexOrder);
  EXPECT_EQ(kept->payload.size(), sizes[1]);
  ExpectRoundTrip(*kept, sphere, v_count);

  StatusOr<ConnectivityCode> reordered = EncodeConnectivity(sphere, v_count, true);
  ASSERT_TRUE(reordered.ok()) << reordered.status().ToString();
  EXPECT_EQ(reordered->method(), ConnectivityCoding::kDracoReordered);
  EXPECT_EQ(reordered->payload.size(), sizes[2]);
  ExpectRoundTrip(*reordered, sphere, v_count);
}

TEST(Connectivity, TinyMeshUsesWhicheverMethodIsSmaller) {
  const MeshSequence tetra = testing::Tetrahedron();
  size_t smallest = SIZE_MAX;
  for (const ConnectivityCoding method :
       {ConnectivityCoding::kIndexed, ConnectivityCoding::kDracoWithVertexOrder}) {
    StatusOr<ConnectivityCode> code =
        EncodeConnectivityWithMethod(tetra.triangles(), tetra.vertex_count(), method);
    ASSERT_TRUE(code.ok()) << code.status().ToString();
    smallest = std::min(smallest, code->payload.size());
  }
  StatusOr<ConnectivityCode> code =
      EncodeConnectivity(tetra.triangles(), tetra.vertex_count(), false);
  ASSERT_TRUE(code.ok()) << code.status().ToString();
  EXPECT_EQ(code->payload.size(), smallest);
  ExpectRoundTrip(*code, tetra.triangles(), tetra.vertex_count());
}

TEST(Connectivity, EmptyAndInvalidInputs) {
  // No triangles: only the indexed method applies.
  StatusOr<ConnectivityCode> empty = EncodeConnectivity(Triangles(0, 3), 5, true);
  ASSERT_TRUE(empty.ok()) << empty.status().ToString();
  EXPECT_EQ(empty->method(), ConnectivityCoding::kIndexed);
  ExpectRoundTrip(*empty, Triangles(0, 3), 5);

  const Triangles out_of_range = FromList({{0, 1, 4}});
  const StatusOr<ConnectivityCode> bad = EncodeConnectivity(out_of_range, 4, false);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kInvalidArgument);
}

// Every payload cut short is an error; so is a payload decoded against the wrong counts or with
// an unknown method byte; random damage never crashes and never yields out-of-range indices.
TEST(Connectivity, DamagedPayloadsAreErrors) {
  const TestMesh mesh = Scramble(Sphere(6, 8), 5);
  const Triangles& sphere = mesh.triangles;
  const int v_count = mesh.vertex_count;
  const auto t_count = static_cast<uint32_t>(sphere.rows());
  std::mt19937 random(6);
  for (const ConnectivityCoding method : kAllMethods) {
    SCOPED_TRACE(static_cast<int>(method));
    StatusOr<ConnectivityCode> code = EncodeConnectivityWithMethod(sphere, v_count, method);
    ASSERT_TRUE(code.ok()) << code.status().ToString();
    const std::vector<uint8_t>& payload = code->payload;
    for (size_t length = 0; length < payload.size(); ++length) {
      const StatusOr<Triangles> cut =
          DecodeConnectivity(std::span(payload).first(length), v_count, t_count);
      EXPECT_FALSE(cut.ok()) << "a payload cut to " << length << " of " << payload.size()
                             << " bytes decoded";
    }
    if (method != ConnectivityCoding::kIndexed) {
      // Draco buffers state their counts; the indexed method trusts the sequence header's.
      EXPECT_FALSE(DecodeConnectivity(payload, v_count + 1, t_count).ok());
      EXPECT_FALSE(DecodeConnectivity(payload, v_count, t_count - 1).ok());
    }
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<uint8_t> damaged = payload;
      damaged[1 + random() % (damaged.size() - 1)] ^= static_cast<uint8_t>(1 + random() % 255);
      const StatusOr<Triangles> result = DecodeConnectivity(damaged, v_count, t_count);
      if (!result.ok()) continue;
      ASSERT_EQ(result->rows(), sphere.rows());
      EXPECT_GE(result->minCoeff(), 0);
      EXPECT_LT(result->maxCoeff(), v_count);
    }
  }
  std::vector<uint8_t> unknown = {7, 0, 0, 0, 0, 0};
  const StatusOr<Triangles> result = DecodeConnectivity(unknown, v_count, t_count);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), ErrorCode::kUnsupported);
}

TEST(ConnectivityLabels, UnusedLabelsRankAndSelect) {
  connectivity::UnusedLabels unused(10);
  EXPECT_EQ(unused.remaining(), 10);
  EXPECT_EQ(unused.Rank(0), 0);
  EXPECT_EQ(unused.Rank(7), 7);
  EXPECT_EQ(unused.Rank(10), 10);
  unused.Remove(3);
  unused.Remove(4);
  unused.Remove(9);
  // Unused now: 0 1 2 5 6 7 8.
  EXPECT_EQ(unused.remaining(), 7);
  EXPECT_EQ(unused.Rank(3), 3);
  EXPECT_EQ(unused.Rank(5), 3);
  EXPECT_EQ(unused.Rank(6), 4);
  EXPECT_EQ(unused.Rank(10), 7);
  const std::array<int32_t, 7> expected = {0, 1, 2, 5, 6, 7, 8};
  for (int rank = 0; rank < 7; ++rank) EXPECT_EQ(unused.Select(rank), expected[rank]);
}

// PlanarGrid(3): vertices 0..8 row by row; neighbours (hand-derived from its triangles):
// 0:{1,3,4} 1:{0,2,4,5} 2:{1,5} 3:{0,4,6,7} 4:{0,1,3,5,7,8} 5:{1,2,4,8} 6:{3,7} 7:{3,4,6,8}
// 8:{4,5,7}.
TEST(ConnectivityLabels, AdjacencyListsTrianglesAndNeighbours) {
  const MeshSequence grid = testing::PlanarGrid(3);
  const connectivity::TriangleAdjacency adjacency(grid.triangles(), grid.vertex_count());
  // Triangles: 0 (0,1,4) 1 (0,4,3) 2 (1,2,5) 3 (1,5,4) 4 (3,4,7) 5 (3,7,6) 6 (4,5,8) 7 (4,8,7).
  const std::vector<int32_t> of_four = {0, 1, 3, 4, 6, 7};
  EXPECT_EQ(std::vector<int32_t>(adjacency.TrianglesOf(4).begin(), adjacency.TrianglesOf(4).end()),
            of_four);
  std::vector<int32_t> neighbors;
  adjacency.Neighbors(4, neighbors);
  EXPECT_EQ(neighbors, (std::vector<int32_t>{0, 1, 3, 5, 7, 8}));
  adjacency.Neighbors(2, neighbors);
  EXPECT_EQ(neighbors, (std::vector<int32_t>{1, 5}));
}

TEST(ConnectivityLabels, CodingOrderPrefersVerticesWithMostCodedNeighbours) {
  const MeshSequence grid = testing::PlanarGrid(3);
  const connectivity::TriangleAdjacency adjacency(grid.triangles(), grid.vertex_count());
  // 0 (seed); 1 (1 coded neighbour, lowest index among 1,3,4); 4 (2: 0,1); 3 (2, before 5);
  // 5 (2); 2 (2: 1,5, before 7); 7 (2: 3,4); 8 (3: 4,5,7); 6.
  const std::vector<int32_t> expected = {0, 1, 4, 3, 5, 2, 7, 8, 6};
  EXPECT_EQ(connectivity::LabelCodingOrder(adjacency), expected);

  // Two components: the second starts from its lowest vertex once the first is exhausted.
  const Triangles two = FromList({{3, 4, 5}, {0, 1, 2}});
  const std::vector<int32_t> expected_two = {0, 1, 2, 3, 4, 5};
  EXPECT_EQ(connectivity::LabelCodingOrder(connectivity::TriangleAdjacency(two, 6)), expected_two);
}

TEST(ConnectivityLabels, PredictionsFromDecodedNeighbours) {
  const MeshSequence grid = testing::PlanarGrid(3);
  const connectivity::TriangleAdjacency adjacency(grid.triangles(), grid.vertex_count());
  std::vector<int32_t> labels(9, -1);
  std::vector<int64_t> scratch;
  // Nothing decoded: previous label + 1.
  connectivity::LabelPrediction p =
      connectivity::PredictLabel(adjacency, labels, 3, LabelPredictor::kNeighborMedian, 5, scratch);
  EXPECT_EQ(p.kind, PredictionKind::kNoNeighbor);
  EXPECT_EQ(p.label, 6);
  EXPECT_EQ(p.neighbor_min, -1);
  EXPECT_EQ(connectivity::LabelContext(p, connectivity::UnusedLabels(9), true), 0);
  p = connectivity::PredictLabel(adjacency, labels, 3, LabelPredictor::kNeighborMedian, 8, scratch);
  EXPECT_EQ(p.label, 8);  // clamped to V - 1
  // Vertices 0, 1, 4 decoded with their grid labels; predict vertex 3 (neighbours 0, 4, 6, 7).
  labels[0] = 0, labels[1] = 1, labels[4] = 4;
  p = connectivity::PredictLabel(adjacency, labels, 3, LabelPredictor::kNeighborMedian, 4, scratch);
  EXPECT_EQ(p.kind, PredictionKind::kNeighborMedian);
  EXPECT_EQ(p.label, 0);  // lower median of {0, 4}
  EXPECT_EQ(p.neighbor_min, 0);
  EXPECT_EQ(p.neighbor_max, 4);
  // Context: kind 1 times 6 buckets; with spread contexts, unused labels between 0 and 4 are
  // {2, 3}: spread 2, bit width 2, bucket 1.
  connectivity::UnusedLabels unused(9);
  for (const int32_t used : {0, 1, 4}) unused.Remove(used);
  EXPECT_EQ(connectivity::LabelContext(p, unused, false), 6);
  EXPECT_EQ(connectivity::LabelContext(p, unused, true), 7);
  // Triangle (0, 4, 3) faces triangle (0, 1, 4) across edge 0-4: 0 + 4 - 1 = 3, the true label.
  p = connectivity::PredictLabel(adjacency, labels, 3, LabelPredictor::kParallelogram, 4, scratch);
  EXPECT_EQ(p.kind, PredictionKind::kParallelogram);
  EXPECT_EQ(p.label, 3);
  // Vertex 2 has only vertex 1 decoded in a triangle (1, 2, 5) with 5 unknown: no parallelogram.
  p = connectivity::PredictLabel(adjacency, labels, 2, LabelPredictor::kParallelogram, 4, scratch);
  EXPECT_EQ(p.kind, PredictionKind::kNeighborMedian);
  EXPECT_EQ(p.label, 1);
}

// The label model byte of a kDracoWithVertexOrder payload (after the method and the Draco
// buffer).
uint8_t LabelModelByte(const std::vector<uint8_t>& payload) {
  ByteReader reader(std::span<const uint8_t>(payload).subspan(1));
  uint64_t draco_size = 0;
  EXPECT_TRUE(reader.GetVarU(&draco_size, "draco size").ok());
  return payload.at(1 + reader.position() + draco_size);
}

// Format 1.1 adds label kernels: a 1.0 payload never uses them and decodes alike under both
// versions; a 1.1 payload that uses one decodes as 1.1 and is refused as 1.0, and no truncation of
// it decodes.
void ExpectKernelsOnlyFromFormat11(const Triangles& triangles, int v_count, bool expect_kernel) {
  const auto t_count = static_cast<uint32_t>(triangles.rows());
  StatusOr<ConnectivityCode> v10 = EncodeConnectivityWithMethod(
      triangles, v_count, ConnectivityCoding::kDracoWithVertexOrder, /*version_minor=*/0);
  StatusOr<ConnectivityCode> v11 = EncodeConnectivityWithMethod(
      triangles, v_count, ConnectivityCoding::kDracoWithVertexOrder, /*version_minor=*/1);
  ASSERT_TRUE(v10.ok()) << v10.status().ToString();
  ASSERT_TRUE(v11.ok()) << v11.status().ToString();
  EXPECT_LT(LabelModelByte(v10->payload), connectivity::kLabelModelCount);
  EXPECT_LE(v11->payload.size(), v10->payload.size());
  for (const uint8_t minor : {0, 1}) {
    StatusOr<Triangles> decoded = DecodeConnectivity(v10->payload, v_count, t_count, minor);
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    EXPECT_EQ(*decoded, v10->triangles);
  }
  StatusOr<Triangles> decoded = DecodeConnectivity(v11->payload, v_count, t_count, 1);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_EQ(*decoded, v11->triangles);
  const bool kernel = LabelModelByte(v11->payload) >= connectivity::kLabelModelCount;
  if (expect_kernel) {
    EXPECT_TRUE(kernel) << "no kernel chosen";
    EXPECT_LT(v11->payload.size(), v10->payload.size());
  }
  if (!kernel) return;
  const StatusOr<Triangles> as_10 = DecodeConnectivity(v11->payload, v_count, t_count, 0);
  EXPECT_EQ(as_10.status().code(), ErrorCode::kCorruptStream);
  EXPECT_NE(as_10.status().message().find("in format 1.0"), std::string::npos)
      << as_10.status().ToString();
  const size_t step = std::max<size_t>(1, v11->payload.size() / 128);
  for (size_t length = 0; length < v11->payload.size(); length += step) {
    EXPECT_FALSE(
        DecodeConnectivity(std::span(v11->payload).first(length), v_count, t_count, 1).ok())
        << length;
  }
}

TEST(ConnectivityLabels, KernelsOnlyFromFormat11OnAGrid) {
  const MeshSequence grid = testing::PlanarGrid(24);
  ExpectKernelsOnlyFromFormat11(Scramble({grid.triangles(), grid.vertex_count()}, 4).triangles,
                                grid.vertex_count(), /*expect_kernel=*/false);
  ExpectKernelsOnlyFromFormat11(grid.triangles(), grid.vertex_count(), /*expect_kernel=*/false);
}

// jump's input labels are far from every 1.0 predictor but near its neighbours' labels: the
// kernels win there (RD.md, "Format 1.1 basis and labels").
TEST(ConnectivityLabels, KernelsOnlyFromFormat11OnJump) {
  DMC_REQUIRE_SHARED_DATA(path, "jump");
  ReadOptions options;
  options.max_frames = 1;
  StatusOr<MeshSequence> sequence = ReadSequence(path, options);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  ExpectKernelsOnlyFromFormat11(sequence->triangles(), sequence->vertex_count(),
                                /*expect_kernel=*/true);
}

// The real meshes: exact round trips, and the rate of each method (printed for the record).
class ConnectivityOnSharedData : public ::testing::TestWithParam<const char*> {};

TEST_P(ConnectivityOnSharedData, RoundTripsAndReportsRates) {
  DMC_REQUIRE_SHARED_DATA(path, GetParam());
  ReadOptions options;
  options.max_frames = 1;
  StatusOr<MeshSequence> sequence = ReadSequence(path, options);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  const Triangles& triangles = sequence->triangles();
  const int v_count = sequence->vertex_count();
  const double t_count = static_cast<double>(triangles.rows());
  for (const ConnectivityCoding method : kAllMethods) {
    StatusOr<ConnectivityCode> code = EncodeConnectivityWithMethod(triangles, v_count, method);
    ASSERT_TRUE(code.ok()) << code.status().ToString();
    ExpectRoundTrip(*code, triangles, v_count);
    const double bytes = static_cast<double>(code->payload.size());
    std::printf("[ rate ] %-18s method %d: %8.0f bytes  %6.3f bits/triangle  %6.3f bits/vertex\n",
                GetParam(), static_cast<int>(method), bytes, 8.0 * bytes / t_count,
                8.0 * bytes / v_count);
  }
  StatusOr<ConnectivityCode> kept = EncodeConnectivity(triangles, v_count, false);
  ASSERT_TRUE(kept.ok()) << kept.status().ToString();
  EXPECT_EQ(kept->method(), ConnectivityCoding::kDracoWithVertexOrder);
  // Edgebreaker plus labels stays far below the indexed method's ~25 bits per triangle.
  EXPECT_LT(8.0 * static_cast<double>(kept->payload.size()) / t_count, 8.0);
}

INSTANTIATE_TEST_SUITE_P(Meshes, ConnectivityOnSharedData,
                         ::testing::Values("samba", "crane", "horse-gallop", "chicken-crossing"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace dmc
