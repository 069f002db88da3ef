#include "sweep/baselines.h"

#include <draco/attributes/geometry_attribute.h>
#include <draco/attributes/point_attribute.h>
#include <draco/compression/config/compression_shared.h>
#include <draco/compression/config/encoder_options.h>
#include <draco/compression/decode.h>
#include <draco/compression/mesh/mesh_edgebreaker_encoder.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <string_view>

#include "entropy/byte_io.h"

namespace dmc::sweep {
namespace {

// ---------------------------------------------------------------------------------------------
// The baselines' containers: the codec's byte streams (entropy/byte_io.h) plus length-prefixed
// blocks.

void PutBlock(ByteWriter& sink, std::span<const uint8_t> bytes) {
  sink.PutVarU(bytes.size());
  sink.PutBytes(bytes);
}

Status GetBlock(ByteReader& source, std::span<const uint8_t>* bytes, std::string_view what) {
  uint64_t size;
  DMC_RETURN_IF_ERROR(source.GetVarU(&size, what));
  return source.GetBytes(static_cast<size_t>(size), bytes, what);
}

Status GetFiniteF64(ByteReader& source, double* value, std::string_view what) {
  DMC_RETURN_IF_ERROR(source.GetF64(value, what));
  if (!std::isfinite(*value)) return CorruptStreamError(std::string(what) + " is not finite");
  return Status::Ok();
}

Status ExpectEnd(const ByteReader& source, std::string_view what) {
  if (!source.at_end()) {
    return CorruptStreamError(std::string(what) + ": " + std::to_string(source.remaining()) +
                              " trailing bytes");
  }
  return Status::Ok();
}

// Limits a decoder accepts before allocating from a stream's own counts.
constexpr uint64_t kMaxVertices = uint64_t{1} << 28;
constexpr uint64_t kMaxTriangles = uint64_t{1} << 29;
constexpr uint64_t kMaxFrames = uint64_t{1} << 20;
constexpr uint64_t kMaxPositionValues = uint64_t{1} << 33;  // 32 GiB of float32
constexpr uint64_t kMaxDecompressedBytes = uint64_t{1} << 34;

Status CheckBits(int bits) {
  if (bits < kMinBaselineBits || bits > kMaxBaselineBits) {
    return InvalidArgumentError(
        "baseline quantisation bits must be in [" + std::to_string(kMinBaselineBits) + ", " +
        std::to_string(kMaxBaselineBits) + "], got " + std::to_string(bits));
  }
  return Status::Ok();
}

Status CheckSequenceSize(uint64_t vertices, uint64_t triangles, uint64_t frames) {
  if (vertices == 0 || triangles == 0 || frames == 0) {
    return CorruptStreamError("stream declares an empty sequence");
  }
  if (vertices * frames * 3 > kMaxPositionValues) {
    return CorruptStreamError("stream declares " + std::to_string(vertices) + " vertices x " +
                              std::to_string(frames) + " frames, more than a decoder accepts");
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------------
// The sequence-wide cubic quantisation grid of meshopt and zstd.

struct Grid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double step = 1.0;
  uint32_t max_level = 0;  // 2^bits − 1

  uint32_t Quantize(double value, int axis) const {
    const double level = std::round((value - origin[axis]) / step);
    return static_cast<uint32_t>(std::clamp(level, 0.0, static_cast<double>(max_level)));
  }
  float Dequantize(int64_t level, int axis) const {
    return static_cast<float>(origin[axis] + step * static_cast<double>(level));
  }
};

Grid MakeGrid(const MeshSequence& sequence, int bits) {
  const BoundingBox box = ComputeBoundingBox(sequence);
  Grid grid;
  grid.origin = box.min;
  grid.max_level = (uint32_t{1} << bits) - 1;
  const double extent = (box.max - box.min).maxCoeff();
  // A sequence that is one point everywhere has nothing to resolve; any positive step will do.
  grid.step = extent > 0.0 ? extent / grid.max_level : 1.0;
  return grid;
}

void PutGrid(ByteWriter& sink, const Grid& grid, int bits) {
  sink.PutVarU(static_cast<uint64_t>(bits));
  for (int axis = 0; axis < 3; ++axis) sink.PutF64(grid.origin[axis]);
  sink.PutF64(grid.step);
}

Status GetGrid(ByteReader& source, Grid* grid) {
  uint64_t bits;
  DMC_RETURN_IF_ERROR(source.GetVarURange(&bits, 0, kMaxBaselineBits, "quantisation bits"));
  if (bits < 1) return CorruptStreamError("quantisation bits are 0");
  grid->max_level = (uint32_t{1} << bits) - 1;
  for (int axis = 0; axis < 3; ++axis) {
    DMC_RETURN_IF_ERROR(GetFiniteF64(source, &grid->origin[axis], "grid origin"));
  }
  DMC_RETURN_IF_ERROR(GetFiniteF64(source, &grid->step, "grid step"));
  if (!(grid->step > 0.0)) return CorruptStreamError("grid step is not positive");
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------------
// zstd at its best level, one frame.

std::vector<uint8_t> ZstdCompress(std::span<const uint8_t> input) {
  std::vector<uint8_t> output(ZSTD_compressBound(input.size()));
  const size_t size =
      ZSTD_compress(output.data(), output.size(), input.data(), input.size(), ZSTD_maxCLevel());
  // Cannot fail: the buffer has the documented bound and the level is valid.
  output.resize(ZSTD_isError(size) ? 0 : size);
  return output;
}

StatusOr<std::vector<uint8_t>> ZstdDecompress(std::span<const uint8_t> input) {
  const unsigned long long size = ZSTD_getFrameContentSize(input.data(), input.size());
  if (size == ZSTD_CONTENTSIZE_ERROR) return CorruptStreamError("not a zstd frame");
  if (size == ZSTD_CONTENTSIZE_UNKNOWN || size > kMaxDecompressedBytes) {
    return CorruptStreamError("zstd frame declares no or an implausible content size");
  }
  std::vector<uint8_t> output(static_cast<size_t>(size));
  const size_t decoded = ZSTD_decompress(output.data(), output.size(), input.data(), input.size());
  if (ZSTD_isError(decoded)) {
    return CorruptStreamError(std::string("zstd: ") + ZSTD_getErrorName(decoded));
  }
  if (decoded != output.size()) return TruncatedStreamError("zstd frame is shorter than declared");
  return output;
}

// ---------------------------------------------------------------------------------------------
// draco

// One Draco point per input vertex with an identity-mapped float32 POSITION attribute, so that
// Draco's corner table has exactly the input's vertices (no deduplication of equal positions).
struct DracoFrameMesh {
  draco::Mesh mesh;
  draco::PointAttribute* position = nullptr;
  int position_id = -1;
};

std::unique_ptr<DracoFrameMesh> MakeDracoMesh(const MeshSequence& sequence) {
  auto frame_mesh = std::make_unique<DracoFrameMesh>();
  const auto vertex_count = static_cast<uint32_t>(sequence.vertex_count());
  frame_mesh->mesh.set_num_points(vertex_count);
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false,
                3 * sizeof(float), 0);
  frame_mesh->position_id = frame_mesh->mesh.AddAttribute(position, true, vertex_count);
  frame_mesh->position = frame_mesh->mesh.attribute(frame_mesh->position_id);
  const Triangles& triangles = sequence.triangles();
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    frame_mesh->mesh.AddFace({draco::PointIndex(static_cast<uint32_t>(triangles(t, 0))),
                              draco::PointIndex(static_cast<uint32_t>(triangles(t, 1))),
                              draco::PointIndex(static_cast<uint32_t>(triangles(t, 2)))});
  }
  return frame_mesh;
}

StatusOr<BaselineStream> EncodeDraco(const MeshSequence& sequence, int bits) {
  const int vertex_count = sequence.vertex_count();
  std::unique_ptr<DracoFrameMesh> frame_mesh = MakeDracoMesh(sequence);
  // What draco::Encoder does for SetSpeedOptions(0, 0), SetAttributeQuantization(POSITION, bits)
  // and SetEncodingMethod(MESH_EDGEBREAKER_ENCODING); the edgebreaker encoder is used directly
  // because only it exposes the vertex order it chose (tests/unit/sweep checks the bytes agree).
  draco::EncoderOptions options = draco::EncoderOptions::CreateDefaultOptions();
  options.SetSpeed(0, 0);
  options.SetAttributeInt(frame_mesh->position_id, "quantization_bits", bits);
  // Bookkeeping only (the bytes do not change): makes num_encoded_faces() available.
  options.SetGlobalBool("store_number_of_encoded_faces", true);

  ByteWriter sink;
  sink.PutVarU(static_cast<uint64_t>(sequence.frame_count()));
  BaselineStream stream;
  for (int f = 0; f < sequence.frame_count(); ++f) {
    const auto frame = sequence.frame(f);
    for (int v = 0; v < vertex_count; ++v) {
      frame_mesh->position->SetAttributeValue(draco::AttributeValueIndex(v), frame.row(v).data());
    }
    draco::MeshEdgebreakerEncoder encoder;
    encoder.SetMesh(frame_mesh->mesh);
    draco::EncoderBuffer buffer;
    if (const draco::Status status = encoder.Encode(options, &buffer); !status.ok()) {
      return UnsupportedError("Draco cannot encode frame " + std::to_string(f) + ": " +
                              status.error_msg_string());
    }
    if (encoder.num_encoded_faces() != static_cast<size_t>(sequence.triangle_count())) {
      return UnsupportedError("Draco dropped " +
                              std::to_string(sequence.triangle_count() -
                                             static_cast<int64_t>(encoder.num_encoded_faces())) +
                              " degenerate triangles");
    }
    // Draco numbers the decoded attribute values in its traversal order; invert its
    // vertex → value map to know which input vertex each decoded value is.
    const draco::MeshAttributeIndicesEncodingData* encoding_data =
        encoder.GetAttributeEncodingData(frame_mesh->position_id);
    if (encoding_data == nullptr ||
        encoding_data->vertex_to_encoded_attribute_value_index_map.size() !=
            static_cast<size_t>(vertex_count)) {
      return UnsupportedError(
          "Draco split non-manifold vertices, so its output does not map one to one onto the "
          "input");
    }
    std::vector<int32_t> input_vertex(vertex_count, -1);
    for (int v = 0; v < vertex_count; ++v) {
      const int32_t value = encoding_data->vertex_to_encoded_attribute_value_index_map[v];
      if (value < 0 || value >= vertex_count || input_vertex[value] >= 0) {
        return InternalError("Draco's vertex order is not a permutation");
      }
      input_vertex[value] = v;
    }
    if (f == 0) {
      stream.input_vertex = std::move(input_vertex);
    } else if (input_vertex != stream.input_vertex) {
      return InternalError("Draco chose a different vertex order in frame " + std::to_string(f));
    }
    PutBlock(sink, {reinterpret_cast<const uint8_t*>(buffer.data()), buffer.size()});
  }
  stream.bytes = sink.Take();
  return stream;
}

StatusOr<MeshSequence> DecodeDraco(std::span<const uint8_t> bytes) {
  ByteReader source(bytes);
  uint64_t frame_count;
  DMC_RETURN_IF_ERROR(source.GetVarURange(&frame_count, 0, kMaxFrames, "frame count"));
  if (frame_count == 0) return CorruptStreamError("stream declares no frames");
  MeshSequence sequence;
  for (uint64_t f = 0; f < frame_count; ++f) {
    std::span<const uint8_t> block;
    DMC_RETURN_IF_ERROR(GetBlock(source, &block, "Draco frame"));
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(block.data()), block.size());
    draco::Decoder decoder;
    draco::StatusOr<std::unique_ptr<draco::Mesh>> decoded = decoder.DecodeMeshFromBuffer(&buffer);
    const std::string where = "Draco frame " + std::to_string(f);
    if (!decoded.ok()) {
      return CorruptStreamError(where + ": " + decoded.status().error_msg_string());
    }
    const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
    const draco::PointAttribute* position =
        mesh ? mesh->GetNamedAttribute(draco::GeometryAttribute::POSITION) : nullptr;
    if (position == nullptr || position->num_components() != 3 ||
        position->data_type() != draco::DT_FLOAT32) {
      return CorruptStreamError(where + " has no float32 xyz POSITION attribute");
    }
    // Output vertex i is attribute value i (the order EncodeDraco's input_vertex refers to).
    const auto value_count = static_cast<int>(position->size());
    if (f == 0) {
      DMC_RETURN_IF_ERROR(
          CheckSequenceSize(static_cast<uint64_t>(value_count), mesh->num_faces(), frame_count));
      Triangles triangles(mesh->num_faces(), 3);
      for (uint32_t t = 0; t < mesh->num_faces(); ++t) {
        const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(t));
        for (int k = 0; k < 3; ++k) {
          if (face[k].value() >= mesh->num_points()) {
            return CorruptStreamError(where + ": triangle " + std::to_string(t) +
                                      " refers to a missing point");
          }
          triangles(t, k) = static_cast<int32_t>(position->mapped_index(face[k]).value());
        }
      }
      sequence = MeshSequence(value_count, std::move(triangles));
    } else if (value_count != sequence.vertex_count() ||
               static_cast<int>(mesh->num_faces()) != sequence.triangle_count()) {
      return CorruptStreamError(where + " has a different vertex or triangle count than frame 0");
    }
    FramePositions positions(value_count, 3);
    for (int v = 0; v < value_count; ++v) {
      position->GetValue(draco::AttributeValueIndex(v), positions.row(v).data());
    }
    DMC_RETURN_IF_ERROR(sequence.AppendFrame(positions));
  }
  DMC_RETURN_IF_ERROR(ExpectEnd(source, "draco stream"));
  return sequence;
}

