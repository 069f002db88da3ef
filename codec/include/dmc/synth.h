// Built-in synthetic animations: deterministic dynamic meshes made in code, the default input of
// the quickstart, the tests and the benchmarks.
//
// Generators (see SynthNames() / SynthDescription()):
//   twist   a closed tube of elliptic section with rounded caps that twists and bends;
//           1 component, genus 0.
//   cloth   a rectangular flag pinned along its x = 0 edge, waving with travelling waves plus
//           seeded low-frequency noise; 1 component, 1 boundary loop (a disk).
//   walker  a six-part figure (torso, head, two arms, two legs; each a closed capsule) walking
//           along +z, animated by linear blend skinning of an 11-bone hierarchy with smooth
//           weights across elbows, knees and waist; 6 components, each genus 0.
//   blob    a geodesic sphere whose radius is deformed by seeded, slowly varying real spherical
//           harmonics of degree ≤ 4, turning slowly; 1 component, genus 0.
//
// Contract of every generator:
//  - Deterministic: the same (name, options) gives bit-identical output on every run of a build
//    (single-threaded, no global state). Every generator draws its motion parameters from
//    `seed`; different seeds give different motion but the same connectivity.
//  - Frame f is the pose at time f / 30 s (frame_rate = 30), so a sequence of F frames is a
//    prefix of a longer one with the same seed and resolution.
//  - Connectivity is constant and depends only on the name and the resolution: consistently
//    oriented triangles (outward normals for closed parts; the cloth faces +z), no degenerate
//    triangles, no duplicate or unreferenced vertices, edge-manifold.
//  - Motion is smooth in time (low temporal frequencies, at most about 1.5 Hz) and free of
//    triangle flips. Units are metres for the walker and arbitrary elsewhere (sizes of order 1).
//  - The vertex count approximates `resolution`: within ±10% from 1,000 vertices up and ±15%
//    from 500 up (the meshes are sampled from integer parameters; the blob's 10·n² + 2 steps are
//    the coarsest). Below 500 every part keeps a minimum sampling, so the count may deviate more.
//  - Cost is linear in vertices × frames: 200k vertices × 10 frames take well under a second
//    on one core.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc {

struct SynthOptions {
  int frames = 60;        // number of frames, 1 … kMaxSynthFrames
  int resolution = 2000;  // approximate vertex count, kMinSynthResolution … kMaxSynthResolution
  uint64_t seed = 1;      // any value; selects the motion parameters
};

inline constexpr int kMaxSynthFrames = 100'000;
inline constexpr int kMinSynthResolution = 100;
inline constexpr int kMaxSynthResolution = 1'000'000;

// Names of the built-in generators, in table order: twist, cloth, walker, blob.
std::vector<std::string_view> SynthNames();

// One-line description of a generator, or an empty view for an unknown name.
std::string_view SynthDescription(std::string_view name);

// Generates the named animation. The result has name == `name` and frame_rate == 30.
// Errors: kNotFound for an unknown name (the message lists the known names); kInvalidArgument
// naming the option for frames outside [1, kMaxSynthFrames] or resolution outside
// [kMinSynthResolution, kMaxSynthResolution].
StatusOr<MeshSequence> Synthesize(std::string_view name, const SynthOptions& options = {});

}  // namespace dmc
