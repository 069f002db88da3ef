// The glTF scene as import sees it: node order, static node poses, the triangle primitives of the
// mesh nodes with their morph targets and skin influences, and the skins' inverse bind matrices.
#include <numeric>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal::gltf {
namespace {

// The morph targets' POSITION deltas of `primitive` (zeros for a target without POSITION).
Status ReadMorphTargets(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                        const std::string& label, PrimitiveInstance& instance) {
  for (size_t t = 0; t < primitive.targets.size(); ++t) {
    const auto target = primitive.targets[t].find("POSITION");
    if (target == primitive.targets[t].end()) {
      instance.targets.emplace_back(instance.positions.size(), 0.0);
      continue;
    }
    DMC_ASSIGN_OR_RETURN(
        auto deltas, ReadAccessor(model, target->second, label + " target " + std::to_string(t)));
    if (deltas.size() != instance.positions.size()) {
      return ParseError(label + ": morph target " + std::to_string(t) + " has " +
                        std::to_string(deltas.size() / 3) + " positions, expected " +
                        std::to_string(instance.vertex_count));
    }
    instance.targets.push_back(std::move(deltas));
  }
  return Status::Ok();
}

// Every JOINTS_n/WEIGHTS_n set of `primitive`, interleaved per vertex into instance.joints and
// instance.weights (instance.influences per vertex).
Status ReadSkinInfluences(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                          size_t joint_count, const std::string& label,
                          PrimitiveInstance& instance) {
  for (int set = 0;; ++set) {
    const auto joints = primitive.attributes.find("JOINTS_" + std::to_string(set));
    const auto weights = primitive.attributes.find("WEIGHTS_" + std::to_string(set));
    if (joints == primitive.attributes.end() || weights == primitive.attributes.end()) break;
    DMC_ASSIGN_OR_RETURN(auto joint_values, ReadAccessor(model, joints->second, label + " JOINTS"));
    DMC_ASSIGN_OR_RETURN(auto weight_values,
                         ReadAccessor(model, weights->second, label + " WEIGHTS"));
    if (joint_values.size() != 4 * static_cast<size_t>(instance.vertex_count) ||
        weight_values.size() != joint_values.size()) {
      return ParseError(label + ": JOINTS_" + std::to_string(set) + "/WEIGHTS_" +
                        std::to_string(set) + " are not VEC4 per vertex");
    }
    instance.influences += 4;
    for (double j : joint_values) {
      if (j < 0 || j >= static_cast<double>(joint_count)) {
        return ParseError(label + ": joint " + std::to_string(j) + " outside the skin's " +
                          std::to_string(joint_count) + " joints");
      }
    }
    // Interleave the sets per vertex: vertex v's influences are contiguous.
    std::vector<int> merged_joints;
    std::vector<double> merged_weights;
    const int old = instance.influences - 4;
    for (int v = 0; v < instance.vertex_count; ++v) {
      for (int k = 0; k < old; ++k) {
        merged_joints.push_back(instance.joints[static_cast<size_t>(v * old + k)]);
        merged_weights.push_back(instance.weights[static_cast<size_t>(v * old + k)]);
      }
      for (int k = 0; k < 4; ++k) {
        merged_joints.push_back(static_cast<int>(joint_values[static_cast<size_t>(4 * v + k)]));
        merged_weights.push_back(weight_values[static_cast<size_t>(4 * v + k)]);
      }
    }
    instance.joints = std::move(merged_joints);
    instance.weights = std::move(merged_weights);
  }
  return Status::Ok();
}

// Primitive `p` of the mesh of node `n` appended to `primitives`, or skipped with a warning.
Status AddPrimitive(const tinygltf::Model& model, int n, size_t p, ScenePrimitives& primitives,
                    std::vector<std::string>& warnings) {
  const tinygltf::Node& node = model.nodes[static_cast<size_t>(n)];
  const tinygltf::Mesh& mesh = model.meshes[static_cast<size_t>(node.mesh)];
  const tinygltf::Primitive& primitive = mesh.primitives[p];
  const std::string label = "mesh " + std::to_string(node.mesh) +
                            (mesh.name.empty() ? "" : " '" + mesh.name + "'") + ", primitive " +
                            std::to_string(p);
  if (!IsTriangleMode(primitive.mode)) {
    warnings.push_back(label + ": points or lines skipped");
    return Status::Ok();
  }
  const auto position = primitive.attributes.find("POSITION");
  if (position == primitive.attributes.end()) {
    warnings.push_back(label + ": no POSITION attribute, skipped");
    return Status::Ok();
  }
  PrimitiveInstance instance;
  instance.node = n;
  instance.mesh = node.mesh;
  instance.primitive = static_cast<int>(p);
  instance.skin = node.skin;
  instance.vertex_offset = primitives.vertex_total;
  int components = 0;
  DMC_ASSIGN_OR_RETURN(instance.positions,
                       ReadAccessor(model, position->second, label + " POSITION", &components));
  if (components != 3) return ParseError(label + ": POSITION is not VEC3");
  instance.vertex_count = static_cast<int>(instance.positions.size() / 3);
  std::vector<double> indices;
  if (primitive.indices >= 0) {
    DMC_ASSIGN_OR_RETURN(indices, ReadAccessor(model, primitive.indices, label + " indices"));
  } else {
    indices.resize(static_cast<size_t>(instance.vertex_count));
    std::iota(indices.begin(), indices.end(), 0.0);
  }
  DMC_RETURN_IF_ERROR(AppendTriangles(primitive, indices, instance.vertex_count,
                                      primitives.vertex_total, primitives.triangles, label));
  DMC_RETURN_IF_ERROR(ReadMorphTargets(model, primitive, label, instance));
  instance.default_weights = mesh.weights;
  if (node.skin >= 0) {
    const size_t joint_count = model.skins[static_cast<size_t>(node.skin)].joints.size();
    DMC_RETURN_IF_ERROR(ReadSkinInfluences(model, primitive, joint_count, label, instance));
    if (instance.influences == 0) {
      warnings.push_back(label +
                         ": skinned node without JOINTS_0/WEIGHTS_0; posed by its node transform");
      instance.skin = -1;
    }
  }
  primitives.vertex_total += instance.vertex_count;
  primitives.instances.push_back(std::move(instance));
  return Status::Ok();
}

}  // namespace