// ---------------------------------------------------------------------------------------------
// meshopt

// KHR_mesh_quantization's position layout: xyz as uint16 plus one padding value, because the
// vertex codec needs a vertex size that is a multiple of 4 bytes.
struct QuantizedVertex {
  std::array<uint16_t, 4> xyzw;
};
static_assert(sizeof(QuantizedVertex) == 8);

StatusOr<BaselineStream> EncodeMeshopt(const MeshSequence& sequence, int bits) {
  const size_t vertex_count = static_cast<size_t>(sequence.vertex_count());
  const size_t index_count = static_cast<size_t>(sequence.triangle_count()) * 3;
  // gltfpack's order: triangles for the post-transform cache, then vertices in first-use order.
  std::vector<uint32_t> input_indices(index_count);
  for (size_t i = 0; i < index_count; ++i) {
    input_indices[i] = static_cast<uint32_t>(sequence.triangles().data()[i]);
  }
  std::vector<uint32_t> cache_indices(index_count);
  meshopt_optimizeVertexCache(cache_indices.data(), input_indices.data(), index_count,
                              vertex_count);
  std::vector<uint32_t> remap(vertex_count);
  size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), cache_indices.data(), index_count,
                                                 vertex_count);
  // Unreferenced vertices (~0u) keep their place at the end, so the vertex count is kept.
  for (uint32_t& slot : remap) {
    if (slot == ~0u) slot = static_cast<uint32_t>(used++);
  }
  std::vector<uint32_t> indices(index_count);
  meshopt_remapIndexBuffer(indices.data(), cache_indices.data(), index_count, remap.data());
  BaselineStream stream;
  stream.input_vertex.resize(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) stream.input_vertex[remap[v]] = static_cast<int32_t>(v);

  const Grid grid = MakeGrid(sequence, bits);
  ByteWriter sink;
  sink.PutVarU(vertex_count);
  sink.PutVarU(static_cast<uint64_t>(sequence.triangle_count()));
  sink.PutVarU(static_cast<uint64_t>(sequence.frame_count()));
  PutGrid(sink, grid, bits);
  std::vector<uint8_t> coded(meshopt_encodeIndexBufferBound(index_count, vertex_count));
  coded.resize(meshopt_encodeIndexBuffer(coded.data(), coded.size(), indices.data(), index_count));
  PutBlock(sink, coded);

  std::vector<QuantizedVertex> vertices(vertex_count, QuantizedVertex{{0, 0, 0, 0}});
  coded.resize(meshopt_encodeVertexBufferBound(vertex_count, sizeof(QuantizedVertex)));
  for (int f = 0; f < sequence.frame_count(); ++f) {
    const auto frame = sequence.frame(f);
    for (size_t v = 0; v < vertex_count; ++v) {
      for (int axis = 0; axis < 3; ++axis) {
        vertices[remap[v]].xyzw[axis] =
            static_cast<uint16_t>(grid.Quantize(frame(static_cast<Eigen::Index>(v), axis), axis));
      }
    }
    const size_t size = meshopt_encodeVertexBuffer(coded.data(), coded.size(), vertices.data(),
                                                   vertex_count, sizeof(QuantizedVertex));
    PutBlock(sink, {coded.data(), size});
  }
  stream.bytes = ZstdCompress(sink.bytes());
  if (stream.bytes.empty()) return InternalError("zstd failed to compress the meshopt stream");
  return stream;
}

