// walker: a six-part figure (torso, head, two arms, two legs) walking along +z, animated by
// linear blend skinning (LBS).
//
// Rest pose: standing upright (y up, facing +z, metres), arms hanging. Each part is a closed
// capsule; the torso is flattened front to back. An 11-bone hierarchy (pelvis → chest → head and
// shoulders → forearms; pelvis → thighs → shins) is posed every frame from a parametric gait
// cycle: hips and shoulders swing in counter-phase, knees flex during the swing, elbows follow
// the arm swing, the pelvis bobs, sways and turns and the chest counter-rotates, while the root
// advances at the speed the stride implies.
//
// Skinning: a vertex of a two-bone part (torso: pelvis/chest, arm: upper arm/forearm, leg:
// thigh/shin) blends the two bone transforms with a C²-smooth weight of its position along the
// part's axis, ramping over a band around the joint; the head is rigid on its bone.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "synth/generators.h"
#include "synth/random.h"
#include "synth/shapes.h"

namespace dmc::synth {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kMinSegments = 6;
constexpr uint64_t kRandomStream = 0x77616c6b6572;  // "walker"

enum Bone : int {
  kPelvis,
  kChest,
  kHead,
  kLeftUpperArm,
  kLeftForearm,
  kRightUpperArm,
  kRightForearm,
  kLeftThigh,
  kLeftShin,
  kRightThigh,
  kRightShin,
  kBoneCount,
};

// Parents come before children, so global transforms can be composed in index order.
struct BoneRest {
  int parent;
  double x, y, z;  // joint position in the rest pose
};
constexpr std::array<BoneRest, kBoneCount> kSkeleton = {{
    {-1, 0.0, 0.95, 0.0},                // pelvis (root)
    {kPelvis, 0.0, 1.15, 0.0},           // chest: waist joint
    {kChest, 0.0, 1.50, 0.0},            // head: neck joint
    {kChest, 0.23, 1.40, 0.0},           // left shoulder
    {kLeftUpperArm, 0.23, 1.12, 0.0},    // left elbow
    {kChest, -0.23, 1.40, 0.0},          // right shoulder
    {kRightUpperArm, -0.23, 1.12, 0.0},  // right elbow
    {kPelvis, 0.10, 0.92, 0.0},          // left hip
    {kLeftThigh, 0.10, 0.50, 0.0},       // left knee
    {kPelvis, -0.10, 0.92, 0.0},         // right hip
    {kRightThigh, -0.10, 0.50, 0.0},     // right knee
}};

Eigen::Vector3d Joint(int bone) {
  return {kSkeleton[bone].x, kSkeleton[bone].y, kSkeleton[bone].z};
}

// A capsule part: axis along +y (up) or −y (hanging) from its origin, skinned to `first_bone`
// before the joint and `second_bone` past it, with the weight ramping across the joint.
struct PartSpec {
  double radius;
  double length;
  double origin_x, origin_y, origin_z;
  bool points_up;
  double depth_scale;  // front-to-back (z) scale of the cross-section
  Bone first_bone;     // bone near the origin
  Bone second_bone;    // bone past the joint (== first_bone for a rigid part)
  double joint_along;  // axial position of the blend centre
  double blend_width;  // the weight ramps from 0 to 1 over this axial band
};
constexpr std::array<PartSpec, 6> kParts = {{
    {0.16, 0.41, 0.0, 0.95, 0.0, true, 0.65, kPelvis, kChest, 0.20, 0.20},  // torso
    {0.105, 0.05, 0.0, 1.62, 0.0, true, 0.95, kHead, kHead, 0.0, 1.0},      // head
    {0.045, 0.60, 0.23, 1.40, 0.0, false, 1.0, kLeftUpperArm, kLeftForearm, 0.28, 0.10},
    {0.045, 0.60, -0.23, 1.40, 0.0, false, 1.0, kRightUpperArm, kRightForearm, 0.28, 0.10},
    {0.065, 0.84, 0.10, 0.92, 0.0, false, 1.0, kLeftThigh, kLeftShin, 0.42, 0.16},
    {0.065, 0.84, -0.10, 0.92, 0.0, false, 1.0, kRightThigh, kRightShin, 0.42, 0.16},
}};

// 0 below -1/2, 1 above +1/2, C²-smooth in between (Perlin's smootherstep).
double SmoothRamp(double x) {
  const double s = std::clamp(x + 0.5, 0.0, 1.0);
  return s * s * s * (s * (6.0 * s - 15.0) + 10.0);
}

// Per-vertex LBS data: position = (1 − weight) · M[first] · rest + weight · M[second] · rest.
struct SkinnedMesh {
  RestMesh rest;
  std::vector<std::array<int8_t, 2>> bones;
  std::vector<double> second_weight;
};

SkinnedMesh BuildFigure(double spacing) {
  SkinnedMesh figure;
  std::vector<RestMesh> parts;
  int vertex_total = 0, triangle_total = 0;
  for (const PartSpec& spec : kParts) {
    parts.push_back(BuildCapsule(spec.radius, spec.length,
                                 LayoutCapsule(spec.radius, spec.length, spacing, kMinSegments)));
    vertex_total += parts.back().vertex_count();
    triangle_total += static_cast<int>(parts.back().triangles.rows());
  }
  figure.rest.positions.resize(vertex_total, 3);
  figure.rest.triangles.resize(triangle_total, 3);
  figure.bones.resize(vertex_total);
  figure.second_weight.resize(vertex_total);
  int vertex_offset = 0, triangle_offset = 0;
  for (size_t p = 0; p < parts.size(); ++p) {
    const PartSpec& spec = kParts[p];
    const RestMesh& part = parts[p];
    // Capsule frame (x, y, z=axis) → world: (u, v, axis) right-handed, so orientation is kept.
    const Eigen::Vector3d axis(0.0, spec.points_up ? 1.0 : -1.0, 0.0);
    const Eigen::Vector3d u = spec.points_up ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(1, 0, 0);
    const Eigen::Vector3d v = spec.points_up ? Eigen::Vector3d(1, 0, 0) : Eigen::Vector3d(0, 0, 1);
    const Eigen::Vector3d origin(spec.origin_x, spec.origin_y, spec.origin_z);
    for (int i = 0; i < part.vertex_count(); ++i) {
      Eigen::Vector3d cross = u * part.positions(i, 0) + v * part.positions(i, 1);
      cross.z() *= spec.depth_scale;
      const double along = part.positions(i, 2);
      const int out = vertex_offset + i;
      figure.rest.positions.row(out) = (origin + axis * along + cross).transpose();
      figure.bones[out] = {static_cast<int8_t>(spec.first_bone),
                           static_cast<int8_t>(spec.second_bone)};
      figure.second_weight[out] = spec.first_bone == spec.second_bone
                                      ? 0.0
                                      : SmoothRamp((along - spec.joint_along) / spec.blend_width);
    }
    figure.rest.triangles.middleRows(triangle_offset, part.triangles.rows()) =
        part.triangles.array() + vertex_offset;
    vertex_offset += part.vertex_count();
    triangle_offset += static_cast<int>(part.triangles.rows());
  }
  return figure;
}

// Gait parameters drawn from the seed; angles in radians, lengths in metres.
struct Gait {
  double period;  // seconds per cycle (two steps)
  double phase;
  double hip_swing, knee_flex, shoulder_swing, elbow_flex;
  double pelvis_turn, arm_abduction, sway, bob, speed;

