// glTF import: the file loaded by tinygltf, then posed into a MeshSequence frame by frame, with
// optional seam welding. The maths is summarised in gltf_format.h, the steps in
// gltf_import_internal.h.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numeric>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal {

StatusOr<GlbJsonChunk> CheckGlbContainer(std::string_view glb) {
  auto u32 = [&](size_t offset) {
    uint32_t value = 0;
    std::memcpy(&value, glb.data() + offset, 4);
    return value;
  };
  if (glb.size() < 12 || u32(0) != 0x46546C67u) {
    return ParseError("not a GLB file (it does not start with the glTF magic)");
  }
  if (u32(4) == 1) return UnsupportedError("a glTF 1.0 binary file (dmc reads glTF 2.0)");
  if (u32(4) != 2) return ParseError("GLB container version " + std::to_string(u32(4)));
  if (u32(8) != glb.size()) {
    return ParseError("the GLB header declares " + std::to_string(u32(8)) +
                      " bytes, the file has " + std::to_string(glb.size()) + " (truncated?)");
  }
  GlbJsonChunk json;
  for (size_t offset = 12, chunk = 0; offset < glb.size(); ++chunk) {
    if (glb.size() - offset < 8)
      return ParseError("GLB chunk " + std::to_string(chunk) + " is cut");
    const size_t length = u32(offset);
    if (length > glb.size() - offset - 8) {
      return ParseError("GLB chunk " + std::to_string(chunk) + " declares " +
                        std::to_string(length) + " bytes, " +
                        std::to_string(glb.size() - offset - 8) + " remain (truncated?)");
    }
    if (chunk == 0) {
      if (u32(offset + 4) != 0x4E4F534Au) return ParseError("the first GLB chunk is not JSON");
      json = {offset + 8, length};
    }
    offset += 8 + length;
  }
  if (json.offset == 0) return ParseError("the GLB holds no JSON chunk");
  return json;
}

std::string ReplaceGlbJson(std::string_view glb, const GlbJsonChunk& chunk, std::string json) {
  while (json.size() % 4 != 0) json.push_back(' ');
  std::string out(glb.substr(0, 12));
  auto put = [&](uint32_t value) { out.append(reinterpret_cast<const char*>(&value), 4); };
  put(static_cast<uint32_t>(json.size()));
  put(0x4E4F534Au);
  out += json;
  out.append(glb.substr(chunk.offset + chunk.length));
  const uint32_t total = static_cast<uint32_t>(out.size());
  std::memcpy(out.data() + 8, &total, 4);
  return out;
}

