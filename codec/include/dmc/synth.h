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
#include "dmc/tvm.h"

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

// Time-varying examples (every frame has its own connectivity) with known volume-centre
// trajectories, the inputs of dmc::tvm (see dmc/tvm.h), listed apart from the dynamic meshes above:
//   prism      a pentagonal prism (circumradius 1, height 2, axis z) rotating about its axis; each
//              frame is re-triangulated with a different sampling (vertex count within about ±20%
//              of `resolution`); centres on a lattice inside the volume, rotating with it.
//   collision  a unit cube and a sphere of radius 0.5 on the x axis that approach, touch at the
//              middle frame (a point contact at the origin) and separate to a different gap; the
//              cube spins about x, the sphere about z; each is re-tessellated every frame. Centres
//              0 .. m-1 lie on a lattice inside the cube, the rest inside the sphere.
// Same determinism and timing contract as Synthesize (frame f at f / 30 s; the seed varies the
// speeds, never the connectivity pattern); centres number about `centres` (within ±25%).
struct TimeVaryingSynthOptions {
  int frames = 60;
  int resolution = 2000;  // approximate vertex count per frame
  int centres = 300;      // approximate number of volume centres
  uint64_t seed = 1;
};
inline constexpr int kMinSynthCentres = 8;
inline constexpr int kMaxSynthCentres = 100'000;

struct TimeVaryingSynthesis {
  tvm::TimeVaryingMesh mesh;        // name == the generator's, frame_rate == 30
  tvm::CentreTrajectories centres;  // one trajectory per volume centre, same frame count
};

// Names (prism, collision) and one-line descriptions of the time-varying generators.
std::vector<std::string_view> TimeVaryingSynthNames();
std::string_view TimeVaryingSynthDescription(std::string_view name);

// Errors: kNotFound for an unknown name (listing the known ones); kInvalidArgument naming the
// option for frames, resolution or centres out of range.
StatusOr<TimeVaryingSynthesis> SynthesizeTimeVarying(std::string_view name,
                                                     const TimeVaryingSynthOptions& options = {});

}  // namespace dmc
