// Reading the real sequences of ../shared/data (skipped when it is absent): sizes and topology as
// its README states them, OpenMesh agreeing on well-formed files, and the Sumner pose archives.
#include <gtest/gtest.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <cstdlib>
#include <string>

#include "dmc/io.h"
#include "dmc/topology.h"
#include "io_test_util.h"
#include "test_support.h"

namespace dmc {
namespace {

struct DataSet {
  std::string directory;
  int vertices;
  int triangles;
  int frames;  // in the folder
  int components;
  int boundary_loops;
  int boundary_edges;
};

class SharedObjSequenceTest : public ::testing::TestWithParam<DataSet> {};

// The first three frames of each set (all of them would take seconds in total for no gain:
// every frame goes through the same parser and the same consistency check).
TEST_P(SharedObjSequenceTest, ReadsWithTheDocumentedSizeAndTopology) {
  const DataSet& set = GetParam();
  DMC_REQUIRE_SHARED_DATA(directory, set.directory);
  ReadOptions options;
  options.max_frames = 3;
  ReadReport report;
  auto sequence = ReadSequence(directory, options, &report);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  EXPECT_EQ(sequence->vertex_count(), set.vertices);
  EXPECT_EQ(sequence->triangle_count(), set.triangles);
  EXPECT_EQ(sequence->frame_count(), std::min(3, set.frames));
  EXPECT_EQ(sequence->name, set.directory);
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  const MeshTopology topology = BuildTopology(sequence->triangles(), sequence->vertex_count());
  EXPECT_EQ(topology.component_count, set.components);
  EXPECT_EQ(topology.boundary_loop_count, set.boundary_loops);
  EXPECT_EQ(topology.boundary_edge_count, set.boundary_edges);
  EXPECT_EQ(topology.non_manifold_edge_count, 0);
  EXPECT_EQ(topology.isolated_vertex_count, 0);
}

INSTANTIATE_TEST_SUITE_P(Readme, SharedObjSequenceTest,
                         ::testing::Values(DataSet{"horse-gallop", 8431, 16843, 48, 1, 2, 19},
                                           DataSet{"samba", 9971, 19938, 30, 1, 0, 0},
                                           DataSet{"crane", 10002, 20000, 16, 1, 0, 0},
                                           DataSet{"chicken-crossing", 3030, 5664, 60, 41, 31, 294},
                                           DataSet{"cow", 2904, 5804, 40, 1, 0, 0},
                                           DataSet{"dance", 7061, 14118, 20, 1, 0, 0},
                                           DataSet{"jump", 15830, 31660, 4, 1, 0, 0},
                                           DataSet{"elephant-gallop", 42321, 84638, 2, 1, 0, 0},
                                           DataSet{"horse-collapse", 8431, 16843, 8, 1, 2, 19}),
                         [](const auto& info) {
                           std::string name = info.param.directory;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

TEST(SharedDataTest, HorseGallopFramesAreInNaturalOrder) {
  DMC_REQUIRE_SHARED_DATA(directory, "horse-gallop");
  // The README: 0024.obj is byte-identical to 0048.obj, and frame k+24 is within 1e-4 of frame k.
  auto sequence = ReadSequence(directory);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  ASSERT_EQ(sequence->frame_count(), 48);
  EXPECT_EQ(sequence->frame(23), sequence->frame(47));
  EXPECT_LT((sequence->frame(0) - sequence->frame(24)).cwiseAbs().maxCoeff(), 1e-4f);
  EXPECT_GT((sequence->frame(0) - sequence->frame(12)).cwiseAbs().maxCoeff(), 1e-2f);
}

TEST(SharedDataTest, AgreesWithOpenMeshOnAWellFormedFile) {
  DMC_REQUIRE_SHARED_DATA(file, "samba/mesh_0000.obj");
  auto sequence = ReadSequence(file);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  OpenMesh::PolyMesh_ArrayKernelT<> mesh;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(mesh, file.string()));
  ASSERT_EQ(static_cast<int>(mesh.n_vertices()), sequence->vertex_count());
  ASSERT_EQ(static_cast<int>(mesh.n_faces()), sequence->triangle_count());
  const auto frame = sequence->frame(0);
  for (const auto vertex : mesh.vertices()) {
    const auto& point = mesh.point(vertex);
    for (int axis = 0; axis < 3; ++axis) {
      ASSERT_EQ(point[axis], frame(vertex.idx(), axis)) << "vertex " << vertex.idx();
    }
  }
  for (const auto face : mesh.faces()) {
    // OpenMesh may start a face's corner cycle elsewhere; compare as a rotation.
    std::vector<int> corners;
    for (const auto corner : mesh.fv_range(face)) corners.push_back(corner.idx());
    ASSERT_EQ(corners.size(), 3u);
    const auto row = sequence->triangles().row(face.idx());
    const auto start = std::find(corners.begin(), corners.end(), row(0)) - corners.begin();
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(corners[(start + k) % 3], row(k)) << "face " << face.idx();
    }
  }
}

// dmc's binary PLY reader against OpenMesh's writer: the samba frame written by OpenMesh as a
// binary PLY, in both byte orders, must come back as OpenMesh holds it.
TEST(SharedDataTest, ReadsTheBinaryPlyOpenMeshWrites) {
  DMC_REQUIRE_SHARED_DATA(file, "samba/mesh_0000.obj");
  OpenMesh::PolyMesh_ArrayKernelT<> mesh;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(mesh, file.string()));
  for (bool big_endian : {false, true}) {
    testing::ScratchDir dir;
    const std::filesystem::path ply = dir / "samba.ply";
    OpenMesh::IO::Options options = OpenMesh::IO::Options::Binary;
    if (big_endian) options += OpenMesh::IO::Options::MSB;
    ASSERT_TRUE(OpenMesh::IO::write_mesh(mesh, ply.string(), options));
    auto sequence = ReadSequence(ply);
    ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
    ASSERT_EQ(static_cast<int>(mesh.n_vertices()), sequence->vertex_count());
    ASSERT_EQ(static_cast<int>(mesh.n_faces()), sequence->triangle_count());
    const auto frame = sequence->frame(0);
    for (const auto vertex : mesh.vertices()) {
      for (int axis = 0; axis < 3; ++axis) {
        ASSERT_EQ(mesh.point(vertex)[axis], frame(vertex.idx(), axis)) << "vertex " << vertex.idx();
      }
    }
    for (const auto face : mesh.faces()) {
      int k = 0;
      for (const auto corner : mesh.fv_range(face)) {
        ASSERT_EQ(corner.idx(), sequence->triangles()(face.idx(), k++)) << "face " << face.idx();
      }
    }
  }
}

class PoseArchiveTest : public ::testing::TestWithParam<std::pair<std::string, int>> {};

// The Sumner archives use "vn" lines and "f v//vn" faces; all ten poses share the connectivity.
TEST_P(PoseArchiveTest, ReadsTheExtractedPoses) {
  const auto& [name, vertices] = GetParam();
  DMC_REQUIRE_SHARED_DATA(archive, name + "-poses/" + name + "-poses.tgz");
  testing::ScratchDir dir;
  const std::string command = "tar xzf '" + archive.string() + "' -C '" + dir.path().string() + "'";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  // The archive may or may not have a top-level folder: find the reference pose.
  std::filesystem::path poses;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir.path())) {
    if (entry.path().filename() == name + "-reference.obj") poses = entry.path().parent_path();
  }
  ASSERT_FALSE(poses.empty()) << "no " << name << "-reference.obj in the archive";
  ReadOptions options;
  options.max_frames = 4;
  auto sequence = ReadSequence(poses / (name + "-0*.obj"), options);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  EXPECT_EQ(sequence->vertex_count(), vertices);
  EXPECT_EQ(sequence->frame_count(), 4);
  auto reference = ReadSequence(poses / (name + "-reference.obj"));
  ASSERT_TRUE(reference.ok()) << reference.status().ToString();
  EXPECT_EQ(reference->triangles(), sequence->triangles());
  const MeshTopology topology = BuildTopology(sequence->triangles(), sequence->vertex_count());
  EXPECT_EQ(topology.euler_characteristic, 2);  // closed, genus 0
  EXPECT_EQ(topology.boundary_edge_count, 0);
}

INSTANTIATE_TEST_SUITE_P(Sumner, PoseArchiveTest,
                         ::testing::Values(std::make_pair(std::string("cat"), 7207),
                                           std::make_pair(std::string("lion"), 5000)),
                         [](const auto& info) { return info.param.first; });

}  // namespace
}  // namespace dmc
