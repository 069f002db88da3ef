// Compact GLB export (KHR_mesh_quantization, EXT_meshopt_compression) and the compressed-geometry
// import paths (meshopt views, Draco primitives, required extensions): positions within half a
// grid step, normals along the frame's normals, and hostile files refused without a crash.
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "dmc/io.h"
#include "gltf_test_models.h"
#include "io/gltf_glb_builder.h"
#include "io/gltf_import_internal.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::TempFile;

using io_internal::EncodeGlb;
using io_internal::GlbEncoding;
using io_internal::GlbLayout;
using testing::Glb;
using testing::SplitGlb;

// A 6×6 grid that bends and turns over (its normals rotate by 180° about x) in 9 frames.
MeshSequence TurningGrid() {
  MeshSequence sequence = testing::PlanarGrid(6, 9);
  const MeshSequence flat = testing::PlanarGrid(6, 1);
  for (int f = 0; f < 9; ++f) {
    const double angle = M_PI * f / 8.0;
    for (int v = 0; v < sequence.vertex_count(); ++v) {
      const double x = flat.frame(0)(v, 0), y = flat.frame(0)(v, 1);
      const double z = 0.2 * std::sin(3.0 * x + 0.5 * f);
      sequence.frame(f)(v, 0) = static_cast<float>(x + 0.3 * f);
      sequence.frame(f)(v, 1) = static_cast<float>(std::cos(angle) * y - std::sin(angle) * z);
      sequence.frame(f)(v, 2) = static_cast<float>(std::sin(angle) * y + std::cos(angle) * z);
    }
  }
  sequence.frame_rate = 24.0;
  sequence.name = "turning";
  return sequence;
}

std::filesystem::path WriteBytes(const std::vector<uint8_t>& bytes, const std::string& name) {
  const auto path = TempFile(name);
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  return path;
}

// The half grid step of the compact encoding for `sequence` (PositionGrid in gltf_export.cpp).
double HalfGridStep(const MeshSequence& sequence) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(HUGE_VALF), hi = -lo;
  for (int f = 0; f < sequence.frame_count(); ++f) {
    lo = lo.cwiseMin(sequence.frame(f).colwise().minCoeff().transpose());
    hi = hi.cwiseMax(sequence.frame(f).colwise().maxCoeff().transpose());
  }
  return 0.5 * (0.5 * (hi - lo).maxCoeff() / 16383.0);
}

// Morph and frames: within half a grid step (rounding); basis: within one (its fit's bound).
TEST(GltfCompactTest, EveryLayoutAndEncodingReadsBackWithinItsBound) {
  const MeshSequence sequence = TurningGrid();
  for (const GlbLayout layout : {GlbLayout::kMorph, GlbLayout::kFrames, GlbLayout::kBasis}) {
    const double tolerance =
        (layout == GlbLayout::kBasis ? 2 : 1) * HalfGridStep(sequence) * (1 + 1e-6) + 1e-6;
    for (const GlbEncoding encoding : {GlbEncoding::kCompact, GlbEncoding::kQuantized}) {
      SCOPED_TRACE(::testing::Message() << "layout " << static_cast<int>(layout) << " encoding "
                                        << static_cast<int>(encoding));
      auto glb = EncodeGlb(sequence, layout, encoding);
      ASSERT_TRUE(glb.ok()) << glb.status().ToString();
      auto model = io_internal::LoadGltfModel(WriteBytes(*glb, "out.glb"));
      ASSERT_TRUE(model.ok()) << model.status().ToString();
      auto posed = io_internal::PoseGltfModel(*model, {});
      ASSERT_TRUE(posed.ok()) << posed.status().ToString();
      ASSERT_EQ(posed->sequence.frame_count(), 9);
      EXPECT_EQ(posed->sequence.frame_rate, 24.0);
      for (int f = 0; f < 9; ++f) {
        const double error = (posed->sequence.frame(f) - sequence.frame(f)).cwiseAbs().maxCoeff();
        EXPECT_LE(error, tolerance) << "frame " << f;
      }
    }
  }
}

