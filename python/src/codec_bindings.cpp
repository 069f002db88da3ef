// dmc.encode, dmc.decode, dmc.info: the codec on NumPy arrays and bytes.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/encoder_options.h"
#include "dmc/io.h"
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

py::dict ReportToDict(const EncodeReport& report, const EncoderOptions& options) {
  py::dict breakdown;
  breakdown["header"] = report.header_bytes;
  breakdown["connectivity"] = report.connectivity_bytes;
  breakdown["mean"] = report.mean_bytes;
  breakdown["basis"] = report.basis_bytes;
  breakdown["operator"] = report.operator_bytes;
  breakdown["anchors"] = report.anchor_bytes;
  breakdown["residuals"] = report.residual_bytes;
  breakdown["scene"] = report.scene_bytes;
  py::dict out;
  out["bpfv"] = report.bpfv;
  out["positions_bpfv"] = report.positions_bpfv;
  out["bytes"] = report.bytes;
  out["frames"] = report.frames;
  out["vertices"] = report.vertices;
  out["seconds"] = report.seconds;
  out["breakdown"] = breakdown;
  out["operator"] = options.operator_name;
  out["effort"] = options.effort;
  out["rank"] = report.rank;
  out["anchors"] = report.anchors;
  out["segments"] = report.segments;
  out["residual_step"] = report.residual_step;
  out["segment_operators"] = report.segment_operators;
  py::list segment_details;
  for (const EncodeReport::Segment& segment : report.segment_details) {
    py::dict entry;
    entry["first_frame"] = segment.first_frame;
    entry["frames"] = segment.frames;
    entry["operator"] = segment.operator_name;
    entry["rank"] = segment.rank;
    entry["anchors"] = segment.anchors;
    entry["residual_step"] = segment.residual_step;
    segment_details.append(entry);
  }
  out["segment_details"] = segment_details;
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

py::dict StreamInfoToDict(const StreamInfo& info, const std::vector<ClipInfo>& clips) {
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
  out["scene_bytes"] = info.scene_bytes;
  out["scene_size"] = info.scene_size;
  py::list clip_list;
  for (const ClipInfo& clip : clips) {
    py::dict entry;
    entry["name"] = clip.name;
    entry["first_frame"] = clip.first_frame;
    entry["frames"] = clip.frame_count;
    entry["start_time"] = clip.start_time;
    clip_list.append(entry);
  }
  out["clips"] = clip_list;
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
  return py::make_tuple(std::move(stream), ReportToDict(report, options));
}

// "    name: help." wrapped at 100 columns, continuation lines indented as the other entries.
std::string DocEntry(std::string_view name, std::string_view help) {
  std::string entry;
  std::string line = "    ";
  line.append(name).append(":");
  std::string_view rest = help;
  while (!rest.empty()) {
    const size_t space = rest.find(' ');
    const std::string_view word = rest.substr(0, space);
    rest = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
    if (line.size() + 1 + word.size() + (rest.empty() ? 1 : 0) > 100) {
      entry.append(line).append("\n");
      line.assign(7, ' ');
    }
    line.append(" ").append(word);
  }
  return entry.append(line).append(".\n");
}

// dmc.encode()'s docstring: the signature and one entry per option, from the option table.
std::string EncodeDoc() {
  const EncoderOptions defaults;
  std::string signature = "encode(frames, faces, *";
  std::string options;
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    const std::string value = std::visit(
        [&](auto field) { return std::string(py::repr(py::cast(defaults.*field))); }, spec.field);
    signature += ", " + std::string(spec.name) + "=" + value;
    options += DocEntry(spec.name, spec.help);
  }
  signature += ", name='', frame_rate=0.0, return_report=False) -> bytes";
  // name and frame_rate also take None (unknown), read_sequence(metadata=True)'s values.
  return signature + R"(

Compresses a mesh sequence to a .dmc stream (trajectory PCA, Laplace operator, high-pass
quantisation, range coding). The bytes are identical to what `dmc encode` writes for the same
sequence and options (the CLI takes `name` from the input's stem and `frame_rate` from the files).
The options are the CLI's flags, '_' written for '-' (ddl_mu=0.05 for --ddl-mu 0.05,
ddl_fallback=False for --no-ddl-fallback).

Args:
    frames: float32 array (F, V, 3), or (V, 3) for one frame; other real dtypes are converted.
    faces: int32 array (T, 3) of 0-based vertex indices.
)" + options +
         R"(    name: sequence name stored in the stream.
    frame_rate: frames per second stored in the stream (0 or None = unknown).
    return_report: also return a dict like `dmc encode --json` prints (bytes, bpfv, breakdown,
        rank, anchors, segments, residual_step, segment_operators, kg, sted, sted_s, sted_t,
        rmse_rel, max_error); kg and the other distortions are None unless measure is True.

