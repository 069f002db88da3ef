#include "kit/vector_kit.h"

#include <xxhash.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/basis_reader.h"
#include "decoder/connectivity_decoder.h"
#include "decoder/segment_reconstruction.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/topology.h"
#include "entropy/byte_io.h"

namespace dmc::conformance {
namespace {

using Json = nlohmann::ordered_json;

// Streaming XXH64 over signed 64-bit little-endian values: the digest input of spec §12.2.
class IntegerDigest {
 public:
  IntegerDigest() : state_(XXH64_createState()) { XXH64_reset(state_, 0); }
  ~IntegerDigest() { XXH64_freeState(state_); }
  IntegerDigest(const IntegerDigest&) = delete;
  IntegerDigest& operator=(const IntegerDigest&) = delete;

  void Add(int64_t value) {
    uint8_t bytes[8];
    const auto bits = static_cast<uint64_t>(value);
    for (int i = 0; i < 8; ++i) bytes[i] = static_cast<uint8_t>(bits >> (8 * i));
    XXH64_update(state_, bytes, sizeof bytes);
  }
  void AddDoubleBits(double value) { Add(static_cast<int64_t>(std::bit_cast<uint64_t>(value))); }
  uint64_t Finish() const { return XXH64_digest(state_); }

 private:
  XXH64_state_t* state_;
};

// The syntax readers hand out dequantised values q·step (one correctly rounded product) or
// q / levels; dividing back and rounding recovers q exactly for every |q| < 2^50, far beyond
// what the readers accept for residuals (2^40) and what any encoder produces elsewhere.
int64_t QuantisationIndex(double value, double step) { return std::llround(value / step); }

std::string ReadText(const std::filesystem::path& path, Status* status) {
  StatusOr<std::vector<uint8_t>> bytes = ReadBytes(path);
  if (!bytes.ok()) {
    *status = bytes.status();
    return {};
  }
  return std::string(bytes->begin(), bytes->end());
}

std::string CodeName(ErrorCode code) { return std::string(ErrorCodeName(code)); }

VectorResult Fail(VectorResult result, const std::string& why) {
  result.passed = false;
  result.detail = why;
  return result;
}

VectorResult CheckValid(const Json& manifest, const std::filesystem::path& directory,
                        const CheckOptions& options, VectorResult result) {
  const std::filesystem::path stream_path = directory / manifest.at("stream").get<std::string>();
  StatusOr<std::vector<uint8_t>> stream = ReadBytes(stream_path);
  if (!stream.ok()) return Fail(result, stream.status().ToString());
  if (manifest.contains("stream_xxh64")) {
    const StatusOr<uint64_t> expected = ParseHashHex(manifest.at("stream_xxh64"));
    if (!expected.ok()) return Fail(result, expected.status().ToString());
    if (XXH64(stream->data(), stream->size(), 0) != *expected) {
      return Fail(result, "stream file differs from the one the manifest describes (XXH64)");
    }
  }

  StatusOr<MeshSequence> decoded = Decode(*stream, kNoCallerLimit);
  if (!decoded.ok()) return Fail(result, "decoding failed: " + decoded.status().ToString());
  const int v_count = manifest.at("vertex_count").get<int>();
  const int t_count = manifest.at("triangle_count").get<int>();
  const int f_count = manifest.at("frame_count").get<int>();
  if (decoded->vertex_count() != v_count || decoded->triangle_count() != t_count ||
      decoded->frame_count() != f_count) {
    return Fail(result, "decoded V/T/F " + std::to_string(decoded->vertex_count()) + "/" +
                            std::to_string(decoded->triangle_count()) + "/" +
                            std::to_string(decoded->frame_count()) + ", expected " +
                            std::to_string(v_count) + "/" + std::to_string(t_count) + "/" +
                            std::to_string(f_count));
  }
  const uint64_t triangles_hash =
      XXH64(decoded->triangles().data(), sizeof(int32_t) * 3 * static_cast<size_t>(t_count), 0);
  const StatusOr<uint64_t> expected_triangles = ParseHashHex(manifest.at("triangles_xxh64"));
  if (!expected_triangles.ok()) return Fail(result, expected_triangles.status().ToString());
  if (triangles_hash != *expected_triangles) {
    return Fail(result, "decoded triangle list differs (XXH64 " + HashHex(triangles_hash) + ")");
  }

  StatusOr<StreamInfo> info = ReadStreamInfo(*stream);
  if (!info.ok()) return Fail(result, "ReadStreamInfo failed: " + info.status().ToString());
  // Format 1.3: the scene decompresses to the manifest's bytes (§6.3).
  StatusOr<std::vector<uint8_t>> scene = DecodeScene(*stream, kNoCallerLimit);
  if (!scene.ok()) return Fail(result, "DecodeScene failed: " + scene.status().ToString());
  if (manifest.contains("scene")) {
    const StatusOr<uint64_t> expected_scene = ParseHashHex(manifest.at("scene").at("xxh64"));
    if (!expected_scene.ok()) return Fail(result, expected_scene.status().ToString());
    if (scene->size() != manifest.at("scene").at("bytes").get<size_t>() ||
        XXH64(scene->data(), scene->size(), 0) != *expected_scene) {
      return Fail(result, "the decompressed scene differs from the manifest's");
    }
  } else if (!scene->empty()) {
    return Fail(result, "the stream has a scene the manifest does not list");
  }
  // The sequence header's name and frame rate (spec §6.1), when the manifest records them.
  if (manifest.contains("name") && info->name != manifest.at("name").get<std::string>()) {
    return Fail(result, "stream name '" + info->name + "' differs from the manifest's");
  }
  if (manifest.contains("frame_rate") &&
      info->frame_rate != manifest.at("frame_rate").get<double>()) {
    return Fail(result,
                "frame rate " + std::to_string(info->frame_rate) + " differs from the manifest's");
  }
  const Json& segments = manifest.at("segments");
  if (info->segments.size() != segments.size() ||
      info->reordered != manifest.at("reordered").get<bool>()) {
    return Fail(result, "segment count or reordered flag differs from the manifest");
  }

  StatusOr<SyntaxDigests> digests = ComputeSyntaxDigests(*stream);
  if (!digests.ok()) return Fail(result, "syntax parse failed: " + digests.status().ToString());
  const StatusOr<uint64_t> connectivity = ParseHashHex(manifest.at("connectivity_digest"));
  if (!connectivity.ok()) return Fail(result, connectivity.status().ToString());
  if (digests->connectivity != *connectivity ||
      digests->connectivity_method != manifest.at("connectivity_method").get<int>()) {
    return Fail(result, "connectivity syntax digest " + HashHex(digests->connectivity) +
                            " differs from the manifest's " + HashHex(*connectivity));
  }
  for (size_t s = 0; s < segments.size(); ++s) {
    const SegmentInfo& segment = info->segments[s];
    const Json& expected = segments[s];
    if (segment.first_frame != expected.at("first_frame").get<int>() ||
        segment.frame_count != expected.at("frame_count").get<int>() ||
        segment.rank != expected.at("rank").get<int>() ||
        segment.operator_id != expected.at("operator_id").get<int>() ||
        segment.anchor_count != expected.at("anchor_count").get<int>()) {
      return Fail(result, "segment " + std::to_string(s) + " header differs from the manifest");
    }
    const StatusOr<uint64_t> digest = ParseHashHex(expected.at("syntax_digest"));
    if (!digest.ok()) return Fail(result, digest.status().ToString());
    if (digests->segments[s] != *digest) {
      return Fail(result, "segment " + std::to_string(s) + " syntax digest " +
                              HashHex(digests->segments[s]) + " differs from the manifest's " +
                              HashHex(*digest));
    }
  }

  const Json& positions = manifest.at("positions");
  StatusOr<std::vector<uint8_t>> compressed =
      ReadBytes(directory / positions.at("file").get<std::string>());
  if (!compressed.ok()) return Fail(result, compressed.status().ToString());
  StatusOr<std::vector<float>> reference =
      DecompressPositions(*compressed, decoded->position_value_count());
  if (!reference.ok()) return Fail(result, reference.status().ToString());
  std::vector<uint64_t> frame_hashes;
  for (const Json& hash : positions.at("frame_xxh64")) {
    const StatusOr<uint64_t> value = ParseHashHex(hash);
    if (!value.ok()) return Fail(result, value.status().ToString());
    frame_hashes.push_back(*value);
  }
  const double diagonal = positions.at("diagonal").get<double>();
  const PositionComparison comparison =
      ComparePositions(*decoded, *reference, diagonal, frame_hashes);
  if (!comparison.within_tolerance) {
    return Fail(result, "decoded positions outside the tolerance: " + comparison.first_violation);
  }
  if (options.require_bit_exact && comparison.bit_exact_frames != f_count) {
    return Fail(result, std::to_string(f_count - comparison.bit_exact_frames) +
                            " frame(s) differ from the reference bytes (--bit-exact)");
  }

  // Segment-by-segment decoding must give exactly the frames of the whole decode.
  Decoder decoder;
  const Status opened = decoder.Open(*stream);
  if (!opened.ok()) return Fail(result, "Decoder::Open failed: " + opened.ToString());
  for (int s = 0; s < decoder.segment_count(); ++s) {
    StatusOr<MeshSequence> part = decoder.DecodeSegment(s);
    if (!part.ok()) return Fail(result, "DecodeSegment failed: " + part.status().ToString());
    const size_t offset = static_cast<size_t>(decoder.info().segments[s].first_frame) *
                          static_cast<size_t>(v_count) * 3;
    if (std::memcmp(part->data(), decoded->data() + offset,
                    sizeof(float) * part->position_value_count()) != 0) {
      return Fail(result, "DecodeSegment(" + std::to_string(s) + ") differs from Decode");
    }
  }

  result.passed = true;
  char ratio[32];
  std::snprintf(ratio, sizeof ratio, "%.3g", comparison.max_error / diagonal);
  result.detail = std::to_string(v_count) + " V, " + std::to_string(t_count) + " T, " +
                  std::to_string(f_count) + " F, " + std::to_string(segments.size()) +
                  " segment(s); digests match; max error " + ratio + " D; " +
                  std::to_string(comparison.bit_exact_frames) + "/" + std::to_string(f_count) +
                  " frames bit-exact";
  // Which spec rules the vector exercises (the generator lists them).
  if (manifest.contains("covers")) {
    std::string covers;
    for (const Json& rule : manifest.at("covers")) {
      covers += (covers.empty() ? "" : ", ") + rule.get<std::string>();
    }
    result.detail += "; covers §" + covers;
  }
  return result;
}

VectorResult CheckInvalid(const Json& manifest, const std::filesystem::path& directory,
                          VectorResult result) {
  const std::filesystem::path stream_path = directory / manifest.at("stream").get<std::string>();
  StatusOr<std::vector<uint8_t>> stream = ReadBytes(stream_path);
  if (!stream.ok()) return Fail(result, stream.status().ToString());
  const std::string expected = manifest.at("error").get<std::string>();
  const StatusOr<MeshSequence> decoded = Decode(*stream, kNoCallerLimit);
  const std::string got = decoded.ok() ? "ok" : CodeName(decoded.status().code());
  if (got != expected) {
    return Fail(result,
                "Decode returned " +
                    (decoded.ok() ? std::string("a sequence") : decoded.status().ToString()) +
                    ", expected " + expected);
  }
  if (manifest.contains("stream_info_error")) {
    const std::string expected_info = manifest.at("stream_info_error").get<std::string>();
    const StatusOr<StreamInfo> info = ReadStreamInfo(*stream);
    const std::string got_info = info.ok() ? "ok" : CodeName(info.status().code());
    if (got_info != expected_info) {
      return Fail(result, "ReadStreamInfo returned " +
                              (info.ok() ? std::string("ok") : info.status().ToString()) +
                              ", expected " + expected_info);
    }
  }
  result.passed = true;
  result.detail = expected + ": " + decoded.status().message();
  return result;
}

}  // namespace

StatusOr<Framed> SplitFramed(std::span<const uint8_t> stream) {
  ByteReader reader(stream);
  Framed framed;
  std::span<const uint8_t> preamble;
  DMC_RETURN_IF_ERROR(reader.GetBytes(kPreambleBytes, &preamble, "preamble"));
  framed.preamble.assign(preamble.begin(), preamble.end());
  while (true) {
    Chunk chunk;
    DMC_RETURN_IF_ERROR(reader.GetU8(&chunk.type, "chunk type"));
    uint64_t size = 0;
    DMC_RETURN_IF_ERROR(reader.GetVarU(&size, "chunk size"));
    if (size > reader.remaining()) return TruncatedStreamError("chunk payload runs past the end");
    std::span<const uint8_t> payload;
    DMC_RETURN_IF_ERROR(reader.GetBytes(static_cast<size_t>(size), &payload, "chunk payload"));
    chunk.payload.assign(payload.begin(), payload.end());
    DMC_RETURN_IF_ERROR(reader.GetU32(&chunk.checksum, "chunk checksum"));
    framed.chunks.push_back(std::move(chunk));
    if (framed.chunks.back().type == static_cast<uint8_t>(ChunkType::kEnd)) break;
  }
  std::span<const uint8_t> trailing;
  DMC_RETURN_IF_ERROR(reader.GetBytes(reader.remaining(), &trailing, "trailing bytes"));
  framed.trailing.assign(trailing.begin(), trailing.end());
  return framed;
}

std::vector<uint8_t> JoinFramed(const Framed& framed, bool recompute_checksums) {
  ByteWriter out;
  out.PutBytes(framed.preamble);
  for (const Chunk& chunk : framed.chunks) {
    out.PutU8(chunk.type);
    out.PutVarU(chunk.payload.size());
    out.PutBytes(chunk.payload);
    // The seed holds the preamble's minor version (byte 5; spec §4.2).
    const uint8_t minor = framed.preamble.size() > 5 ? framed.preamble[5] : format::kVersionMinor;
    out.PutU32(recompute_checksums ? format::ChunkChecksum(chunk.type, chunk.payload, minor)
                                   : chunk.checksum);
  }
  out.PutBytes(framed.trailing);
  return out.Take();
}

StatusOr<ParsedStream> ParseStream(std::span<const uint8_t> stream) {
  // The public decoder checks the container (checksums, chunk order, counts) first.
  DMC_ASSIGN_OR_RETURN(const StreamInfo info, ReadStreamInfo(stream));
  ParsedStream parsed;
  DMC_ASSIGN_OR_RETURN(parsed.framed, SplitFramed(stream));
  const std::vector<Chunk>& chunks = parsed.framed.chunks;
  DMC_ASSIGN_OR_RETURN(parsed.header, syntax::ReadSequenceHeader(chunks[0].payload));
  const format::SequenceHeader& header = parsed.header;
  const auto version_minor = static_cast<uint8_t>(info.version_minor);
  DMC_ASSIGN_OR_RETURN(parsed.triangles, DecodeConnectivity(chunks[1].payload, header.vertex_count,
                                                            header.triangle_count, version_minor));
  const int v_count = static_cast<int>(header.vertex_count);
  parsed.first_segment_chunk = info.scene_bytes > 0 ? 3 : 2;
  parsed.topology = BuildTopology(parsed.triangles, v_count);
  parsed.vertex_order = format::BreadthFirstOrder(parsed.topology);
  for (size_t s = 0; s < info.segments.size(); ++s) {
    const size_t base = parsed.first_segment_chunk + 6 * s;
    const auto first_frame = static_cast<uint32_t>(info.segments[s].first_frame);
    SegmentSyntax syntax;
    DMC_ASSIGN_OR_RETURN(syntax.header,
                         syntax::ReadSegmentHeader(chunks[base].payload, first_frame,
                                                   header.frame_count - first_frame,
                                                   header.vertex_count, version_minor));
    DMC_RETURN_IF_ERROR(syntax::ReadMean(chunks[base + 1].payload, syntax));
    DMC_RETURN_IF_ERROR(syntax::ReadBasis(chunks[base + 2].payload, syntax, info.version_minor));
    DMC_RETURN_IF_ERROR(syntax::ReadOperator(chunks[base + 3].payload, parsed.topology, syntax));
    DMC_RETURN_IF_ERROR(syntax::ReadAnchors(chunks[base + 4].payload, v_count, syntax));
    DMC_RETURN_IF_ERROR(syntax::ReadResiduals(chunks[base + 5].payload, parsed.topology,
                                              parsed.vertex_order, syntax));
    parsed.segments.push_back(std::move(syntax));
  }
  return parsed;
}

StatusOr<SyntaxDigests> ComputeSyntaxDigests(std::span<const uint8_t> stream) {
  DMC_ASSIGN_OR_RETURN(const ParsedStream parsed, ParseStream(stream));
  const format::SequenceHeader& header = parsed.header;
  SyntaxDigests digests;
  digests.connectivity_method = parsed.framed.chunks[1].payload.front();
  {
    IntegerDigest digest;
    digest.Add(digests.connectivity_method);
    digest.Add(header.vertex_count);
    digest.Add(header.triangle_count);
    for (Eigen::Index t = 0; t < parsed.triangles.rows(); ++t) {
      for (int k = 0; k < 3; ++k) digest.Add(parsed.triangles(t, k));
    }
    digests.connectivity = digest.Finish();
  }
  const int v_count = static_cast<int>(header.vertex_count);
  for (size_t segment = 0; segment < parsed.segments.size(); ++segment) {
    const SegmentSyntax& syntax = parsed.segments[segment];
    const format::SegmentHeader& h = syntax.header;
    const int frames = static_cast<int>(h.frame_count);
    const int rank = static_cast<int>(h.rank);
    IntegerDigest digest;
    for (const int64_t field :
         {int64_t{h.first_frame}, int64_t{h.frame_count}, int64_t{h.rank}, int64_t{h.operator_id},
          int64_t{h.basis_bits}, int64_t{h.weight_bits}, int64_t{h.weight_prediction},
          int64_t{h.anchor_count}}) {
      digest.Add(field);
    }
    for (const double step : {h.mean_step, h.residual_step, h.anchor_step, h.anchor_weight}) {
      digest.AddDoubleBits(step);
    }
    for (int axis = 0; axis < 3; ++axis) {
      for (int f = 0; f < frames; ++f) {
        digest.Add(QuantisationIndex(syntax.mean[3 * f + axis], h.mean_step));
      }
    }
    const double levels = std::ldexp(1.0, h.basis_bits - 1) - 1.0;
    for (int k = 0; k < rank; ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        for (int f = 0; f < frames; ++f) {
          digest.Add(std::llround(syntax.basis(3 * f + axis, k) * levels));
        }
      }
    }
    for (const int64_t weight : syntax.edge_weights) digest.Add(weight);
    if (format::IsGeometricOperator(h.operator_id)) {
      // The reference frame's step is the operator payload's leading f64 (spec §8.4).
      const std::vector<uint8_t>& payload =
          parsed.framed.chunks[parsed.first_segment_chunk + 6 * segment + 3].payload;
      if (payload.size() < 8) return TruncatedStreamError("reference frame step");
      uint64_t step_bits = 0;
      for (int i = 0; i < 8; ++i) step_bits |= uint64_t{payload[i]} << (8 * i);
      const double step = std::bit_cast<double>(step_bits);
      digest.AddDoubleBits(step);
      for (int v = 0; v < v_count; ++v) {
        for (int axis = 0; axis < 3; ++axis) {
          digest.Add(QuantisationIndex(syntax.reference_frame(v, axis), step));
        }
      }
    }
    for (const int32_t anchor : syntax.anchors) digest.Add(anchor);
    for (const int8_t exponent : syntax.anchor_step_exponents) digest.Add(exponent);  // 1.2
    for (Eigen::Index a = 0; a < syntax.anchor_values.rows(); ++a) {
      for (int k = 0; k < rank; ++k) {
        digest.Add(QuantisationIndex(syntax.anchor_values(a, k), h.anchor_step));
      }
    }
    // 1.2: each vertex's residual step is scaled by its anchor region's factor (spec §8.5.1).
    const std::vector<double> factors =
        format::VertexStepFactors(parsed.topology, syntax.anchors, syntax.anchor_step_exponents);
    for (int k = 0; k < rank; ++k) {
      for (int v = 0; v < v_count; ++v) {
        digest.Add(QuantisationIndex(syntax.delta(v, k),
                                     format::VertexResidualStep(h.residual_step, factors, v)));
      }
    }
    digests.segments.push_back(digest.Finish());
  }
  return digests;
}

