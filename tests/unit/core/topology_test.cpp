#include "dmc/topology.h"

#include <gtest/gtest.h>

#include "test_support.h"

namespace dmc {
namespace {

TEST(Topology, ClosedTetrahedron) {
  const MeshSequence seq = testing::Tetrahedron();
  const MeshTopology topo = BuildTopology(seq.triangles(), seq.vertex_count());
  EXPECT_EQ(topo.edge_count(), 6);
  EXPECT_EQ(topo.boundary_edge_count, 0);
  EXPECT_EQ(topo.boundary_loop_count, 0);
  EXPECT_EQ(topo.component_count, 1);
  EXPECT_EQ(topo.euler_characteristic, 2);
  EXPECT_TRUE(topo.is_manifold());
  for (int v = 0; v < 4; ++v) EXPECT_EQ(topo.degree(v), 3);
  for (int e = 0; e < topo.edge_count(); ++e) {
    EXPECT_LT(topo.edges[e][0], topo.edges[e][1]);
    EXPECT_EQ(topo.edge_face_count[e], 2);
    EXPECT_GE(topo.edge_opposite[e][1], 0);
  }
}

TEST(Topology, GridHasOneBoundaryLoopAndSortedRings) {
  const MeshSequence seq = testing::PlanarGrid(4);
  const MeshTopology topo = BuildTopology(seq.triangles(), seq.vertex_count());
  EXPECT_EQ(topo.edge_count(), 33);  // 3*4*2 axis edges + 9 diagonals
  EXPECT_EQ(topo.boundary_edge_count, 12);
  EXPECT_EQ(topo.boundary_loop_count, 1);
  EXPECT_EQ(topo.euler_characteristic, 1);
  EXPECT_FALSE(topo.is_boundary_vertex(5));
  EXPECT_TRUE(topo.is_boundary_vertex(0));
  for (int v = 0; v < topo.vertex_count; ++v) {
    for (int k = topo.ring_offsets[v]; k < topo.ring_offsets[v + 1]; ++k) {
      if (k > topo.ring_offsets[v]) {
        EXPECT_LT(topo.ring_neighbors[k - 1], topo.ring_neighbors[k]);
      }
      const auto& edge = topo.edges[topo.ring_edges[k]];
      EXPECT_TRUE((edge[0] == v && edge[1] == topo.ring_neighbors[k]) ||
                  (edge[1] == v && edge[0] == topo.ring_neighbors[k]));
    }
  }
}

TEST(Topology, ComponentsIsolatedVerticesAndNonManifoldEdges) {
  // Two separate triangles, one isolated vertex, then a fin making edge (0,1) non-manifold.
  Triangles tris(3, 3);
  tris << 0, 1, 2, 3, 4, 5, 0, 1, 7;
  const MeshTopology topo = BuildTopology(tris, 8);
  EXPECT_EQ(topo.component_count, 3);  // {0,1,2,7}, {3,4,5}, {6}
  EXPECT_EQ(topo.isolated_vertex_count, 1);
  EXPECT_EQ(topo.non_manifold_edge_count, 0);
  Triangles fins(3, 3);
  fins << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  const MeshTopology fin_topo = BuildTopology(fins, 5);
  EXPECT_EQ(fin_topo.non_manifold_edge_count, 1);
  EXPECT_FALSE(fin_topo.is_manifold());
}

}  // namespace
}  // namespace dmc