StatusOr<MeshSequence> DecodeMeshopt(std::span<const uint8_t> bytes) {
  DMC_ASSIGN_OR_RETURN(const std::vector<uint8_t> payload, ZstdDecompress(bytes));
  ByteReader source(payload);
  uint64_t vertex_count, triangle_count, frame_count;
  DMC_RETURN_IF_ERROR(source.GetVarURange(&vertex_count, 0, kMaxVertices, "vertex count"));
  DMC_RETURN_IF_ERROR(source.GetVarURange(&triangle_count, 0, kMaxTriangles, "triangle count"));
  DMC_RETURN_IF_ERROR(source.GetVarURange(&frame_count, 0, kMaxFrames, "frame count"));
  DMC_RETURN_IF_ERROR(CheckSequenceSize(vertex_count, triangle_count, frame_count));
  Grid grid;
  DMC_RETURN_IF_ERROR(GetGrid(source, &grid));

  std::span<const uint8_t> block;
  DMC_RETURN_IF_ERROR(GetBlock(source, &block, "index buffer"));
  const size_t index_count = static_cast<size_t>(triangle_count) * 3;
  std::vector<uint32_t> indices(index_count);
  if (meshopt_decodeIndexBuffer(indices.data(), index_count, sizeof(uint32_t), block.data(),
                                block.size()) != 0) {
    return CorruptStreamError("meshopt cannot decode the index buffer");
  }
  Triangles triangles(static_cast<Eigen::Index>(triangle_count), 3);
  for (size_t i = 0; i < index_count; ++i) {
    if (indices[i] >= vertex_count) {
      return CorruptStreamError("index " + std::to_string(i) + " is " + std::to_string(indices[i]) +
                                ", past the vertex count");
    }
    triangles.data()[i] = static_cast<int32_t>(indices[i]);
  }
  MeshSequence sequence(static_cast<int>(vertex_count), std::move(triangles),
                        static_cast<int>(frame_count));
  std::vector<QuantizedVertex> vertices(vertex_count);
  for (uint64_t f = 0; f < frame_count; ++f) {
    DMC_RETURN_IF_ERROR(GetBlock(source, &block, "vertex buffer"));
    if (meshopt_decodeVertexBuffer(vertices.data(), vertex_count, sizeof(QuantizedVertex),
                                   block.data(), block.size()) != 0) {
      return CorruptStreamError("meshopt cannot decode the vertex buffer of frame " +
                                std::to_string(f));
    }
    auto frame = sequence.frame(static_cast<int>(f));
    for (size_t v = 0; v < vertex_count; ++v) {
      for (int axis = 0; axis < 3; ++axis) {
        frame(static_cast<Eigen::Index>(v), axis) = grid.Dequantize(vertices[v].xyzw[axis], axis);
      }
    }
  }
  DMC_RETURN_IF_ERROR(ExpectEnd(source, "meshopt stream"));
  return sequence;
}

