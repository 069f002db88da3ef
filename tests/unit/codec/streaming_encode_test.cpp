// Streaming encode (EncodeStreaming over FrameSources) and streaming decode (DecodeToPc2): the
// bytes, reports and files must be exactly those of the in-memory paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "bitstream/format.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/io.h"
#include "dmc/synth.h"
#include "encoder/syntax_writer.h"
#include "entropy/byte_io.h"
#include "test_support.h"

namespace dmc {
namespace {

// A fresh directory under the system temp dir, unique per test, removed with the object.
class ScratchDirectory {
 public:
  explicit ScratchDirectory(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = std::filesystem::temp_directory_path() / ("dmc_stream_" + tag + "_" + name);
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

std::vector<uint8_t> FileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

std::vector<std::string> DirectoryNames(const ScratchDirectory& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// A small articulated sequence (6 components, about 600 vertices).
MeshSequence Walker(int frames) {
  SynthOptions options;
  options.frames = frames;
  options.resolution = 600;
  auto sequence = Synthesize("walker", options);
  EXPECT_TRUE(sequence.ok()) << sequence.status().ToString();
  return std::move(*sequence);
}

void ExpectSameReport(const EncodeReport& streamed, const EncodeReport& memory) {
  EXPECT_EQ(streamed.bytes, memory.bytes);
  EXPECT_EQ(streamed.bpfv, memory.bpfv);
  EXPECT_EQ(streamed.frames, memory.frames);
  EXPECT_EQ(streamed.vertices, memory.vertices);
  EXPECT_EQ(streamed.segments, memory.segments);
  EXPECT_EQ(streamed.rank, memory.rank);
  EXPECT_EQ(streamed.anchors, memory.anchors);
  EXPECT_EQ(streamed.residual_step, memory.residual_step);
  EXPECT_EQ(streamed.residual_bits_equivalent, memory.residual_bits_equivalent);
  EXPECT_EQ(streamed.header_bytes, memory.header_bytes);
  EXPECT_EQ(streamed.connectivity_bytes, memory.connectivity_bytes);
  EXPECT_EQ(streamed.mean_bytes, memory.mean_bytes);
  EXPECT_EQ(streamed.basis_bytes, memory.basis_bytes);
  EXPECT_EQ(streamed.operator_bytes, memory.operator_bytes);
  EXPECT_EQ(streamed.anchor_bytes, memory.anchor_bytes);
  EXPECT_EQ(streamed.residual_bytes, memory.residual_bytes);
  ASSERT_EQ(streamed.measured, memory.measured);
  if (memory.measured) {
    // Bit for bit: the streamed sums are formed in the in-memory meter's order.
    EXPECT_EQ(streamed.distortion.kg, memory.distortion.kg);
    EXPECT_EQ(streamed.distortion.sted, memory.distortion.sted);
    EXPECT_EQ(streamed.distortion.sted_s, memory.distortion.sted_s);
    EXPECT_EQ(streamed.distortion.sted_t, memory.distortion.sted_t);
    EXPECT_EQ(streamed.distortion.rmse_rel, memory.distortion.rmse_rel);
    EXPECT_EQ(streamed.distortion.max_error, memory.distortion.max_error);
    EXPECT_EQ(streamed.distortion.frames, memory.distortion.frames);
    EXPECT_EQ(streamed.distortion.vertices, memory.distortion.vertices);
    EXPECT_GT(memory.distortion.sted, 0.0);
  }
}

// (frames, segment_frames, operator, allow_reorder, segments_in_flight)
using Layout = std::tuple<int, int, std::string, bool, int>;

class StreamingLayouts : public ::testing::TestWithParam<Layout> {};

TEST_P(StreamingLayouts, BytesReportAndMetricsEqualInMemoryEncode) {
  const auto& [frames, segment_frames, operator_name, reorder, in_flight] = GetParam();
  const MeshSequence sequence = Walker(frames);
  EncoderOptions options;
  options.operator_name = operator_name;
  options.segment_frames = segment_frames;
  options.allow_reorder = reorder;
  EncodeReport memory_report;
  auto memory = Encode(sequence, options, &memory_report);
  ASSERT_TRUE(memory.ok()) << memory.status().ToString();

  const ScratchDirectory dir("layouts");
  const auto output = dir / "streamed.dmc";
  SequenceFrameSource source(sequence);
  StreamingEncodeOptions streaming;
  streaming.segments_in_flight = in_flight;
  std::vector<std::tuple<EncodeStage, int, int>> calls;
  streaming.progress = [&](EncodeStage stage, int done, int total) {
    calls.emplace_back(stage, done, total);
  };
  EncodeReport streamed_report;
  const Status status = EncodeStreaming(source, output, options, &streamed_report, streaming);
  ASSERT_TRUE(status.ok()) << status.ToString();

  EXPECT_EQ(FileBytes(output), *memory);
  ExpectSameReport(streamed_report, memory_report);
  EXPECT_EQ(DirectoryNames(dir), std::vector<std::string>{"streamed.dmc"});  // no temporaries

  // Progress: every stage ends at the frame count; encoding and measuring report each segment.
  int encode_calls = 0, measure_calls = 0;
  std::tuple<EncodeStage, int, int> last_of[3] = {};
  for (const auto& call : calls) {
    EXPECT_EQ(std::get<2>(call), frames);
    last_of[static_cast<int>(std::get<0>(call))] = call;
    encode_calls += std::get<0>(call) == EncodeStage::kEncode;
    measure_calls += std::get<0>(call) == EncodeStage::kMeasure;
  }
  EXPECT_EQ(encode_calls, memory_report.segments);
  EXPECT_EQ(measure_calls, memory_report.segments);
  for (const auto& last : last_of) EXPECT_EQ(std::get<1>(last), frames);
}

INSTANTIATE_TEST_SUITE_P(
    Layouts, StreamingLayouts,
    ::testing::Values(Layout{24, 0, "ddl", false, 1},          // one segment
                      Layout{40, 16, "ddl", false, 1},         // 3 segments of 14, 13, 13 frames
                      Layout{40, 7, "tutte", false, 2},        // 6 segments, two encoded at once
                      Layout{33, 11, "ddl", true, 1},          // reordered vertices, 3 segments
                      Layout{12, 1, "kirchhoff", false, 3}));  // one-frame segments

TEST(StreamingEncode, MeasureOffGivesTheSameBytesAndNoMetrics) {
  const MeshSequence sequence = Walker(20);
  EncoderOptions options;
  options.segment_frames = 8;
  options.measure = false;
  EncodeReport memory_report, streamed_report;
  auto memory = Encode(sequence, options, &memory_report);
  ASSERT_TRUE(memory.ok());
  const ScratchDirectory dir("nomeasure");
  const auto output = dir / "out.dmc";
  SequenceFrameSource source(sequence);
  ASSERT_TRUE(EncodeStreaming(source, output, options, &streamed_report).ok());
  EXPECT_EQ(FileBytes(output), *memory);
  EXPECT_FALSE(streamed_report.measured);
  ExpectSameReport(streamed_report, memory_report);
}

TEST(StreamingEncode, Pc2SourceEncodesAsReadSequenceDoes) {
  MeshSequence sequence = Walker(30);
  sequence.frame_rate = 24.0;
  const ScratchDirectory dir("pc2");
  const auto cache = dir / "walk.pc2";
  ASSERT_TRUE(WriteSequence(sequence, cache).ok());
  auto loaded = ReadSequence(cache);
  ASSERT_TRUE(loaded.ok());
  EncoderOptions options;
  options.segment_frames = 12;
  EncodeReport memory_report, streamed_report;
  auto memory = Encode(*loaded, options, &memory_report);
  ASSERT_TRUE(memory.ok());

  auto source = OpenPc2FrameSource(cache);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  EXPECT_EQ((*source)->name(), "walk");
  EXPECT_EQ((*source)->frame_rate(), 24.0);  // the mesh's rate / sampleRate 1
  EXPECT_EQ((*source)->frame_count(), 30);
  const auto output = dir / "walk.dmc";
  const Status status = EncodeStreaming(**source, output, options, &streamed_report);
  ASSERT_TRUE(status.ok()) << status.ToString();
  EXPECT_EQ(FileBytes(output), *memory);
  ExpectSameReport(streamed_report, memory_report);
}

TEST(StreamingEncode, Pc2TruncatedWhileStreamingFailsAndLeavesNoOutput) {
  const MeshSequence sequence = Walker(20);
  const ScratchDirectory dir("truncated");
  const auto cache = dir / "walk.pc2";
  ASSERT_TRUE(WriteSequence(sequence, cache).ok());
  auto source = OpenPc2FrameSource(cache);
  ASSERT_TRUE(source.ok());
  // Cut the file after it was opened (and its size checked): mid-frame 12.
  const uint64_t frame_bytes = 12u * static_cast<uint64_t>(sequence.vertex_count());
  std::filesystem::resize_file(cache, 32 + 12 * frame_bytes + frame_bytes / 2);
  const auto output = dir / "walk.dmc";
  const Status status = EncodeStreaming(**source, output, EncoderOptions());
  ASSERT_EQ(status.code(), ErrorCode::kParseError) << status.ToString();
  EXPECT_NE(status.message().find("ends within frame 12"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find(cache.string()), std::string::npos) << status.message();
  EXPECT_EQ(DirectoryNames(dir), (std::vector<std::string>{"walk.obj", "walk.pc2"}));
}

TEST(StreamingEncode, TruncatedPc2IsRefusedWhenOpened) {
  const MeshSequence sequence = Walker(5);
  const ScratchDirectory dir("short");
  const auto cache = dir / "walk.pc2";
  ASSERT_TRUE(WriteSequence(sequence, cache).ok());
  std::filesystem::resize_file(cache, std::filesystem::file_size(cache) - 7);
  auto source = OpenPc2FrameSource(cache);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), ErrorCode::kParseError);
  EXPECT_NE(source.status().message().find("truncated"), std::string::npos);
}

// A source that fails on its `fail_at`-th ReadFrames call (counting from 1), to fail a chosen
// pass: the scan reads frame 0, then one block; the encode pass reads one block per segment.
class FailingSource final : public FrameSource {
 public:
  FailingSource(const MeshSequence& sequence, int fail_at) : inner_(sequence), fail_at_(fail_at) {}
  int vertex_count() const override { return inner_.vertex_count(); }
  int frame_count() const override { return inner_.frame_count(); }
  const Triangles& triangles() const override { return inner_.triangles(); }
  double frame_rate() const override { return inner_.frame_rate(); }
  const std::string& name() const override { return inner_.name(); }
  Status ReadFrames(int first, int count, float* out) override {
    if (++calls_ == fail_at_) return IoError("disk gone at frame " + std::to_string(first));
    return inner_.ReadFrames(first, count, out);
  }

 private:
  SequenceFrameSource inner_;
  int fail_at_;
  int calls_ = 0;
};

TEST(StreamingEncode, SourceFailureInAnyPassKeepsTheExistingOutput) {
  const MeshSequence sequence = Walker(30);
  const ScratchDirectory dir("failing");
  const auto output = dir / "out.dmc";
  EncoderOptions options;
  options.segment_frames = 10;
  // Calls: 1 = frame 0, 2 = scan block, 3..5 = the three segments, 6.. = measuring.
  for (int fail_at : {2, 4, 7}) {
    SCOPED_TRACE("failing call " + std::to_string(fail_at));
    { std::ofstream(output) << "previous"; }
    FailingSource source(sequence, fail_at);
    const Status status = EncodeStreaming(source, output, options);
    EXPECT_EQ(status.code(), ErrorCode::kIoError) << status.ToString();
    EXPECT_NE(status.message().find("disk gone"), std::string::npos);
    EXPECT_EQ(DirectoryNames(dir), std::vector<std::string>{"out.dmc"});
    const std::vector<uint8_t> kept = FileBytes(output);
    EXPECT_EQ(std::string(kept.begin(), kept.end()), "previous");
  }
}

// Rate control streams too: the trials encode into memory from the frame source, and the search
// is Encode()'s, so the chosen step, the bytes and the report are Encode()'s.
TEST(StreamingEncode, RateControlChoosesWhatEncodeChooses) {
  const MeshSequence sequence = Walker(8);
  const ScratchDirectory dir("rate");
  SequenceFrameSource source(sequence);
  for (const bool distortion_target : {false, true}) {
    EncoderOptions options;
    options.segment_frames = 4;
    if (distortion_target) {
      options.target_sted = 0.02;
    } else {
      options.target_bpfv = 3.0;
    }
    EncodeReport memory, streamed;
    auto bytes = Encode(sequence, options, &memory);
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    const Status status = EncodeStreaming(source, dir / "a.dmc", options, &streamed);
    ASSERT_TRUE(status.ok()) << status.ToString();
    EXPECT_EQ(FileBytes(dir / "a.dmc"), *bytes);
    ExpectSameReport(streamed, memory);
    EXPECT_EQ(DirectoryNames(dir), std::vector<std::string>{"a.dmc"});
    if (distortion_target) {
      EXPECT_LE(streamed.distortion.sted, 0.02);
    } else {
      EXPECT_LE(streamed.bpfv, 3.0);
    }
  }
  EncoderOptions unreachable;
  unreachable.target_bpfv = 1e-6;
  EXPECT_EQ(EncodeStreaming(source, dir / "b.dmc", unreachable).code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(DirectoryNames(dir), std::vector<std::string>{"a.dmc"});
}

TEST(StreamingEncode, RefusesBadInputs) {
  const MeshSequence sequence = Walker(6);
  const ScratchDirectory dir("refused");
  SequenceFrameSource source(sequence);
  StreamingEncodeOptions none_in_flight;
  none_in_flight.segments_in_flight = 0;
  EXPECT_EQ(
      EncodeStreaming(source, dir / "a.dmc", EncoderOptions(), nullptr, none_in_flight).code(),
      ErrorCode::kInvalidArgument);
  EXPECT_EQ(EncodeStreaming(source, dir / "missing" / "a.dmc", EncoderOptions()).code(),
            ErrorCode::kIoError);

  MeshSequence broken = sequence;
  broken.frame(4)(7, 1) = std::numeric_limits<float>::quiet_NaN();
  SequenceFrameSource broken_source(broken);
  const Status status = EncodeStreaming(broken_source, dir / "b.dmc", EncoderOptions());
  EXPECT_EQ(status.code(), ErrorCode::kInvalidSequence);
  EXPECT_NE(status.message().find("frame 4, vertex 7: coordinate y is not finite"),
            std::string::npos)
      << status.message();
  EXPECT_TRUE(DirectoryNames(dir).empty());

  float out[3];
  EXPECT_EQ(source.ReadFrames(6, 1, out).code(), ErrorCode::kInvalidArgument);
}

class StreamingDecode : public ::testing::TestWithParam<int> {};

TEST_P(StreamingDecode, Pc2FilesEqualWriteSequenceOfDecode) {
  MeshSequence sequence = Walker(25);
  sequence.frame_rate = 30.0;
  EncoderOptions options;
  options.segment_frames = 9;
  options.measure = false;
  auto bytes = Encode(sequence, options);
  ASSERT_TRUE(bytes.ok());
  const ScratchDirectory dir("decode");
  auto decoded = Decode(*bytes);
  ASSERT_TRUE(decoded.ok());
  ASSERT_TRUE(WriteSequence(*decoded, dir / "memory.pc2").ok());

  std::vector<std::pair<int, int>> calls;
  const Status status = DecodeToPc2(
      *bytes, dir / "streamed.pc2", [&](int done, int total) { calls.emplace_back(done, total); },
      GetParam());
  ASSERT_TRUE(status.ok()) << status.ToString();
  EXPECT_EQ(FileBytes(dir / "streamed.pc2"), FileBytes(dir / "memory.pc2"));
  EXPECT_EQ(FileBytes(dir / "streamed.obj"), FileBytes(dir / "memory.obj"));
  EXPECT_EQ(DirectoryNames(dir),
            (std::vector<std::string>{"memory.obj", "memory.pc2", "streamed.obj", "streamed.pc2"}));
  // One call per segment (3 segments of 9, 8, 8 frames), in frame order.
  EXPECT_EQ(calls, (std::vector<std::pair<int, int>>{{9, 25}, {17, 25}, {25, 25}}));
}

INSTANTIATE_TEST_SUITE_P(SegmentsInFlight, StreamingDecode, ::testing::Values(1, 2, 3));

// `stream` with chunk `index` (0 = the sequence header) given `payload`, framed and checksummed
// anew: a stream that opens (every checksum holds) but fails when that chunk is decoded.
std::vector<uint8_t> ReplaceChunk(const std::vector<uint8_t>& stream, size_t index,
                                  const std::vector<uint8_t>& payload) {
  ByteReader reader(stream);
  std::span<const uint8_t> prefix;
  EXPECT_TRUE(reader.GetBytes(7, &prefix, "magic and version").ok());
  ByteWriter out;
  for (uint8_t byte : prefix)
    out.PutU8(byte);  // (PutBytes here trips GCC 12's -Wstringop-overflow)
  for (size_t chunk = 0; !reader.at_end(); ++chunk) {
    uint8_t type = 0;
    uint64_t size = 0;
    uint32_t checksum = 0;
    std::span<const uint8_t> original;
    EXPECT_TRUE(reader.GetU8(&type, "type").ok());
    EXPECT_TRUE(reader.GetVarU(&size, "size").ok());
    EXPECT_TRUE(reader.GetBytes(size, &original, "payload").ok());
    EXPECT_TRUE(reader.GetU32(&checksum, "checksum").ok());
    syntax::AppendChunk(
        out, static_cast<format::ChunkType>(type),
        chunk == index ? payload : std::vector<uint8_t>(original.begin(), original.end()));
  }
  return out.Take();
}

TEST(StreamingDecodeErrors, DamagedStreamLeavesNoFilesAndKeepsTheOldOnes) {
  const MeshSequence sequence = Walker(12);
  EncoderOptions options;
  options.segment_frames = 4;
  options.measure = false;
  auto bytes = Encode(sequence, options);
  ASSERT_TRUE(bytes.ok());
  const ScratchDirectory dir("damaged");
  { std::ofstream(dir / "out.pc2") << "previous"; }
  auto expect_nothing_written = [&] {
    EXPECT_EQ(DirectoryNames(dir), std::vector<std::string>{"out.pc2"});
    const std::vector<uint8_t> kept = FileBytes(dir / "out.pc2");
    EXPECT_EQ(std::string(kept.begin(), kept.end()), "previous");
  };

  // A flipped byte: the checksum fails when the stream is opened, before any file is created.
  std::vector<uint8_t> flipped = *bytes;
  flipped[flipped.size() - 40] ^= 0x5a;
  EXPECT_EQ(DecodeToPc2(flipped, dir / "out.pc2").code(), ErrorCode::kCorruptStream);
  expect_nothing_written();

  // The last of 3 segments with its residuals cut to five zero bytes: long enough to pass the
  // structure's checks (a payload under 5 bytes is refused when the stream is opened), so
  // segments 0 and 1 are written before it fails. Chunks: sequence header, connectivity, then 6
  // per segment; residuals are a segment's 6th.
  const std::vector<uint8_t> five_bytes = {0, 0, 0, 0, 0};
  const std::vector<uint8_t> cut = ReplaceChunk(*bytes, 2 + 6 * 2 + 5, five_bytes);
  std::vector<int> progress;
  const Status status =
      DecodeToPc2(cut, dir / "out.pc2", [&](int done, int) { progress.push_back(done); });
  EXPECT_EQ(status.code(), ErrorCode::kTruncatedStream) << status.ToString();
  EXPECT_NE(status.message().find("segment 2 residuals"), std::string::npos) << status.ToString();
  EXPECT_EQ(progress, (std::vector<int>{4, 8}));
  expect_nothing_written();

  EXPECT_EQ(DecodeToPc2(*bytes, dir / "out.pc2", {}, 0).code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc
