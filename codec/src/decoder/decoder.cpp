#include "dmc/decoder.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <mutex>
#include <optional>
#include <string>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "core/allocation_guard.h"
#include "core/parallel.h"
#include "decoder/basis_reader.h"
#include "decoder/connectivity_decoder.h"
#include "decoder/segment_reconstruction.h"
#include "decoder/syntax_reader.h"
#include "dmc/operators.h"
#include "dmc/wire_ids.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace {

struct RawChunk {
  uint8_t type;
  size_t offset;  // of the payload within the stream
  size_t size;    // payload size
  size_t framed_size;
};

// The chunk type's stable name (kChunkTypeNames) with spaces for hyphens, as messages spell it.
std::string ChunkName(uint8_t type) {
  std::string name(WireNameOf(kChunkTypeNames, static_cast<format::ChunkType>(type)));
  if (name.empty()) return "unknown (" + std::to_string(type) + ")";
  std::replace(name.begin(), name.end(), '-', ' ');
  return name;
}

// Splits the stream into checksummed chunks: magic, version, reserved byte, then
// (u8 type, varint size, payload, u32 XXH32) until the end chunk.
StatusOr<std::vector<RawChunk>> SplitChunks(std::span<const uint8_t> stream, int* major,
                                            int* minor) {
  ByteReader reader(stream);
  std::span<const uint8_t> magic;
  DMC_RETURN_IF_ERROR(reader.GetBytes(format::kMagic.size(), &magic, "magic"));
  if (!std::equal(magic.begin(), magic.end(), format::kMagic.begin())) {
    return CorruptStreamError("not a .dmc stream (bad magic)");
  }
  uint8_t version_major, version_minor, reserved;
  DMC_RETURN_IF_ERROR(reader.GetU8(&version_major, "major version"));
  DMC_RETURN_IF_ERROR(reader.GetU8(&version_minor, "minor version"));
  if (version_major != format::kVersionMajor || version_minor > format::kVersionMinor) {
    return UnsupportedError(
        "format version " + std::to_string(version_major) + "." + std::to_string(version_minor) +
        " is not supported (this decoder reads " + std::to_string(format::kVersionMajor) + "." +
        std::to_string(format::kVersionMinor) + " and older)");
  }
  DMC_RETURN_IF_ERROR(reader.GetU8(&reserved, "reserved byte"));
  if (reserved != 0) return CorruptStreamError("reserved header byte is not zero");
  *major = version_major;
  *minor = version_minor;

  std::vector<RawChunk> chunks;
  while (true) {
    const size_t start = reader.position();
    const std::string where = "chunk " + std::to_string(chunks.size());
    uint8_t type = 0;
    DMC_RETURN_IF_ERROR(reader.GetU8(&type, where + " type"));
    uint64_t size = 0;
    DMC_RETURN_IF_ERROR(reader.GetVarU(&size, where + " size"));
    if (size > reader.remaining()) {
      return TruncatedStreamError(where + " (" + ChunkName(type) + ") declares " +
                                  std::to_string(size) + " bytes, only " +
                                  std::to_string(reader.remaining()) + " remain");
    }
    std::span<const uint8_t> payload;
    DMC_RETURN_IF_ERROR(reader.GetBytes(size, &payload, where + " payload"));
    uint32_t checksum = 0;
    DMC_RETURN_IF_ERROR(reader.GetU32(&checksum, where + " checksum"));
    if (checksum != format::ChunkChecksum(type, payload, version_minor)) {
      return CorruptStreamError(where + " (" + ChunkName(type) + ") fails its checksum");
    }
    chunks.push_back({type, static_cast<size_t>(payload.data() - stream.data()), payload.size(),
                      reader.position() - start});
    if (type == static_cast<uint8_t>(format::ChunkType::kEnd)) break;
  }
  if (!reader.at_end()) {
    return CorruptStreamError(std::to_string(reader.remaining()) +
                              " trailing byte(s) after the end chunk");
  }
  // End chunk payload: number of chunks before it.
  const RawChunk& end = chunks.back();
  ByteReader end_reader(stream.subspan(end.offset, end.size));
  uint64_t count;
  DMC_RETURN_IF_ERROR(end_reader.GetVarU(&count, "end chunk count"));
  if (count != chunks.size() - 1 || !end_reader.at_end()) {
    return CorruptStreamError("end chunk count does not match the chunks present");
  }
  return chunks;
}

