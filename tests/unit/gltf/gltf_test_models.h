// Small glTF models built in memory for the import tests: every value is chosen so the posed
// positions can be computed by hand.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "io/gltf_format.h"

namespace dmc::testing {

// Appends data to buffer 0 and creates views and accessors over it.
class GltfBuilder {
 public:
  GltfBuilder() {
    model.buffers.emplace_back();
    model.asset.version = "2.0";
  }

  int Floats(const std::vector<float>& values, int type) {
    return Accessor(values.data(), values.size() * sizeof(float), TINYGLTF_COMPONENT_TYPE_FLOAT,
                    type, values.size() / Components(type));
  }
  int Indices(const std::vector<uint16_t>& values) {
    return Accessor(values.data(), values.size() * sizeof(uint16_t),
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR, values.size());
  }
  int Joints(const std::vector<uint8_t>& values) {
    return Accessor(values.data(), values.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                    TINYGLTF_TYPE_VEC4, values.size() / 4);
  }

  // A mesh with one triangle primitive, and a node showing it; returns the node index.
  int MeshNode(const std::vector<float>& positions, const std::vector<uint16_t>& indices,
               const std::string& name = "mesh") {
    tinygltf::Primitive primitive;
    primitive.attributes["POSITION"] = Floats(positions, TINYGLTF_TYPE_VEC3);
    primitive.indices = Indices(indices);
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(primitive);
    model.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = name + "_node";
    node.mesh = static_cast<int>(model.meshes.size()) - 1;
    return AddNode(node);
  }

  int AddNode(const tinygltf::Node& node) {
    model.nodes.push_back(node);
    return static_cast<int>(model.nodes.size()) - 1;
  }

  // One animation channel; `values` per key as the path needs (×3 for CUBICSPLINE).
  void Channel(int node, const std::string& path, const std::string& interpolation,
               const std::vector<float>& times, const std::vector<float>& values, int type) {
    if (model.animations.empty()) model.animations.emplace_back();
    tinygltf::Animation& animation = model.animations.back();
    tinygltf::AnimationSampler sampler;
    sampler.input = Floats(times, TINYGLTF_TYPE_SCALAR);
    sampler.output = Floats(values, type);
    sampler.interpolation = interpolation;
    animation.samplers.push_back(sampler);
    tinygltf::AnimationChannel channel;
    channel.sampler = static_cast<int>(animation.samplers.size()) - 1;
    channel.target_node = node;
    channel.target_path = path;
    animation.channels.push_back(channel);
  }

  // Puts every parentless node into scene 0.
  void FinishScene() {
    std::vector<bool> is_child(model.nodes.size(), false);
    for (const auto& node : model.nodes) {
      for (int child : node.children) is_child[static_cast<size_t>(child)] = true;
    }
    tinygltf::Scene scene;
    for (size_t n = 0; n < model.nodes.size(); ++n) {
      if (!is_child[n]) scene.nodes.push_back(static_cast<int>(n));
    }
    model.scenes = {scene};
    model.defaultScene = 0;
  }

  tinygltf::Model model;

 private:
  static size_t Components(int type) {
    return static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(type)));
  }

  int Accessor(const void* data, size_t bytes, int component_type, int type, size_t count) {
    std::vector<unsigned char>& buffer = model.buffers[0].data;
    while (buffer.size() % 4 != 0) buffer.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = bytes;
    buffer.resize(buffer.size() + bytes);
    std::memcpy(buffer.data() + view.byteOffset, data, bytes);
    model.bufferViews.push_back(view);
    tinygltf::Accessor accessor;
    accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
    accessor.componentType = component_type;
    accessor.type = type;
    accessor.count = count;
    model.accessors.push_back(accessor);
    return static_cast<int>(model.accessors.size()) - 1;
  }
};

// A unit right triangle in the z = 0 plane: (0,0,0), (1,0,0), (0,1,0).
// A GLB container of `json` and `bin`.
// `name` in a temporary directory of the running test's own.
inline std::filesystem::path TempFile(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir = std::filesystem::temp_directory_path() /
                   ("dmc_gltf_" + std::string(info->test_suite_name()) + "_" + info->name());
  std::filesystem::create_directories(dir);
  return dir / name;
}

inline std::vector<uint8_t> Glb(const nlohmann::json& json, std::vector<uint8_t> bin) {
  std::string text = json.dump();
  while (text.size() % 4 != 0) text.push_back(' ');
  while (bin.size() % 4 != 0) bin.push_back(0);
  std::vector<uint8_t> out;
  auto put = [&](uint32_t value) {
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<uint8_t>(value >> (8 * b)));
  };
  put(0x46546C67u);
  put(2);
  put(static_cast<uint32_t>(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
  put(static_cast<uint32_t>(text.size()));
  put(0x4E4F534Au);
  out.insert(out.end(), text.begin(), text.end());
  if (!bin.empty()) {
    put(static_cast<uint32_t>(bin.size()));
    put(0x004E4942u);
    out.insert(out.end(), bin.begin(), bin.end());
  }
  return out;
}

inline std::pair<nlohmann::json, std::vector<uint8_t>> SplitGlb(const std::vector<uint8_t>& glb) {
  uint32_t json_length = 0, bin_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  std::memcpy(&bin_length, glb.data() + 20 + json_length, 4);
  nlohmann::json json = nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + json_length);
  std::vector<uint8_t> bin(glb.begin() + 28 + json_length,
                           glb.begin() + 28 + json_length + bin_length);
  return {json, bin};
}

inline std::vector<float> UnitTriangle() { return {0, 0, 0, 1, 0, 0, 0, 1, 0}; }

}  // namespace dmc::testing