// ---------------------------------------------------------------------------------------------
// zstd

StatusOr<BaselineStream> EncodeZstd(const MeshSequence& sequence, int bits) {
  const int vertex_count = sequence.vertex_count();
  const int frame_count = sequence.frame_count();
  const Grid grid = MakeGrid(sequence, bits);
  // Zigzagged differences of consecutive frames' levels (frame 0 against all zeros), per frame
  // and axis: values[(f * 3 + axis) * V + v].
  std::vector<uint32_t> values(static_cast<size_t>(frame_count) * 3 * vertex_count);
  std::vector<int64_t> previous(static_cast<size_t>(vertex_count) * 3, 0);
  uint32_t largest = 0;
  for (int f = 0; f < frame_count; ++f) {
    const auto frame = sequence.frame(f);
    for (int axis = 0; axis < 3; ++axis) {
      for (int v = 0; v < vertex_count; ++v) {
        const int64_t level = grid.Quantize(frame(v, axis), axis);
        const auto coded = static_cast<uint32_t>(ZigZagEncode(level - previous[3 * v + axis]));
        previous[3 * v + axis] = level;
        values[(static_cast<size_t>(f) * 3 + axis) * vertex_count + v] = coded;
        largest = std::max(largest, coded);
      }
    }
  }
  const int width = largest < (1u << 8) ? 1 : largest < (1u << 16) ? 2 : 4;

  ByteWriter sink;
  sink.PutVarU(static_cast<uint64_t>(vertex_count));
  sink.PutVarU(static_cast<uint64_t>(sequence.triangle_count()));
  sink.PutVarU(static_cast<uint64_t>(frame_count));
  PutGrid(sink, grid, bits);
  sink.PutVarU(static_cast<uint64_t>(width));
  for (Eigen::Index i = 0; i < sequence.triangles().size(); ++i) {
    sink.PutU32(static_cast<uint32_t>(sequence.triangles().data()[i]));
  }
  // Byte planes per (frame, axis) row of V values: all lowest bytes, then the next ones.
  for (size_t row = 0; row < static_cast<size_t>(frame_count) * 3; ++row) {
    const uint32_t* row_values = values.data() + row * vertex_count;
    for (int plane = 0; plane < width; ++plane) {
      for (int v = 0; v < vertex_count; ++v) {
        sink.PutU8(static_cast<uint8_t>(row_values[v] >> (8 * plane)));
      }
    }
  }
  BaselineStream stream;
  stream.bytes = ZstdCompress(sink.bytes());
  if (stream.bytes.empty()) return InternalError("zstd failed to compress the delta stream");
  return stream;
}

