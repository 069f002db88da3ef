// The WebAssembly decoder's C interface (web/dmc.js wraps it): open a stream, read its
// description, decode segment by segment. Every call that can fail returns 0/null and leaves the
// spec's error code (bitstream-spec/dmc-format.md §11) and a message for dmc_last_error_*.
#include <emscripten/emscripten.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dmc/decoder.h"
#include "dmc/status.h"

namespace {

struct LastError {
  std::string code = "ok";
  std::string message;
} last_error;

void SetError(const dmc::Status& status) {
  last_error.code = std::string(dmc::ErrorCodeName(status.code()));
  last_error.message = status.message();
}

// A JSON string literal: quotes, backslashes and control characters escaped (names are UTF-8, as
// the spec requires; JSON carries UTF-8 as is).
std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

struct Handle {
  std::vector<uint8_t> bytes;  // the decoder reads the stream in place
  dmc::Decoder decoder;
  std::string info_json;
  std::vector<float> positions;  // the last decoded segment
};

}  // namespace

extern "C" {

EMSCRIPTEN_KEEPALIVE const char* dmc_last_error_code() { return last_error.code.c_str(); }
EMSCRIPTEN_KEEPALIVE const char* dmc_last_error_message() { return last_error.message.c_str(); }

// Copies `size` bytes from `bytes`; null on a stream the decoder refuses. The limits are
// DecoderOptions' (0: none; negative: the native default, 4 GiB each).
EMSCRIPTEN_KEEPALIVE Handle* dmc_open(const uint8_t* bytes, size_t size, double max_output_bytes,
                                      double max_matrix_bytes) {
  auto handle = std::make_unique<Handle>();
  handle->bytes.assign(bytes, bytes + size);
  dmc::DecoderOptions options;
  if (max_output_bytes >= 0) options.max_output_bytes = static_cast<uint64_t>(max_output_bytes);
  if (max_matrix_bytes >= 0) options.max_matrix_bytes = static_cast<uint64_t>(max_matrix_bytes);
  const dmc::Status opened = handle->decoder.Open(handle->bytes, options);
  if (!opened.ok()) {
    SetError(opened);
    return nullptr;
  }
  const dmc::StreamInfo& info = handle->decoder.info();
  std::string segments;
  for (const dmc::SegmentInfo& segment : info.segments) {
    segments += std::string(segments.empty() ? "" : ",") +
                "{\"firstFrame\":" + std::to_string(segment.first_frame) +
                ",\"frameCount\":" + std::to_string(segment.frame_count) +
                ",\"rank\":" + std::to_string(segment.rank) +
                ",\"operator\":" + JsonString(segment.operator_name) + "}";
  }
  char rate[32];
  std::snprintf(rate, sizeof(rate), "%.17g", info.frame_rate);
  handle->info_json =
      "{\"version\":\"" + std::to_string(info.version_major) + "." +
      std::to_string(info.version_minor) +
      "\",\"vertexCount\":" + std::to_string(info.vertex_count) +
      ",\"triangleCount\":" + std::to_string(info.triangle_count) +
      ",\"frameCount\":" + std::to_string(info.frame_count) + ",\"frameRate\":" + rate +
      ",\"name\":" + JsonString(info.name) + ",\"bytes\":" + std::to_string(info.total_bytes) +
      ",\"sceneBytes\":" + std::to_string(info.scene_size) + ",\"segments\":[" + segments + "]}";
  last_error = {};
  return handle.release();
}

EMSCRIPTEN_KEEPALIVE const char* dmc_info_json(Handle* handle) { return handle->info_json.c_str(); }

// The triangles, three vertex indices each (0-based).
EMSCRIPTEN_KEEPALIVE const int32_t* dmc_triangles(Handle* handle) {
  return handle->decoder.triangles().data();
}

// Decodes segment `index`: its frames' positions (frames × vertices × 3 floats) until the next
// call; null on failure.
EMSCRIPTEN_KEEPALIVE const float* dmc_decode_segment(Handle* handle, int index) {
  if (index < 0 || index >= handle->decoder.segment_count()) {
    SetError(dmc::InvalidArgumentError("no segment " + std::to_string(index)));
    return nullptr;
  }
  const dmc::SegmentInfo& segment = handle->decoder.info().segments[static_cast<size_t>(index)];
  handle->positions.assign(static_cast<size_t>(segment.frame_count) *
                               static_cast<size_t>(handle->decoder.info().vertex_count) * 3,
                           0.0f);
  const dmc::Status decoded = handle->decoder.DecodeSegmentInto(
      index, [&](int) -> dmc::StatusOr<float*> { return handle->positions.data(); });
  if (!decoded.ok()) {
    SetError(decoded);
    return nullptr;
  }
  last_error = {};
  return handle->positions.data();
}

EMSCRIPTEN_KEEPALIVE void dmc_close(Handle* handle) { delete handle; }

}  // extern "C"