StatusOr<SceneOrder> OrderScene(const tinygltf::Model& model) {
  const size_t node_count = model.nodes.size();
  SceneOrder scene;
  scene.parent.assign(node_count, -1);
  std::vector<int>& parent = scene.parent;
  for (size_t n = 0; n < node_count; ++n) {
    for (int child : model.nodes[n].children) {
      if (child < 0 || static_cast<size_t>(child) >= node_count ||
          parent[static_cast<size_t>(child)] != -1) {
        return ParseError("node " + std::to_string(n) + ": child " + std::to_string(child) +
                          " does not exist or has two parents");
      }
      parent[static_cast<size_t>(child)] = static_cast<int>(n);
    }
  }
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const size_t root_scene =
        model.defaultScene >= 0 && static_cast<size_t>(model.defaultScene) < model.scenes.size()
            ? static_cast<size_t>(model.defaultScene)
            : 0;
    roots = model.scenes[root_scene].nodes;
  } else {
    for (size_t n = 0; n < node_count; ++n) {
      if (parent[n] == -1) roots.push_back(static_cast<int>(n));
    }
  }
  // Depth-first order from the roots: parents before children, and the import order of meshes.
  std::vector<char> visited(node_count, 0);
  std::vector<int> stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    if (n < 0 || static_cast<size_t>(n) >= node_count) {
      return ParseError("scene node " + std::to_string(n) + " does not exist");
    }
    if (visited[static_cast<size_t>(n)])
      return ParseError("node " + std::to_string(n) + " is reached twice");
    visited[static_cast<size_t>(n)] = 1;
    scene.order.push_back(n);
    const auto& children = model.nodes[static_cast<size_t>(n)].children;
    stack.insert(stack.end(), children.rbegin(), children.rend());
  }
  return scene;
}