uint64_t FrameHash(const MeshSequence& sequence, int frame) {
  // float32 little-endian bytes; every supported host is little-endian (checked below).
  static_assert(std::endian::native == std::endian::little);
  const size_t values = static_cast<size_t>(sequence.vertex_count()) * 3;
  return XXH64(sequence.data() + static_cast<size_t>(frame) * values, values * sizeof(float), 0);
}

double SequenceDiagonal(const MeshSequence& sequence) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (int f = 0; f < sequence.frame_count(); ++f) {
    const Eigen::MatrixXd frame = sequence.frame(f).cast<double>();
    low = low.cwiseMin(frame.colwise().minCoeff().transpose());
    high = high.cwiseMax(frame.colwise().maxCoeff().transpose());
  }
  return sequence.frame_count() > 0 && sequence.vertex_count() > 0 ? (high - low).norm() : 0.0;
}

std::vector<uint8_t> CompressPositions(const MeshSequence& sequence) {
  const size_t bytes = sequence.position_value_count() * sizeof(float);
  std::vector<uint8_t> out(ZSTD_compressBound(bytes));
  const size_t written = ZSTD_compress(out.data(), out.size(), sequence.data(), bytes, 19);
  out.resize(ZSTD_isError(written) ? 0 : written);
  return out;
}

