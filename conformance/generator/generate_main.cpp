// dmc_conformance_generate: writes the conformance vectors of the current format version.
//
//   dmc_conformance_generate --out DIR [--check]
//
// Valid vectors are encoded from built-in synthetic animations (dmc::Synthesize) and a few
// hand-made meshes with the public encoder, so the same build always writes the same bytes.
// Invalid vectors are edits of small valid streams, each made to trip exactly one rule of the
// spec; the generator decodes every invalid vector and refuses to write a manifest whose expected
// error differs from what the reference decoder reports (so the manifests never lie).
//
// Vectors of an older format version already in DIR/valid are kept: a valid vector whose manifest
// names another version is renamed <name>-v<major>.<minor> before a new vector of that name is
// written, because a decoder must still decode it. Invalid vectors are rewritten (what is
// invalid can change with the version). --check runs the runner's checks over DIR afterwards.
#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/connectivity_decoder.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/encoder_options.h"
#include "dmc/laplace_operator.h"
#include "dmc/operator_traits.h"
#include "dmc/synth.h"
#include "encoder/connectivity_encoder.h"
#include "encoder/range_encoder.h"
#include "encoder/stream_writer.h"
#include "encoder/syntax_writer.h"
#include "entropy/byte_io.h"
#include "kit/vector_kit.h"
#include "synth/grid_triangles.h"

namespace dmc::conformance {
namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

std::string VersionText() {
  return std::to_string(format::kVersionMajor) + "." + std::to_string(format::kVersionMinor);
}

// ---------------------------------------------------------------------------------------------
// Sources

struct Source {
  Json description;  // recorded in the manifest so the vector can be understood and remade
  std::function<StatusOr<MeshSequence>()> make;
};

Source Synth(const std::string& name, int resolution, int frames, uint64_t seed = 1) {
  Json description = {
      {"synth", name}, {"resolution", resolution}, {"frames", frames}, {"seed", seed}};
  return {description, [=]() -> StatusOr<MeshSequence> {
            SynthOptions options;
            options.resolution = resolution;
            options.frames = frames;
            options.seed = seed;
            return Synthesize(name, options);
          }};
}

// Frame 0 of a synthetic animation repeated: no motion at all, so automatic rank selection keeps
// no basis vector (a mean-only segment).
Source StaticSynth(const std::string& name, int resolution, int frames) {
  Json description = {{"synth", name},
                      {"resolution", resolution},
                      {"frames", frames},
                      {"seed", 1},
                      {"static", true}};
  return {description, [=]() -> StatusOr<MeshSequence> {
            SynthOptions options;
            options.resolution = resolution;
            options.frames = 1;
            DMC_ASSIGN_OR_RETURN(MeshSequence first, Synthesize(name, options));
            MeshSequence sequence(first.vertex_count(), first.triangles(), frames);
            for (int f = 0; f < frames; ++f) sequence.frame(f) = first.frame(0);
            sequence.name = name + "-static";
            sequence.frame_rate = first.frame_rate;
            return sequence;
          }};
}

// An n×n grid waving in z plus one isolated vertex (referenced by no triangle): Draco cannot code
// an isolated vertex, so the encoder falls back to the indexed connectivity method, and the
// isolated vertex forms its own connected component (which needs its own anchor).
Source GridWithIsolatedVertex(int n, int frames) {
  Json description = {{"mesh", "grid with one isolated vertex"}, {"grid", n}, {"frames", frames}};
  return {description, [=]() -> StatusOr<MeshSequence> {
            const Triangles triangles = synth::GridTriangles(n, n, synth::GridDiagonals::kUniform);
            const int isolated = n * n;
            MeshSequence sequence(n * n + 1, triangles, frames);
            for (int f = 0; f < frames; ++f) {
              const double phase = 2.0 * std::numbers::pi * f / 8.0;
              for (int v = 0; v < n * n; ++v) {
                const double x = static_cast<double>(v % n) / (n - 1);
                const double y = static_cast<double>(v / n) / (n - 1);
                const double z = 0.08 * std::sin(2.0 * std::numbers::pi * x + phase) *
                                 std::cos(std::numbers::pi * y);
                sequence.frame(f).row(v) << static_cast<float>(x), static_cast<float>(y),
                    static_cast<float>(z);
              }
              sequence.frame(f).row(isolated) << 0.5f, 0.5f,
                  static_cast<float>(0.3 + 0.02 * std::sin(phase));
            }
            sequence.name = "grid-isolated";
            sequence.frame_rate = 25.0;
            return sequence;
          }};
}

// An n×n grid whose columns are 16 times closer on the left than on the right (spacing growing
// geometrically), waving in z: a mesh of uneven triangles, so step shaping gives its anchor regions
// different steps (spec §8.5.1).
Source GradedGrid(int n, int frames) {
  Json description = {{"mesh", "graded grid"}, {"grid", n}, {"frames", frames}};
  return {description, [=]() -> StatusOr<MeshSequence> {
            MeshSequence sequence(n * n, synth::GridTriangles(n, n, synth::GridDiagonals::kUniform),
                                  frames);
            for (int f = 0; f < frames; ++f) {
              for (int v = 0; v < n * n; ++v) {
                const double u = static_cast<double>(v % n) / (n - 1);
                const double x = (std::exp2(4.0 * u) - 1.0) / 15.0;
                const double y = static_cast<double>(v / n) / (n - 1);
                const double z = 0.1 * std::sin(6.0 * x + 0.4 * f) * std::cos(3.0 * y - 0.2 * f);
                sequence.frame(f).row(v) << static_cast<float>(x), static_cast<float>(y),
                    static_cast<float>(z);
              }
            }
            sequence.name = "graded-grid";
            sequence.frame_rate = 25.0;
            return sequence;
          }};
}

// A torus (genus 1: every edgebreaker traversal of it meets its handles, so the Draco buffer holds
// topology split events), an n × m grid wrapped in both directions, breathing and turning.
Source Torus(int n, int m, int frames) {
  Json description = {{"mesh", "torus"}, {"around", n}, {"tube", m}, {"frames", frames}};
  return {description, [=]() -> StatusOr<MeshSequence> {
            Triangles triangles(2 * n * m, 3);
            auto at = [&](int i, int j) { return (i % n) * m + (j % m); };
            for (int i = 0; i < n; ++i) {
              for (int j = 0; j < m; ++j) {
                triangles.row(2 * (i * m + j)) << at(i, j), at(i + 1, j), at(i + 1, j + 1);
                triangles.row(2 * (i * m + j) + 1) << at(i, j), at(i + 1, j + 1), at(i, j + 1);
              }
            }
            MeshSequence sequence(n * m, triangles, frames);
            for (int f = 0; f < frames; ++f) {
              const double r = 0.3 + 0.05 * std::sin(0.7 * f), turn = 0.2 * f;
              for (int i = 0; i < n; ++i) {
                for (int j = 0; j < m; ++j) {
                  const double u = 2.0 * std::numbers::pi * i / n + turn;
                  const double v = 2.0 * std::numbers::pi * j / m;
                  sequence.frame(f).row(at(i, j))
                      << static_cast<float>((1.0 + r * std::cos(v)) * std::cos(u)),
                      static_cast<float>((1.0 + r * std::cos(v)) * std::sin(u)),
                      static_cast<float>(r * std::sin(v));
                }
              }
            }
            sequence.name = "torus";
            sequence.frame_rate = 24.0;
            return sequence;
          }};
}

// An n × n sheet with every case the geometric formulas of §9.5 guard against: its first two rows
// 10^-4 apart (slivers whose angles are far below 1°: clamped cotangents), a vertex j whose only
// triangle is (0, 0, j) (a repeated vertex: degenerate corners, and j's unit-sum row sums to 0,
// so it takes the Tutte row), a third triangle on an interior edge (a non-manifold edge) and an
// isolated vertex (so the connectivity is the indexed method 0, which allows all of these).
// `slivers` false: evenly spaced rows; `fin` false: no third triangle on the interior edge (its
// apex would have no Voronoi area: only an edge's first two opposite vertices are visited, §9.5).
Source DegenerateSheet(int n, int frames, bool slivers = true, bool fin_triangle = true) {
  Json description = {{"mesh",
                       "sheet with slivers, a repeated-vertex triangle, a non-manifold "
                       "edge and an isolated vertex"},
                      {"grid", n},
                      {"frames", frames},
                      {"slivers", slivers},
                      {"non_manifold_edge", fin_triangle}};
  return {description, [=]() -> StatusOr<MeshSequence> {
            const Triangles grid = synth::GridTriangles(n, n, synth::GridDiagonals::kUniform);
            const int dangling = n * n, fin = n * n + 1, isolated = n * n + 2;
            const int centre = (n / 2) * n + n / 2;
            Triangles triangles(grid.rows() + (fin_triangle ? 2 : 1), 3);
            triangles.topRows(grid.rows()) = grid;
            triangles.row(grid.rows()) << 0, 0, dangling;
            if (fin_triangle) triangles.row(grid.rows() + 1) << centre, centre + 1, fin;
            MeshSequence sequence(n * n + 3, triangles, frames);
            for (int f = 0; f < frames; ++f) {
              const double phase = 2.0 * std::numbers::pi * f / 6.0;
              for (int v = 0; v < n * n; ++v) {
                const int row = v / n;
                const double x = static_cast<double>(v % n) / (n - 1);
                const double y = !slivers   ? static_cast<double>(row) / (n - 1)
                                 : row == 0 ? 0.0
                                            : 1e-4 + static_cast<double>(row - 1) / (n - 2);
                const double z = 0.05 * std::sin(3.0 * x + phase) * std::cos(2.0 * y);
                sequence.frame(f).row(v) << static_cast<float>(x), static_cast<float>(y),
                    static_cast<float>(z);
              }
              sequence.frame(f).row(dangling) << -0.1f, -0.05f,
                  static_cast<float>(0.02 * std::sin(phase));
              sequence.frame(f).row(fin) << static_cast<float>((centre % n + 0.5) / (n - 1)), 0.5f,
                  static_cast<float>(0.2 + 0.03 * std::cos(phase));
              sequence.frame(f).row(isolated) << 1.2f, 1.2f,
                  static_cast<float>(0.1 * std::sin(phase));
            }
            sequence.name = "degenerate-sheet";
            sequence.frame_rate = 30.0;
            return sequence;
          }};
}

// Every option that can change the bytes, under its table name (dmc/encoder_options.h).
Json OptionsJson(const EncoderOptions& options) {
  Json json = Json::object();
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    if (!spec.shapes_stream) continue;
    std::visit([&](auto field) { json[std::string(spec.name)] = options.*field; }, spec.field);
  }
  return json;
}

// The vectors named after an operator cover that operator's decoding, so the DDL's per-segment
// fallback to kirchhoff/tutte/mean-value is off here; one vector covers the fallback itself.
EncoderOptions Options(const std::string& operator_name) {
  EncoderOptions options;
  options.operator_name = operator_name;
  options.ddl_fallback = false;
  options.measure = false;
  return options;
}