  explicit Gait(uint64_t seed) {
    SeededRandom random(seed, kRandomStream);
    period = random.Uniform(1.0, 1.2);
    phase = random.Phase();
    hip_swing = random.Uniform(0.38, 0.5);
    knee_flex = random.Uniform(0.5, 0.7);
    shoulder_swing = random.Uniform(0.25, 0.4);
    elbow_flex = random.Uniform(0.2, 0.35);
    pelvis_turn = random.Uniform(0.05, 0.1);
    arm_abduction = random.Uniform(0.08, 0.12);
    sway = random.Uniform(0.015, 0.03);
    bob = random.Uniform(0.015, 0.03);
    // Two steps per cycle, each as long as the chord the leg sweeps.
    const double leg_length = Joint(kLeftThigh).y() - 0.08;  // hip to ankle
    speed = 2.0 * (2.0 * leg_length * std::sin(hip_swing)) / period;
  }
};

// Rotation that swings a hanging limb forward (+z) by `angle` (negative: backwards).
Eigen::Matrix3d Swing(double angle) {
  return Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d Turn(double angle) {  // about the vertical axis
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d Roll(double angle) {  // about the walking direction
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// Skinning transforms (global pose × inverse rest pose) of every bone at `time`.
std::array<Eigen::Isometry3d, kBoneCount> PoseSkeleton(const Gait& gait, double time) {
  const double cycle = 2.0 * kPi * time / gait.period + gait.phase;
  const double left = cycle, right = cycle + kPi;  // the legs' phases; arms swing opposite
  // Knee flexion peaks in mid-swing, when the hip swings forward fastest.
  auto knee = [&](double leg_phase) {
    const double bump = 0.5 + 0.5 * std::cos(leg_phase - 0.3);
    return 0.08 + gait.knee_flex * bump * bump;
  };
  auto elbow = [&](double arm_phase) {
    return 0.2 + gait.elbow_flex * (0.5 + 0.5 * std::sin(arm_phase));
  };

  std::array<Eigen::Matrix3d, kBoneCount> local;
  local[kPelvis] = Turn(gait.pelvis_turn * std::sin(cycle)) * Roll(0.035 * std::cos(cycle));
  // The chest counter-rotates against the pelvis and leans slightly forward.
  local[kChest] = Turn(-1.4 * gait.pelvis_turn * std::sin(cycle)) *
                  Swing(-(0.06 + 0.015 * std::cos(2.0 * cycle)));
  // The head turns back towards the walking direction and nods twice per cycle.
  local[kHead] =
      Turn(0.9 * gait.pelvis_turn * std::sin(cycle)) * Swing(-0.04 * std::sin(2.0 * cycle));
  local[kLeftUpperArm] = Roll(gait.arm_abduction) * Swing(gait.shoulder_swing * std::sin(right));
  local[kLeftForearm] = Swing(elbow(right));
  local[kRightUpperArm] = Roll(-gait.arm_abduction) * Swing(gait.shoulder_swing * std::sin(left));
  local[kRightForearm] = Swing(elbow(left));
  local[kLeftThigh] = Swing(0.05 + gait.hip_swing * std::sin(left));
  local[kLeftShin] = Swing(-knee(left));
  local[kRightThigh] = Swing(0.05 + gait.hip_swing * std::sin(right));
  local[kRightShin] = Swing(-knee(right));

  const Eigen::Vector3d root_offset(gait.sway * std::sin(cycle), gait.bob * std::cos(2.0 * cycle),
                                    gait.speed * time);
  std::array<Eigen::Isometry3d, kBoneCount> global;
  std::array<Eigen::Isometry3d, kBoneCount> skinning;
  for (int bone = 0; bone < kBoneCount; ++bone) {
    Eigen::Isometry3d joint_frame = Eigen::Isometry3d::Identity();
    joint_frame.linear() = local[bone];
    const int parent = kSkeleton[bone].parent;
    if (parent < 0) {
      joint_frame.translation() = Joint(bone) + root_offset;
      global[bone] = joint_frame;
    } else {
      joint_frame.translation() = Joint(bone) - Joint(parent);
      global[bone] = global[parent] * joint_frame;
    }
    skinning[bone] = global[bone] * Eigen::Translation3d(-Joint(bone));
  }
  return skinning;
}

int FigureVertexCount(double spacing) {
  int count = 0;
  for (const PartSpec& spec : kParts) {
    count += LayoutCapsule(spec.radius, spec.length, spacing, kMinSegments).vertex_count();
  }
  return count;
}

}  // namespace

MeshSequence GenerateWalker(const SynthOptions& options) {
  double area = 0.0;
  for (const PartSpec& spec : kParts) {
    area += 2.0 * kPi * spec.radius * spec.length + 4.0 * kPi * spec.radius * spec.radius;
  }
  const double spacing =
      FitSpacing(FigureVertexCount, options.resolution, std::sqrt(area / options.resolution));
  const SkinnedMesh figure = BuildFigure(spacing);
  const Gait gait(options.seed);

  return AnimateFrames(
      figure.rest, options.frames, "walker", [&](double time, FramePositionsD& out) {
        const auto skinning = PoseSkeleton(gait, time);
        for (int v = 0; v < figure.rest.vertex_count(); ++v) {
          const Eigen::Vector3d rest = figure.rest.positions.row(v).transpose();
          const double w = figure.second_weight[v];
          const auto& first = skinning[figure.bones[v][0]];
          const auto& second = skinning[figure.bones[v][1]];
          out.row(v) = ((1.0 - w) * (first * rest) + w * (second * rest)).transpose();
        }
      });
}

}  // namespace dmc::synth