constexpr format::ChunkType kSegmentChunkOrder[] = {
    format::ChunkType::kSegmentHeader, format::ChunkType::kMean,    format::ChunkType::kBasis,
    format::ChunkType::kOperator,      format::ChunkType::kAnchors, format::ChunkType::kResiduals};
constexpr int kChunksPerSegment = 6;

}  // namespace

StatusOr<std::vector<uint8_t>> ReadFileBytes(const std::filesystem::path& path) {
  return core_internal::GuardAllocation(
      "reading " + path.string(), [&]() -> StatusOr<std::vector<uint8_t>> {
        std::ifstream in(path, std::ios::binary);
        if (!in) return IoError("cannot open " + path.string());
        std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
        if (in.bad()) return IoError("cannot read " + path.string());
        return bytes;
      });
}

uint64_t DeclaredOutputBytes(const StreamInfo& info) {
  return 12 * (static_cast<uint64_t>(info.vertex_count) * static_cast<uint64_t>(info.frame_count) +
               static_cast<uint64_t>(info.triangle_count)) +
         info.scene_size;
}

Status Decoder::Open(std::span<const uint8_t> stream, const DecoderOptions& options) {
  return core_internal::GuardAllocation("opening the stream",
                                        [&] { return OpenImpl(stream, &options); });
}