namespace {

using gltf::Channel;
using gltf::Member;

constexpr double kDefaultFrameRate = 30.0;

// Frames a glTF import may pose, over all its clips.
constexpr int kMaxGltfFrames = 10'000'000;

// The sequence of a dmc "frames" export (see gltf_export.cpp): mesh f holds frame f, all sharing
// one index accessor, under a root node whose transform dequantises compact exports. Posing the
// file instead would give every frame mesh at once.
StatusOr<GltfImport> ReadFramesExport(const tinygltf::Model& model, const GltfReadOptions& options,
                                      int max_frames) {
  const gltf::Matrix4 root =
      model.nodes.empty() ? gltf::Matrix4::Identity() : gltf::StaticPose(model.nodes[0]).Local();
  int frame_count = static_cast<int>(model.meshes.size());
  if (max_frames > 0) frame_count = std::min(frame_count, max_frames);
  GltfImport result;
  for (int f = 0; f < frame_count; ++f) {
    const auto& primitives = model.meshes[static_cast<size_t>(f)].primitives;
    const std::string label = "frame mesh " + std::to_string(f);
    if (primitives.size() != 1 || !primitives[0].attributes.count("POSITION")) {
      return ParseError(label + ": expected one primitive with POSITION");
    }
    DMC_ASSIGN_OR_RETURN(
        const std::vector<double> positions,
        gltf::ReadAccessor(model, primitives[0].attributes.at("POSITION"), label + " POSITION"));
    if (f == 0) {
      DMC_ASSIGN_OR_RETURN(const std::vector<double> indices,
                           gltf::ReadAccessor(model, primitives[0].indices, label + " indices"));
      std::vector<int32_t> triangles;
      const int vertex_count = static_cast<int>(positions.size() / 3);
      DMC_RETURN_IF_ERROR(
          gltf::AppendTriangles(primitives[0], indices, vertex_count, 0, triangles, label));
      result.sequence = MeshSequence(vertex_count, gltf::ToTriangles(triangles), frame_count);
      result.sequence.frame_rate = options.frame_rate;
      result.vertex_map.resize(static_cast<size_t>(vertex_count));
      std::iota(result.vertex_map.begin(), result.vertex_map.end(), 0);
    }
    if (positions.size() != 3 * static_cast<size_t>(result.sequence.vertex_count())) {
      return ParseError(label + ": " + std::to_string(positions.size() / 3) +
                        " vertices, frame 0 has " + std::to_string(result.sequence.vertex_count()));
    }
    float* frame = result.sequence.frame(f).data();
    for (size_t i = 0; i < positions.size(); i += 3) {
      const Eigen::Vector4d p =
          root * Eigen::Vector4d(positions[i], positions[i + 1], positions[i + 2], 1.0);
      for (size_t c = 0; c < 3; ++c) frame[i + c] = static_cast<float>(p[static_cast<long>(c)]);
    }
  }
  if (frame_count == 0) return UnsupportedError("the dmc frames export holds no frame");
  return result;
}

// The animation's channels and the time span they cover (0, 0 without an animation).
struct Clip {
  std::string name;
  int animation = -1;
  std::vector<Channel> channels;
  double start = 0.0;
  double end = 0.0;
  bool animated = true;  // false: the file has no animation (one frame of the static scene)
};

StatusOr<Clip> LoadClip(const tinygltf::Model& model, int animation_index) {
  Clip clip;
  if (animation_index < 0) return clip;
  const tinygltf::Animation& animation = model.animations[static_cast<size_t>(animation_index)];
  clip.name = animation.name;
  clip.animation = animation_index;
  DMC_ASSIGN_OR_RETURN(
      clip.channels,
      gltf::LoadChannels(model, animation, "animation " + std::to_string(animation_index)));
  bool first = true;
  for (const Channel& channel : clip.channels) {
    clip.start = first ? channel.times.front() : std::min(clip.start, channel.times.front());
    clip.end = first ? channel.times.back() : std::max(clip.end, channel.times.back());
    first = false;
  }
  return clip;
}

// The clips `wanted` names: every animation for "" or "all", else the one FindAnimation picks;
// one empty clip (a single frame of the static scene) when the file has no animation.
StatusOr<std::vector<Clip>> LoadClips(const tinygltf::Model& model, const std::string& wanted) {
  std::vector<Clip> clips;
  if ((wanted.empty() || wanted == "all") && !model.animations.empty()) {
    for (size_t a = 0; a < model.animations.size(); ++a) {
      DMC_ASSIGN_OR_RETURN(Clip clip, LoadClip(model, static_cast<int>(a)));
      clips.push_back(std::move(clip));
    }
    return clips;
  }
  DMC_ASSIGN_OR_RETURN(const int animation_index,
                       gltf::FindAnimation(model, wanted == "all" ? std::string() : wanted));
  DMC_ASSIGN_OR_RETURN(Clip clip, LoadClip(model, animation_index));
  clip.animated = animation_index >= 0;
  clips.push_back(std::move(clip));
  return clips;
}

// The rate the clip is keyed at when every key of every channel lies on one grid of period 1/r
// from the clip's start, kMinKeyRate ≤ r ≤ kMaxKeyRate (0 otherwise): sampling there reproduces
// the keys themselves, as baked animations (keyed every frame) need. Sparser keys leave motion to
// the interpolation between them, which the default rate samples. Key times are float32, so a key
// may miss its grid point by a few units in the last place; rates within 10^-4 of a whole number,
// or of the NTSC rates n·1000/1001, are taken as that rate.
double UniformKeyRate(const Clip& clip) {
  constexpr double kMinKeyRate = 12.0;
  constexpr double kMaxKeyRate = 240.0;
  std::vector<double> times;
  for (const Channel& channel : clip.channels) {
    times.insert(times.end(), channel.times.begin(), channel.times.end());
  }
  std::sort(times.begin(), times.end());
  const double slack = std::ldexp(std::abs(clip.start) + std::abs(clip.end), -22);
  double period = HUGE_VAL;
  for (size_t k = 1; k < times.size(); ++k) {
    if (times[k] - times[k - 1] > slack) period = std::min(period, times[k] - times[k - 1]);
  }
  if (!std::isfinite(period) || 1.0 / period > kMaxKeyRate * (1 + 1e-4)) return 0.0;
  // The period from the whole span (less rounding than one interval).
  const double steps = std::round((clip.end - clip.start) / period);
  if (steps < 1) return 0.0;
  period = (clip.end - clip.start) / steps;
  for (const double t : times) {
    const double k = std::round((t - clip.start) / period);
    if (std::abs(t - clip.start - k * period) > 1e-3 * period + slack) return 0.0;
  }
  const double rate = 1.0 / period;
  if (rate < kMinKeyRate * (1 - 1e-4)) return 0.0;
  for (const double nice : {std::round(rate), std::round(rate * 1.001) / 1.001}) {
    if (std::abs(rate - nice) <= 1e-4 * nice) return nice;
  }
  return rate;
}

// A frame at every 1/fps from the start, the last one no later than the end. Key times are
// float32 (glTF accessors), so start and end each carry up to 2^-24 of their magnitude in
// rounding: twice that is the slack (in frames), so a clip whose last key is at (F − 1)/fps has
// its F-th frame (an exported 59-frame, 30 fps sequence read back with 58 frames under 1e-9 of
// slack).
StatusOr<int> ClipFrameCount(const Clip& clip, double frame_rate, int max_frames) {
  const double span = (clip.end - clip.start) * frame_rate;
  const double slack =
      std::ldexp(std::abs(clip.start) + std::abs(clip.end), -23) * frame_rate + 1e-9;
  if (!(span + slack <= kMaxGltfFrames)) {
    return InvalidArgumentError("the animation would need more than 10^7 frames");
  }
  int frame_count = static_cast<int>(std::floor(span + slack)) + 1;
  if (max_frames > 0) frame_count = std::min(frame_count, max_frames);
  return frame_count;
}

}  // namespace

