// blob: a sphere that deforms slowly, like a soft body drifting and turning.
//
// The rest mesh is a geodesic sphere. At time t a vertex with rest direction u sits at
// centre(t) + R(t) · exp(d(u, t)) · u, where d is a combination of the real spherical harmonics of
// degree ≤ 4 whose coefficients each hold a seeded offset (the blob's lumpy shape) plus a seeded
// slow oscillation. exp(·) keeps the radius positive, so the surface stays star-shaped about the
// centre and can neither self-intersect nor flip a triangle. R(t) is a slow rotation about a
// seeded axis and centre(t) a small drift.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "synth/generators.h"
#include "synth/random.h"
#include "synth/shapes.h"
#include "synth/spherical_harmonics.h"

namespace dmc::synth {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr uint64_t kRandomStream = 0x626c6f62;  // "blob"

// Per-degree scale of the log-radius coefficients: a gentle breathing (l = 0), then mostly
// degree 2–3 lumps. exp(d) stays within roughly [0.6, 1.6] for every seed.
constexpr std::array<double, kMaxHarmonicDegree + 1> kDegreeAmplitude = {0.04, 0.06, 0.08, 0.05,
                                                                         0.035};

struct BlobMotion {
  // coefficient_i(t) = offset_i + amplitude_i · sin(2π frequency_i t + phase_i)
  std::array<double, kHarmonicCount> offset, amplitude, frequency, phase;
  Eigen::Vector3d spin_axis;
  double spin_rate;  // rad/s
  Eigen::Vector3d drift;
  double drift_frequency;

  explicit BlobMotion(uint64_t seed) {
    SeededRandom random(seed, kRandomStream);
    for (int l = 0; l <= kMaxHarmonicDegree; ++l) {
      for (int m = -l; m <= l; ++m) {
        const int i = HarmonicIndex(l, m);
        // The mean radius (l = 0) only breathes; higher degrees also keep a lasting lump.
        offset[i] = l == 0 ? 0.0 : kDegreeAmplitude[l] * random.Uniform(-1.0, 1.0);
        amplitude[i] = kDegreeAmplitude[l] * random.Uniform(0.5, 1.0);
        // Low degrees move slower; nothing exceeds 0.7 Hz.
        frequency[i] = random.Uniform(0.15, 0.4 + 0.075 * l);
        phase[i] = random.Phase();
      }
    }
    spin_axis = random.UnitVector();
    spin_rate = random.Uniform(0.2, 0.4);
    drift = 0.1 * random.UnitVector();
    drift_frequency = random.Uniform(0.1, 0.2);
  }
};

}  // namespace

MeshSequence GenerateBlob(const SynthOptions& options) {
  // V = 10 n² + 2 for frequency n.
  const int frequency =
      std::max(1, static_cast<int>(std::lround(std::sqrt((options.resolution - 2) / 10.0))));
  const RestMesh rest = BuildGeodesicSphere(frequency);
  const BlobMotion motion(options.seed);

  return AnimateFrames(rest, options.frames, "blob", [&](double time, FramePositionsD& out) {
    std::array<double, kHarmonicCount> coefficient;
    for (int i = 0; i < kHarmonicCount; ++i) {
      coefficient[i] =
          motion.offset[i] +
          motion.amplitude[i] * std::sin(2.0 * kPi * motion.frequency[i] * time + motion.phase[i]);
    }
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(motion.spin_rate * time, motion.spin_axis).toRotationMatrix();
    const Eigen::Vector3d centre =
        motion.drift * std::sin(2.0 * kPi * motion.drift_frequency * time);
    for (int v = 0; v < rest.vertex_count(); ++v) {
      const Eigen::Vector3d direction = rest.positions.row(v).transpose();
      const auto basis = RealSphericalHarmonics(direction);
      double log_radius = 0.0;
      for (int i = 0; i < kHarmonicCount; ++i) log_radius += coefficient[i] * basis[i];
      out.row(v) = (centre + rotation * (std::exp(log_radius) * direction)).transpose();
    }
  });
}

}  // namespace dmc::synth
