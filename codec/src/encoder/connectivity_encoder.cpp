#include "encoder/connectivity_encoder.h"

#include <draco/compression/config/compression_shared.h>
#include <draco/compression/config/encoder_options.h>
#include <draco/compression/mesh/mesh_edgebreaker_encoder.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <array>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include "bitstream/format.h"
#include "encoder/range_encoder.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace {

using connectivity::LabelPredictor;

Status CheckTriangles(const Triangles& triangles, int vertex_count) {
  if (vertex_count < 0) {
    return InvalidArgumentError("vertex count " + std::to_string(vertex_count) + " is negative");
  }
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (triangles(t, k) < 0 || triangles(t, k) >= vertex_count) {
        return InvalidArgumentError("triangle " + std::to_string(t) + " has vertex " +
                                    std::to_string(triangles(t, k)) + " outside [0, " +
                                    std::to_string(vertex_count) + ")");
      }
    }
  }
  return Status::Ok();
}

// The oriented triangles as a sorted list, each rotated to start at its smallest index: equal
// lists mean the same set of triangles with the same orientation.
std::vector<std::array<int32_t, 3>> CanonicalTriangleSet(const Triangles& triangles) {
  std::vector<std::array<int32_t, 3>> set(static_cast<size_t>(triangles.rows()));
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const std::array<int32_t, 3> tri = {triangles(t, 0), triangles(t, 1), triangles(t, 2)};
    const int first = static_cast<int>(std::min_element(tri.begin(), tri.end()) - tri.begin());
    set[t] = {tri[first], tri[(first + 1) % 3], tri[(first + 2) % 3]};
  }
  std::sort(set.begin(), set.end());
  return set;
}

Triangles Relabel(const Triangles& triangles, std::span<const int32_t> labels) {
  Triangles out(triangles.rows(), 3);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) out(t, k) = labels[triangles(t, k)];
  }
  return out;
}

std::vector<uint8_t> EncodeIndexed(const Triangles& triangles) {
  RangeEncoder encoder;
  IntegerContexts first, second, third;
  int64_t previous = 0;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const int64_t a = triangles(t, 0), b = triangles(t, 1), c = triangles(t, 2);
    encoder.EncodeSigned(first, a - previous);
    encoder.EncodeSigned(second, b - a);
    encoder.EncodeSigned(third, c - a);
    previous = a;
  }
  std::vector<uint8_t> payload = {static_cast<uint8_t>(ConnectivityCoding::kIndexed)};
  const std::vector<uint8_t> coded = encoder.Finish();
  payload.insert(payload.end(), coded.begin(), coded.end());
  return payload;
}

// A Draco buffer that reproduces the input, with the input vertex of every decoded point.
struct DracoCoding {
  std::vector<uint8_t> buffer;
  Triangles decoded;                  // faces over Draco points, exactly as the decoder gets them
  std::vector<int32_t> input_vertex;  // decoded point -> input vertex (a permutation)
};

// Builds the Draco mesh: one point per input vertex, and the 1-component all-zero uint8 POSITION
// attribute that Draco needs for its corner table (identity-mapped, so that distinct vertices
// stay distinct). Its coded values cost a few bytes in total.
std::unique_ptr<draco::Mesh> MakeDracoMesh(const Triangles& triangles, int vertex_count,
                                           int* attribute_id) {
  auto mesh = std::make_unique<draco::Mesh>();
  mesh->set_num_points(static_cast<uint32_t>(vertex_count));
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 1, draco::DT_UINT8, false, 1, 0);
  *attribute_id = mesh->AddAttribute(position, true, static_cast<uint32_t>(vertex_count));
  const uint8_t zero = 0;
  draco::PointAttribute* attribute = mesh->attribute(*attribute_id);
  for (int v = 0; v < vertex_count; ++v) {
    attribute->SetAttributeValue(draco::AttributeValueIndex(v), &zero);
  }
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    mesh->AddFace({draco::PointIndex(static_cast<uint32_t>(triangles(t, 0))),
                   draco::PointIndex(static_cast<uint32_t>(triangles(t, 1))),
                   draco::PointIndex(static_cast<uint32_t>(triangles(t, 2)))});
  }
  return mesh;
}