namespace {

// tinygltf parses, copies and frees JSON recursively: a document nested deeper than this (a few
// hundred bytes of brackets, or far fewer zstd-compressed in a stream's scene) would exhaust the
// stack, so it is refused first. Real files nest a dozen levels.
constexpr int kMaxJsonDepth = 128;

Status CheckJsonDepth(std::string_view json) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) {
        return ParseError("the glTF JSON nests deeper than " + std::to_string(kMaxJsonDepth) +
                          " levels");
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return Status::Ok();
}

// tinygltf throws on some malformed input (std::out_of_range from a zero-length buffer's
// at(0), nlohmann's parse errors): every call into it goes through here.
template <typename Load>
Status CallTinygltf(const std::string& label, Load&& load) {
  try {
    return load();
  } catch (const std::bad_alloc&) {
    throw;  // GuardAllocation's concern (resource-limit)
  } catch (const std::exception& error) {
    return ParseError(label + ": " + error.what());
  }
}

// For a GLB held in memory: no file is ever read or written on its behalf.
tinygltf::FsCallbacks NoFileSystem() {
  tinygltf::FsCallbacks callbacks{};
  callbacks.FileExists = [](const std::string&, void*) { return false; };
  callbacks.ExpandFilePath = [](const std::string& path, void*) { return path; };
  callbacks.ReadWholeFile = [](std::vector<unsigned char>*, std::string* error,
                               const std::string& path, void*) {
    if (error != nullptr) *error += "external file " + path + " refused\n";
    return false;
  };
  callbacks.WriteWholeFile = [](std::string*, const std::string&, const std::vector<unsigned char>&,
                                void*) { return false; };
  callbacks.user_data = nullptr;
  return callbacks;
}

// The whole file; kIoError naming it when it cannot be read or exceeds what tinygltf indexes.
StatusOr<std::string> ReadWholeFile(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return IoError("cannot open " + path.string() + ": " + std::strerror(errno));
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) return IoError("cannot read " + path.string() + ": " + std::strerror(errno));
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    return UnsupportedError(path.string() + ": glTF files of 4 GiB or more are not supported");
  }
  return bytes;
}

}  // namespace

