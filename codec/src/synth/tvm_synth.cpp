// The table of time-varying synthetic examples and SynthesizeTimeVarying().
#include <string>

#include "synth/generator_table.h"
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

}  // namespace

std::vector<std::string_view> TimeVaryingSynthNames() {
  return synth::GeneratorNames(kTimeVaryingGenerators);
}

std::string_view TimeVaryingSynthDescription(std::string_view name) {
  return synth::GeneratorDescription(kTimeVaryingGenerators, name);
}

StatusOr<TimeVaryingSynthesis> SynthesizeTimeVarying(std::string_view name,
                                                     const TimeVaryingSynthOptions& options) {
  const TimeVaryingEntry* entry = synth::FindGenerator(kTimeVaryingGenerators, name);
  if (entry == nullptr) {
    return NotFoundError("unknown time-varying synthetic sequence '" + std::string(name) +
                         "'; known: " + synth::JoinedGeneratorNames(kTimeVaryingGenerators));
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