StatusOr<MeshSequence> DecodeZstd(std::span<const uint8_t> bytes) {
  DMC_ASSIGN_OR_RETURN(const std::vector<uint8_t> payload, ZstdDecompress(bytes));
  ByteReader source(payload);
  uint64_t vertex_count, triangle_count, frame_count, width;
  DMC_RETURN_IF_ERROR(source.GetVarURange(&vertex_count, 0, kMaxVertices, "vertex count"));
  DMC_RETURN_IF_ERROR(source.GetVarURange(&triangle_count, 0, kMaxTriangles, "triangle count"));
  DMC_RETURN_IF_ERROR(source.GetVarURange(&frame_count, 0, kMaxFrames, "frame count"));
  DMC_RETURN_IF_ERROR(CheckSequenceSize(vertex_count, triangle_count, frame_count));
  Grid grid;
  DMC_RETURN_IF_ERROR(GetGrid(source, &grid));
  DMC_RETURN_IF_ERROR(source.GetVarURange(&width, 0, 4, "delta width"));
  if (width != 1 && width != 2 && width != 4) {
    return CorruptStreamError("delta width " + std::to_string(width) + " is not 1, 2 or 4");
  }

  std::span<const uint8_t> block;
  DMC_RETURN_IF_ERROR(
      source.GetBytes(static_cast<size_t>(triangle_count) * 12, &block, "triangles"));
  Triangles triangles(static_cast<Eigen::Index>(triangle_count), 3);
  for (size_t i = 0; i < triangle_count * 3; ++i) {
    uint32_t index = 0;
    for (int k = 0; k < 4; ++k) index |= static_cast<uint32_t>(block[4 * i + k]) << (8 * k);
    if (index >= vertex_count) {
      return CorruptStreamError("triangle index " + std::to_string(i) +
                                " is past the vertex count");
    }
    triangles.data()[i] = static_cast<int32_t>(index);
  }
  const auto v_count = static_cast<int>(vertex_count);
  MeshSequence sequence(v_count, std::move(triangles), static_cast<int>(frame_count));
  std::vector<int64_t> levels(static_cast<size_t>(vertex_count) * 3, 0);
  for (int f = 0; f < static_cast<int>(frame_count); ++f) {
    auto frame = sequence.frame(f);
    for (int axis = 0; axis < 3; ++axis) {
      DMC_RETURN_IF_ERROR(
          source.GetBytes(static_cast<size_t>(width * vertex_count), &block, "delta planes"));
      for (int v = 0; v < v_count; ++v) {
        uint32_t coded = 0;
        for (uint64_t plane = 0; plane < width; ++plane) {
          coded |= static_cast<uint32_t>(block[plane * vertex_count + v]) << (8 * plane);
        }
        int64_t& level = levels[3 * static_cast<size_t>(v) + axis];
        level += ZigZagDecode(coded);
        frame(v, axis) = grid.Dequantize(level, axis);
      }
    }
  }
  DMC_RETURN_IF_ERROR(ExpectEnd(source, "zstd stream"));
  return sequence;
}

}  // namespace