// Codes with one edgebreaker traversal, decodes the result and checks that, relabelled back to
// input vertices, it is the input triangle set. nullopt when Draco fails or cannot reproduce it.
std::optional<DracoCoding> TryDraco(const draco::Mesh& mesh, int attribute_id,
                                    const Triangles& triangles, int vertex_count,
                                    int edgebreaker_method) {
  draco::EncoderOptions options = draco::EncoderOptions::CreateDefaultOptions();
  options.SetSpeed(0, 0);  // best compression
  options.SetGlobalInt("edgebreaker_method", edgebreaker_method);
  // The attribute is constant: prediction would only add side information.
  options.SetAttributeInt(attribute_id, "prediction_scheme", draco::PREDICTION_NONE);
  draco::MeshEdgebreakerEncoder encoder;
  encoder.SetMesh(mesh);
  draco::EncoderBuffer buffer;
  if (!encoder.Encode(options, &buffer).ok()) return std::nullopt;

  DracoCoding coding;
  coding.buffer.assign(reinterpret_cast<const uint8_t*>(buffer.data()),
                       reinterpret_cast<const uint8_t*>(buffer.data()) + buffer.size());
  // Draco numbers attribute values in its traversal order; the decoder's points refer to those
  // value indices. Invert the encoder's vertex -> value map to get each point's input vertex.
  const draco::MeshAttributeIndicesEncodingData* encoding_data =
      encoder.GetAttributeEncodingData(attribute_id);
  if (encoding_data == nullptr) return std::nullopt;
  const std::vector<int32_t>& value_of_vertex =
      encoding_data->vertex_to_encoded_attribute_value_index_map;
  if (static_cast<int>(value_of_vertex.size()) != vertex_count) return std::nullopt;  // split
  std::vector<int32_t> vertex_of_value(vertex_count, -1);
  for (int v = 0; v < vertex_count; ++v) {
    const int32_t value = value_of_vertex[v];
    if (value < 0 || value >= vertex_count || vertex_of_value[value] >= 0) return std::nullopt;
    vertex_of_value[value] = v;
  }

  std::vector<int32_t> point_values;
  StatusOr<Triangles> decoded =
      connectivity::DecodeDracoTriangles(coding.buffer, static_cast<uint32_t>(vertex_count),
                                         static_cast<uint32_t>(triangles.rows()), &point_values);
  if (!decoded.ok()) return std::nullopt;  // vertices or triangles dropped, or Draco failed
  coding.decoded = std::move(decoded).value();
  coding.input_vertex.resize(vertex_count);
  for (int p = 0; p < vertex_count; ++p) {
    const int32_t value = point_values[p];
    if (value < 0 || value >= vertex_count || vertex_of_value[value] < 0) return std::nullopt;
    coding.input_vertex[p] = vertex_of_value[value];
  }
  if (CanonicalTriangleSet(Relabel(coding.decoded, coding.input_vertex)) !=
      CanonicalTriangleSet(triangles)) {
    return std::nullopt;
  }
  return coding;
}

// The smallest exact Draco coding over the standard and valence edgebreaker traversals (valence
// wins on large meshes, standard on tiny ones).
StatusOr<DracoCoding> EncodeDraco(const Triangles& triangles, int vertex_count) {
  // Draco needs at least one non-degenerate triangle over three distinct vertices.
  if (vertex_count < 3 || triangles.rows() == 0) {
    return UnsupportedError("Draco cannot code " + std::to_string(triangles.rows()) +
                            " triangles over " + std::to_string(vertex_count) + " vertices");
  }
  int attribute_id = -1;
  const std::unique_ptr<draco::Mesh> mesh = MakeDracoMesh(triangles, vertex_count, &attribute_id);
  std::optional<DracoCoding> best;
  for (const int method :
       {draco::MESH_EDGEBREAKER_STANDARD_ENCODING, draco::MESH_EDGEBREAKER_VALENCE_ENCODING}) {
    std::optional<DracoCoding> coding =
        TryDraco(*mesh, attribute_id, triangles, vertex_count, method);
    if (coding && (!best || coding->buffer.size() < best->buffer.size())) best = std::move(coding);
  }
  if (!best) {
    return UnsupportedError(
        "Draco cannot reproduce this triangle list exactly (isolated vertices, degenerate "
        "triangles or non-manifold vertices)");
  }
  return std::move(*best);
}

