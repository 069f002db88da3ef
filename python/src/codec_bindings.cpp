// dmc.encode, dmc.decode, dmc.info: the codec on NumPy arrays and bytes.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "errors.h"

namespace dmc::python {
namespace {

// A read-only, C-contiguous view of a bytes-like object (bytes, bytearray, memoryview, a uint8
// NumPy array, mmap), released on destruction. Holding the view keeps the object alive and, for
// bytearray, unresizable, so the bytes stay valid while the GIL is released.
class ByteView {
 public:
  explicit ByteView(const py::handle& object) {
    if (PyObject_GetBuffer(object.ptr(), &view_, PyBUF_SIMPLE) != 0) {
      PyErr_Clear();
      ThrowInvalidArgument(
          "data must be a bytes-like object (bytes, bytearray, memoryview, contiguous uint8 "
          "array) or a path to a .dmc file, got " +
          py::str(py::type::of(object)).cast<std::string>());
    }
  }
  ByteView(const ByteView&) = delete;
  ByteView& operator=(const ByteView&) = delete;
  ~ByteView() { PyBuffer_Release(&view_); }

  std::span<const uint8_t> bytes() const {
    return {static_cast<const uint8_t*>(view_.buf), static_cast<size_t>(view_.len)};
  }

 private:
  Py_buffer view_{};
};

// str and os.PathLike name a file; everything else must be bytes-like.
bool IsPath(const py::handle& object) {
  return py::isinstance<py::str>(object) ||
         py::isinstance(object, py::module_::import("os").attr("PathLike"));
}

// Runs `work(bytes)` on the stream `data` names (its bytes, or a file's contents) with the GIL
// released.
template <typename Work>
auto WithStream(const py::handle& data, Work work) {
  if (IsPath(data)) {
    const auto path = data.cast<std::filesystem::path>();
    py::gil_scoped_release release;
    const std::vector<uint8_t> bytes = ValueOrThrow(ReadFileBytes(path));
    return work(std::span<const uint8_t>(bytes));
  }
  const ByteView view(data);
  py::gil_scoped_release release;
  return work(view.bytes());
}

py::dict ReportToDict(const EncodeReport& report, const std::string& operator_name) {
  py::dict breakdown;
  breakdown["header"] = report.header_bytes;
  breakdown["connectivity"] = report.connectivity_bytes;
  breakdown["mean"] = report.mean_bytes;
  breakdown["basis"] = report.basis_bytes;
  breakdown["operator"] = report.operator_bytes;
  breakdown["anchors"] = report.anchor_bytes;
  breakdown["residuals"] = report.residual_bytes;
  py::dict out;
  out["bpfv"] = report.bpfv;
  out["bytes"] = report.bytes;
  out["frames"] = report.frames;
  out["vertices"] = report.vertices;
  out["seconds"] = report.seconds;
  out["breakdown"] = breakdown;
  out["operator"] = operator_name;
  out["rank"] = report.rank;
  out["anchors"] = report.anchors;
  out["segments"] = report.segments;
  out["residual_step"] = report.residual_step;
  out["segment_operators"] = report.segment_operators;
  const py::object none = py::none();
  const DistortionReport& d = report.distortion;
  out["kg"] = report.measured ? py::object(py::float_(d.kg)) : none;
  out["sted"] = report.measured ? py::object(py::float_(d.sted)) : none;
  out["sted_s"] = report.measured ? py::object(py::float_(d.sted_s)) : none;
  out["sted_t"] = report.measured ? py::object(py::float_(d.sted_t)) : none;
  out["rmse_rel"] = report.measured ? py::object(py::float_(d.rmse_rel)) : none;
  out["max_error"] = report.measured ? py::object(py::float_(d.max_error)) : none;
  return out;
}

py::dict StreamInfoToDict(const StreamInfo& info) {
  py::list segments;
  for (const SegmentInfo& s : info.segments) {
    py::dict bytes;
    bytes["header"] = s.header_bytes;
    bytes["mean"] = s.mean_bytes;
    bytes["basis"] = s.basis_bytes;
    bytes["operator"] = s.operator_bytes;
    bytes["anchors"] = s.anchor_bytes;
    bytes["residuals"] = s.residual_bytes;
    py::dict segment;
    segment["first_frame"] = s.first_frame;
    segment["frames"] = s.frame_count;
    segment["rank"] = s.rank;
    segment["operator"] = s.operator_name;
    segment["operator_id"] = s.operator_id;
    segment["basis_bits"] = s.basis_bits;
    segment["weight_bits"] = s.weight_bits;
    segment["anchors"] = s.anchor_count;
    segment["residual_step"] = s.residual_step;
    segment["anchor_step"] = s.anchor_step;
    segment["bytes"] = bytes;
    segments.append(segment);
  }
  const double value_count = static_cast<double>(info.frame_count) * info.vertex_count;
  py::dict out;
  out["format_version"] =
      std::to_string(info.version_major) + "." + std::to_string(info.version_minor);
  out["name"] = info.name;
  out["vertices"] = info.vertex_count;
  out["triangles"] = info.triangle_count;
  out["frames"] = info.frame_count;
  out["frame_rate"] = info.frame_rate > 0.0 ? py::object(py::float_(info.frame_rate)) : py::none();
  out["reordered"] = info.reordered;
  out["bytes"] = info.total_bytes;
  out["bpfv"] = value_count > 0.0 ? 8.0 * static_cast<double>(info.total_bytes) / value_count : 0.0;
  out["header_bytes"] = info.header_bytes;
  out["connectivity_bytes"] = info.connectivity_bytes;
  out["segments"] = segments;
  return out;
}

py::object EncodeBinding(const py::handle& frames, const py::handle& faces,
                         const EncoderOptions& options, const std::string& name, double frame_rate,
                         bool return_report) {
  MeshSequence sequence = SequenceFromArrays(frames, faces);
  sequence.name = name;
  sequence.frame_rate = frame_rate;
  EncodeReport report;
  std::vector<uint8_t> bytes;
  {
    py::gil_scoped_release release;
    bytes = ValueOrThrow(Encode(sequence, options, &report));
  }
  py::bytes stream(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (!return_report) return stream;
  return py::make_tuple(std::move(stream), ReportToDict(report, options.operator_name));
}

constexpr const char* kEncodeDoc = R"(encode(frames, faces, *, operator="ddl", ...) -> bytes

Compresses a mesh sequence to a .dmc stream (trajectory PCA, Laplace operator, high-pass
quantisation, range coding). The bytes are identical to what `dmc encode` writes for the same
sequence and options (the CLI takes `name` from the input's stem and `frame_rate` from the files).

Args:
    frames: float32 array (F, V, 3), or (V, 3) for one frame; other real dtypes are converted.
    faces: int32 array (T, 3) of 0-based vertex indices.
    operator: Laplace operator: ddl, tutte, kirchhoff, cotan, cotan-area, cotan-sym, mean-value
        (see dmc.operators()).
    rank: PCA basis vectors per segment; 0 = automatic.
    rank_threshold: automatic rank keeps components with eigenvalue > T * V * step^2.
    basis_bits: basis quantisation bits (2..16).
    residual_bits: residual step = bounding-box diagonal * 2^-bits.
    residual_step: absolute residual step; overrides residual_bits when > 0.
    anchors: anchor vertices per segment; -1 = automatic.
    anchor_step_ratio: anchor quantisation step relative to the residual step.
    segment_frames: maximum frames per segment; 0 = default.
    reference_bits: geometric operators: reference frame step = diagonal * 2^-bits.
    weight_bits: DDL weight step 2^-bits.
    ddl_mu: DDL Tikhonov pull toward Tutte (relative).
    ddl_fallback: with operator ddl, code a segment with kirchhoff, tutte or mean-value instead
        when that has the lower rate at equal STED (report["segment_operators"] names each
        segment's choice); False = always the fitted DDL weights.
    rank_search: with operator ddl, its fallback and an automatic rank, also code each segment
        at the lower ranks of 2 and 4 times rank_threshold and keep the one with the lowest
        bits * STED^0.8; False = the rank of rank_threshold alone.
    uniform_weight_prediction: predict DDL weights by the uniform share instead of the degree
        reference.
    target_bpfv: > 0: search the residual step for this rate (bits per frame and vertex).
    target_sted: > 0: search the residual step for this STED.
    allow_reorder: let the stream use the codec's own vertex order (smaller connectivity).
    name: sequence name stored in the stream.
    frame_rate: frames per second stored in the stream (0 = unknown).
    return_report: also return a dict like `dmc encode --json` prints (bytes, bpfv, breakdown,
        rank, anchors, segments, residual_step, segment_operators, kg, sted, sted_s, sted_t,
        rmse_rel, max_error).
    measure: with return_report, decode the stream and measure KG/STED (else those are None).

Returns:
    bytes, or (bytes, report) when return_report is True.

Raises:
    dmc.Error: INVALID_ARGUMENT (bad shape, dtype or option), INVALID_SEQUENCE (index out of range,
        non-finite coordinate, empty mesh), NOT_FOUND (unknown operator), ...
)";

constexpr const char* kDecodeDoc = R"(decode(data) -> (frames, faces)

Decodes a .dmc stream.

Args:
    data: the stream as a bytes-like object (bytes, bytearray, memoryview, uint8 array), or a
        str / os.PathLike path to a .dmc file.

Returns:
    (frames, faces): float32 array (F, V, 3) and int32 array (T, 3), equal to what `dmc decode`
    writes. The arrays own their memory (no copy was made from the decoder's output).

Raises:
    dmc.Error: CORRUPT_STREAM (checksum mismatch, impossible value), TRUNCATED_STREAM, UNSUPPORTED
        (newer format or unknown method), IO_ERROR (unreadable path), INVALID_ARGUMENT (not
        bytes-like).
)";

constexpr const char* kInfoDoc = R"(info(data) -> dict

Describes a .dmc stream without decoding it: the container header and every segment's parameters
and sizes, checksums verified. The keys are those of `dmc info --json` (without "input"):
format_version, name, vertices, triangles, frames, frame_rate (None when unknown), reordered,
bytes, bpfv, header_bytes, connectivity_bytes, and segments (a list of dicts: first_frame, frames,
rank, operator, operator_id, basis_bits, weight_bits, anchors, residual_step, anchor_step, bytes).

Args:
    data: bytes-like stream, or a str / os.PathLike path to a .dmc file.

Raises:
    dmc.Error: as decode.
)";

}  // namespace

void RegisterCodec(py::module_& module) {
  const EncoderOptions defaults;
  module.def(
      "encode",
      [](const py::handle& frames, const py::handle& faces, const std::string& operator_name,
         int rank, double rank_threshold, int basis_bits, int residual_bits, double residual_step,
         int anchors, double anchor_step_ratio, int segment_frames, int reference_bits,
         int weight_bits, double ddl_mu, bool ddl_fallback, bool rank_search,
         bool uniform_weight_prediction, double target_bpfv, double target_sted, bool allow_reorder,
         const std::string& name, double frame_rate, bool return_report, bool measure) {
        EncoderOptions options;
        options.operator_name = operator_name;
        options.rank = rank;
        options.rank_threshold = rank_threshold;
        options.basis_bits = basis_bits;
        options.residual_bits = residual_bits;
        options.residual_step = residual_step;
        options.anchors = anchors;
        options.anchor_step_ratio = anchor_step_ratio;
        options.segment_frames = segment_frames;
        options.reference_bits = reference_bits;
        options.weight_bits = weight_bits;
        options.ddl_regularization = ddl_mu;
        options.ddl_fallback = ddl_fallback;
        options.rank_search = rank_search;
        options.weight_prediction_uniform = uniform_weight_prediction;
        options.target_bpfv = target_bpfv;
        options.target_sted = target_sted;
        options.allow_reorder = allow_reorder;
        options.measure = return_report && measure;
        return EncodeBinding(frames, faces, options, name, frame_rate, return_report);
      },
      kEncodeDoc, py::arg("frames"), py::arg("faces"), py::kw_only(),
      py::arg("operator") = defaults.operator_name, py::arg("rank") = defaults.rank,
      py::arg("rank_threshold") = defaults.rank_threshold,
      py::arg("basis_bits") = defaults.basis_bits,
      py::arg("residual_bits") = defaults.residual_bits,
      py::arg("residual_step") = defaults.residual_step, py::arg("anchors") = defaults.anchors,
      py::arg("anchor_step_ratio") = defaults.anchor_step_ratio,
      py::arg("segment_frames") = defaults.segment_frames,
      py::arg("reference_bits") = defaults.reference_bits,
      py::arg("weight_bits") = defaults.weight_bits,
      py::arg("ddl_mu") = defaults.ddl_regularization,
      py::arg("ddl_fallback") = defaults.ddl_fallback,
      py::arg("rank_search") = defaults.rank_search,
      py::arg("uniform_weight_prediction") = defaults.weight_prediction_uniform,
      py::arg("target_bpfv") = defaults.target_bpfv, py::arg("target_sted") = defaults.target_sted,
      py::arg("allow_reorder") = defaults.allow_reorder, py::arg("name") = "",
      py::arg("frame_rate") = 0.0, py::arg("return_report") = false, py::arg("measure") = true);

  module.def(
      "decode",
      [](const py::handle& data) {
        MeshSequence sequence = WithStream(
            data, [](std::span<const uint8_t> bytes) { return ValueOrThrow(Decode(bytes)); });
        return SequenceToArrays(std::move(sequence));
      },
      kDecodeDoc, py::arg("data"));

  module.def(
      "info",
      [](const py::handle& data) {
        const StreamInfo info = WithStream(data, [](std::span<const uint8_t> bytes) {
          return ValueOrThrow(ReadStreamInfo(bytes));
        });
        return StreamInfoToDict(info);
      },
      kInfoDoc, py::arg("data"));
}

}  // namespace dmc::python