TEST(GltfCompactTest, FilesDeclareWhatTheyRequire) {
  const MeshSequence sequence = TurningGrid();
  for (const GlbEncoding encoding :
       {GlbEncoding::kCompact, GlbEncoding::kQuantized, GlbEncoding::kFloat}) {
    auto glb = EncodeGlb(sequence, GlbLayout::kMorph, encoding);
    ASSERT_TRUE(glb.ok());
    const nlohmann::json json = SplitGlb(*glb).first;
    const auto required = json.value("extensionsRequired", nlohmann::json::array());
    const auto has = [&](const char* name) {
      return std::find(required.begin(), required.end(), name) != required.end();
    };
    EXPECT_EQ(has("KHR_mesh_quantization"), encoding != GlbEncoding::kFloat);
    EXPECT_EQ(has("EXT_meshopt_compression"), encoding == GlbEncoding::kCompact);
    const int position = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
    EXPECT_EQ(json["accessors"][position]["componentType"], encoding == GlbEncoding::kFloat
                                                                ? TINYGLTF_COMPONENT_TYPE_FLOAT
                                                                : TINYGLTF_COMPONENT_TYPE_SHORT);
    if (encoding == GlbEncoding::kCompact) {
      EXPECT_TRUE(json["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"]);
      for (const auto& view : json["bufferViews"]) {
        EXPECT_EQ(view["buffer"], 1);
        EXPECT_TRUE(view["extensions"].contains("EXT_meshopt_compression"));
      }
    }
  }
  // Compression pays on a mesh of some size: well under half of the quantised file.
  MeshSequence larger = testing::PlanarGrid(40, 12);
  for (int f = 0; f < 12; ++f) {
    for (int v = 0; v < larger.vertex_count(); ++v) {
      larger.frame(f)(v, 2) = 0.05f * static_cast<float>(f) * std::sin(larger.frame(f)(v, 0));
    }
  }
  auto compact = EncodeGlb(larger, GlbLayout::kMorph, GlbEncoding::kCompact);
  auto quantized = EncodeGlb(larger, GlbLayout::kMorph, GlbEncoding::kQuantized);
  ASSERT_TRUE(compact.ok() && quantized.ok());
  EXPECT_LT(2 * compact->size(), quantized->size());
}

// Renderers normalise base + Σ weight·target: at every frame that sum must point along the
// frame's own normal, including where the normals turn over.
TEST(GltfCompactTest, MorphNormalsFollowEveryFrame) {
  const MeshSequence sequence = TurningGrid();
  auto glb = EncodeGlb(sequence, GlbLayout::kMorph, GlbEncoding::kCompact);
  auto reference = EncodeGlb(sequence, GlbLayout::kMorph, GlbEncoding::kFloat);
  ASSERT_TRUE(glb.ok() && reference.ok());
  auto model = io_internal::LoadGltfModel(WriteBytes(*glb, "compact.glb"));
  auto exact = io_internal::LoadGltfModel(WriteBytes(*reference, "float.glb"));
  ASSERT_TRUE(model.ok() && exact.ok());
  const tinygltf::Primitive& primitive = model->meshes[0].primitives[0];
  const tinygltf::Primitive& exact_primitive = exact->meshes[0].primitives[0];
  auto read = [](const tinygltf::Model& m, int accessor) {
    auto values = io_internal::gltf::ReadAccessor(m, accessor, "test");
    EXPECT_TRUE(values.ok());
    return std::move(values).value();
  };
  std::vector<double> sum = read(*model, primitive.attributes.at("NORMAL"));
  const std::vector<double> exact_base = read(*exact, exact_primitive.attributes.at("NORMAL"));
  double worst = 0;
  for (int f = 0; f < 9; ++f) {
    std::vector<double> truth = exact_base;
    if (f > 0) {
      const auto steps = read(*model, primitive.targets[static_cast<size_t>(f - 1)].at("NORMAL"));
      for (size_t i = 0; i < sum.size(); ++i) sum[i] += steps[i];
      const auto delta =
          read(*exact, exact_primitive.targets[static_cast<size_t>(f - 1)].at("NORMAL"));
      for (size_t i = 0; i < truth.size(); ++i) truth[i] += delta[i];
    }
    for (size_t v = 0; v < sum.size() / 3; ++v) {
      const Eigen::Vector3d a(sum[3 * v], sum[3 * v + 1], sum[3 * v + 2]);
      const Eigen::Vector3d b(truth[3 * v], truth[3 * v + 1], truth[3 * v + 2]);
      worst = std::max(worst, std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)));
    }
  }
  // 8-bit normals: within 2° everywhere.
  EXPECT_LT(worst, 2.0 * M_PI / 180);
}