// Without `options` (ReadStreamInfo) no output limit applies and the shared topology is not built.
Status Decoder::OpenImpl(std::span<const uint8_t> stream, const DecoderOptions* options) {
  stream_ = stream;
  info_ = StreamInfo();
  max_matrix_bytes_ = options != nullptr ? options->max_matrix_bytes : 0;
  triangles_ = Triangles();
  topology_ = MeshTopology();
  vertex_order_.clear();
  segment_chunks_.clear();
  scene_.clear();
  DMC_ASSIGN_OR_RETURN(std::vector<RawChunk> chunks,
                       SplitChunks(stream, &info_.version_major, &info_.version_minor));
  info_.total_bytes = stream.size();
  auto payload = [&](const RawChunk& c) { return stream.subspan(c.offset, c.size); };
  auto expect = [&](size_t index, format::ChunkType type) -> Status {
    if (index >= chunks.size() || chunks[index].type != static_cast<uint8_t>(type)) {
      return CorruptStreamError("chunk " + std::to_string(index) + " should be " +
                                ChunkName(static_cast<uint8_t>(type)) + ", found " +
                                (index < chunks.size() ? ChunkName(chunks[index].type) : "none"));
    }
    return Status::Ok();
  };
  DMC_RETURN_IF_ERROR(expect(0, format::ChunkType::kSequenceHeader));
  DMC_ASSIGN_OR_RETURN(format::SequenceHeader header,
                       syntax::ReadSequenceHeader(payload(chunks[0])));
  DMC_RETURN_IF_ERROR(expect(1, format::ChunkType::kConnectivity));
  // Format 1.3: an optional scene chunk third (§4.4); in older streams type 9 is unassigned.
  const bool has_scene = info_.version_minor >= format::kFirstSceneMinor && chunks.size() > 2 &&
                         chunks[2].type == static_cast<uint8_t>(format::ChunkType::kScene);
  const size_t first_segment_chunk = has_scene ? 3 : 2;
  const size_t expected_chunks =
      first_segment_chunk + kChunksPerSegment * size_t{header.segment_count} + 1;
  if (chunks.size() != expected_chunks) {
    return CorruptStreamError("stream has " + std::to_string(chunks.size()) + " chunks, " +
                              std::to_string(header.segment_count) + " segment(s) need " +
                              std::to_string(expected_chunks));
  }
  info_.vertex_count = static_cast<int>(header.vertex_count);
  info_.triangle_count = static_cast<int>(header.triangle_count);
  info_.frame_count = static_cast<int>(header.frame_count);
  info_.frame_rate = header.frame_rate;
  info_.reordered = (header.flags & format::kFlagReordered) != 0;
  info_.name = header.name;
  std::optional<syntax::SceneHeader> scene;
  if (has_scene) {
    DMC_ASSIGN_OR_RETURN(scene, syntax::ReadSceneHeader(payload(chunks[2])));
    info_.scene_bytes = chunks[2].framed_size;
    info_.scene_size = scene->size;
  }
  // Output size bound of the format: no decoder produces more than 16 GiB of positions.
  if (uint64_t{header.vertex_count} * header.frame_count * 12 > (uint64_t{1} << 34)) {
    return UnsupportedError("decoded sequence would exceed 16 GiB");
  }
  // The caller's bound, before anything is sized by the declared counts.
  const uint64_t declared_output = DeclaredOutputBytes(info_);
  if (options != nullptr && options->max_output_bytes != 0 &&
      declared_output > options->max_output_bytes) {
    return ResourceLimitError(
        "the stream declares " + std::to_string(declared_output) + " bytes of output (" +
        std::to_string(header.vertex_count) + " vertices x " + std::to_string(header.frame_count) +
        " frames, " + std::to_string(header.triangle_count) + " triangles" +
        (has_scene ? ", a scene of " + std::to_string(info_.scene_size) + " bytes" : "") +
        "), above the limit of " + std::to_string(options->max_output_bytes) + " bytes");
  }
  info_.header_bytes = 7 + chunks[0].framed_size + chunks.back().framed_size;
  info_.connectivity_bytes = chunks[1].framed_size;

  // Segment headers first: they and the payload sizes alone show whether the payloads can hold
  // what the headers declare, before the connectivity (whose cost grows with V and T) is decoded.
  uint32_t next_frame = 0;
  for (uint32_t s = 0; s < header.segment_count; ++s) {
    const size_t base = first_segment_chunk + kChunksPerSegment * size_t{s};
    std::vector<ChunkRef> refs;
    for (int k = 0; k < kChunksPerSegment; ++k) {
      DMC_RETURN_IF_ERROR(expect(base + k, kSegmentChunkOrder[k]));
      refs.push_back({chunks[base + k].type, chunks[base + k].offset, chunks[base + k].size});
    }
    DMC_ASSIGN_OR_RETURN(format::SegmentHeader seg,
                         syntax::ReadSegmentHeader(
                             payload(chunks[base]), next_frame, header.frame_count - next_frame,
                             header.vertex_count, static_cast<uint8_t>(info_.version_minor)));
    DMC_RETURN_IF_ERROR(syntax::CheckPayloadCapacity(
                            seg, header.vertex_count,
                            {chunks[base + 1].size, chunks[base + 2].size, chunks[base + 3].size,
                             chunks[base + 4].size, chunks[base + 5].size})
                            .WithContext("segment " + std::to_string(s)));
    SegmentInfo segment;
    segment.first_frame = static_cast<int>(seg.first_frame);
    segment.frame_count = static_cast<int>(seg.frame_count);
    segment.rank = static_cast<int>(seg.rank);
    segment.operator_id = seg.operator_id;
    segment.operator_name = std::string(OperatorIdName(static_cast<OperatorId>(seg.operator_id)));
    segment.basis_bits = seg.basis_bits;
    segment.weight_bits = seg.weight_bits;
    segment.anchor_count = static_cast<int>(seg.anchor_count);
    segment.residual_step = seg.residual_step;
    segment.anchor_step = seg.anchor_step;
    segment.header_bytes = chunks[base].framed_size;
    segment.mean_bytes = chunks[base + 1].framed_size;
    segment.basis_bytes = chunks[base + 2].framed_size;
    segment.operator_bytes = chunks[base + 3].framed_size;
    segment.anchor_bytes = chunks[base + 4].framed_size;
    segment.residual_bytes = chunks[base + 5].framed_size;
    info_.segments.push_back(segment);
    segment_chunks_.push_back(std::move(refs));
    next_frame += seg.frame_count;
  }
  if (next_frame != header.frame_count) {
    return CorruptStreamError("segments cover " + std::to_string(next_frame) + " of " +
                              std::to_string(header.frame_count) + " frames");
  }
  // The scene is decompressed by decoders that reconstruct (ReadStreamInfo only checks its
  // fields), after everything that costs only the stream's bytes.
  if (scene && options != nullptr) {
    DMC_ASSIGN_OR_RETURN(scene_, syntax::ReadScene(*scene));
  }
  DMC_ASSIGN_OR_RETURN(
      triangles_, DecodeConnectivity(payload(chunks[1]), header.vertex_count, header.triangle_count,
                                     static_cast<uint8_t>(info_.version_minor)));
  if (options != nullptr) {
    topology_ = BuildTopology(triangles_, static_cast<int>(header.vertex_count));
    vertex_order_ = format::BreadthFirstOrder(topology_);
  }
  return Status::Ok();
}

