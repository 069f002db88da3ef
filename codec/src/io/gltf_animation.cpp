// glTF animation channels: loading (paths, interpolation, keyframe checks) and sampling.
#include <algorithm>
#include <cmath>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal::gltf {

std::vector<double> Channel::Sample(double t) const {
  const size_t w = static_cast<size_t>(width);
  std::vector<double> out(w);
  const size_t keys = times.size();
  if (keys == 1 || t <= times.front()) {
    std::copy_n(Value(0), w, out.begin());
    return out;
  }
  if (t >= times.back()) {
    std::copy_n(Value(keys - 1), w, out.begin());
    return out;
  }
  const size_t k =
      static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  const double interval = times[k + 1] - times[k];
  const double s = (t - times[k]) / interval;
  const double* a = Value(k);
  const double* b = Value(k + 1);
  switch (interpolation) {
    case Interpolation::kStep:
      std::copy_n(a, w, out.begin());
      return out;
    case Interpolation::kLinear:
      if (path == Path::kRotation) {
        // glTF stores x, y, z, w; Eigen's slerp takes the shorter arc, as the spec asks.
        const Eigen::Quaterniond qa(a[3], a[0], a[1], a[2]);
        const Eigen::Quaterniond qb(b[3], b[0], b[1], b[2]);
        const Eigen::Quaterniond q = qa.normalized().slerp(s, qb.normalized());
        out = {q.x(), q.y(), q.z(), q.w()};
        return out;
      }
      for (size_t c = 0; c < w; ++c) out[c] = a[c] + s * (b[c] - a[c]);
      return out;
    case Interpolation::kCubicSpline: {
      // Hermite basis; tangents are per second, hence the interval factor (spec, appendix C).
      const double s2 = s * s, s3 = s2 * s;
      const double* out_tangent_a = a + w;  // k's out-tangent follows its value
      const double* in_tangent_b = b - w;   // k+1's in-tangent precedes its value
      for (size_t c = 0; c < w; ++c) {
        out[c] = (2 * s3 - 3 * s2 + 1) * a[c] + (s3 - 2 * s2 + s) * interval * out_tangent_a[c] +
                 (-2 * s3 + 3 * s2) * b[c] + (s3 - s2) * interval * in_tangent_b[c];
      }
      if (path == Path::kRotation) {
        const double norm =
            std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
        if (norm > 0) {
          for (double& value : out) value /= norm;
        }
      }
      return out;
    }
  }
  return out;
}

StatusOr<std::vector<Channel>> LoadChannels(const tinygltf::Model& model,
                                            const tinygltf::Animation& animation,
                                            const std::string& animation_label) {
  std::vector<Channel> channels;
  for (size_t c = 0; c < animation.channels.size(); ++c) {
    const tinygltf::AnimationChannel& source = animation.channels[c];
    const std::string label = animation_label + ", channel " + std::to_string(c);
    if (source.target_node < 0) continue;  // targets an extension object: nothing to pose
    if (static_cast<size_t>(source.target_node) >= model.nodes.size()) {
      return ParseError(label + ": node " + std::to_string(source.target_node) + " does not exist");
    }
    if (source.sampler < 0 || static_cast<size_t>(source.sampler) >= animation.samplers.size()) {
      return ParseError(label + ": sampler " + std::to_string(source.sampler) + " does not exist");
    }
    const tinygltf::AnimationSampler& sampler =
        animation.samplers[static_cast<size_t>(source.sampler)];
    Channel channel;
    channel.node = source.target_node;
    if (source.target_path == "translation") {
      channel.path = Path::kTranslation;
    } else if (source.target_path == "rotation") {
      channel.path = Path::kRotation;
    } else if (source.target_path == "scale") {
      channel.path = Path::kScale;
    } else if (source.target_path == "weights") {
      channel.path = Path::kWeights;
    } else {
      continue;  // "pointer" and other extension paths do not move vertices of plain glTF
    }
    if (sampler.interpolation == "STEP") {
      channel.interpolation = Interpolation::kStep;
    } else if (sampler.interpolation == "CUBICSPLINE") {
      channel.interpolation = Interpolation::kCubicSpline;
    } else if (sampler.interpolation == "LINEAR" || sampler.interpolation.empty()) {
      channel.interpolation = Interpolation::kLinear;
    } else {
      return ParseError(label + ": unknown interpolation '" + sampler.interpolation + "'");
    }
    DMC_ASSIGN_OR_RETURN(channel.times, ReadAccessor(model, sampler.input, "animation input"));
    int output_components = 0;
    DMC_ASSIGN_OR_RETURN(channel.values, ReadAccessor(model, sampler.output, "animation output",
                                                      &output_components));
    if (channel.times.empty()) return ParseError(label + ": no keyframes");
    for (size_t k = 1; k < channel.times.size(); ++k) {
      if (!(channel.times[k] > channel.times[k - 1])) {
        return ParseError(label + ": keyframe times are not strictly increasing at key " +
                          std::to_string(k));
      }
    }
    const size_t per_key = channel.interpolation == Interpolation::kCubicSpline ? 3 : 1;
    const size_t keys = channel.times.size();
    if (channel.values.size() % (keys * per_key) != 0) {
      return ParseError(label + ": " + std::to_string(channel.values.size()) +
                        " output values do not divide into " + std::to_string(keys) + " keys");
    }
    channel.width = static_cast<int>(channel.values.size() / (keys * per_key));
    const int expected = channel.path == Path::kRotation  ? 4
                         : channel.path == Path::kWeights ? channel.width
                                                          : 3;
    if (channel.width != expected || channel.width == 0 || output_components <= 0) {
      return ParseError(label + ": " + std::to_string(channel.width) +
                        " values per key, expected " + std::to_string(expected));
    }
    channels.push_back(std::move(channel));
  }
  return channels;
}

StatusOr<int> FindAnimation(const tinygltf::Model& model, const std::string& wanted) {
  if (model.animations.empty()) {
    if (!wanted.empty()) {
      return InvalidArgumentError("the file has no animation, so none named '" + wanted + "'");
    }
    return -1;
  }
  if (wanted.empty()) return 0;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    if (model.animations[a].name == wanted) return static_cast<int>(a);
  }
  if (std::all_of(wanted.begin(), wanted.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
      wanted.size() < 9) {
    const int index = std::stoi(wanted);
    if (static_cast<size_t>(index) < model.animations.size()) return index;
  }
  std::string names;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    if (a > 0) names += ", ";
    const std::string& name = model.animations[a].name;
    if (name.empty()) {
      names += '#';
      names += std::to_string(a);
    } else {
      names += name;
    }
  }
  return InvalidArgumentError("no animation named '" + wanted + "' (the file has " + names + ")");
}

}  // namespace dmc::io_internal::gltf
