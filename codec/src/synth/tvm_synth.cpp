// The table of time-varying synthetic examples and SynthesizeTimeVarying().
#include <string>

#include "synth/tvm_shapes.h"

namespace dmc {

namespace {

struct TimeVaryingEntry {
  std::string_view name;
  std::string_view description;
  TimeVaryingSynthesis (*generate)(const TimeVaryingSynthOptions&);
};

constexpr TimeVaryingEntry kTimeVaryingGenerators[] = {
    {"prism",
     "pentagonal prism rotating about its axis, re-triangulated every frame; volume centres "
     "(time-varying: frames + centres.txt)",
     synth::GeneratePrism},
    {"collision",
     "a box and a sphere that approach, touch at the middle frame and separate; volume centres "
     "(time-varying: frames + centres.txt)",
     synth::GenerateCollision},
};

const TimeVaryingEntry* FindTimeVarying(std::string_view name) {
  for (const auto& entry : kTimeVaryingGenerators) {
    if (entry.name == name) return &entry;
  }
  return nullptr;
}

}  // namespace

std::vector<std::string_view> TimeVaryingSynthNames() {
  std::vector<std::string_view> names;
  for (const auto& entry : kTimeVaryingGenerators) names.push_back(entry.name);
  return names;
}

std::string_view TimeVaryingSynthDescription(std::string_view name) {
  const TimeVaryingEntry* entry = FindTimeVarying(name);
  return entry ? entry->description : std::string_view();
}

StatusOr<TimeVaryingSynthesis> SynthesizeTimeVarying(std::string_view name,
                                                     const TimeVaryingSynthOptions& options) {
  const TimeVaryingEntry* entry = FindTimeVarying(name);
  if (entry == nullptr) {
    std::string known;
    for (const auto& candidate : kTimeVaryingGenerators) {
      known += (known.empty() ? "" : ", ") + std::string(candidate.name);
    }
    return NotFoundError("unknown time-varying synthetic sequence '" + std::string(name) +
                         "'; known: " + known);
  }
  if (options.frames < 1 || options.frames > kMaxSynthFrames) {
    return InvalidArgumentError("frames must be in [1, " + std::to_string(kMaxSynthFrames) +
                                "], got " + std::to_string(options.frames));
  }
  if (options.resolution < kMinSynthResolution || options.resolution > kMaxSynthResolution) {
    return InvalidArgumentError("resolution must be in [" + std::to_string(kMinSynthResolution) +
                                ", " + std::to_string(kMaxSynthResolution) + "] vertices, got " +
                                std::to_string(options.resolution));
  }
  if (options.centres < kMinSynthCentres || options.centres > kMaxSynthCentres) {
    return InvalidArgumentError("centres must be in [" + std::to_string(kMinSynthCentres) + ", " +
                                std::to_string(kMaxSynthCentres) + "], got " +
                                std::to_string(options.centres));
  }
  return entry->generate(options);
}

namespace synth {

tvm::TvmFrame MovedFrame(const tvm::TvmFrame& frame, const Eigen::Isometry3d& motion) {
  tvm::TvmFrame moved = frame;
  for (int v = 0; v < frame.vertex_count(); ++v) {
    moved.positions.row(v) = (motion * Eigen::Vector3d(frame.positions.row(v))).transpose();
  }
  return moved;
}

FramePositionsD MovedPoints(const std::vector<Eigen::Vector3d>& points,
                            const Eigen::Isometry3d& motion) {
  FramePositionsD moved(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) {
    moved.row(static_cast<Eigen::Index>(i)) = (motion * points[i]).transpose();
  }
  return moved;
}

}  // namespace synth

}  // namespace dmc