Status Decoder::DecodeSegmentInto(int index, const FrameDestination& destination) const {
  return core_internal::GuardAllocation("decoding segment " + std::to_string(index),
                                        [&] { return DecodeSegmentIntoImpl(index, destination); });
}

Status Decoder::DecodeSegmentIntoImpl(int index, const FrameDestination& destination) const {
  if (index < 0 || index >= segment_count()) {
    return InvalidArgumentError("segment " + std::to_string(index) + " does not exist (" +
                                std::to_string(segment_count()) + " segments)");
  }
  const std::vector<ChunkRef>& refs = segment_chunks_[index];
  auto payload = [&](int k) { return stream_.subspan(refs[k].offset, refs[k].size); };
  const SegmentInfo& info = info_.segments[index];
  const uint32_t frames_left = static_cast<uint32_t>(info_.frame_count - info.first_frame);
  SegmentSyntax syntax;
  DMC_ASSIGN_OR_RETURN(syntax.header, syntax::ReadSegmentHeader(
                                          payload(0), static_cast<uint32_t>(info.first_frame),
                                          frames_left, static_cast<uint32_t>(info_.vertex_count),
                                          static_cast<uint8_t>(info_.version_minor)));
  const MeshTopology& topology = topology_;
  const std::string where = "segment " + std::to_string(index) + " ";
  DMC_RETURN_IF_ERROR(syntax::ReadMean(payload(1), syntax).WithContext(where + "mean"));
  DMC_RETURN_IF_ERROR(
      syntax::ReadBasis(payload(2), syntax, info_.version_minor).WithContext(where + "basis"));
  DMC_RETURN_IF_ERROR(
      syntax::ReadOperator(payload(3), topology, syntax).WithContext(where + "operator"));
  DMC_RETURN_IF_ERROR(
      syntax::ReadAnchors(payload(4), info_.vertex_count, syntax).WithContext(where + "anchors"));
  // The residuals decode while the operator is rebuilt and factored (the factorisation does not
  // read them; on real captures the two take similar time). A stream rejected in its residuals
  // therefore pays a factorisation, whose memory grows with V only; the output is claimed after
  // the solve, so such a stream costs no output memory (allocation_bound_test).
  Status residuals;
  std::optional<StatusOr<AnchoredLaplacianSolver>> solver;
  core_internal::ParallelInvoke(
      [&] {
        residuals = syntax::ReadResiduals(payload(5), topology, vertex_order_, syntax)
                        .WithContext(where + "residuals");
      },
      [&] {
        if (syntax.header.rank == 0) return;
        StatusOr<LaplaceOperator> laplace = RebuildSegmentOperator(topology, syntax);
        solver.emplace(laplace.ok()
                           ? FactorSegmentOperator(topology, *laplace, syntax, max_matrix_bytes_)
                           : StatusOr<AnchoredLaplacianSolver>(laplace.status()));
      });
  DMC_RETURN_IF_ERROR(residuals);
  // The deltas become the coefficients in place: one V×r matrix instead of three.
  Eigen::MatrixXd coefficients = std::move(syntax.delta);
  if (solver) {
    DMC_RETURN_IF_ERROR(solver->status());
    DMC_RETURN_IF_ERROR((*solver)->SolveInPlace(coefficients, syntax.anchor_values));
    solver.reset();  // the factor, before the output is claimed
  }
  DMC_ASSIGN_OR_RETURN(float* frames, destination(index));
  return SynthesizeFrames(syntax.mean, syntax.basis, coefficients, info.frame_count, frames)
      .WithContext(where + "frames");
}