TEST(GltfCompactTest, WriteSequenceChoosesTheEncoding) {
  const MeshSequence sequence = TurningGrid();
  const auto path = TempFile("grid.glb");
  WriteOptions write;
  for (const char* encoding : {"compact", "quantized", "float"}) {
    write.glb_encoding = encoding;
    ASSERT_TRUE(WriteSequence(sequence, path, write).ok()) << encoding;
    auto back = ReadSequence(path);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    const double error = (back->frame(5) - sequence.frame(5)).cwiseAbs().maxCoeff();
    if (std::string(encoding) == "float") {
      EXPECT_LT(error, 1e-6);
    } else {
      // auto may choose the basis layout: within one grid step.
      EXPECT_LE(error, 2 * HalfGridStep(sequence) * (1 + 1e-6) + 1e-6);
    }
  }
  write.glb_encoding = "zip";
  const Status status = WriteSequence(sequence, path, write);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("zip"), std::string::npos);
}

// Every prefix of a compact GLB, and every single corrupted byte of its compressed data, is
// refused (or read) without a crash.
TEST(GltfCompactTest, TruncatedAndCorruptCompactFilesFailCleanly) {
  MeshSequence sequence = testing::PlanarGrid(3, 3);
  sequence.frame(1)(4, 2) = 0.5f;
  auto glb = EncodeGlb(sequence, GlbLayout::kMorph, GlbEncoding::kCompact);
  ASSERT_TRUE(glb.ok());
  const auto path = TempFile("cut.glb");
  for (size_t length = 0; length < glb->size(); ++length) {
    std::vector<uint8_t> cut(glb->begin(), glb->begin() + static_cast<long>(length));
    WriteBytes(cut, "cut.glb");
    EXPECT_FALSE(ReadSequence(path).ok()) << length << " bytes";
  }
  auto [json, bin] = SplitGlb(*glb);
  for (size_t i = 0; i < bin.size(); ++i) {
    std::vector<uint8_t> corrupt = bin;
    corrupt[i] ^= 0xA5;
    WriteBytes(Glb(json, corrupt), "cut.glb");
    const auto result = ReadSequence(path);
    if (!result.ok()) {
      EXPECT_EQ(result.status().code(), ErrorCode::kParseError) << i;
    }
  }
}

TEST(GltfCompactTest, HostileMeshoptSizesAreRefusedBeforeAllocating) {
  auto glb = EncodeGlb(testing::PlanarGrid(3, 3), GlbLayout::kMorph, GlbEncoding::kCompact);
  ASSERT_TRUE(glb.ok());
  const auto [json, bin] = SplitGlb(*glb);
  {
    nlohmann::json hostile = json;
    hostile["buffers"][1]["byteLength"] = uint64_t{1} << 40;
    WriteBytes(Glb(hostile, bin), "big.glb");
    const Status status = ReadSequence(TempFile("big.glb")).status();
    EXPECT_EQ(status.code(), ErrorCode::kParseError);
    EXPECT_NE(status.message().find("fallback"), std::string::npos) << status.ToString();
  }
  {
    nlohmann::json hostile = json;
    hostile["bufferViews"][1]["byteLength"] = uint64_t{1} << 36;
    hostile["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["count"] = uint64_t{1} << 33;
    WriteBytes(Glb(hostile, bin), "count.glb");
    const Status status = ReadSequence(TempFile("count.glb")).status();
    EXPECT_EQ(status.code(), ErrorCode::kParseError);
    EXPECT_NE(status.message().find("EXT_meshopt_compression"), std::string::npos)
        << status.ToString();
  }
  {
    nlohmann::json hostile = json;
    hostile["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["mode"] = "SIDEWAYS";
    WriteBytes(Glb(hostile, bin), "mode.glb");
    const Status status = ReadSequence(TempFile("mode.glb")).status();
    EXPECT_EQ(status.code(), ErrorCode::kParseError);
    EXPECT_NE(status.message().find("SIDEWAYS"), std::string::npos) << status.ToString();
  }
}

// A one-primitive GLB whose geometry is a Draco buffer (sequential coding keeps the point order),
// as KHR_draco_mesh_compression lays it out: the accessors have no buffer views.
std::vector<uint8_t> DracoGlb(const MeshSequence& mesh, bool corrupt) {
  draco::TriangleSoupMeshBuilder builder;
  const int triangles = static_cast<int>(mesh.triangles().rows());
  builder.Start(triangles);
  const int position =
      builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (int t = 0; t < triangles; ++t) {
    std::array<Eigen::Vector3f, 3> corners;
    for (int c = 0; c < 3; ++c) corners[c] = mesh.frame(0).row(mesh.triangles()(t, c)).transpose();
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(t), corners[0].data(),
                                      corners[1].data(), corners[2].data());
  }
  std::unique_ptr<draco::Mesh> draco_mesh = builder.Finalize();
  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 14);
  draco::EncoderBuffer buffer;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(*draco_mesh, &buffer).ok());
  std::vector<uint8_t> bin(buffer.data(), buffer.data() + buffer.size());
  if (corrupt) bin.resize(bin.size() / 2);
  const int unique_id = draco_mesh->attribute(position)->unique_id();
  nlohmann::json json = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"KHR_draco_mesh_compression"}},
      {"extensionsRequired", {"KHR_draco_mesh_compression"}},
      {"buffers", {{{"byteLength", bin.size()}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", bin.size()}}}},
      {"accessors",
       {{{"componentType", TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
         {"count", 3 * triangles},
         {"type", "SCALAR"}},
        {{"componentType", TINYGLTF_COMPONENT_TYPE_FLOAT},
         {"count", draco_mesh->num_points()},
         {"type", "VEC3"},
         {"min", {-1, -1, -1}},
         {"max", {1, 1, 1}}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 1}}},
            {"indices", 0},
            {"extensions",
             {{"KHR_draco_mesh_compression",
               {{"bufferView", 0}, {"attributes", {{"POSITION", unique_id}}}}}}}}}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"scenes", {{{"nodes", {0}}}}},
      {"scene", 0}};
  return Glb(json, bin);
}