// ---------------------------------------------------------------------------------------------
// Valid vectors

struct ValidVector {
  std::string name;
  std::string description;
  Source source;
  EncoderOptions options;
  int expected_connectivity_method;  // what the vector is meant to cover
  int minimum_segments = 1;
  bool rank_zero = false;        // meant to cover a mean-only segment
  bool mixed_operators = false;  // meant to cover segments of different operators; otherwise
                                 // every segment has the requested operator
  bool step_shaped = false;      // meant to cover non-zero step exponents (1.2, spec §8.5.1)
  // A scene chunk (1.3, spec §6.3) inserted third: its payload (ScenePayload's, or hand-made).
  std::vector<uint8_t> scene_payload;
  std::vector<uint8_t> scene;  // what it decompresses to
  // Repairs the geometric operator of every segment must make (spec §9.5), counted by rebuilding
  // it from the stream: each flag set means "at least one".
  bool clamped_cotangents = false, degenerate_triangles = false, tutte_fallback_rows = false,
       clamped_areas = false;
  // Every segment header's anchor weight set to this after encoding (0: kept); the stream stays
  // valid, the reconstruction is what the decoder makes of it (spec §10.1).
  double anchor_weight = 0.0;
  // The connectivity recoded with this label model (wire value, spec §7.3; -1: the encoder's
  // smallest). The labels, hence the output, are the same; only their coding changes.
  int label_model = -1;
  // The Draco buffer must hold topology split events (spec §7.3.1; a mesh of genus > 0).
  bool topology_splits = false;
};

// Where the parts of a method-1/2 connectivity payload lie: the method byte, varint n, the n Draco
// bytes from `draco_start`, then the rest (method 1: the label model byte and the labels).
struct DracoPayloadParts {
  size_t draco_start = 0;
  size_t draco_size = 0;
  size_t rest_start() const { return draco_start + draco_size; }
};

std::optional<DracoPayloadParts> SplitDracoPayload(std::span<const uint8_t> payload) {
  if (payload.empty()) return std::nullopt;
  ByteReader reader(payload.subspan(1));
  uint64_t size = 0;
  if (!reader.GetVarU(&size, "Draco buffer size").ok() || size > reader.remaining()) {
    return std::nullopt;
  }
  return DracoPayloadParts{1 + reader.position(), static_cast<size_t>(size)};
}

// The label model byte of a method-1 connectivity payload, or -1.
int LabelModelOf(std::span<const uint8_t> payload) {
  const std::optional<DracoPayloadParts> parts = SplitDracoPayload(payload);
  if (!parts || parts->rest_start() >= payload.size()) return -1;
  return payload[parts->rest_start()];
}

// num_encoded_split_symbols of a method-1/2 payload's Draco buffer (after the 12 bytes of §7.3.1's
// header and traversal type: varint vertices, varint faces, u8 attribute data, varint symbols,
// varint split symbols; Draco 2.2), or -1.
int64_t DracoSplitSymbols(std::span<const uint8_t> payload) {
  const std::optional<DracoPayloadParts> parts = SplitDracoPayload(payload);
  if (!parts || parts->draco_size < 12) return -1;
  ByteReader reader(payload.subspan(parts->draco_start + 12, parts->draco_size - 12));
  uint64_t vertices = 0, faces = 0, symbols = 0, splits = 0;
  uint8_t attribute_data = 0;
  if (!reader.GetVarU(&vertices, "vertices").ok() || !reader.GetVarU(&faces, "faces").ok() ||
      !reader.GetU8(&attribute_data, "attribute data").ok() ||
      !reader.GetVarU(&symbols, "symbols").ok() || !reader.GetVarU(&splits, "splits").ok()) {
    return -1;
  }
  return static_cast<int64_t>(splits);
}

// Spec sections a valid stream exercises, from what it holds (the runner prints them).
std::vector<std::string> Covers(const ParsedStream& parsed, const StreamInfo& info,
                                const std::vector<OperatorStats>& stats) {
  std::set<std::string> covers = {"4.1", "4.2", "4.4", "6.1", "10.1", "10.2"};
  const uint8_t method = parsed.framed.chunks[1].payload.front();
  covers.insert(method == 0 ? "7.2" : "7.3");
  if (method != 0) covers.insert("7.3.1");
  if (method != 0 && DracoSplitSymbols(parsed.framed.chunks[1].payload) > 0) {
    covers.insert("D.2 split symbols");
  }
  if (method == 1) {
    covers.insert({"7.3.2", "7.3.3"});
    if (const int model = LabelModelOf(parsed.framed.chunks[1].payload); model >= 0) {
      covers.insert("7.3 label model " + std::to_string(model));
      if (connectivity::LabelModel::FromWire(static_cast<uint8_t>(model)).kernel_code > 0) {
        covers.insert("7.3.4");
      }
    }
  }
  if (info.scene_bytes > 0) covers.insert("6.3");
  for (size_t s = 0; s < parsed.segments.size(); ++s) {
    const SegmentSyntax& segment = parsed.segments[s];
    covers.insert({"8.1", "8.2", "8.5", "8.6"});
    if (segment.header.rank > 0) covers.insert(info.version_minor >= 1 ? "8.3.2" : "8.3.1");
    // The operator's side information says which §9 section builds it (operator_traits.h).
    switch (FindOperatorTraits(static_cast<OperatorId>(segment.header.operator_id))->side_info) {
      case OperatorSideInfo::kEdgeWeights:
        covers.insert("9.4");
        break;
      case OperatorSideInfo::kReferenceFrame:
        covers.insert({"8.4", "9.5"});
        break;
      default:
        covers.insert("9.3");
        break;
    }
    if (std::any_of(segment.anchor_step_exponents.begin(), segment.anchor_step_exponents.end(),
                    [](int8_t e) { return e != 0; })) {
      covers.insert("8.5.1");
    }
    if (segment.header.anchor_weight != 1.0) covers.insert("10.1 anchor weight");
    if (s < stats.size()) {
      if (stats[s].clamped_cotangents > 0) covers.insert("9.5 clamped cotangent");
      if (stats[s].degenerate_triangles > 0) covers.insert("9.5 degenerate corner");
      if (stats[s].fallback_rows > 0) covers.insert("9.5 Tutte fallback");
      if (stats[s].clamped_areas > 0) covers.insert("9.5 area floor");
    }
  }
  return {covers.begin(), covers.end()};
}

// A minimal glTF binary: the content of the scene vectors (opaque to decoding, spec §6.3).
std::vector<uint8_t> MinimalGlb() {
  std::string json = R"({"asset":{"version":"2.0","generator":"dmc conformance"}})";
  while (json.size() % 4 != 0) json.push_back(' ');
  ByteWriter out;
  out.PutU32(0x46546C67u);  // "glTF"
  out.PutU32(2);
  out.PutU32(static_cast<uint32_t>(20 + json.size()));
  out.PutU32(static_cast<uint32_t>(json.size()));
  out.PutU32(0x4E4F534Au);  // "JSON"
  out.PutBytes(std::vector<uint8_t>(json.begin(), json.end()));
  return out.Take();
}

// The scene chunk's payload storing `scene` uncompressed (compression 0).
std::vector<uint8_t> StoredScenePayload(const std::vector<uint8_t>& scene) {
  ByteWriter out;
  out.PutU8(format::kSceneKindGlb);
  out.PutU8(format::kSceneStored);
  out.PutVarU(scene.size());
  out.PutBytes(scene);
  return out.Take();
}

// `stream` with a scene chunk of `payload` third, the end chunk counting it.
StatusOr<std::vector<uint8_t>> WithScene(const std::vector<uint8_t>& stream,
                                         const std::vector<uint8_t>& payload) {
  DMC_ASSIGN_OR_RETURN(Framed framed, SplitFramed(stream));
  framed.chunks.insert(framed.chunks.begin() + 2,
                       Chunk{static_cast<uint8_t>(ChunkType::kScene), payload, 0});
  ByteWriter count;
  count.PutVarU(framed.chunks.size() - 1);
  framed.chunks.back().payload = count.Take();
  return JoinFramed(framed);
}