Returns:
    bytes, or (bytes, report) when return_report is True.

Raises:
    TypeError: an unknown keyword, or a value of the wrong type.
    dmc.Error: INVALID_ARGUMENT (bad shape, dtype or option; the message names the keyword),
        INVALID_SEQUENCE (index out of range, non-finite coordinate, empty mesh), NOT_FOUND
        (unknown operator), ...
)";
}

// A keyword's value converted as a typed pybind11 argument would be (TypeError otherwise:
// rank="three", rank=2.5).
template <typename T>
T KeywordValue(const std::string& keyword, const py::handle& value) {
  py::detail::make_caster<T> caster;
  if (!caster.load(value, /*convert=*/true)) {
    throw py::type_error("encode(): " + keyword + " must be " +
                         py::detail::make_caster<T>::name.text + ", got " +
                         py::str(py::type::of(value)).cast<std::string>());
  }
  return py::detail::cast_op<T>(std::move(caster));
}

py::list EncoderOptionList() {
  const EncoderOptions defaults;
  py::list list;
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    py::dict row;
    row["name"] = std::string(spec.name);
    std::visit(
        [&](auto field) {
          using T = std::remove_reference_t<decltype(defaults.*field)>;
          row["type"] = std::string(py::detail::make_caster<T>::name.text);
          row["default"] = defaults.*field;
        },
        spec.field);
    row["flag"] = SpellOption(spec.name, OptionSpelling::kCliFlag);
    row["help"] = std::string(spec.help);
    row["shapes_stream"] = spec.shapes_stream;
    list.append(row);
  }
  return list;
}

constexpr const char* kEncoderOptionsDoc = R"(encoder_options() -> list[dict]

The encoder's options, in a fixed order: one dict per option with name (the dmc.encode() keyword
and the key of conformance manifests), type ("int", "float", "bool" or "str"), default, flag (the
`dmc encode` flag; a bool is also --no-<name>), help and shapes_stream (False for options that
cannot change the stream's bytes, such as measure).
)";

py::object EncodeKeywords(const py::handle& frames, const py::handle& faces,
                          const py::kwargs& keywords) {
  EncoderOptions options;
  std::string name;
  double frame_rate = 0.0;
  bool return_report = false;
  std::vector<std::string> given;
  for (const auto& [key, value] : keywords) {
    const std::string keyword = key.cast<std::string>();
    // None for the name and the frame rate means unknown, as read_sequence(metadata=True)
    // returns them for inputs that record none (so its dict can be passed on as it is).
    if (keyword == "name") {
      name = value.is_none() ? std::string() : KeywordValue<std::string>(keyword, value);
    } else if (keyword == "frame_rate") {
      frame_rate = value.is_none() ? 0.0 : KeywordValue<double>(keyword, value);
    } else if (keyword == "return_report") {
      return_report = KeywordValue<bool>(keyword, value);
    } else if (const EncoderOptionSpec* spec = FindEncoderOption(keyword)) {
      std::visit(
          [&](auto field) {
            using T = std::remove_reference_t<decltype(options.*field)>;
            options.*field = KeywordValue<T>(keyword, value);
          },
          spec->field);
      given.push_back(keyword);
    } else {
      throw py::type_error("encode() got an unexpected keyword argument '" + keyword + "'");
    }
  }
  // A switch named True that the effort would not honour is an error, not ignored (the encoder
  // checks the rest).
  if (ValidateOptions(options).ok()) ThrowIfError(CheckGivenSwitches(options, given));
  // Without a report nobody sees the measurement, so it is skipped.
  options.measure = options.measure && return_report;
  return EncodeBinding(frames, faces, options, name, frame_rate, return_report);
}

