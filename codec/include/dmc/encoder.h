// Encoding mesh sequences to .dmc streams (trajectory PCA -> Laplace operator -> high-pass
// quantisation -> adaptive range coding), with closed-loop distortion measurement.
//
// Contract: Encode validates its input (ValidateSequence) and options; the encoder works in
// closed loop (every quantity it derives uses what the decoder will rebuild), and when
// EncoderOptions::measure is set it decodes its own stream with the real decoder, so the reported
// KG/STED are exactly those of `dmc decode`'s output. Output bytes are identical for identical
// input and options, whatever the thread count.
//
// Streaming (EncodeStreaming): the same stream, byte for byte, from a FrameSource that hands out
// frames on demand (a PC2 cache read incrementally, say), holding one segment's trajectories at a
// time instead of the whole sequence.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/metrics.h"
#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc {

// Each field is one row of the option table (dmc/encoder_options.h), which gives it its name as
// a CLI flag, a Python keyword and a manifest key; a new field needs a row there too.
struct EncoderOptions {
  std::string operator_name = "ddl";  // any codec-capable operator of the registry
  // How hard the encoder searches each segment's rank and operator, 0..9 (like zstd's levels):
  // 0 = one pass (the threshold's rank, the fitted DDL weights, nothing decoded to compare),
  // 1 = the ddl fallback at the threshold's rank, 2 = the default: also the rank search, the lower
  // ranks coded with the operator, weights and factorisation the top rank chose, candidates
  // measured on 8 frames and those that rate alone rules out not measured; 3-7 measure on more
  // frames and refit or retry the operators per rank; 8 = every candidate rank and operator
  // fitted and measured on 32 frames (the search of the encoder before the levels existed);
  // 9 = that search measured on every frame. rank, rank_search and ddl_fallback
  // restrict the search at every level: a fixed rank, rank_search = false or ddl_fallback =
  // false turn that part off whatever the effort; their defaults (automatic, true, true) leave
  // it to the effort, which codes the fallback from kFallbackEffort and searches ranks from
  // kRankSearchEffort up (CheckGivenSwitches, dmc/encoder_options.h). RD.md, "Effort", has each
  // level's rate and time.
  int effort = 2;
  int rank = 0;  // PCA basis vectors per segment; 0 = automatic
  // Automatic rank keeps component k while its eigenvalue λ_k > rank_threshold · V · Δ² (Δ the
  // residual step): a component is worth its coefficients while dropping it would cost more
  // squared error than quantising it does.
  double rank_threshold = 50.0;
  int basis_bits = 10;         // basis quantisation bits (2..16)
  int residual_bits = 10;      // residual step = bbox diagonal * 2^-residual_bits
  double residual_step = 0.0;  // absolute step; overrides residual_bits when > 0
  // Anchor vertices per segment; -1 = automatic: 1 % of the vertices, 2 % in segments of at least
  // kLongSegmentFrames frames, at least 1 and at most 1000 (RD.md, "Anchors and steps").
  int anchors = -1;
  double anchor_step_ratio = 1.0;  // anchor quantisation step / residual step
  // Rate–distortion optimised rounding of the residuals: a value may be rounded one level toward
  // zero when that lowers (error in steps)² + λ · bits; 0 = plain rounding. 0.05: measured
  // against 0, 0.1 and 0.2 on six sequences (RD.md, "Residual rounding").
  double residual_rdo_lambda = 0.05;
  // STED-aware step shaping (format 1.2): the residual step of each anchor's region of the mesh
  // is scaled by (its mean edge length / the mesh's geometric mean)^strength, in quarter octaves
  // within [1/4, 4], since STED measures edge-length change relative to the edge. -1 =
  // automatic: strength 0 for meshes of even edge lengths, rising to 1 as the spread of the
  // logarithm of the vertices' mean edge length grows from 0.25 to 0.6 (RD.md, "Step
  // shaping"); 0 = off (one step everywhere); > 0 = that strength (at most 2).
  double step_shaping = -1.0;
  int segment_frames = 0;   // maximum frames per segment; 0 = default
  int reference_bits = 10;  // geometric operators: reference frame step = diagonal · 2^-bits
  // DDL weight step 2^-weight_bits per segment; 0 = automatic: 8 for segments of at least
  // kLongSegmentFrames frames, 7 below (SegmentWeightBits). The weights are paid once per segment,
  // so long segments afford finer ones: jump-full (222 frames) -20.9 % BD-rate (STED) at 7 bits,
  // -27.2 % at 8, -27.8 % at 9; crane-full (175) -14.2 / -14.7 / -13.9 %; horse-gallop (48) and
  // cow (40) lose 0.4 and 0.8 points at 8 (RD.md, "DDL weights").
  int weight_bits = 0;
  double ddl_mu = 0.1;  // DDL Tikhonov pull toward Tutte (relative)
  // DDL weights within this many units of their prediction are sent as the prediction (0.5 =
  // plain rounding; infinity = predicted weights only). 0 = per segment, whichever of the two
  // gives the smaller payload at the same step: better rate–STED on short segments (crane), but
  // it can raise the largest vertex error several-fold, so it is not the default.
  double ddl_dead_zone = 0.5;
  // The ddl operator may code a segment with kirchhoff, tutte (no side information) or
  // mean-value (a coded reference frame) instead when that has the lower rate at equal STED;
  // short segments rarely pay for fitted weights. The stream names each segment's operator.
  // false = always the fitted DDL weights; true = as the effort decides (from kFallbackEffort).
  bool ddl_fallback = true;
  // With the ddl operator's fallback and an automatic rank: each segment is also coded at the
  // ranks of 1/4, 2 and 4 times rank_threshold (the first higher, the others lower, when they
  // differ), and the rank with the lowest bits · STED^1.3 (bits of the segment's payloads, STED
  // measured as the fallback does) is kept.
  // false = the rank of rank_threshold alone; true = as the effort decides (from
  // kRankSearchEffort).
  bool rank_search = true;
  // DDL weight prediction: false = shared in proportion to a degree-based reference weight,
  // true = shared equally (the thesis's p = (1 - Σ known)/|unknown|).
  bool uniform_weight_prediction = false;
  double target_bpfv = 0.0;    // > 0: search parameters for this rate
  double target_sted = 0.0;    // > 0: search parameters for this distortion
  bool allow_reorder = false;  // let the output use the codec's own vertex order
  // Frames per second recorded in the stream (and used for GLB output) when > 0, replacing the
  // input's own rate; for inputs that have none (OBJ/OFF/PLY frames, PC2 caches). 0 = the
  // input's rate (0 when it has none: unknown).
  double fps = 0.0;
  bool measure = true;  // decode and measure KG/STED
};