TEST(GltfCompactTest, DracoPrimitivesAreDecoded) {
  MeshSequence mesh = testing::PlanarGrid(5, 1);
  for (int v = 0; v < mesh.vertex_count(); ++v) mesh.frame(0)(v, 2) = 0.01f * static_cast<float>(v);
  WriteBytes(DracoGlb(mesh, /*corrupt=*/false), "draco.glb");
  ReadOptions options;
  options.gltf.weld = true;  // Draco's triangle soup has one point per corner; welding rejoins them
  auto read = ReadSequence(TempFile("draco.glb"), options);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->triangles().rows(), mesh.triangles().rows());
  // Every decoded vertex is one of the mesh's vertices, to Draco's 14-bit quantisation.
  for (int v = 0; v < read->vertex_count(); ++v) {
    double nearest = HUGE_VAL;
    for (int w = 0; w < mesh.vertex_count(); ++w) {
      nearest = std::min<double>(nearest, (read->frame(0).row(v) - mesh.frame(0).row(w)).norm());
    }
    EXPECT_LT(nearest, 1e-3) << "vertex " << v;
  }
  WriteBytes(DracoGlb(mesh, /*corrupt=*/true), "corrupt.glb");
  const Status status = ReadSequence(TempFile("corrupt.glb")).status();
  EXPECT_EQ(status.code(), ErrorCode::kParseError);
  EXPECT_NE(status.message().find("KHR_draco_mesh_compression"), std::string::npos)
      << status.ToString();
}

