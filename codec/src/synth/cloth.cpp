// cloth: a rectangular flag pinned along its x = 0 edge (the pole) and waving in the wind.
//
// The sheet spans [0, kWidth] × [0, kHeight] in the z = 0 plane at rest. Its out-of-plane
// displacement is two travelling waves running away from the pole (slanted crests, different
// speeds) plus seeded low-frequency noise (a few random plane waves drifting slowly), all scaled
// by the distance from the pole so the pinned edge stays still. The free end also droops by a
// slowly varying amount, as a flag does when the wind eases.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "synth/generators.h"
#include "synth/random.h"
#include "synth/shapes.h"

namespace dmc::synth {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kWidth = 2.0;
constexpr double kHeight = 1.25;
constexpr uint64_t kRandomStream = 0x636c6f7468;  // "cloth"

// z += amplitude · sin(kx·x + ky·y − 2π·frequency·t + phase)
struct PlaneWave {
  double amplitude, kx, ky, frequency, phase;
  double At(double x, double y, double time) const {
    return amplitude * std::sin(kx * x + ky * y - 2.0 * kPi * frequency * time + phase);
  }
};

struct ClothMotion {
  std::array<PlaneWave, 2> waves;
  std::array<PlaneWave, 6> noise;
  double droop_mean, droop_amplitude, droop_frequency, droop_phase;

  explicit ClothMotion(uint64_t seed) {
    SeededRandom random(seed, kRandomStream);
    // Main wave: wavelength ≈ 1.2, about one flap per second.
    waves[0] = {random.Uniform(0.10, 0.14), 2.0 * kPi / random.Uniform(1.0, 1.4),
                random.Uniform(-0.8, 0.8), random.Uniform(0.7, 1.0), random.Phase()};
    // Ripple: shorter and faster, more slanted.
    waves[1] = {random.Uniform(0.03, 0.05), 2.0 * kPi / random.Uniform(0.45, 0.65),
                random.Uniform(-2.0, 2.0), random.Uniform(1.1, 1.5), random.Phase()};
    // Noise: wavelengths of 1.5–4 sheet units in random directions, drifting at ≤ 0.6 Hz.
    for (auto& mode : noise) {
      const double wavenumber = 2.0 * kPi / random.Uniform(1.5, 4.0);
      const double direction = random.Phase();
      mode = {random.Uniform(0.015, 0.03), wavenumber * std::cos(direction),
              wavenumber * std::sin(direction), random.Uniform(0.15, 0.6), random.Phase()};
    }
    droop_mean = random.Uniform(0.05, 0.08);
    droop_amplitude = random.Uniform(0.02, 0.035);
    droop_frequency = random.Uniform(0.1, 0.25);
    droop_phase = random.Phase();
  }
};

}  // namespace

MeshSequence GenerateCloth(const SynthOptions& options) {
  const int columns =
      std::max(2, static_cast<int>(std::lround(std::sqrt(options.resolution * kWidth / kHeight))));
  const int rows = std::max(2, static_cast<int>(std::lround(1.0 * options.resolution / columns)));
  const RestMesh rest = BuildGrid(columns, rows, kWidth, kHeight);
  const ClothMotion motion(options.seed);

  return AnimateFrames(rest, options.frames, "cloth", [&](double time, FramePositionsD& out) {
    const double droop =
        motion.droop_mean +
        motion.droop_amplitude *
            std::sin(2.0 * kPi * motion.droop_frequency * time + motion.droop_phase);
    for (int v = 0; v < rest.vertex_count(); ++v) {
      const double x = rest.positions(v, 0), y = rest.positions(v, 1);
      const double reach = x / kWidth;  // 0 on the pole, 1 on the free edge
      double z = 0.0;
      for (const auto& wave : motion.waves) z += wave.At(x, y, time);
      for (const auto& mode : motion.noise) z += mode.At(x, y, time);
      out(v, 0) = x;
      out(v, 1) = y - droop * reach * reach;
      out(v, 2) = reach * z;
    }
  });
}

}  // namespace dmc::synth