// Segments of at least this many frames pay for more side information: finer DDL weights
// (SegmentWeightBits) and twice the anchors (encoder/anchors.h).
inline constexpr int kLongSegmentFrames = 128;
// EncoderOptions::weight_bits of a segment of `frame_count` frames: the option when set, else 8
// from kLongSegmentFrames frames and 7 below.
inline int SegmentWeightBits(const EncoderOptions& options, int frame_count) {
  if (options.weight_bits != 0) return options.weight_bits;
  return frame_count >= kLongSegmentFrames ? 8 : 7;
}

// The lowest effort that searches ranks (with an automatic rank, the ddl operator, rank_search and
// ddl_fallback), and the lowest that codes the ddl operator's fallback (with ddl_fallback).
inline constexpr int kRankSearchEffort = 2;
inline constexpr int kFallbackEffort = 1;
inline constexpr int kMaxEffort = 9;

struct EncodeReport {
  uint64_t bytes = 0;
  double bpfv = 0.0;
  int frames = 0;
  int vertices = 0;
  DistortionReport distortion;  // valid when measured
  bool measured = false;
  // Why EncoderOptions::measure was set but nothing was measured: KG and STED are undefined for
  // the input (e.g. every vertex of a frame at one point). The stream was still decoded to check
  // it. Empty otherwise.
  std::string not_measured_reason;
  double seconds = 0.0;
  // Bytes per syntax element, over all segments (chunk framing included).
  uint64_t header_bytes = 0, connectivity_bytes = 0, mean_bytes = 0, basis_bytes = 0,
           operator_bytes = 0, anchor_bytes = 0, residual_bytes = 0;
  // The scene chunk (format 1.3; StreamingEncodeOptions::scene), included in bytes and bpfv; 0
  // without one. positions_bpfv leaves it out: the rate of the motion alone, which rate control's
  // target_bpfv aims at.
  uint64_t scene_bytes = 0;
  double positions_bpfv = 0.0;
  // What rate control chose (of the first segment when they differ).
  int rank = 0;
  int anchors = 0;
  int residual_bits_equivalent = 0;
  double residual_step = 0.0;
  int segments = 0;
  // The operator each segment was coded with, in segment order: the requested one, or with the
  // ddl operator's fallback (EncoderOptions::ddl_fallback) kirchhoff, tutte or mean-value.
  std::vector<std::string> segment_operators;
  // What each segment's header says, in segment order (what `dmc info` of the stream shows).
  struct Segment {
    int first_frame = 0;
    int frames = 0;
    std::string operator_name;
    int rank = 0;
    int anchors = 0;
    double residual_step = 0.0;  // as coded: a kirchhoff segment's is scaled by the mean degree
  };
  std::vector<Segment> segment_details;
};

StatusOr<std::vector<uint8_t>> Encode(const MeshSequence& sequence, const EncoderOptions& options,
                                      EncodeReport* report = nullptr);

// Encodes and writes atomically (temporary file, then rename).
Status EncodeToFile(const MeshSequence& sequence, const std::filesystem::path& output,
                    const EncoderOptions& options, EncodeReport* report = nullptr);