StatusOr<std::vector<float>> DecompressPositions(std::span<const uint8_t> compressed,
                                                 size_t expected_values) {
  const unsigned long long content = ZSTD_getFrameContentSize(compressed.data(), compressed.size());
  if (content != expected_values * sizeof(float)) {
    return ParseError("reference positions hold " + std::to_string(content) + " bytes, expected " +
                      std::to_string(expected_values * sizeof(float)));
  }
  std::vector<float> values(expected_values);
  const size_t got = ZSTD_decompress(values.data(), values.size() * sizeof(float),
                                     compressed.data(), compressed.size());
  if (ZSTD_isError(got) || got != values.size() * sizeof(float)) {
    return ParseError("reference positions do not decompress");
  }
  return values;
}

PositionComparison ComparePositions(const MeshSequence& decoded, std::span<const float> reference,
                                    double diagonal, const std::vector<uint64_t>& frame_hashes) {
  PositionComparison comparison;
  const size_t per_frame = static_cast<size_t>(decoded.vertex_count()) * 3;
  for (int f = 0; f < decoded.frame_count(); ++f) {
    if (static_cast<size_t>(f) < frame_hashes.size() &&
        FrameHash(decoded, f) == frame_hashes[static_cast<size_t>(f)]) {
      ++comparison.bit_exact_frames;
    }
    for (size_t i = 0; i < per_frame; ++i) {
      const size_t index = static_cast<size_t>(f) * per_frame + i;
      const double x = decoded.data()[index];
      const double r = reference[index];
      const double error = std::abs(x - r);
      const double allowed =
          kToleranceDiagonalFraction * diagonal + kToleranceValueFraction * std::abs(r);
      // NaN compares false everywhere: test for "not within" so NaN fails.
      const bool within = error <= allowed;
      if (std::isfinite(error)) {
        comparison.max_error = std::max(comparison.max_error, error);
        if (allowed > 0.0)
          comparison.max_error_ratio = std::max(comparison.max_error_ratio, error / allowed);
      }
      if (!within && comparison.within_tolerance) {
        comparison.within_tolerance = false;
        comparison.first_violation =
            "frame " + std::to_string(f) + " vertex " + std::to_string(i / 3) + " axis " +
            std::to_string(i % 3) + ": decoded " + std::to_string(x) + ", reference " +
            std::to_string(r) + ", allowed error " + std::to_string(allowed);
      }
    }
  }
  return comparison;
}