std::vector<ValidVector> ValidVectors() {
  std::vector<ValidVector> vectors;
  auto add = [&](std::string name, std::string description, Source source, EncoderOptions options,
                 ConnectivityMethod method, int minimum_segments = 1) {
    ValidVector vector;
    vector.name = std::move(name);
    vector.description = std::move(description);
    vector.source = std::move(source);
    vector.options = options;
    vector.expected_connectivity_method = static_cast<int>(method);
    vector.minimum_segments = minimum_segments;
    vectors.push_back(std::move(vector));
  };
  add("twist_ddl", "closed genus-0 tube, symmetric DDL operator, default parameters",
      Synth("twist", 300, 10), Options("ddl"), ConnectivityMethod::kDracoWithVertexOrder);
  add("cloth_tutte_boundary", "open sheet with one boundary loop, Tutte operator",
      Synth("cloth", 250, 8), Options("tutte"), ConnectivityMethod::kDracoWithVertexOrder);
  add("walker_kirchhoff_components", "six closed components, Kirchhoff operator",
      Synth("walker", 300, 6), Options("kirchhoff"), ConnectivityMethod::kDracoWithVertexOrder);
  add("blob_single_frame", "a single frame (rank at most 3), DDL", Synth("blob", 200, 1),
      Options("ddl"), ConnectivityMethod::kDracoWithVertexOrder);
  {
    EncoderOptions options = Options("ddl");
    options.segment_frames = 5;
    add("twist_four_segments", "16 frames in four segments of 4 frames, DDL",
        Synth("twist", 200, 16, 3), options, ConnectivityMethod::kDracoWithVertexOrder, 4);
  }
  {
    EncoderOptions options = Options("ddl");
    options.allow_reorder = true;
    add("cloth_reordered_ddl", "codec vertex order (--allow-reorder), boundary, DDL",
        Synth("cloth", 200, 6, 2), options, ConnectivityMethod::kDracoReordered);
  }
  {
    EncoderOptions options = Options("tutte");
    options.allow_reorder = true;
    options.segment_frames = 4;
    add("walker_reordered_tutte_segments",
        "codec vertex order with six components, two segments, Tutte", Synth("walker", 300, 8, 4),
        options, ConnectivityMethod::kDracoReordered, 2);
  }
  add("grid_isolated_indexed",
      "indexed connectivity (an isolated vertex Draco cannot code), two components, DDL",
      GridWithIsolatedVertex(10, 6), Options("ddl"), ConnectivityMethod::kIndexed);
  add("static_frames", "four identical frames: every trajectory is constant",
      StaticSynth("twist", 150, 4), Options("ddl"), ConnectivityMethod::kDracoWithVertexOrder);
  {
    EncoderOptions options = Options("ddl");
    options.basis_bits = 2;
    options.residual_bits = 1;
    options.weight_bits = 2;
    options.anchors = 1;
    add("extreme_coarse",
        "coarsest quantisers: 2 basis bits, residual step = diagonal / 2 (so rank 0: the mean "
        "trajectory only, DDL weights all predicted), 2 weight bits, one anchor",
        Synth("blob", 150, 5), options, ConnectivityMethod::kDracoWithVertexOrder);
    vectors.back().rank_zero = true;
  }
  {
    EncoderOptions options = Options("ddl");
    options.basis_bits = 16;
    options.residual_bits = 24;
    options.weight_bits = 20;
    options.rank = 12;
    options.anchors = 40;
    options.anchor_step_ratio = 0.25;
    options.uniform_weight_prediction = true;
    add("extreme_fine",
        "finest quantisers: 16 basis bits, 2^-24 residual step, 20 weight bits, "
        "full rank 12, 40 anchors, uniform weight prediction",
        Synth("twist", 150, 4, 5), options, ConnectivityMethod::kDracoWithVertexOrder);
  }
  // The geometric operators rebuild their weights from a coded reference frame (spec §8.4, §9.5).
  {
    EncoderOptions options = Options("cotan");
    options.reference_bits = 24;
    add("twist_cotan_fine_reference", "cotangent operator, reference frame step 2^-24 D",
        Synth("twist", 200, 6, 7), options, ConnectivityMethod::kDracoWithVertexOrder);
  }
  add("cloth_cotan_area_boundary", "area-normalised cotangent operator on a sheet with a boundary",
      Synth("cloth", 200, 5, 8), Options("cotan-area"), ConnectivityMethod::kDracoWithVertexOrder);
  {
    EncoderOptions options = Options("cotan-sym");
    options.allow_reorder = true;
    add("walker_cotan_sym_reordered", "symmetric cotangent operator, six components, codec order",
        Synth("walker", 300, 4, 9), options, ConnectivityMethod::kDracoReordered);
  }
  {
    EncoderOptions options = Options("mean-value");
    options.reference_bits = 4;
    add("blob_mean_value_coarse_reference",
        "mean value operator from a reference frame quantised on a coarse 2^-4 D grid",
        Synth("blob", 150, 5, 10), options, ConnectivityMethod::kDracoWithVertexOrder);
  }
  {
    EncoderOptions options = Options("ddl");
    options.ddl_fallback = true;
    options.segment_frames = 4;
    add("twist_ddl_fallback_mixed",
        "the DDL encoder's per-segment fallback: three 4-frame segments, each coded with the "
        "operator the fallback chose (at least two different ones occur)",
        Synth("twist", 200, 12, 1), options, ConnectivityMethod::kDracoWithVertexOrder, 3);
    vectors.back().mixed_operators = true;
  }
  {
    EncoderOptions options = Options("ddl");
    options.step_shaping = 1.0;
    options.anchors = 24;
    add("graded_grid_step_shaped",
        "step shaping (1.2): a grid of uneven cells whose 24 anchor regions have step exponents "
        "from negative (short edges) to positive (long edges)",
        GradedGrid(33, 10), options, ConnectivityMethod::kDracoWithVertexOrder);
    vectors.back().step_shaped = true;
  }
  {
    add("cloth_scene_zstd",
        "a scene chunk (1.3) third: a minimal glTF binary, zstd-compressed as the encoder writes "
        "it",
        Synth("cloth", 150, 4, 11), Options("ddl"), ConnectivityMethod::kDracoWithVertexOrder);
    vectors.back().scene = MinimalGlb();
    vectors.back().scene_payload = ScenePayload(vectors.back().scene).value();
    add("cloth_scene_stored", "a scene chunk (1.3) third, stored uncompressed (compression 0)",
        Synth("cloth", 150, 4, 12), Options("tutte"), ConnectivityMethod::kDracoWithVertexOrder);
    vectors.back().scene = MinimalGlb();
    vectors.back().scene_payload = StoredScenePayload(vectors.back().scene);
  }
  // Coverage of §7.3 and §9.5's guards (issue 26).
  add("torus_ddl_topology_splits",
      "a torus (genus 1): the edgebreaker traversal meets its handles, so the Draco buffer holds "
      "topology split events; labels in input order",
      Torus(16, 8, 5), Options("ddl"), ConnectivityMethod::kDracoWithVertexOrder);
  vectors.back().topology_splits = true;
  add("twist_label_model_2",
      "vertex labels coded with label model 2 (neighbour-median predictor, spread contexts, no "
      "kernel), which the encoder's choice never picks for this mesh",
      Synth("twist", 200, 4, 13), Options("tutte"), ConnectivityMethod::kDracoWithVertexOrder);
  vectors.back().label_model = 2;
  // cotan: slivers clamp cotangents, the lone vertex of (0, 0, j) takes the Tutte row; mean-value:
  // the Tutte row. (cotan-area on this sheet does not decode: the lone vertex's weights are
  // 0 / floor, and the slivers' large ones leave N numerically indefinite.)
  {
    EncoderOptions options = Options("cotan");
    options.reference_bits = 24;  // the slivers survive the reference frame's grid
    add("degenerate_sheet_cotan",
        "cotangent operator on a sheet with slivers (clamped cotangents), a triangle with a "
        "repeated vertex whose lone vertex takes the Tutte row, a non-manifold edge and an "
        "isolated vertex (indexed connectivity)",
        DegenerateSheet(12, 6), options, ConnectivityMethod::kIndexed);
    vectors.back().clamped_cotangents = true;
    vectors.back().tutte_fallback_rows = true;
  }
  {
    // The sheet without slivers and without the fin (whose apex would get no Voronoi area): the
    // repeated-vertex triangle's corners are degenerate in the areas and its lone vertex takes
    // the area floor, with weights 0 / floor = 0, so every vertex is an anchor (N would be
    // singular otherwise, spec §10.1).
    EncoderOptions options = Options("cotan-area");
    options.reference_bits = 24;
    options.anchors = 12 * 12 + 3;
    add("degenerate_sheet_cotan_area",
        "area-normalised cotangent operator on a sheet whose repeated-vertex triangle has "
        "degenerate corners in the mixed Voronoi areas and a lone vertex at the area floor, plus "
        "an isolated vertex (indexed connectivity); every vertex an anchor",
        DegenerateSheet(12, 6, false, false), options, ConnectivityMethod::kIndexed);
    // The floor is reached because the lone vertex's only corners are degenerate and add no area.
    vectors.back().clamped_areas = true;
  }
  {
    EncoderOptions options = Options("mean-value");
    options.reference_bits = 24;
    add("degenerate_sheet_mean_value",
        "mean value operator on the same sheet: the repeated-vertex triangle adds nothing and its "
        "lone vertex takes the Tutte row; the non-manifold edge and the isolated vertex",
        DegenerateSheet(12, 6), options, ConnectivityMethod::kIndexed);
    vectors.back().tutte_fallback_rows = true;
  }
  add("cloth_anchor_weight_quarter",
      "every segment's anchor weight set to 0.25 after encoding: the normal equations weigh the "
      "anchors less (spec §10.1)",
      Synth("cloth", 200, 6, 14), Options("tutte"), ConnectivityMethod::kDracoWithVertexOrder);
  vectors.back().anchor_weight = 0.25;
  return vectors;
}