std::string_view BaselineName(BaselineKind kind) {
  switch (kind) {
    case BaselineKind::kDraco:
      return "draco";
    case BaselineKind::kMeshopt:
      return "meshopt";
    case BaselineKind::kZstd:
      return "zstd";
  }
  return "";
}

std::vector<BaselineKind> AllBaselines() {
  return {BaselineKind::kDraco, BaselineKind::kMeshopt, BaselineKind::kZstd};
}

StatusOr<BaselineKind> ParseBaseline(std::string_view name) {
  std::string known;
  for (const BaselineKind kind : AllBaselines()) {
    if (BaselineName(kind) == name) return kind;
    known += (known.empty() ? "" : ", ") + std::string(BaselineName(kind));
  }
  return InvalidArgumentError("unknown baseline '" + std::string(name) + "' (known: " + known +
                              ")");
}

StatusOr<BaselineStream> EncodeBaseline(BaselineKind kind, const MeshSequence& sequence, int bits) {
  DMC_RETURN_IF_ERROR(CheckBits(bits));
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  switch (kind) {
    case BaselineKind::kDraco:
      return EncodeDraco(sequence, bits);
    case BaselineKind::kMeshopt:
      return EncodeMeshopt(sequence, bits);
    case BaselineKind::kZstd:
      return EncodeZstd(sequence, bits);
  }
  return InternalError("unknown baseline kind");
}