TEST(GltfCompactTest, RequiredExtensionsThatMoveVerticesAreNamed) {
  auto glb = EncodeGlb(testing::PlanarGrid(3, 2), GlbLayout::kMorph, GlbEncoding::kFloat);
  ASSERT_TRUE(glb.ok());
  const auto [json, bin] = SplitGlb(*glb);
  nlohmann::json instanced = json;
  instanced["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  instanced["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
  WriteBytes(Glb(instanced, bin), "instanced.glb");
  const Status status = ReadSequence(TempFile("instanced.glb")).status();
  EXPECT_EQ(status.code(), ErrorCode::kUnsupported);
  EXPECT_NE(status.message().find("EXT_mesh_gpu_instancing"), std::string::npos);
  // A required material extension does not move vertices: the file reads.
  nlohmann::json material = json;
  material["extensionsUsed"] = {"KHR_materials_variants"};
  material["extensionsRequired"] = {"KHR_materials_variants"};
  WriteBytes(Glb(material, bin), "material.glb");
  EXPECT_TRUE(ReadSequence(TempFile("material.glb")).ok());
}

// A low-rank motion (two shapes blended over 60 frames, moving along x): the basis layout holds
// a few targets per axis instead of 59, reads back within one grid step, is far smaller than the
// morph layout, and refuses float32.
TEST(GltfCompactTest, BasisLayoutGrowsWithTheRankNotTheFrames) {
  MeshSequence sequence = testing::PlanarGrid(20, 60);
  for (int f = 0; f < 60; ++f) {
    const double a = std::sin(0.1 * f), b = std::cos(0.23 * f);
    for (int v = 0; v < sequence.vertex_count(); ++v) {
      const double x = sequence.frame(f)(v, 0), y = sequence.frame(f)(v, 1);
      sequence.frame(f)(v, 0) = static_cast<float>(x + 0.01 * f);
      sequence.frame(f)(v, 2) = static_cast<float>(0.2 * a * std::sin(3 * x) + 0.1 * b * x * y);
    }
  }
  auto basis = EncodeGlb(sequence, GlbLayout::kBasis, GlbEncoding::kCompact);
  auto morph = EncodeGlb(sequence, GlbLayout::kMorph, GlbEncoding::kCompact);
  ASSERT_TRUE(basis.ok() && morph.ok()) << basis.status().ToString();
  EXPECT_LT(basis->size(), morph->size() / 2);
  const nlohmann::json json = SplitGlb(*basis).first;
  EXPECT_EQ(json["asset"]["extras"]["dmc"]["layout"], "basis");
  int position_targets = 0;
  for (const auto& target : json["meshes"][0]["primitives"][0]["targets"]) {
    position_targets += target.contains("POSITION") ? 1 : 0;
  }
  EXPECT_GE(position_targets, 2);
  EXPECT_LE(position_targets, 3 * 3);  // x: a translation; z: two shapes (and the base's offset)
  auto model = io_internal::LoadGltfModel(WriteBytes(*basis, "basis.glb"));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  auto posed = io_internal::PoseGltfModel(*model, {});
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  ASSERT_EQ(posed->sequence.frame_count(), 60);
  const double tolerance = 2 * HalfGridStep(sequence) * (1 + 1e-6) + 1e-6;
  for (int f = 0; f < 60; ++f) {
    EXPECT_LE((posed->sequence.frame(f) - sequence.frame(f)).cwiseAbs().maxCoeff(), tolerance)
        << "frame " << f;
  }
  auto float_basis = EncodeGlb(sequence, GlbLayout::kBasis, GlbEncoding::kFloat);
  EXPECT_EQ(float_basis.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(float_basis.status().message().find("basis"), std::string::npos);
}

// The basis layout's normals: base + Σ weight·target, normalised, within 4/127 per component
// (3° at most) of each frame's normals, including where they turn over.
TEST(GltfCompactTest, BasisNormalsFollowEveryFrame) {
  const MeshSequence sequence = TurningGrid();
  auto glb = EncodeGlb(sequence, GlbLayout::kBasis, GlbEncoding::kQuantized);
  ASSERT_TRUE(glb.ok());
  auto model = io_internal::LoadGltfModel(WriteBytes(*glb, "basis.glb"));
  ASSERT_TRUE(model.ok());
  const tinygltf::Primitive& primitive = model->meshes[0].primitives[0];
  auto read = [&](int accessor) {
    auto values = io_internal::gltf::ReadAccessor(*model, accessor, "test");
    EXPECT_TRUE(values.ok());
    return std::move(values).value();
  };
  const std::vector<double> base = read(primitive.attributes.at("NORMAL"));
  const tinygltf::AnimationSampler& sampler = model->animations[0].samplers[0];
  const std::vector<double> weights = read(sampler.output);
  const size_t targets = primitive.targets.size();
  ASSERT_EQ(weights.size(), 9 * targets);
  double worst = 0;
  for (int f = 0; f < 9; ++f) {
    std::vector<double> sum = base;
    for (size_t t = 0; t < targets; ++t) {
      if (primitive.targets[t].count("NORMAL") == 0) continue;
      const std::vector<double> delta = read(primitive.targets[t].at("NORMAL"));
      for (size_t i = 0; i < sum.size(); ++i)
        sum[i] += weights[static_cast<size_t>(f) * targets + t] * delta[i];
    }
    const std::vector<float> truth = io_internal::glb::FrameNormals(sequence, f);
    for (size_t v = 0; v < sum.size() / 3; ++v) {
      const Eigen::Vector3d a(sum[3 * v], sum[3 * v + 1], sum[3 * v + 2]);
      const Eigen::Vector3d b(truth[3 * v], truth[3 * v + 1], truth[3 * v + 2]);
      worst = std::max(worst, std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)));
    }
  }
  EXPECT_LT(worst, 3.5 * M_PI / 180);
}

}  // namespace
}  // namespace dmc