std::string HashHex(uint64_t value) {
  char text[19];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(value));
  return text;
}

StatusOr<uint64_t> ParseHashHex(const std::string& text) {
  if (text.size() != 18 || text[0] != '0' || text[1] != 'x') {
    return ParseError("'" + text + "' is not a 0x-prefixed 16-digit hash");
  }
  uint64_t value = 0;
  for (size_t i = 2; i < text.size(); ++i) {
    const char c = text[i];
    int digit;
    if (c >= '0' && c <= '9') {
      digit = c - '0';
    } else if (c >= 'a' && c <= 'f') {
      digit = c - 'a' + 10;
    } else {
      return ParseError("'" + text + "' is not a 0x-prefixed 16-digit hash");
    }
    value = (value << 4) | static_cast<uint64_t>(digit);
  }
  return value;
}

VectorResult CheckVector(const std::filesystem::path& manifest_path, const CheckOptions& options) {
  VectorResult result;
  result.name = manifest_path.stem().string();
  Status read_status;
  const std::string text = ReadText(manifest_path, &read_status);
  if (!read_status.ok()) return Fail(result, read_status.ToString());
  try {
    const Json manifest = Json::parse(text);
    const std::filesystem::path directory = manifest_path.parent_path();
    const std::string kind = manifest.at("kind").get<std::string>();
    if (kind == "valid") return CheckValid(manifest, directory, options, result);
    if (kind == "invalid") return CheckInvalid(manifest, directory, result);
    return Fail(result, "manifest kind '" + kind + "' is neither valid nor invalid");
  } catch (const nlohmann::json::exception& error) {
    return Fail(result, std::string("malformed manifest: ") + error.what());
  }
}

std::vector<std::filesystem::path> FindManifests(const std::filesystem::path& root) {
  std::vector<std::filesystem::path> manifests;
  std::error_code error;
  for (std::filesystem::recursive_directory_iterator it(root, error), end; !error && it != end;
       it.increment(error)) {
    if (it->is_regular_file() && it->path().extension() == ".json") manifests.push_back(it->path());
  }
  std::sort(manifests.begin(), manifests.end());
  return manifests;
}

StatusOr<std::vector<uint8_t>> ReadBytes(const std::filesystem::path& path) {
  return ReadFileBytes(path);
}

}  // namespace dmc::conformance