StatusOr<MeshSequence> DecodeBaseline(BaselineKind kind, std::span<const uint8_t> bytes) {
  switch (kind) {
    case BaselineKind::kDraco:
      return DecodeDraco(bytes);
    case BaselineKind::kMeshopt:
      return DecodeMeshopt(bytes);
    case BaselineKind::kZstd:
      return DecodeZstd(bytes);
  }
  return InternalError("unknown baseline kind");
}

StatusOr<MeshSequence> RestoreInputOrder(const MeshSequence& decoded,
                                         std::span<const int32_t> input_vertex) {
  if (input_vertex.empty()) return decoded;
  const int vertex_count = decoded.vertex_count();
  if (static_cast<int>(input_vertex.size()) != vertex_count) {
    return MismatchError("vertex order has " + std::to_string(input_vertex.size()) +
                         " entries for " + std::to_string(vertex_count) + " decoded vertices");
  }
  std::vector<uint8_t> seen(vertex_count, 0);
  for (const int32_t v : input_vertex) {
    if (v < 0 || v >= vertex_count || seen[v]) {
      return MismatchError("vertex order is not a permutation of the decoded vertices");
    }
    seen[v] = 1;
  }
  Triangles triangles(decoded.triangle_count(), 3);
  for (Eigen::Index i = 0; i < triangles.size(); ++i) {
    triangles.data()[i] = input_vertex[decoded.triangles().data()[i]];
  }
  MeshSequence restored(vertex_count, std::move(triangles), decoded.frame_count());
  restored.name = decoded.name;
  restored.frame_rate = decoded.frame_rate;
  for (int f = 0; f < decoded.frame_count(); ++f) {
    const auto from = decoded.frame(f);
    auto to = restored.frame(f);
    for (int v = 0; v < vertex_count; ++v) to.row(input_vertex[v]) = from.row(v);
  }
  return restored;
}

}  // namespace dmc::sweep