StatusOr<MeshSequence> Decoder::DecodeSegment(int index) const {
  std::optional<MeshSequence> sequence;
  DMC_RETURN_IF_ERROR(DecodeSegmentInto(index, [&](int s) -> StatusOr<float*> {
    sequence.emplace(info_.vertex_count, triangles_, info_.segments[s].frame_count);
    return sequence->data();
  }));
  sequence->name = info_.name;
  sequence->frame_rate = info_.frame_rate;
  return std::move(*sequence);
}

StatusOr<StreamInfo> ReadStreamInfo(std::span<const uint8_t> stream) {
  return core_internal::GuardAllocation("reading the stream's structure",
                                        [&]() -> StatusOr<StreamInfo> {
                                          Decoder decoder;
                                          DMC_RETURN_IF_ERROR(decoder.OpenImpl(stream, nullptr));
                                          return decoder.info();
                                        });
}

namespace {

StatusOr<MeshSequence> DecodeWhole(std::span<const uint8_t> stream, const DecoderOptions& options,
                                   std::vector<uint8_t>* scene) {
  Decoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Open(stream, options));
  if (scene != nullptr) *scene = decoder.scene();
  const StreamInfo& info = decoder.info();
  // The output (12·V·F bytes) is allocated only once a segment has decoded and solved, so a tiny
  // stream declaring a huge mesh fails before it costs that memory.
  std::mutex output_mutex;
  std::optional<MeshSequence> sequence;
  auto destination = [&](int s) -> StatusOr<float*> {
    std::lock_guard<std::mutex> lock(output_mutex);
    if (!sequence) sequence.emplace(info.vertex_count, decoder.triangles(), info.frame_count);
    return sequence->data() + static_cast<size_t>(info.segments[s].first_frame) *
                                  static_cast<size_t>(info.vertex_count) * 3;
  };
  // Segments are independent: decode them in parallel into their own frame ranges.
  std::vector<Status> statuses(decoder.segment_count());
  core_internal::ParallelFor(0, decoder.segment_count(), [&](int s) {
    statuses[s] = decoder.DecodeSegmentInto(s, destination);
  });
  for (const Status& status : statuses) DMC_RETURN_IF_ERROR(status);
  if (!sequence) sequence.emplace(info.vertex_count, decoder.triangles(), info.frame_count);
  sequence->name = info.name;
  sequence->frame_rate = info.frame_rate;
  return std::move(*sequence);
}

}  // namespace

StatusOr<MeshSequence> Decode(std::span<const uint8_t> stream, const DecoderOptions& options,
                              std::vector<uint8_t>* scene) {
  return core_internal::GuardAllocation("decoding the stream",
                                        [&] { return DecodeWhole(stream, options, scene); });
}

StatusOr<MeshSequence> DecodeFile(const std::filesystem::path& path,
                                  const DecoderOptions& options) {
  DMC_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, ReadFileBytes(path));
  return Decode(bytes, options);
}

StatusOr<std::vector<uint8_t>> DecodeScene(std::span<const uint8_t> stream,
                                           const DecoderOptions& options) {
  return core_internal::GuardAllocation("decoding the scene",
                                        [&]() -> StatusOr<std::vector<uint8_t>> {
                                          Decoder decoder;
                                          DMC_RETURN_IF_ERROR(decoder.Open(stream, options));
                                          return decoder.scene();
                                        });
}

}  // namespace dmc