Status WriteJson(const fs::path& path, const Json& json) {
  const std::string text = json.dump(1) + "\n";
  return WriteBytes(
      path, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

// Renames an existing valid vector of another format version out of the way (see the header).
Status KeepOlderVersion(const fs::path& directory, const std::string& name) {
  const fs::path manifest_path = directory / (name + ".json");
  if (!fs::exists(manifest_path)) return Status::Ok();
  DMC_ASSIGN_OR_RETURN(const std::vector<uint8_t> bytes, ReadBytes(manifest_path));
  const Json manifest = Json::parse(bytes.begin(), bytes.end(), nullptr, false);
  if (manifest.is_discarded() || !manifest.contains("format_version")) return Status::Ok();
  const std::string version = manifest["format_version"].get<std::string>();
  if (version == VersionText()) return Status::Ok();
  const std::string kept = name + "-v" + version;
  Json renamed = manifest;
  renamed["stream"] = kept + ".dmc";
  renamed["positions"]["file"] = kept + ".ref.zst";
  std::error_code error;
  fs::rename(directory / (name + ".dmc"), directory / (kept + ".dmc"), error);
  if (!error) fs::rename(directory / (name + ".ref.zst"), directory / (kept + ".ref.zst"), error);
  if (error)
    return IoError("cannot keep " + name + " of version " + version + ": " + error.message());
  DMC_RETURN_IF_ERROR(WriteJson(directory / (kept + ".json"), renamed));
  fs::remove(manifest_path, error);
  std::printf("kept %s (format %s) as %s\n", name.c_str(), version.c_str(), kept.c_str());
  return Status::Ok();
}

Status GenerateValid(const ValidVector& vector, const fs::path& directory) {
  DMC_ASSIGN_OR_RETURN(const MeshSequence sequence, vector.source.make());
  DMC_ASSIGN_OR_RETURN(std::vector<uint8_t> stream, Encode(sequence, vector.options));
  if (vector.label_model >= 0 || vector.anchor_weight != 0.0) {
    DMC_ASSIGN_OR_RETURN(Framed framed, SplitFramed(stream));
    if (vector.label_model >= 0) {
      DMC_ASSIGN_OR_RETURN(
          const ConnectivityCode code,
          EncodeConnectivityWithLabelModel(sequence.triangles(), sequence.vertex_count(),
                                           static_cast<uint8_t>(vector.label_model)));
      framed.chunks[1].payload = code.payload;
    }
    if (vector.anchor_weight != 0.0) {
      DMC_ASSIGN_OR_RETURN(const ParsedStream parsed, ParseStream(stream));
      for (size_t s = 0; s < parsed.segments.size(); ++s) {
        format::SegmentHeader header = parsed.segments[s].header;
        header.anchor_weight = vector.anchor_weight;
        framed.chunks[parsed.first_segment_chunk + 6 * s].payload =
            syntax::WriteSegmentHeader(header);
      }
    }
    stream = JoinFramed(framed);
  }
  if (!vector.scene_payload.empty()) {
    DMC_ASSIGN_OR_RETURN(stream, WithScene(stream, vector.scene_payload));
    DMC_ASSIGN_OR_RETURN(const std::vector<uint8_t> scene, DecodeScene(stream, kNoCallerLimit));
    if (scene != vector.scene) return InternalError(vector.name + ": the scene does not decode");
  }
  DMC_ASSIGN_OR_RETURN(const MeshSequence decoded, Decode(stream, kNoCallerLimit));
  DMC_ASSIGN_OR_RETURN(const StreamInfo info, ReadStreamInfo(stream));
  DMC_ASSIGN_OR_RETURN(const SyntaxDigests digests, ComputeSyntaxDigests(stream));
  if (digests.connectivity_method != vector.expected_connectivity_method) {
    return InternalError(vector.name + ": connectivity method " +
                         std::to_string(digests.connectivity_method) + ", meant to cover " +
                         std::to_string(vector.expected_connectivity_method));
  }
  if (static_cast<int>(info.segments.size()) < vector.minimum_segments) {
    return InternalError(vector.name + ": " + std::to_string(info.segments.size()) +
                         " segment(s), meant to cover " + std::to_string(vector.minimum_segments));
  }
  if (vector.rank_zero && std::none_of(info.segments.begin(), info.segments.end(),
                                       [](const SegmentInfo& s) { return s.rank == 0; })) {
    return InternalError(vector.name + ": no rank-0 segment, meant to cover one");
  }
  std::set<std::string> operators;
  for (const SegmentInfo& segment : info.segments) operators.insert(segment.operator_name);
  if (vector.mixed_operators ? operators.size() < 2
                             : operators != std::set<std::string>{vector.options.operator_name}) {
    return InternalError(vector.name +
                         ": segment operators do not cover what the vector is "
                         "meant to (" +
                         std::to_string(operators.size()) + " distinct)");
  }
  if (vector.step_shaped) {
    DMC_ASSIGN_OR_RETURN(const ParsedStream parsed, ParseStream(stream));
    const bool positive_and_negative = std::any_of(
        parsed.segments.begin(), parsed.segments.end(), [](const SegmentSyntax& segment) {
          const auto& e = segment.anchor_step_exponents;
          return std::any_of(e.begin(), e.end(), [](int8_t x) { return x < 0; }) &&
                 std::any_of(e.begin(), e.end(), [](int8_t x) { return x > 0; });
        });
    if (!positive_and_negative) {
      return InternalError(vector.name + ": no segment has both finer and coarser step regions");
    }
  }
  // What the operator rebuilt from the stream had to repair (spec §9.5), and what the vector is
  // meant to exercise.
  DMC_ASSIGN_OR_RETURN(const ParsedStream parsed, ParseStream(stream));
  std::vector<OperatorStats> stats;
  for (const SegmentSyntax& segment : parsed.segments) {
    DMC_ASSIGN_OR_RETURN(const LaplaceOperator laplace,
                         RebuildSegmentOperator(parsed.topology, segment));
    stats.push_back(laplace.stats);
  }
  const auto every_segment = [&](auto count) {
    return std::all_of(stats.begin(), stats.end(),
                       [&](const OperatorStats& s) { return count(s) > 0; });
  };
  if ((vector.clamped_cotangents && !every_segment([](auto& s) { return s.clamped_cotangents; })) ||
      (vector.degenerate_triangles &&
       !every_segment([](auto& s) { return s.degenerate_triangles; })) ||
      (vector.tutte_fallback_rows && !every_segment([](auto& s) { return s.fallback_rows; })) ||
      (vector.clamped_areas && !every_segment([](auto& s) { return s.clamped_areas; }))) {
    return InternalError(
        vector.name + ": the operator does not make the repairs it is meant to " +
        "cover: clamped cotangents " + std::to_string(stats.front().clamped_cotangents) +
        ", degenerate triangles " + std::to_string(stats.front().degenerate_triangles) +
        ", Tutte rows " + std::to_string(stats.front().fallback_rows) + ", area floors " +
        std::to_string(stats.front().clamped_areas) + " (first segment)");
  }
  if (vector.topology_splits && DracoSplitSymbols(parsed.framed.chunks[1].payload) <= 0) {
    return InternalError(vector.name + ": the Draco buffer has no split symbol");
  }
  if (vector.label_model >= 0 &&
      LabelModelOf(parsed.framed.chunks[1].payload) != vector.label_model) {
    return InternalError(vector.name + ": not coded with label model " +
                         std::to_string(vector.label_model));
  }
  DMC_RETURN_IF_ERROR(KeepOlderVersion(directory, vector.name));

  Json segments = Json::array();
  for (size_t s = 0; s < info.segments.size(); ++s) {
    const SegmentInfo& segment = info.segments[s];
    segments.push_back({{"first_frame", segment.first_frame},
                        {"frame_count", segment.frame_count},
                        {"rank", segment.rank},
                        {"operator_id", segment.operator_id},
                        {"operator", segment.operator_name},
                        {"anchor_count", segment.anchor_count},
                        {"syntax_digest", HashHex(digests.segments[s])}});
  }
  Json frame_hashes = Json::array();
  for (int f = 0; f < decoded.frame_count(); ++f)
    frame_hashes.push_back(HashHex(FrameHash(decoded, f)));
  const std::string positions_file = vector.name + ".ref.zst";
  Json manifest = {
      {"kind", "valid"},
      {"format_version", VersionText()},
      {"generated", true},
      {"description", vector.description},
      {"stream", vector.name + ".dmc"},
      {"stream_bytes", stream.size()},
      {"stream_xxh64", HashHex(XXH64(stream.data(), stream.size(), 0))},
      {"source", vector.source.description},
      {"encoder_options", OptionsJson(vector.options)},
      {"covers", Covers(parsed, info, stats)},
      {"name", info.name},
      {"frame_rate", info.frame_rate},
      {"vertex_count", decoded.vertex_count()},
      {"triangle_count", decoded.triangle_count()},
      {"frame_count", decoded.frame_count()},
      {"reordered", info.reordered},
      {"connectivity_method", digests.connectivity_method},
      {"connectivity_digest", HashHex(digests.connectivity)},
      {"triangles_xxh64",
       HashHex(XXH64(decoded.triangles().data(),
                     sizeof(int32_t) * 3 * static_cast<size_t>(decoded.triangle_count()), 0))},
      {"segments", segments},
      {"positions",
       {{"file", positions_file},
        {"diagonal", SequenceDiagonal(decoded)},
        {"tolerance", "|x - r| <= 2^-20 * diagonal + 2^-22 * |r|"},
        {"frame_xxh64", frame_hashes}}}};
  if (!vector.scene.empty()) {
    manifest["scene"] = {{"bytes", vector.scene.size()},
                         {"xxh64", HashHex(XXH64(vector.scene.data(), vector.scene.size(), 0))}};
  }
  DMC_RETURN_IF_ERROR(WriteBytes(directory / (vector.name + ".dmc"), stream));
  DMC_RETURN_IF_ERROR(WriteBytes(directory / positions_file, CompressPositions(decoded)));
  DMC_RETURN_IF_ERROR(WriteJson(directory / (vector.name + ".json"), manifest));
  std::printf("valid   %-34s %6zu bytes  V %4d  F %2d  segments %zu  method %d\n",
              vector.name.c_str(), stream.size(), decoded.vertex_count(), decoded.frame_count(),
              info.segments.size(), digests.connectivity_method);
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------------
// Invalid vectors

struct InvalidVector {
  std::string name;
  std::string description;
  std::string derived_from;
  std::vector<uint8_t> stream;
  ErrorCode error;       // what Decode must report
  ErrorCode info_error;  // what ReadStreamInfo must report (kOk: it succeeds)
};

// A valid base stream with its parsed syntax, to derive invalid vectors from.
struct Base {
  std::string name;
  std::vector<uint8_t> stream;
  ParsedStream parsed;
};

StatusOr<Base> MakeBase(const std::string& name, Source source, EncoderOptions options) {
  Base base;
  base.name = name;
  DMC_ASSIGN_OR_RETURN(const MeshSequence sequence, source.make());
  DMC_ASSIGN_OR_RETURN(base.stream, Encode(sequence, options));
  DMC_ASSIGN_OR_RETURN(base.parsed, ParseStream(base.stream));
  return base;
}

// Chunk indices of a one-segment stream.
constexpr size_t kSequenceHeaderChunk = 0, kConnectivityChunk = 1, kSegmentHeaderChunk = 2,
                 kMeanChunk = 3, kBasisChunk = 4, kOperatorChunk = 5, kAnchorsChunk = 6,
                 kResidualsChunk = 7, kEndChunk = 8;

// Byte offset where each chunk starts, plus the stream size at the end.
std::vector<size_t> ChunkStarts(const Framed& framed) {
  std::vector<size_t> starts;
  size_t offset = framed.preamble.size();
  for (const Chunk& chunk : framed.chunks) {
    starts.push_back(offset);
    ByteWriter varint;
    varint.PutVarU(chunk.payload.size());
    offset += 1 + varint.size() + chunk.payload.size() + 4;
  }
  starts.push_back(offset);
  return starts;
}

std::vector<uint8_t> Edited(const Base& base, const std::function<void(Framed&)>& edit,
                            bool recompute_checksums = true) {
  Framed framed = base.parsed.framed;
  edit(framed);
  return JoinFramed(framed, recompute_checksums);
}

// A sequence header payload with raw (possibly out-of-range) field values.
std::vector<uint8_t> RawSequenceHeader(uint64_t vertices, uint64_t triangles, uint64_t frames,
                                       uint64_t segments, double frame_rate, uint8_t flags,
                                       const std::string& name) {
  ByteWriter w;
  w.PutVarU(vertices);
  w.PutVarU(triangles);
  w.PutVarU(frames);
  w.PutVarU(segments);
  w.PutF64(frame_rate);
  w.PutU8(flags);
  w.PutString(name);
  return w.Take();
}

std::vector<uint8_t> SegmentHeaderWith(const Base& base,
                                       const std::function<void(format::SegmentHeader&)>& edit) {
  format::SegmentHeader header = base.parsed.segments[0].header;
  edit(header);
  return syntax::WriteSegmentHeader(header);
}

// An anchor chunk payload of the current version: ascending indices as gaps, the step exponents
// (`exponents`, 0 for the anchors it does not reach), then the quantised values (spec §8.5).
std::vector<uint8_t> AnchorPayload(const std::vector<int64_t>& indices,
                                   const std::vector<std::vector<int64_t>>& values,
                                   const std::vector<int64_t>& exponents = {}) {
  static_assert(format::kVersionMinor >= 2, "the exponents are 1.2 syntax");
  RangeEncoder encoder;
  auto contexts = std::make_unique<format::AnchorContexts>();
  int64_t previous = -1;
  for (const int64_t index : indices) {
    encoder.EncodeUnsigned(contexts->index_gap, static_cast<uint64_t>(index - previous - 1));
    previous = index;
  }
  for (size_t a = 0; a < indices.size(); ++a) {
    encoder.EncodeSigned(contexts->step_exponent, a < exponents.size() ? exponents[a] : 0);
  }
  for (const auto& row : values) {
    for (size_t k = 0; k < row.size(); ++k) {
      encoder.EncodeSigned(contexts->value[std::min<size_t>(k, format::kBasisColumnGroups - 1)],
                           row[k]);
    }
  }
  return encoder.Finish();
}

// The base's anchors and quantised anchor values (segment 0).
void BaseAnchors(const Base& base, std::vector<int64_t>* indices,
                 std::vector<std::vector<int64_t>>* values) {
  const SegmentSyntax& syntax = base.parsed.segments[0];
  for (size_t a = 0; a < syntax.anchors.size(); ++a) {
    indices->push_back(syntax.anchors[a]);
    std::vector<int64_t> row;
    for (Eigen::Index k = 0; k < syntax.anchor_values.cols(); ++k) {
      row.push_back(std::llround(syntax.anchor_values(static_cast<Eigen::Index>(a), k) /
                                 syntax.header.anchor_step));
    }
    values->push_back(row);
  }
}

std::vector<InvalidVector> InvalidVectors(const Base& ddl, const Base& tutte, const Base& walker,
                                          const Base& cotan, const Base& indexed) {
  std::vector<InvalidVector> out;
  const ErrorCode kCorrupt = ErrorCode::kCorruptStream;
  const ErrorCode kTruncated = ErrorCode::kTruncatedStream;
  const ErrorCode kUnsupported = ErrorCode::kUnsupported;
  const ErrorCode kOk = ErrorCode::kOk;
  auto add = [&](std::string name, std::string description, const Base& base,
                 std::vector<uint8_t> stream, ErrorCode error, ErrorCode info_error) {
    out.push_back(
        {std::move(name), std::move(description), base.name, std::move(stream), error, info_error});
  };
  const std::vector<uint8_t>& s = ddl.stream;
  const format::SequenceHeader& h = ddl.parsed.header;

  // --- Truncation: the empty stream, inside the preamble, at every chunk boundary, inside
  // payloads and checksums. Every proper prefix of a stream is truncated-stream.
  add("truncated_empty", "zero bytes", ddl, {}, kTruncated, kTruncated);
  add("truncated_in_magic", "3 bytes of the magic", ddl, {s.begin(), s.begin() + 3}, kTruncated,
      kTruncated);
  add("truncated_in_preamble", "magic and version, no reserved byte", ddl,
      {s.begin(), s.begin() + 6}, kTruncated, kTruncated);
  const std::vector<size_t> starts = ChunkStarts(ddl.parsed.framed);
  const char* chunk_names[] = {"sequence_header", "connectivity", "segment_header", "mean", "basis",
                               "operator",        "anchors",      "residuals",      "end"};
  for (size_t c = 0; c < ddl.parsed.framed.chunks.size(); ++c) {
    add(std::string("truncated_before_") + chunk_names[c],
        std::string("stream cut at the chunk boundary before the ") + chunk_names[c] + " chunk",
        ddl, {s.begin(), s.begin() + static_cast<std::ptrdiff_t>(starts[c])}, kTruncated,
        kTruncated);
  }
  for (const size_t c : {kConnectivityChunk, kResidualsChunk}) {
    const size_t middle = (starts[c] + starts[c + 1]) / 2;
    add(std::string("truncated_inside_") + chunk_names[c],
        std::string("stream cut in the middle of the ") + chunk_names[c] + " chunk", ddl,
        {s.begin(), s.begin() + static_cast<std::ptrdiff_t>(middle)}, kTruncated, kTruncated);
  }
  add("truncated_in_last_checksum", "the end chunk's checksum lacks its last byte", ddl,
      {s.begin(), s.end() - 1}, kTruncated, kTruncated);

  // --- Preamble.
  {
    std::vector<uint8_t> bad = s;
    bad[0] = 'X';
    add("bad_magic", "first magic byte is 'X'", ddl, bad, kCorrupt, kCorrupt);
    bad = s;
    bad[4] = 2;
    add("version_2_0", "major version 2", ddl, bad, kUnsupported, kUnsupported);
    bad = s;
    bad[4] = 0;
    add("version_0_0", "major version 0", ddl, bad, kUnsupported, kUnsupported);
    bad = s;
    bad[5] = static_cast<uint8_t>(format::kVersionMinor + 1);
    add("version_newer_minor", "minor version one above what this format defines", ddl, bad,
        kUnsupported, kUnsupported);
    bad = s;
    bad[5] = 0;
    add("minor_version_lowered",
        "minor version 0 in a 1.1 stream (the minor version seeds the checksums: corrupt-stream)",
        ddl, bad, kCorrupt, kCorrupt);
    bad = s;
    bad[6] = 0x01;
    add("reserved_byte_set", "reserved preamble byte is 1", ddl, bad, kCorrupt, kCorrupt);
  }

  // --- Framing and checksums.
  add("checksum_mismatch_residuals", "one residual payload bit flipped, checksum kept", ddl,
      Edited(
          ddl, [](Framed& f) { f.chunks[kResidualsChunk].payload.back() ^= 0x10; }, false),
      kCorrupt, kCorrupt);
  add("checksum_mismatch_header", "sequence header checksum off by one", ddl,
      Edited(
          ddl, [](Framed& f) { f.chunks[kSequenceHeaderChunk].checksum += 1; }, false),
      kCorrupt, kCorrupt);
  add("checksum_of_other_type",
      "mean chunk relabelled as basis with its old checksum (the type seeds the checksum)", ddl,
      Edited(
          ddl,
          [](Framed& f) { f.chunks[kMeanChunk].type = static_cast<uint8_t>(ChunkType::kBasis); },
          false),
      kCorrupt, kCorrupt);
  add("chunk_order_swapped", "mean and basis chunks swapped (each with a valid checksum)", ddl,
      Edited(ddl, [](Framed& f) { std::swap(f.chunks[kMeanChunk], f.chunks[kBasisChunk]); }),
      kCorrupt, kCorrupt);
  add("chunk_type_unknown", "operator chunk carries the unassigned type 10", ddl,
      Edited(ddl, [](Framed& f) { f.chunks[kOperatorChunk].type = 10; }), kCorrupt, kCorrupt);
  add("scene_chunk_at_operator", "operator chunk carries type 9 (scene): a scene only goes third",
      ddl, Edited(ddl, [](Framed& f) { f.chunks[kOperatorChunk].type = 9; }), kCorrupt, kCorrupt);

  // --- The scene chunk (1.3, spec §6.3), each built from a valid scene inserted third.
  {
    const std::vector<uint8_t> glb = MinimalGlb();
    const std::vector<uint8_t> zstd = ScenePayload(glb).value();
    auto scene_stream = [&](std::vector<uint8_t> payload) { return WithScene(s, payload).value(); };
    auto patched = [&](size_t at, uint8_t value) {
      std::vector<uint8_t> payload = zstd;
      payload[at] = value;
      return scene_stream(payload);
    };
    add("scene_kind_unknown", "scene kind 2 (only 1, glTF binary, is defined)", ddl, patched(0, 2),
        kCorrupt, kCorrupt);
    add("scene_compression_unknown", "scene compression 2 (0 stored, 1 zstd)", ddl, patched(1, 2),
        kCorrupt, kCorrupt);
    add("scene_size_zero", "scene size 0", ddl, scene_stream({1, 0, 0}), kCorrupt, kCorrupt);
    {
      std::vector<uint8_t> payload = StoredScenePayload(glb);
      payload.pop_back();
      add("scene_stored_short", "a stored scene one byte shorter than its size", ddl,
          scene_stream(payload), kCorrupt, kCorrupt);
    }
    add("scene_truncated_fields", "the scene payload ends inside its size varint", ddl,
        scene_stream({1, 1, 0x80}), kTruncated, kTruncated);
    {
      // The size field is the varint after kind and compression: one more than the frame states.
      std::vector<uint8_t> payload = zstd;
      payload[2] = static_cast<uint8_t>(payload[2] + 1);
      add("scene_zstd_size_mismatch",
          "the scene's size is one more than its zstd frame's content size; only decompressing "
          "shows it",
          ddl, scene_stream(payload), kCorrupt, kOk);
    }
    {
      std::vector<uint8_t> payload = zstd;
      payload.push_back(0);
      add("scene_zstd_trailing", "a byte after the scene's zstd frame", ddl, scene_stream(payload),
          kCorrupt, kOk);
    }
    {
      std::vector<uint8_t> payload = zstd;
      payload.resize(payload.size() - 3);
      add("scene_zstd_cut", "the scene's zstd frame lacks its last 3 bytes", ddl,
          scene_stream(payload), kCorrupt, kOk);
    }
    {
      std::vector<uint8_t> stream = scene_stream(zstd);
      stream[5] = 2;  // minor version 2, checksums recomputed for it
      Framed framed = SplitFramed(stream).value();
      add("scene_in_1_2_stream", "a scene chunk third in a 1.2 stream, where type 9 is unassigned",
          ddl, JoinFramed(framed), kCorrupt, kCorrupt);
    }
  }
  add("chunk_type_zero", "operator chunk carries the reserved type 0", ddl,
      Edited(ddl, [](Framed& f) { f.chunks[kOperatorChunk].type = 0; }), kCorrupt, kCorrupt);
  add("end_chunk_missing", "the end chunk is absent", ddl,
      {s.begin(), s.begin() + static_cast<std::ptrdiff_t>(starts[kEndChunk])}, kTruncated,
      kTruncated);
  add("end_count_wrong", "end chunk counts 7 chunks before it instead of 8", ddl,
      Edited(ddl, [](Framed& f) { f.chunks[kEndChunk].payload = {7}; }), kCorrupt, kCorrupt);
  add("end_chunk_trailing_payload", "end chunk payload has a byte after its varint", ddl,
      Edited(ddl, [](Framed& f) { f.chunks[kEndChunk].payload.push_back(0); }), kCorrupt, kCorrupt);
  add("trailing_bytes", "one zero byte after the end chunk", ddl,
      Edited(ddl, [](Framed& f) { f.trailing = {0}; }), kCorrupt, kCorrupt);
  add("segment_chunks_repeated", "the segment's six chunks appear twice, the header says one", ddl,
      Edited(ddl,
             [](Framed& f) {
               std::vector<Chunk> segment(f.chunks.begin() + kSegmentHeaderChunk,
                                          f.chunks.begin() + kEndChunk);
               f.chunks.insert(f.chunks.begin() + kEndChunk, segment.begin(), segment.end());
               f.chunks.back().payload = {14};
             }),
      kCorrupt, kCorrupt);
  {
    // Chunk size as an 11-byte varint: longer than 64 bits.
    std::vector<uint8_t> bad(s.begin(), s.begin() + 7);
    bad.push_back(static_cast<uint8_t>(ChunkType::kSequenceHeader));
    for (int i = 0; i < 10; ++i) bad.push_back(0xFF);
    bad.push_back(0x01);
    add("chunk_size_varint_too_long", "first chunk size is an 11-byte varint", ddl, bad, kCorrupt,
        kCorrupt);
    bad.assign(s.begin(), s.begin() + 7);
    bad.push_back(static_cast<uint8_t>(ChunkType::kSequenceHeader));
    for (int i = 0; i < 8; ++i) bad.push_back(0xFF);
    bad.push_back(0x01);  // 2^63 - 1 + ...: far more than the stream holds
    add("chunk_size_past_end", "first chunk declares about 2^57 payload bytes", ddl, bad,
        kTruncated, kTruncated);
  }

  // --- Sequence header.
  auto header_vector = [&](std::string name, std::string description, std::vector<uint8_t> payload,
                           ErrorCode error) {
    add(std::move(name), std::move(description), ddl,
        Edited(ddl, [&](Framed& f) { f.chunks[kSequenceHeaderChunk].payload = payload; }), error,
        error);
  };
  const uint64_t V = h.vertex_count, T = h.triangle_count, F = h.frame_count;
  header_vector("reserved_flag_bits", "sequence flags 0x81: a reserved bit set",
                RawSequenceHeader(V, T, F, 1, h.frame_rate, 0x81, h.name), kCorrupt);
  header_vector("frame_count_zero", "frame count 0",
                RawSequenceHeader(V, T, 0, 1, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector("frame_count_2pow32", "frame count 2^32",
                RawSequenceHeader(V, T, uint64_t{1} << 32, 1, h.frame_rate, h.flags, h.name),
                kCorrupt);
  header_vector("vertex_count_zero", "vertex count 0",
                RawSequenceHeader(0, T, F, 1, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector("vertex_count_above_limit", "vertex count 2^26 + 1",
                RawSequenceHeader((uint64_t{1} << 26) + 1, T, F, 1, h.frame_rate, h.flags, h.name),
                kCorrupt);
  header_vector("triangle_count_above_limit", "triangle count 2^27 + 1",
                RawSequenceHeader(V, (uint64_t{1} << 27) + 1, F, 1, h.frame_rate, h.flags, h.name),
                kCorrupt);
  header_vector("vertex_count_beyond_connectivity",
                "vertex count one more than the connectivity holds",
                RawSequenceHeader(V + 1, T, F, 1, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector("triangle_count_beyond_connectivity",
                "triangle count one more than the connectivity holds",
                RawSequenceHeader(V, T + 1, F, 1, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector("segment_count_zero", "segment count 0",
                RawSequenceHeader(V, T, F, 0, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector("segment_count_above_frames", "more segments than frames",
                RawSequenceHeader(V, T, F, F + 1, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector("segment_count_without_chunks", "two segments declared, chunks for one",
                RawSequenceHeader(V, T, F, 2, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector("frame_count_beyond_segments", "one frame more than the segments cover",
                RawSequenceHeader(V, T, F + 1, 1, h.frame_rate, h.flags, h.name), kCorrupt);
  header_vector(
      "output_above_16gib", "2^26 vertices × 2^20 frames: more than 16 GiB of decoded positions",
      RawSequenceHeader(uint64_t{1} << 26, T, uint64_t{1} << 20, 1, h.frame_rate, h.flags, h.name),
      kUnsupported);
  header_vector("frame_rate_nan", "frame rate is NaN",
                RawSequenceHeader(V, T, F, 1, std::nan(""), h.flags, h.name), kCorrupt);
  header_vector("frame_rate_negative", "frame rate -25",
                RawSequenceHeader(V, T, F, 1, -25.0, h.flags, h.name), kCorrupt);
  header_vector("name_too_long", "a 257-byte name",
                RawSequenceHeader(V, T, F, 1, h.frame_rate, h.flags, std::string(257, 'n')),
                kCorrupt);
  {
    std::vector<uint8_t> payload = RawSequenceHeader(V, T, F, 1, h.frame_rate, h.flags, h.name);
    payload.push_back(0);
    header_vector("sequence_header_trailing_byte", "sequence header payload one byte too long",
                  payload, kCorrupt);
    payload.resize(payload.size() - 2);
    header_vector("sequence_header_short", "sequence header payload one byte too short", payload,
                  kTruncated);
  }

  // --- Connectivity.
  auto connectivity_vector = [&](std::string name, std::string description,
                                 const std::function<void(std::vector<uint8_t>&)>& edit,
                                 ErrorCode error) {
    add(std::move(name), std::move(description), ddl,
        Edited(ddl, [&](Framed& f) { edit(f.chunks[kConnectivityChunk].payload); }), error, error);
  };
  connectivity_vector(
      "connectivity_method_unknown", "connectivity method 9",
      [](std::vector<uint8_t>& p) { p[0] = 9; }, kUnsupported);
  connectivity_vector(
      "connectivity_empty", "empty connectivity payload",
      [](std::vector<uint8_t>& p) { p.clear(); }, kTruncated);
  // Method 1 payload: method, varint Draco size, Draco buffer "DRACO"...
  const size_t draco_start = SplitDracoPayload(ddl.parsed.framed.chunks[1].payload)->draco_start;
  connectivity_vector(
      "draco_magic_damaged", "Draco buffer starts with 'XRACO'",
      [&](std::vector<uint8_t>& p) { p[draco_start] = 'X'; }, kCorrupt);
  connectivity_vector(
      "draco_version_2_1", "Draco bitstream version 2.1 instead of 2.2",
      [&](std::vector<uint8_t>& p) { p[draco_start + 6] = 1; }, kCorrupt);
  connectivity_vector(
      "draco_method_sequential", "Draco method 0 (sequential) instead of 1",
      [&](std::vector<uint8_t>& p) { p[draco_start + 8] = 0; }, kCorrupt);
  connectivity_vector(
      "draco_traversal_unknown", "Draco edgebreaker traversal 1 (predictive)",
      [&](std::vector<uint8_t>& p) { p[draco_start + 11] = 1; }, kCorrupt);
  connectivity_vector(
      "draco_size_past_payload", "Draco buffer size larger than the payload",
      [&](std::vector<uint8_t>& p) { p.resize(draco_start + 20); }, kTruncated);
  // Appendix D.4: past the header check, every Draco failure is corrupt-stream. The payload
  // rebuilt with a Draco buffer edited by `edit_draco` (n rewritten).
  const auto with_draco = [](std::vector<uint8_t>& p,
                             const std::function<void(std::vector<uint8_t>&)>& edit_draco) {
    const DracoPayloadParts parts = SplitDracoPayload(p).value();
    std::vector<uint8_t> draco(p.begin() + static_cast<std::ptrdiff_t>(parts.draco_start),
                               p.begin() + static_cast<std::ptrdiff_t>(parts.rest_start()));
    const std::vector<uint8_t> rest(p.begin() + static_cast<std::ptrdiff_t>(parts.rest_start()),
                                    p.end());
    edit_draco(draco);
    ByteWriter out;
    out.PutU8(p[0]);
    out.PutVarU(draco.size());
    out.PutBytes(draco);
    out.PutBytes(rest);
    p = out.Take();
  };
  connectivity_vector(
      "draco_data_cut_after_header",
      "Draco buffer cut 4 bytes after its checked header (n says so): the library fails, "
      "corrupt-stream, not truncated-stream (Appendix D.4)",
      [&](std::vector<uint8_t>& p) {
        with_draco(p, [](std::vector<uint8_t>& d) {
          ByteReader reader(std::span<const uint8_t>(d).subspan(12));
          uint64_t count = 0;
          (void)reader.GetVarU(&count, "vertices");
          (void)reader.GetVarU(&count, "faces");
          d.resize(12 + reader.position() + 4);
        });
      },
      kCorrupt);
  connectivity_vector(
      "draco_vertex_count_varint_6_bytes",
      "the Draco vertex count as a 6-byte varint (redundant 0x80 groups): dmc's header check of "
      "§7.3.1 accepts it, the library's 5-byte limit for a 32-bit varint does not (Appendix D.4)",
      [&](std::vector<uint8_t>& p) {
        with_draco(p, [](std::vector<uint8_t>& d) {
          ByteReader reader(std::span<const uint8_t>(d).subspan(12));
          uint64_t count = 0;
          (void)reader.GetVarU(&count, "vertices");
          const size_t length = reader.position();
          std::vector<uint8_t> padded;
          uint64_t value = count;
          for (int byte = 0; byte < 6; ++byte) {
            padded.push_back(static_cast<uint8_t>((value & 0x7F) | (byte < 5 ? 0x80 : 0)));
            value >>= 7;
          }
          d.erase(d.begin() + 12, d.begin() + 12 + static_cast<std::ptrdiff_t>(length));
          d.insert(d.begin() + 12, padded.begin(), padded.end());
        });
      },
      kCorrupt);
  const auto set_label_model = [](std::vector<uint8_t>& p, uint8_t model) {
    p[SplitDracoPayload(p).value().rest_start()] = model;
  };
  connectivity_vector(
      "label_model_unknown", "vertex label model byte 16 (1.1 defines 0-15)",
      [&](std::vector<uint8_t>& p) { set_label_model(p, connectivity::kLabelModelCount11); },
      kCorrupt);
  {
    // A label kernel (model byte 4: kernel radius 16) in a stream that says it is format 1.0
    // (checksums seeded accordingly), which has no kernels; the connectivity is checked before
    // any segment's 1.1 syntax.
    const std::vector<uint8_t> bad = Edited(ddl, [&](Framed& f) {
      f.preamble[5] = 0;
      set_label_model(f.chunks[kConnectivityChunk].payload, connectivity::kLabelModelCount);
    });
    add("label_kernel_in_format_1_0", "vertex label model byte 4 (a label kernel) in a 1.0 stream",
        ddl, bad, kCorrupt, kCorrupt);
  }
  connectivity_vector(
      "labels_truncated", "vertex labels cut to 5 bytes",
      [&](std::vector<uint8_t>& p) { p.resize(SplitDracoPayload(p).value().rest_start() + 1 + 5); },
      kTruncated);

  // --- Segment header.
  auto segment_vector = [&](std::string name, std::string description,
                            const std::function<void(format::SegmentHeader&)>& edit,
                            ErrorCode error, const Base& base) {
    const std::vector<uint8_t> payload = SegmentHeaderWith(base, edit);
    add(std::move(name), std::move(description), base,
        Edited(base, [&](Framed& f) { f.chunks[kSegmentHeaderChunk].payload = payload; }), error,
        error);
  };
  segment_vector(
      "operator_id_unknown", "operator ID 99", [](format::SegmentHeader& g) { g.operator_id = 99; },
      kUnsupported, ddl);
  segment_vector(
      "operator_id_zero", "operator ID 0 (reserved)",
      [](format::SegmentHeader& g) { g.operator_id = 0; }, kUnsupported, ddl);
  {
    // A frozen operator ID (a registry operator) that streams of this version may not name: the
    // first one the reference decoder refuses, so the vector follows the codec operator set.
    for (const WireName<OperatorId>& row : kOperatorIdNames) {
      const auto id = static_cast<uint8_t>(row.value);
      if (row.value == OperatorId::kInvalid) continue;
      const std::vector<uint8_t> payload =
          SegmentHeaderWith(ddl, [&](format::SegmentHeader& g) { g.operator_id = id; });
      std::vector<uint8_t> stream =
          Edited(ddl, [&](Framed& f) { f.chunks[kSegmentHeaderChunk].payload = payload; });
      const StatusOr<StreamInfo> info = ReadStreamInfo(stream);
      if (info.ok() || info.status().code() != kUnsupported) continue;
      add("operator_id_not_codec",
          "operator ID " + std::to_string(id) + " (" + std::string(row.name) +
              "): a frozen registry ID that format " + VersionText() + " streams may not name",
          ddl, std::move(stream), kUnsupported, kUnsupported);
      break;
    }
  }
  segment_vector(
      "segment_first_frame_wrong", "first segment starts at frame 1",
      [](format::SegmentHeader& g) { g.first_frame = 1; }, kCorrupt, ddl);
  segment_vector(
      "segment_frame_count_zero", "segment of 0 frames",
      [](format::SegmentHeader& g) { g.frame_count = 0; }, kCorrupt, ddl);
  segment_vector(
      "segment_frames_beyond_sequence", "segment longer than the sequence",
      [&](format::SegmentHeader& g) { g.frame_count = h.frame_count + 1; }, kCorrupt, ddl);
  segment_vector(
      "rank_above_3f", "rank 3F + 1",
      [&](format::SegmentHeader& g) { g.rank = 3 * g.frame_count + 1; }, kCorrupt, ddl);
  segment_vector(
      "basis_bits_17", "17 basis bits", [](format::SegmentHeader& g) { g.basis_bits = 17; },
      kCorrupt, ddl);
  segment_vector(
      "basis_bits_1", "1 basis bit", [](format::SegmentHeader& g) { g.basis_bits = 1; }, kCorrupt,
      ddl);
  segment_vector(
      "weight_bits_21", "21 weight bits", [](format::SegmentHeader& g) { g.weight_bits = 21; },
      kCorrupt, ddl);
  segment_vector(
      "weight_prediction_unknown", "weight prediction mode 2",
      [](format::SegmentHeader& g) { g.weight_prediction = 2; }, kCorrupt, ddl);
  segment_vector(
      "anchor_count_zero", "no anchors", [](format::SegmentHeader& g) { g.anchor_count = 0; },
      kCorrupt, ddl);
  segment_vector(
      "anchor_count_above_vertices", "more anchors than vertices",
      [&](format::SegmentHeader& g) { g.anchor_count = h.vertex_count + 1; }, kCorrupt, ddl);
  segment_vector(
      "residual_step_nan", "residual step NaN",
      [](format::SegmentHeader& g) { g.residual_step = std::nan(""); }, kCorrupt, ddl);
  segment_vector(
      "mean_step_negative", "mean step -1", [](format::SegmentHeader& g) { g.mean_step = -1.0; },
      kCorrupt, ddl);
  segment_vector(
      "anchor_step_zero", "anchor step 0", [](format::SegmentHeader& g) { g.anchor_step = 0.0; },
      kCorrupt, ddl);
  segment_vector(
      "step_above_2pow64", "residual step 2^65 (steps are at most 2^64)",
      [](format::SegmentHeader& g) { g.residual_step = 0x1p65; }, kCorrupt, ddl);
  segment_vector(
      "anchor_weight_below_2pow-32", "anchor weight 2^-33",
      [](format::SegmentHeader& g) { g.anchor_weight = 0x1p-33; }, kCorrupt, ddl);
  segment_vector(
      "anchor_weight_above_2pow32", "anchor weight 2^33",
      [](format::SegmentHeader& g) { g.anchor_weight = 0x1p33; }, kCorrupt, ddl);
  segment_vector(
      "anchor_weight_infinite", "anchor weight +inf",
      [](format::SegmentHeader& g) { g.anchor_weight = HUGE_VAL; }, kCorrupt, ddl);
  {
    std::vector<uint8_t> payload = syntax::WriteSegmentHeader(ddl.parsed.segments[0].header);
    payload.push_back(0);
    add("segment_header_trailing_byte", "segment header payload one byte too long", ddl,
        Edited(ddl, [&](Framed& f) { f.chunks[kSegmentHeaderChunk].payload = payload; }), kCorrupt,
        kCorrupt);
  }

  // --- Range-coded payloads (the container is intact: ReadStreamInfo succeeds).
  // info_error: a payload too short to start decoding fails the structure parse too (§8.7).
  auto payload_vector = [&](std::string name, std::string description, const Base& base,
                            size_t chunk, std::vector<uint8_t> payload, ErrorCode error,
                            ErrorCode info_error = ErrorCode::kOk) {
    add(std::move(name), std::move(description), base,
        Edited(base, [&](Framed& f) { f.chunks[chunk].payload = payload; }), error, info_error);
  };
  payload_vector("mean_payload_short", "mean payload of 2 bytes (a range-coded payload has >= 5)",
                 ddl, kMeanChunk, {0, 0}, kTruncated, kTruncated);
  {
    std::vector<uint8_t> payload = ddl.parsed.framed.chunks[kResidualsChunk].payload;
    payload[0] = 0x80;
    payload_vector("range_first_byte_nonzero", "residual payload starts with 0x80", ddl,
                   kResidualsChunk, payload, kCorrupt);
    payload.assign(ddl.parsed.framed.chunks[kResidualsChunk].payload.begin(),
                   ddl.parsed.framed.chunks[kResidualsChunk].payload.begin() + 6);
    payload_vector("residuals_truncated", "residual payload cut to its first 6 bytes", ddl,
                   kResidualsChunk, payload, kTruncated);
  }
  {
    RangeEncoder encoder;
    format::MeanContexts contexts;
    encoder.EncodeSigned(contexts.first, (int64_t{1} << 52) + 1);
    payload_vector("mean_value_out_of_range", "first mean sample 2^52 + 1 steps", ddl, kMeanChunk,
                   encoder.Finish(), kCorrupt);
  }
  {
    // An exp-Golomb prefix of 63 one-bits: longer than any 64-bit value needs.
    RangeEncoder encoder;
    IntegerContexts contexts;
    encoder.EncodeBit(contexts.zero, 0);
    encoder.EncodeBit(contexts.sign, 0);
    for (int i = 0; i < IntegerContexts::kUnaryLength; ++i)
      encoder.EncodeBit(contexts.greater[i], 1);
    for (int k = 0; k < 63; ++k) {
      encoder.EncodeBit(contexts.escape[std::min(k, IntegerContexts::kEscapeContexts - 1)], 1);
    }
    for (int k = 0; k < 64; ++k) encoder.EncodeBypass(0);
    payload_vector("escape_code_too_long", "mean value with a 63-bit exp-Golomb prefix", ddl,
                   kMeanChunk, encoder.Finish(), kCorrupt);
  }
  {
    // 1.1 basis syntax (§8.3.2): first column at the header's depth, predictor mode 0, then its
    // first sample one level beyond that depth's range.
    const int depth = static_cast<int>(ddl.parsed.segments[0].header.basis_bits);
    const int levels = (1 << (depth - 1)) - 1;
    const int g = format::BasisContextGroup(0, depth);
    RangeEncoder encoder;
    auto contexts = std::make_unique<format::BasisContexts>();
    encoder.EncodeSigned(contexts->depth, 0);
    encoder.EncodeBit(contexts->predictor_high[g], 0);
    encoder.EncodeBit(contexts->predictor_low[g][0], 0);
    encoder.EncodeSigned(contexts->first[g], levels + 1);
    payload_vector("basis_sample_out_of_range", "first basis sample one level beyond the range",
                   ddl, kBasisChunk, encoder.Finish(), kCorrupt);
  }
  {
    RangeEncoder encoder;
    auto contexts = std::make_unique<format::BasisContexts>();
    encoder.EncodeSigned(contexts->depth, 1);
    payload_vector("basis_depth_above_header", "first basis column one bit deeper than basis_bits",
                   ddl, kBasisChunk, encoder.Finish(), kCorrupt);
  }
  {
    const std::vector<format::WeightVisit> schedule =
        format::BuildWeightSchedule(ddl.parsed.topology);
    RangeEncoder encoder;
    format::WeightContexts contexts;
    const int unknown = static_cast<int>(schedule.front().unknown_edges.size());
    encoder.EncodeSigned(contexts.by_unknown[std::min(unknown, 5) - 2], int64_t{1} << 40);
    payload_vector("ddl_weight_out_of_range", "first DDL weight residual 2^40 units", ddl,
                   kOperatorChunk, encoder.Finish(), kCorrupt);
  }
  payload_vector("operator_payload_for_tutte", "Tutte segment with a non-empty operator chunk",
                 tutte, kOperatorChunk, {0, 0, 0, 0, 0}, kCorrupt);
  {
    RangeEncoder encoder;
    auto contexts = std::make_unique<format::ResidualContexts>();
    encoder.EncodeSigned(contexts->sets[0][0], (int64_t{1} << 40) + 1);
    payload_vector("residual_out_of_range", "first residual 2^40 + 1 steps", ddl, kResidualsChunk,
                   encoder.Finish(), kCorrupt);
  }
  {
    std::vector<int64_t> indices;
    std::vector<std::vector<int64_t>> values;
    BaseAnchors(ddl, &indices, &values);
    indices.back() = h.vertex_count;  // one past the last vertex
    payload_vector("anchor_index_out_of_range", "last anchor index equals the vertex count", ddl,
                   kAnchorsChunk, AnchorPayload(indices, values), kCorrupt);
  }
  for (const int64_t exponent : {int64_t{17}, int64_t{-17}}) {
    std::vector<int64_t> indices;
    std::vector<std::vector<int64_t>> values;
    BaseAnchors(ddl, &indices, &values);
    payload_vector(exponent > 0 ? "anchor_step_exponent_above_16" : "anchor_step_exponent_below_16",
                   "first anchor's step exponent " + std::to_string(exponent) + " (1.2, §8.5)", ddl,
                   kAnchorsChunk, AnchorPayload(indices, values, {exponent}), kCorrupt);
  }
  {
    // Keep only the anchors of the first anchor's component: the other components of the walker
    // have none, so the normal matrix is singular there.
    std::vector<int64_t> indices, kept;
    std::vector<std::vector<int64_t>> values, kept_values;
    BaseAnchors(walker, &indices, &values);
    const std::vector<int32_t>& component = walker.parsed.topology.component_of_vertex;
    for (size_t a = 0; a < indices.size(); ++a) {
      if (component[indices[a]] == component[indices[0]]) {
        kept.push_back(indices[a]);
        kept_values.push_back(values[a]);
      }
    }
    const std::vector<uint8_t> header = SegmentHeaderWith(walker, [&](format::SegmentHeader& g) {
      g.anchor_count = static_cast<uint32_t>(kept.size());
    });
    const std::vector<uint8_t> anchors = AnchorPayload(kept, kept_values);
    add("component_without_anchor",
        "six-component mesh whose anchors all lie in one component: singular normal matrix", walker,
        Edited(walker,
               [&](Framed& f) {
                 f.chunks[kSegmentHeaderChunk].payload = header;
                 f.chunks[kAnchorsChunk].payload = anchors;
               }),
        ErrorCode::kNumericalFailure, kOk);
  }

  // --- Reference frame of a geometric operator (f64 step, then range-coded positions).
  {
    const std::vector<uint8_t>& reference = cotan.parsed.framed.chunks[kOperatorChunk].payload;
    auto with_step = [&](double step) {
      ByteWriter w;
      w.PutF64(step);
      std::vector<uint8_t> payload = w.Take();
      payload.insert(payload.end(), reference.begin() + 8, reference.end());
      return payload;
    };
    payload_vector("reference_step_nan", "reference frame step NaN", cotan, kOperatorChunk,
                   with_step(std::nan("")), kCorrupt);
    payload_vector("reference_step_zero", "reference frame step 0", cotan, kOperatorChunk,
                   with_step(0.0), kCorrupt);
    payload_vector("reference_payload_short", "operator payload of 5 bytes: no room for the step",
                   cotan, kOperatorChunk, {0, 0, 0, 0, 0}, kTruncated, kTruncated);
    payload_vector("reference_frame_truncated", "reference frame cut to the step and 6 coded bytes",
                   cotan, kOperatorChunk, {reference.begin(), reference.begin() + 14}, kTruncated);
    RangeEncoder encoder;
    auto contexts = std::make_unique<format::ReferenceFrameContexts>();
    encoder.EncodeSigned(contexts->without_neighbours[0], (int64_t{1} << 40) + 1);
    ByteWriter w;
    w.PutF64(1.0);
    std::vector<uint8_t> payload = w.Take();
    const std::vector<uint8_t> coded = encoder.Finish();
    payload.insert(payload.end(), coded.begin(), coded.end());
    payload_vector("reference_coordinate_out_of_range",
                   "first reference coordinate 2^40 + 1 steps from its prediction", cotan,
                   kOperatorChunk, payload, kCorrupt);
  }

  // --- Declared sizes the payloads cannot hold (§8.7): a few hundred bytes declaring 2^26 vertices
  // (indexed connectivity: all but the grid's vertices are isolated, which is legal). Each is
  // refused from the headers and the payload sizes alone, before anything grows with V.
  auto bomb = [&](std::string name, std::string description, uint64_t frames,
                  const std::function<void(format::SegmentHeader&)>& edit_header,
                  const std::function<void(Framed&)>& edit_payloads) {
    const format::SequenceHeader& g = indexed.parsed.header;
    format::SegmentHeader header = indexed.parsed.segments[0].header;
    header.frame_count = static_cast<uint32_t>(frames);
    edit_header(header);
    add(std::move(name), std::move(description), indexed,
        Edited(indexed,
               [&](Framed& f) {
                 f.chunks[kSequenceHeaderChunk].payload = RawSequenceHeader(
                     uint64_t{1} << 26, g.triangle_count, frames, 1, g.frame_rate, g.flags, g.name);
                 f.chunks[kSegmentHeaderChunk].payload = syntax::WriteSegmentHeader(header);
                 edit_payloads(f);
               }),
        kCorrupt, kCorrupt);
  };
  bomb(
      "residuals_cannot_hold_declared_vertices",
      "2^26 vertices, 21 frames, rank 63, DDL: the residual payload cannot code 2^26 x 63 values",
      21, [](format::SegmentHeader& g) { g.rank = 63; }, [](Framed&) {});
  bomb(
      "residuals_cannot_hold_declared_vertices_tutte",
      "2^26 vertices, rank 3, Tutte: the residual payload cannot code 2^26 x 3 values", 3,
      [](format::SegmentHeader& g) {
        g.rank = 3;
        g.operator_id = static_cast<uint8_t>(OperatorId::kTutte);
      },
      [](Framed& f) { f.chunks[kOperatorChunk].payload.clear(); });
  bomb(
      "reference_frame_cannot_hold_declared_vertices",
      "2^26 vertices, cotan: the operator payload cannot code a reference frame of 3 x 2^26 values",
      3,
      [](format::SegmentHeader& g) {
        g.rank = 3;
        g.operator_id = static_cast<uint8_t>(OperatorId::kCotan);
      },
      [](Framed& f) {
        ByteWriter w;
        w.PutF64(1.0);
        std::vector<uint8_t> payload = w.Take();
        payload.insert(payload.end(), {0, 0, 0, 0, 0, 0, 0, 0});
        f.chunks[kOperatorChunk].payload = payload;
      });
  bomb(
      "anchors_cannot_hold_declared_count",
      "2^25 anchors at rank 63: the anchor payload cannot code 2^25 x 64 values", 21,
      [](format::SegmentHeader& g) {
        g.rank = 63;
        g.anchor_count = uint32_t{1} << 25;
      },
      [](Framed&) {});
  return out;
}

Status GenerateInvalid(const InvalidVector& vector, const fs::path& directory) {
  const StatusOr<MeshSequence> decoded = Decode(vector.stream, kNoCallerLimit);
  const ErrorCode got = decoded.ok() ? ErrorCode::kOk : decoded.status().code();
  const StatusOr<StreamInfo> info = ReadStreamInfo(vector.stream);
  const ErrorCode got_info = info.ok() ? ErrorCode::kOk : info.status().code();
  if (got != vector.error || got_info != vector.info_error) {
    return InternalError(vector.name + ": meant to give " +
                         std::string(ErrorCodeName(vector.error)) + " / " +
                         std::string(ErrorCodeName(vector.info_error)) + ", the decoder gives " +
                         (decoded.ok() ? "ok" : decoded.status().ToString()) + " / " +
                         (info.ok() ? "ok" : info.status().ToString()));
  }
  const Json manifest = {{"kind", "invalid"},
                         {"format_version", VersionText()},
                         {"generated", true},
                         {"description", vector.description},
                         {"derived_from", vector.derived_from},
                         {"stream", vector.name + ".dmc"},
                         {"error", ErrorCodeName(vector.error)},
                         {"stream_info_error", ErrorCodeName(vector.info_error)},
                         {"reference_message", decoded.ok() ? "" : decoded.status().message()}};
  DMC_RETURN_IF_ERROR(WriteBytes(directory / (vector.name + ".dmc"), vector.stream));
  DMC_RETURN_IF_ERROR(WriteJson(directory / (vector.name + ".json"), manifest));
  return Status::Ok();
}

int Run(const fs::path& out, bool check) {
  const fs::path valid_dir = out / "valid", invalid_dir = out / "invalid";
  std::error_code error;
  fs::create_directories(valid_dir, error);
  fs::create_directories(invalid_dir, error);
  if (error) {
    std::fprintf(stderr, "cannot create %s: %s\n", out.string().c_str(), error.message().c_str());
    return 1;
  }
  int failures = 0;
  auto report = [&](const Status& status) {
    if (!status.ok()) {
      std::fprintf(stderr, "error: %s\n", status.ToString().c_str());
      ++failures;
    }
  };
  const std::vector<ValidVector> valid = ValidVectors();
  // Generated valid vectors of this version that the list no longer holds are removed (older
  // versions were renamed by KeepOlderVersion and stay; hand-added vectors are not marked).
  for (const fs::path& manifest : FindManifests(valid_dir)) {
    const StatusOr<std::vector<uint8_t>> bytes = ReadBytes(manifest);
    if (!bytes.ok()) continue;
    const Json json = Json::parse(bytes->begin(), bytes->end(), nullptr, false);
    if (json.is_discarded() || !json.is_object() || !json.value("generated", false) ||
        json.value("format_version", std::string()) != VersionText()) {
      continue;
    }
    const std::string name = manifest.stem().string();
    if (std::any_of(valid.begin(), valid.end(),
                    [&](const ValidVector& v) { return v.name == name; })) {
      continue;
    }
    fs::remove(manifest.parent_path() / json.value("stream", std::string()), error);
    fs::remove(manifest.parent_path() / (name + ".ref.zst"), error);
    fs::remove(manifest, error);
    std::printf("removed %s (no longer generated)\n", name.c_str());
  }
  for (const ValidVector& vector : valid) report(GenerateValid(vector, valid_dir));

  StatusOr<Base> ddl = MakeBase("base_ddl", Synth("twist", 100, 3), Options("ddl"));
  StatusOr<Base> tutte = MakeBase("base_tutte", Synth("cloth", 100, 3), Options("tutte"));
  StatusOr<Base> walker = MakeBase("base_walker", Synth("walker", 100, 3), Options("ddl"));
  StatusOr<Base> cotan = MakeBase("base_cotan", Synth("twist", 100, 3), Options("cotan"));
  // Indexed connectivity allows vertices no triangle uses: the base of the declared-size bombs.
  StatusOr<Base> indexed = MakeBase("base_indexed", GridWithIsolatedVertex(4, 3), Options("ddl"));
  for (const auto* base : {&ddl, &tutte, &walker, &cotan, &indexed}) {
    if (!base->ok()) {
      report(base->status());
      return 1;
    }
  }
  // The generated invalid vectors are rewritten as a set: remove the old generated ones first so
  // a renamed or retired case does not linger. Hand-added ones (fuzz crashers) have no
  // "generated" mark and stay.
  for (const fs::path& manifest : FindManifests(invalid_dir)) {
    const StatusOr<std::vector<uint8_t>> bytes = ReadBytes(manifest);
    if (!bytes.ok()) continue;
    const Json json = Json::parse(bytes->begin(), bytes->end(), nullptr, false);
    if (json.is_discarded() || !json.is_object() || !json.value("generated", false)) continue;
    fs::remove(manifest.parent_path() / json.value("stream", std::string()), error);
    fs::remove(manifest, error);
  }
  const std::vector<InvalidVector> invalid =
      InvalidVectors(*ddl, *tutte, *walker, *cotan, *indexed);
  for (const InvalidVector& vector : invalid) report(GenerateInvalid(vector, invalid_dir));
  std::printf("invalid %zu vectors from bases of %zu, %zu, %zu and %zu bytes\n", invalid.size(),
              ddl->stream.size(), tutte->stream.size(), walker->stream.size(),
              cotan->stream.size());

  if (check) {
    for (const fs::path& manifest : FindManifests(out)) {
      const VectorResult result = CheckVector(manifest, CheckOptions{});
      if (!result.passed) {
        std::fprintf(stderr, "check failed: %s: %s\n", result.name.c_str(), result.detail.c_str());
        ++failures;
      }
    }
  }
  if (failures > 0) std::fprintf(stderr, "%d failure(s)\n", failures);
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace dmc::conformance

int main(int argc, char** argv) {
  std::filesystem::path out;
  bool check = false;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (argument == "--check") {
      check = true;
    } else {
      std::fprintf(stderr, "usage: dmc_conformance_generate --out DIR [--check]\n");
      return 2;
    }
  }
  if (out.empty()) {
    std::fprintf(stderr, "usage: dmc_conformance_generate --out DIR [--check]\n");
    return 2;
  }
  return dmc::conformance::Run(out, check);
}