// Where the streaming encoder gets a sequence: its shape up front, its positions on demand.
// Contract for implementations: the counts, triangles, name and frame rate do not change, and
// ReadFrames returns the same values every time it is asked for the same frames (the encoder
// reads the sequence more than once: a scan for the bounding box, then segment by segment, then
// again to measure). ReadFrames is never called concurrently.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual int vertex_count() const = 0;
  virtual int frame_count() const = 0;
  virtual const Triangles& triangles() const = 0;
  virtual double frame_rate() const = 0;        // frames per second; 0 when unknown
  virtual const std::string& name() const = 0;  // stored in the stream's header
  // Copies frames [first, first + count) into `out`: count × V × 3 floats, frame after frame (the
  // MeshSequence layout). Errors name the source and frame at fault.
  virtual Status ReadFrames(int first, int count, float* out) = 0;
};

// A MeshSequence as a FrameSource. Keeps a reference: the sequence must outlive the source.
class SequenceFrameSource final : public FrameSource {
 public:
  explicit SequenceFrameSource(const MeshSequence& sequence) : sequence_(sequence) {}
  int vertex_count() const override { return sequence_.vertex_count(); }
  int frame_count() const override { return sequence_.frame_count(); }
  const Triangles& triangles() const override { return sequence_.triangles(); }
  double frame_rate() const override { return sequence_.frame_rate; }
  const std::string& name() const override { return sequence_.name; }
  Status ReadFrames(int first, int count, float* out) override;

 private:
  const MeshSequence& sequence_;
};

// A PC2 point cache read frame block by frame block (never whole), with the triangles of
// `connectivity` (empty: the first of <stem>.obj, .off, .ply beside the cache, as ReadSequence
// does). Same name (the cache's stem) and frame rate (mesh frame rate / sampleRate when both are
// known, else 0) as ReadSequence gives the same input, so the stream is the same too. Open checks
// the header against the file size and the mesh's vertex count against the cache's (kParseError,
// kMismatch); reading the connectivity mesh may add warnings (fan triangulation, degenerate
// triangles) to `warnings`. ReadFrames fails with kInvalidSequence ("frame 7 (<path>), vertex 3:
// coordinate y is not finite") on a non-finite value and with kParseError naming the path and the
// frame when the file has been cut since it was opened.
StatusOr<std::unique_ptr<FrameSource>> OpenPc2FrameSource(
    const std::filesystem::path& cache, const std::filesystem::path& connectivity = {},
    std::vector<std::string>* warnings = nullptr);

// What EncodeStreaming is doing, for progress displays: scanning the input (bounding box and, when
// measuring, the metrics' reference values), encoding segments, measuring (decoding each segment
// and comparing it with the input).
enum class EncodeStage { kScan, kEncode, kMeasure };
std::string_view EncodeStageName(EncodeStage stage);  // "scanning", "encoding", "measuring"

// Called with the frames done so far in `stage` and the frame count after each block of work (each
// segment when encoding and measuring); one call at a time, possibly from a worker thread.
using EncodeProgressCallback =
    std::function<void(EncodeStage stage, int frames_done, int frames_total)>;

struct StreamingEncodeOptions {
  EncodeProgressCallback progress;
  // Segments encoded concurrently. Each holds its trajectories (12·V·F_s bytes) and its operator
  // fit (about 3.7 KB per vertex for DDL) while encoding, so 1 bounds memory best; more use more
  // threads on multi-segment sequences. The bytes do not depend on the value: the DDL fits'
  // METIS orderings (systems above 30k unknowns) use a process-global random state, so the solver
  // runs those analyses one at a time (see DecodeToPc2 in dmc/decoder.h), and the fallback's
  // trial decodes order their normal matrices as the decoder does.
  int segments_in_flight = 1;
  // What the input holds besides vertex motion, as a glTF binary (GLB) file (dmc::BuildGltfScene
  // in dmc/io.h), stored zstd-compressed in the stream's scene chunk (format 1.3, spec §6.3) so a
  // decoder can rebuild the scene; at most 2^30 bytes. Empty: no scene chunk.
  std::vector<uint8_t> scene;
};

// Encodes `source` to `output` segment by segment: the header and connectivity first, then each
// segment's chunks as soon as it is encoded, into a temporary file beside `output` that is renamed
// over it only when everything (including the measurement) succeeded; on failure nothing is left
// and an existing `output` is untouched. The bytes are exactly Encode()'s for the same sequence and
// options, and so is the report; with options.measure the stream is decoded segment by segment
// with the real decoder and KG/STED/RMSE are accumulated over segments, equal to Encode()'s.
// Memory: `segments_in_flight` segments' trajectories and fits, plus, when measuring, one
// segment of decoded and original frames; never the whole sequence.
// Rate control (target_bpfv / target_sted) streams too: a search over the residual step whose
// trials are whole encodes into memory (the compressed stream only); the last trial that met the
// target is written to `output`. The source is read once to scan, then once per trial (12 trials),
// twice per trial for target_sted (the trial's measurement); memory stays as above, and the step,
// bytes and report are Encode()'s (Encode() runs this same pipeline).
Status EncodeStreaming(FrameSource& source, const std::filesystem::path& output,
                       const EncoderOptions& options, EncodeReport* report = nullptr,
                       const StreamingEncodeOptions& streaming = {});

}  // namespace dmc