StatusOr<tinygltf::Model> LoadGltfModel(const std::filesystem::path& path) {
  tinygltf::TinyGLTF loader;
  // dmc needs no pixels: images stay undecoded.
  loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int,
                           const unsigned char*, int, void*) { return true; },
                        nullptr);
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return IoError("cannot open " + path.string() + ": not a readable file");
  }
  DMC_ASSIGN_OR_RETURN(std::string bytes, ReadWholeFile(path));
  const bool binary = LowercaseExtension(path) == ".glb";
  GlbJsonChunk json_chunk{0, bytes.size()};
  if (binary) {
    StatusOr<GlbJsonChunk> checked = CheckGlbContainer(bytes);
    if (!checked.ok()) return checked.status().WithContext(path.string());
    json_chunk = *checked;
  }
  // Before any JSON parser recurses into it.
  if (const Status depth =
          CheckJsonDepth(std::string_view(bytes).substr(json_chunk.offset, json_chunk.length));
      !depth.ok()) {
    return depth.WithContext(path.string());
  }
  // What tinygltf cannot load of the compressed-geometry extensions gets a stand-in first
  // (gltf_extensions.cpp).
  gltf::CompressedGeometryStandIns stand_ins;
  if (bytes.find("EXT_meshopt_compression") != std::string::npos ||
      bytes.find("KHR_draco_mesh_compression") != std::string::npos) {
    const std::string_view json =
        std::string_view(bytes).substr(json_chunk.offset, json_chunk.length);
    DMC_ASSIGN_OR_RETURN(std::string prepared, gltf::PrepareCompressedGeometry(json, stand_ins));
    if (!stand_ins.fallbacks.empty() || !stand_ins.draco_indices.empty()) {
      bytes = binary ? ReplaceGlbJson(bytes, json_chunk, std::move(prepared)) : std::move(prepared);
    }
  }
  tinygltf::Model model;
  std::string errors, warnings;
  const std::string base_dir = std::filesystem::absolute(path, error).parent_path().string();
  bool ok = false;
  DMC_RETURN_IF_ERROR(CallTinygltf(path.string(), [&] {
    ok = binary ? loader.LoadBinaryFromMemory(&model, &errors, &warnings,
                                              reinterpret_cast<const unsigned char*>(bytes.data()),
                                              static_cast<unsigned int>(bytes.size()), base_dir)
                : loader.LoadASCIIFromString(&model, &errors, &warnings, bytes.data(),
                                             static_cast<unsigned int>(bytes.size()), base_dir);
    return Status::Ok();
  }));
  if (!ok) {
    while (!errors.empty() && errors.back() == '\n') errors.pop_back();
    return ParseError(path.string() + ": " + (errors.empty() ? "not a glTF 2.0 file" : errors));
  }
  const Status decoded = [&] {
    DMC_RETURN_IF_ERROR(gltf::CheckRequiredExtensions(model));
    DMC_RETURN_IF_ERROR(gltf::RestoreCompressedGeometry(model, stand_ins));
    return gltf::DecodeCompressedGeometry(model);
  }();
  if (!decoded.ok()) return decoded.WithContext(path.string());
  return model;
}

StatusOr<tinygltf::Model> LoadGlbBytes(std::span<const uint8_t> bytes, const std::string& label) {
  const std::string_view view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  StatusOr<GlbJsonChunk> checked = CheckGlbContainer(view);
  if (!checked.ok()) return checked.status().WithContext(label);
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    return UnsupportedError(label + ": GLBs of 4 GiB or more are not supported");
  }
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int,
                           const unsigned char*, int, void*) { return true; },
                        nullptr);
  loader.SetFsCallbacks(NoFileSystem());
  DMC_RETURN_IF_ERROR(
      CheckJsonDepth(view.substr(checked->offset, checked->length)).WithContext(label));
  tinygltf::Model model;
  std::string errors, warnings;
  bool ok = false;
  DMC_RETURN_IF_ERROR(CallTinygltf(label, [&] {
    ok = loader.LoadBinaryFromMemory(&model, &errors, &warnings, bytes.data(),
                                     static_cast<unsigned int>(bytes.size()), "");
    return Status::Ok();
  }));
  if (!ok) {
    while (!errors.empty() && errors.back() == '\n') errors.pop_back();
    return ParseError(label + ": " + (errors.empty() ? "not a glTF 2.0 file" : errors));
  }
  return model;
}