constexpr const char* kDecodeDoc =
    R"(decode(data, max_output_bytes=4 GiB, max_matrix_bytes=4 GiB) -> (frames, faces)

Decodes a .dmc stream.

Args:
    data: the stream as a bytes-like object (bytes, bytearray, memoryview, uint8 array), or a
        str / os.PathLike path to a .dmc file.
    max_output_bytes: refuse (RESOURCE_LIMIT), before decoding, a stream whose output would
        exceed this many bytes (12 per vertex and frame, 12 per triangle); 0 for no limit but
        the format's 16 GiB.
    max_matrix_bytes: refuse (RESOURCE_LIMIT) a segment whose normal matrix or Cholesky factor
        would exceed this many bytes, before building it (their size follows the connectivity's
        structure: one vertex of degree d puts d² entries in the normal matrix); 0 for no limit.

Returns:
    (frames, faces): float32 array (F, V, 3) and int32 array (T, 3), equal to what `dmc decode`
    writes. The arrays own their memory (no copy was made from the decoder's output).

Raises:
    dmc.Error: CORRUPT_STREAM (checksum mismatch, impossible value), TRUNCATED_STREAM, UNSUPPORTED
        (newer format or unknown method), IO_ERROR (unreadable path), INVALID_ARGUMENT (not
        bytes-like), RESOURCE_LIMIT (output or normal equations above their limit, or memory ran out).
)";

constexpr const char* kInfoDoc = R"(info(data) -> dict

Describes a .dmc stream without decoding it: the container header and every segment's parameters
and sizes, checksums verified. The keys are those of `dmc info --json` (without "input"):
format_version, name, vertices, triangles, frames, frame_rate (None when unknown), reordered,
bytes, bpfv, header_bytes, connectivity_bytes, scene_bytes and scene_size (0 without a scene),
clips (a list of dicts: name, first_frame, frames, start_time; from the scene of a glTF input), and
segments (a list of dicts: first_frame, frames, rank, operator, operator_id, basis_bits,
weight_bits, anchors, residual_step, anchor_step, bytes).

Args:
    data: bytes-like stream, or a str / os.PathLike path to a .dmc file.

Raises:
    dmc.Error: as decode.
)";

}  // namespace

void RegisterCodec(py::module_& module) {
  module.def("encode", &EncodeKeywords, WithTextSignature(EncodeDoc()).c_str(), py::arg("frames"),
             py::arg("faces"));
  module.def("encoder_options", &EncoderOptionList, WithTextSignature(kEncoderOptionsDoc).c_str());

  module.def(
      "decode",
      [](const py::handle& data, uint64_t max_output_bytes, uint64_t max_matrix_bytes) {
        DecoderOptions options;
        options.max_output_bytes = max_output_bytes;
        options.max_matrix_bytes = max_matrix_bytes;
        MeshSequence sequence = WithStream(data, [&](std::span<const uint8_t> bytes) {
          return ValueOrThrow(Decode(bytes, options));
        });
        return SequenceToArrays(std::move(sequence));
      },
      WithTextSignature(
          "decode(data, *, max_output_bytes=" + Repr(DecoderOptions().max_output_bytes) +
          ", max_matrix_bytes=" + Repr(DecoderOptions().max_matrix_bytes) + ") -> (frames, faces)" +
          AfterFirstLine(kDecodeDoc))
          .c_str(),
      py::arg("data"), py::kw_only(),
      py::arg("max_output_bytes") = DecoderOptions().max_output_bytes,
      py::arg("max_matrix_bytes") = DecoderOptions().max_matrix_bytes);

  module.def(
      "info",
      [](const py::handle& data) {
        std::vector<ClipInfo> clips;
        const StreamInfo info = WithStream(data, [&](std::span<const uint8_t> bytes) {
          StreamInfo parsed = ValueOrThrow(ReadStreamInfo(bytes));
          // A scene (format 1.3) lists the input's clips, as dmc info does.
          if (parsed.scene_bytes > 0) {
            const std::vector<uint8_t> scene = ValueOrThrow(DecodeScene(bytes));
            if (auto listed = SceneClips(scene); listed.ok()) clips = std::move(listed).value();
          }
          return parsed;
        });
        return StreamInfoToDict(info, clips);
      },
      WithTextSignature(kInfoDoc).c_str(), py::arg("data"));
}

}  // namespace dmc::python