// Range-codes the labels of the Draco points (see connectivity_decoder.h).
std::vector<uint8_t> EncodeLabels(const connectivity::TriangleAdjacency& adjacency,
                                  const std::vector<int32_t>& order,
                                  std::span<const int32_t> input_vertex,
                                  connectivity::LabelModel model) {
  RangeEncoder encoder;
  std::array<IntegerContexts, connectivity::kLabelContextCount> contexts;
  std::array<AdaptiveBit, connectivity::kKernelEscapeContexts> escape_contexts;
  const int32_t v_count = adjacency.vertex_count();
  connectivity::UnusedLabels unused(v_count);
  std::vector<int32_t> labels(v_count, -1);
  const bool use_kernel = model.kernel_code != 0;
  std::vector<uint8_t> used(use_kernel ? v_count : 0, 0);
  connectivity::LabelKernel kernel(connectivity::kKernelRadii[model.kernel_code],
                                   use_kernel ? v_count : 0);
  int32_t previous_label = -1;
  std::vector<int64_t> scratch;
  std::vector<int32_t> neighbors, centers;
  for (const int32_t v : order) {
    const int32_t label = input_vertex[v];
    bool coded = false;
    if (use_kernel) {
      connectivity::KernelCenters(adjacency, labels, v, neighbors, centers);
      if (!centers.empty()) {
        kernel.Build(centers, used);
        const auto candidate_count = static_cast<int32_t>(kernel.candidates().size());
        if (candidate_count > 0) {
          const int32_t index = kernel.Find(label);
          const size_t escape_context =
              std::min(centers.size(), size_t{connectivity::kKernelEscapeContexts}) - 1;
          encoder.EncodeBit(escape_contexts[escape_context], index < 0 ? 1 : 0);
          if (index >= 0) {
            int32_t lo = 0, hi = candidate_count;
            while (hi - lo > 1) {
              const int32_t mid = lo + (hi - lo) / 2;
              AdaptiveBit split;  // a fixed probability: the model is never reused
              split.fast = split.slow = static_cast<uint16_t>(kernel.SplitP0(lo, hi));
              const int bit = index >= mid ? 1 : 0;
              encoder.EncodeBit(split, bit);
              (bit == 0 ? hi : lo) = mid;
            }
            coded = true;
          }
        }
      }
    }
    if (!coded) {
      const connectivity::LabelPrediction prediction = connectivity::PredictLabel(
          adjacency, labels, v, model.predictor, previous_label, scratch);
      encoder.EncodeSigned(
          contexts[connectivity::LabelContext(prediction, unused, model.spread_contexts)],
          int64_t{unused.Rank(label)} - unused.Rank(prediction.label));
    }
    unused.Remove(label);
    labels[v] = label;
    previous_label = label;
    if (use_kernel) {
      used[static_cast<size_t>(label)] = 1;
      if (!centers.empty()) kernel.Update(centers, label);
    }
  }
  return encoder.Finish();
}

void AppendDracoBuffer(ByteWriter& writer, const std::vector<uint8_t>& buffer) {
  writer.PutVarU(buffer.size());
  writer.PutBytes(buffer);
}

// `forced_model`: code the labels with this model instead of the smallest one.
ConnectivityCode EncodeDracoWithVertexOrder(
    const DracoCoding& draco, uint8_t version_minor,
    std::optional<connectivity::LabelModel> forced_model = std::nullopt) {
  const connectivity::TriangleAdjacency adjacency(draco.decoded,
                                                  static_cast<int32_t>(draco.input_vertex.size()));
  const std::vector<int32_t> order = connectivity::LabelCodingOrder(adjacency);
  // Which model wins depends on how the input was labelled: try each 1.0 model, then (1.1) each
  // kernel radius with the best 1.0 model's predictor and contexts (they code only the escapes),
  // and keep the smallest.
  std::vector<uint8_t> best_labels;
  connectivity::LabelModel best_model;
  auto try_model = [&](const connectivity::LabelModel& model) {
    std::vector<uint8_t> coded = EncodeLabels(adjacency, order, draco.input_vertex, model);
    if (best_labels.empty() || coded.size() < best_labels.size()) {
      best_labels = std::move(coded);
      best_model = model;
    }
  };
  if (forced_model) {
    try_model(*forced_model);
  } else {
    for (int wire = 0; wire < connectivity::kLabelModelCount; ++wire) {
      try_model(connectivity::LabelModel::FromWire(static_cast<uint8_t>(wire)));
    }
  }
  if (!forced_model &&
      connectivity::LabelModelCount(version_minor) > connectivity::kLabelModelCount) {
    const connectivity::LabelModel base = best_model;
    for (uint8_t code = 1; code < connectivity::kKernelRadii.size(); ++code) {
      connectivity::LabelModel model = base;
      model.kernel_code = code;
      try_model(model);
    }
  }
  ByteWriter writer;
  writer.PutU8(static_cast<uint8_t>(ConnectivityCoding::kDracoWithVertexOrder));
  AppendDracoBuffer(writer, draco.buffer);
  writer.PutU8(best_model.wire());
  writer.PutBytes(best_labels);
  ConnectivityCode code;
  code.payload = writer.Take();
  return code;
}