Matrix4 NodePose::Local() const {
  if (matrix) return *matrix;
  Eigen::Affine3d transform = Eigen::Translation3d(translation) * rotation * scale.asDiagonal();
  return transform.matrix();
}

NodePose StaticPose(const tinygltf::Node& node) {
  NodePose pose;
  if (node.matrix.size() == 16) {
    pose.matrix = Eigen::Map<const Matrix4>(node.matrix.data());  // column-major, as glTF
  }
  if (node.translation.size() == 3) {
    pose.translation =
        Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]);
  }
  if (node.rotation.size() == 4) {
    pose.rotation =
        Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2])
            .normalized();
  }
  if (node.scale.size() == 3)
    pose.scale = Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]);
  pose.weights = node.weights;
  return pose;
}

StatusOr<ScenePrimitives> CollectPrimitives(const tinygltf::Model& model,
                                            const std::vector<int>& order,
                                            const std::string& mesh_name,
                                            std::vector<std::string>& warnings) {
  ScenePrimitives primitives;
  bool name_matched = false;
  for (int n : order) {
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(n)];
    if (node.mesh < 0) continue;
    if (static_cast<size_t>(node.mesh) >= model.meshes.size()) {
      return ParseError("node " + std::to_string(n) + ": mesh " + std::to_string(node.mesh) +
                        " does not exist");
    }
    const tinygltf::Mesh& mesh = model.meshes[static_cast<size_t>(node.mesh)];
    if (!mesh_name.empty() && mesh.name != mesh_name && node.name != mesh_name) continue;
    name_matched = true;
    if (node.skin >= 0 && static_cast<size_t>(node.skin) >= model.skins.size()) {
      return ParseError("node " + std::to_string(n) + ": skin " + std::to_string(node.skin) +
                        " does not exist");
    }
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      DMC_RETURN_IF_ERROR(AddPrimitive(model, n, p, primitives, warnings));
    }
  }
  if (!mesh_name.empty() && !name_matched) {
    std::string names;
    for (const auto& mesh : model.meshes) names += (names.empty() ? "" : ", ") + mesh.name;
    return InvalidArgumentError("no mesh or node named '" + mesh_name + "' (meshes: " + names +
                                ")");
  }
  if (primitives.instances.empty() || primitives.triangles.empty()) {
    return UnsupportedError("the glTF scene holds no triangle mesh to import");
  }
  return primitives;
}

StatusOr<std::vector<std::vector<Matrix4>>> InverseBindMatrices(
    const tinygltf::Model& model, const std::vector<PrimitiveInstance>& instances) {
  std::vector<std::vector<Matrix4>> inverse_binds(model.skins.size());
  for (const auto& instance : instances) {
    if (instance.skin < 0 || !inverse_binds[static_cast<size_t>(instance.skin)].empty()) continue;
    const tinygltf::Skin& skin = model.skins[static_cast<size_t>(instance.skin)];
    auto& matrices = inverse_binds[static_cast<size_t>(instance.skin)];
    matrices.assign(skin.joints.size(), Matrix4::Identity());
    for (int joint : skin.joints) {
      if (joint < 0 || static_cast<size_t>(joint) >= model.nodes.size()) {
        return ParseError("skin " + std::to_string(instance.skin) + ": joint node " +
                          std::to_string(joint) + " does not exist");
      }
    }
    if (skin.inverseBindMatrices >= 0) {
      DMC_ASSIGN_OR_RETURN(auto values,
                           ReadAccessor(model, skin.inverseBindMatrices, "inverse bind matrices"));
      if (values.size() != 16 * skin.joints.size()) {
        return ParseError("skin " + std::to_string(instance.skin) + ": " +
                          std::to_string(values.size() / 16) + " inverse bind matrices for " +
                          std::to_string(skin.joints.size()) + " joints");
      }
      for (size_t j = 0; j < skin.joints.size(); ++j) {
        matrices[j] = Eigen::Map<const Matrix4>(values.data() + 16 * j);
      }
    }
  }
  return inverse_binds;
}

}  // namespace dmc::io_internal::gltf