StatusOr<GltfImport> PoseGltfModel(const tinygltf::Model& model, const GltfReadOptions& requested,
                                   int max_frames) {
  if (!(requested.frame_rate >= 0) || !std::isfinite(requested.frame_rate)) {
    return InvalidArgumentError("glTF frame rate must be positive (or 0: automatic), got " +
                                std::to_string(requested.frame_rate));
  }
  const tinygltf::Value& dmc_extras = Member(model.asset.extras, "dmc");
  GltfReadOptions options = requested;
  if (options.frame_rate == 0) {
    const tinygltf::Value& recorded = Member(dmc_extras, "frame_rate");
    if (recorded.IsNumber() && recorded.GetNumberAsDouble() > 0) {
      options.frame_rate = recorded.GetNumberAsDouble();
    }
  }
  // A dmc "frames" export shows one mesh per frame in turn; its sequence is those meshes.
  if (gltf::IsDmcFramesExport(model) && options.mesh.empty()) {
    if (options.frame_rate == 0) options.frame_rate = kDefaultFrameRate;
    return ReadFramesExport(model, options, max_frames);
  }
  GltfImport result;
  DMC_ASSIGN_OR_RETURN(const gltf::SceneOrder scene, gltf::OrderScene(model));
  DMC_ASSIGN_OR_RETURN(const gltf::ScenePrimitives primitives,
                       gltf::CollectPrimitives(model, scene.order, options.mesh, result.warnings));
  DMC_ASSIGN_OR_RETURN(const auto inverse_binds,
                       gltf::InverseBindMatrices(model, primitives.instances));
  DMC_ASSIGN_OR_RETURN(const std::vector<Clip> clips, LoadClips(model, options.animation));
  if (options.frame_rate == 0) {
    // One rate for the sequence: the clips' common key rate, else the default.
    double key_rate = UniformKeyRate(clips.front());
    for (const Clip& clip : clips) {
      if (UniformKeyRate(clip) != key_rate) key_rate = 0;
    }
    options.frame_rate = key_rate > 0 ? key_rate : kDefaultFrameRate;
  }
  std::vector<int> clip_frames;
  int frame_count = 0;
  for (const Clip& clip : clips) {
    const int remaining = max_frames > 0 ? max_frames - frame_count : 0;
    if (max_frames > 0 && remaining <= 0) break;
    DMC_ASSIGN_OR_RETURN(const int frames, ClipFrameCount(clip, options.frame_rate, remaining));
    if (frame_count > kMaxGltfFrames - frames) {
      return InvalidArgumentError("the animations would need more than 10^7 frames");
    }
    clip_frames.push_back(frames);
    frame_count += frames;
  }

  MeshSequence sequence(primitives.vertex_total, gltf::ToTriangles(primitives.triangles),
                        frame_count);
  sequence.frame_rate = options.frame_rate;
  int first_frame = 0;
  for (size_t c = 0; c < clip_frames.size(); ++c) {
    const Clip& clip = clips[c];
    gltf::ScenePoser poser(model, scene, primitives.instances, inverse_binds, clip.channels);
    for (int f = 0; f < clip_frames[c]; ++f) {
      DMC_RETURN_IF_ERROR(
          poser.Pose(clip.start + f / options.frame_rate, sequence.frame(first_frame + f))
              .WithContext("frame " + std::to_string(first_frame + f)));
    }
    if (clip.animated) {
      result.clips.push_back({clip.name, clip.animation, clip.start, first_frame, clip_frames[c]});
    }
    first_frame += clip_frames[c];
  }
  result.sequence = std::move(sequence);
  result.vertex_map.resize(static_cast<size_t>(primitives.vertex_total));
  std::iota(result.vertex_map.begin(), result.vertex_map.end(), 0);
  if (options.weld) DMC_RETURN_IF_ERROR(gltf::WeldImport(result, primitives.triangles));
  return result;
}

StatusOr<std::vector<uint8_t>> ReadSceneRecord(const std::filesystem::path& path,
                                               const GltfReadOptions& options,
                                               const std::vector<int32_t>& vertex_map,
                                               const std::vector<ClipInfo>& clips,
                                               int stream_vertices) {
  DMC_ASSIGN_OR_RETURN(tinygltf::Model model, LoadGltfModel(path));
  StatusOr<std::vector<uint8_t>> record =
      BuildSceneRecord(std::move(model), options, vertex_map, clips, stream_vertices);
  if (!record.ok()) return record.status().WithContext(path.string());
  return record;
}

StatusOr<GltfImport> ReadGltf(const std::filesystem::path& path, const GltfReadOptions& options,
                              int max_frames) {
  DMC_ASSIGN_OR_RETURN(const tinygltf::Model model, LoadGltfModel(path));
  StatusOr<GltfImport> result = PoseGltfModel(model, options, max_frames);
  if (!result.ok()) return result.status().WithContext(path.string());
  return result;
}

}  // namespace dmc::io_internal
