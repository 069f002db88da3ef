// One frame of a glTF animation: sampled node transforms, then morph targets and skinning per
// vertex, in double, rounded to float32 once.
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal::gltf {

ScenePoser::ScenePoser(const tinygltf::Model& model, const SceneOrder& scene,
                       const std::vector<PrimitiveInstance>& instances,
                       const std::vector<std::vector<Matrix4>>& inverse_binds,
                       const std::vector<Channel>& channels)
    : model_(model),
      scene_(scene),
      instances_(instances),
      inverse_binds_(inverse_binds),
      channels_(channels),
      globals_(model.nodes.size(), Matrix4::Identity()),
      joint_matrices_(model.skins.size()) {
  static_poses_.reserve(model.nodes.size());
  for (const auto& node : model.nodes) static_poses_.push_back(StaticPose(node));
}

Status ScenePoser::Pose(double time, Eigen::Map<FramePositions> frame) {
  PoseNodes(time);
  for (const PrimitiveInstance& instance : instances_) {
    DMC_RETURN_IF_ERROR(PoseInstance(instance, frame));
  }
  return Status::Ok();
}

void ScenePoser::PoseNodes(double time) {
  poses_ = static_poses_;
  for (const Channel& channel : channels_) {
    NodePose& pose = poses_[static_cast<size_t>(channel.node)];
    const std::vector<double> value = channel.Sample(time);
    switch (channel.path) {
      case Path::kTranslation:
        pose.translation = Eigen::Vector3d(value[0], value[1], value[2]);
        break;
      case Path::kRotation:
        pose.rotation = Eigen::Quaterniond(value[3], value[0], value[1], value[2]).normalized();
        break;
      case Path::kScale:
        pose.scale = Eigen::Vector3d(value[0], value[1], value[2]);
        break;
      case Path::kWeights:
        pose.weights = value;
        break;
    }
  }
  for (int n : scene_.order) {
    const int p = scene_.parent[static_cast<size_t>(n)];
    const Matrix4 local = poses_[static_cast<size_t>(n)].Local();
    globals_[static_cast<size_t>(n)] =
        p >= 0 ? Matrix4(globals_[static_cast<size_t>(p)] * local) : local;
  }
  for (size_t s = 0; s < model_.skins.size(); ++s) {
    if (inverse_binds_[s].empty()) continue;
    const auto& joints = model_.skins[s].joints;
    joint_matrices_[s].resize(joints.size());
    for (size_t j = 0; j < joints.size(); ++j) {
      joint_matrices_[s][j] = globals_[static_cast<size_t>(joints[j])] * inverse_binds_[s][j];
    }
  }
}

Status ScenePoser::PoseInstance(const PrimitiveInstance& instance,
                                Eigen::Map<FramePositions>& frame) const {
  const NodePose& pose = poses_[static_cast<size_t>(instance.node)];
  const std::vector<double>& weights =
      !pose.weights.empty() ? pose.weights : instance.default_weights;
  for (int v = 0; v < instance.vertex_count; ++v) {
    const size_t base = 3 * static_cast<size_t>(v);
    Eigen::Vector4d point(instance.positions[base], instance.positions[base + 1],
                          instance.positions[base + 2], 1.0);
    for (size_t t = 0; t < instance.targets.size() && t < weights.size(); ++t) {
      if (weights[t] == 0.0) continue;
      for (int axis = 0; axis < 3; ++axis)
        point[axis] += weights[t] * instance.targets[t][base + static_cast<size_t>(axis)];
    }
    Eigen::Vector4d posed;
    if (instance.skin >= 0) {
      posed.setZero();
      const auto& matrices = joint_matrices_[static_cast<size_t>(instance.skin)];
      for (int k = 0; k < instance.influences; ++k) {
        const size_t slot = static_cast<size_t>(v * instance.influences + k);
        const double w = instance.weights[slot];
        if (w != 0.0) posed += w * (matrices[static_cast<size_t>(instance.joints[slot])] * point);
      }
    } else {
      posed = globals_[static_cast<size_t>(instance.node)] * point;
    }
    for (int axis = 0; axis < 3; ++axis) {
      // Non-finite values pass on to ValidateSequence, which names them; a finite one that
      // would overflow the float is named here (the conversion would be undefined).
      if (std::isfinite(posed[axis]) &&
          std::fabs(posed[axis]) > std::numeric_limits<float>::max()) {
        return InvalidSequenceError(fmt::format(
            "vertex {}, coordinate {}: the posed value {} is out of float32 range (at most "
            "3.4028235e+38 in magnitude)",
            instance.vertex_offset + v, "xyz"[axis], posed[axis]));
      }
      frame(instance.vertex_offset + v, axis) = static_cast<float>(posed[axis]);
    }
  }
  return Status::Ok();
}

}  // namespace dmc::io_internal::gltf