ConnectivityCode EncodeDracoReordered(const DracoCoding& draco) {
  ByteWriter writer;
  writer.PutU8(static_cast<uint8_t>(ConnectivityCoding::kDracoReordered));
  AppendDracoBuffer(writer, draco.buffer);
  ConnectivityCode code;
  code.payload = writer.Take();
  code.vertex_order = draco.input_vertex;
  return code;
}

// Closed loop: decodes the payload as a decoder will, stores the result and checks that it is the
// input (through vertex_order when reordered). A failure here is a bug in this coder.
Status FinishByDecoding(const Triangles& input, int vertex_count, uint8_t version_minor,
                        ConnectivityCode& code) {
  StatusOr<Triangles> decoded =
      DecodeConnectivity(code.payload, static_cast<uint32_t>(vertex_count),
                         static_cast<uint32_t>(input.rows()), version_minor);
  if (!decoded.ok()) {
    return InternalError("connectivity payload does not decode: " + decoded.status().ToString());
  }
  code.triangles = std::move(decoded).value();
  const Triangles in_input_labels =
      code.vertex_order.empty() ? code.triangles : Relabel(code.triangles, code.vertex_order);
  const bool exact = code.method() == ConnectivityCoding::kIndexed
                         ? in_input_labels == input
                         : CanonicalTriangleSet(in_input_labels) == CanonicalTriangleSet(input);
  if (!exact) return InternalError("decoded connectivity differs from the input");
  return Status::Ok();
}

}  // namespace

StatusOr<ConnectivityCode> EncodeConnectivityWithMethod(const Triangles& triangles,
                                                        int vertex_count, ConnectivityCoding method,
                                                        uint8_t version_minor) {
  DMC_RETURN_IF_ERROR(CheckTriangles(triangles, vertex_count));
  ConnectivityCode code;
  switch (method) {
    case ConnectivityCoding::kIndexed:
      code.payload = EncodeIndexed(triangles);
      break;
    case ConnectivityCoding::kDracoWithVertexOrder: {
      DMC_ASSIGN_OR_RETURN(const DracoCoding draco, EncodeDraco(triangles, vertex_count));
      code = EncodeDracoWithVertexOrder(draco, version_minor);
      break;
    }
    case ConnectivityCoding::kDracoReordered: {
      DMC_ASSIGN_OR_RETURN(const DracoCoding draco, EncodeDraco(triangles, vertex_count));
      code = EncodeDracoReordered(draco);
      break;
    }
    default:
      return InvalidArgumentError("connectivity method " +
                                  std::to_string(static_cast<int>(method)) + " is unknown");
  }
  DMC_RETURN_IF_ERROR(FinishByDecoding(triangles, vertex_count, version_minor, code));
  return code;
}

StatusOr<ConnectivityCode> EncodeConnectivityWithLabelModel(const Triangles& triangles,
                                                            int vertex_count, uint8_t label_model,
                                                            uint8_t version_minor) {
  DMC_RETURN_IF_ERROR(CheckTriangles(triangles, vertex_count));
  if (label_model >= connectivity::LabelModelCount(version_minor)) {
    return InvalidArgumentError("label model " + std::to_string(label_model) +
                                " does not exist in format 1." + std::to_string(version_minor));
  }
  DMC_ASSIGN_OR_RETURN(const DracoCoding draco, EncodeDraco(triangles, vertex_count));
  ConnectivityCode code = EncodeDracoWithVertexOrder(
      draco, version_minor, connectivity::LabelModel::FromWire(label_model));
  DMC_RETURN_IF_ERROR(FinishByDecoding(triangles, vertex_count, version_minor, code));
  return code;
}

StatusOr<ConnectivityCode> EncodeConnectivity(const Triangles& triangles, int vertex_count,
                                              bool allow_reorder, uint8_t version_minor) {
  DMC_RETURN_IF_ERROR(CheckTriangles(triangles, vertex_count));
  ConnectivityCode best;
  best.payload = EncodeIndexed(triangles);
  StatusOr<DracoCoding> draco = EncodeDraco(triangles, vertex_count);
  if (draco.ok()) {
    // kDracoReordered is kDracoWithVertexOrder without the labels, so it is always smaller.
    ConnectivityCode candidate = allow_reorder ? EncodeDracoReordered(*draco)
                                               : EncodeDracoWithVertexOrder(*draco, version_minor);
    if (candidate.payload.size() < best.payload.size()) best = std::move(candidate);
  } else if (draco.status().code() != ErrorCode::kUnsupported) {
    return draco.status();
  }
  DMC_RETURN_IF_ERROR(FinishByDecoding(triangles, vertex_count, version_minor, best));
  return best;
}

}  // namespace dmc
