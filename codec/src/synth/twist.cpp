// twist: a closed tube with rounded caps that twists about its axis and bends in a slowly
// turning direction.
//
// The tube lies along +z from z = 0 to z = kLength in the rest pose. Its cross-section is an
// ellipse (a round tube would look the same however it twists: only its vertices would slide). At
// time t each point is twisted about the axis by an angle growing linearly along the body (the caps
// turn rigidly with the end rings), then the axis is bent into a circular arc of curvature κ(t) in
// the plane at azimuth ψ(t). Bending maps the axis by arc length, so the body keeps its length; the
// caps follow the end frames rigidly.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "synth/generators.h"
#include "synth/random.h"
#include "synth/shapes.h"

namespace dmc::synth {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadius = 0.4;
constexpr double kLength = 4.0;
constexpr double kFlattening = 0.6;  // minor / major axis of the cross-section
constexpr int kMinSegments = 8;
constexpr uint64_t kRandomStream = 0x7477697374;  // "twist"

struct TwistMotion {
  double twist_amplitude;  // end-to-end twist angle at the peak, radians
  double twist_frequency;  // Hz
  double twist_phase;
  double bend_amplitude;  // peak curvature, 1/length
  double bend_frequency;  // Hz
  double bend_phase;
  double bend_azimuth;       // bend plane azimuth at t = 0
  double bend_azimuth_rate;  // rad/s

  explicit TwistMotion(uint64_t seed) {
    SeededRandom random(seed, kRandomStream);
    twist_amplitude = random.Uniform(0.7, 1.1) * kPi;
    twist_frequency = random.Uniform(0.25, 0.45);
    twist_phase = random.Phase();
    // Peak bend of 55°–90° over the body: the arc radius stays ≥ 2.5 tube radii, so the inner
    // side never folds.
    bend_amplitude = random.Uniform(0.6, 1.0) * 0.5 * kPi / kLength;
    bend_frequency = random.Uniform(0.25, 0.45);
    bend_phase = random.Phase();
    bend_azimuth = random.Phase();
    bend_azimuth_rate = random.Uniform(0.3, 0.6) * (random.Uniform(0.0, 1.0) < 0.5 ? -1 : 1);
  }
};

}  // namespace

MeshSequence GenerateTwist(const SynthOptions& options) {
  auto count = [](double spacing) {
    return LayoutCapsule(kRadius, kLength, spacing, kMinSegments).vertex_count();
  };
  const double area = 2.0 * kPi * kRadius * kLength + 4.0 * kPi * kRadius * kRadius;
  const double spacing =
      FitSpacing(count, options.resolution, std::sqrt(area / options.resolution));
  RestMesh rest =
      BuildCapsule(kRadius, kLength, LayoutCapsule(kRadius, kLength, spacing, kMinSegments));
  rest.positions.col(1) *= kFlattening;  // a positive scale keeps the outward orientation
  const TwistMotion motion(options.seed);

  return AnimateFrames(rest, options.frames, "twist", [&](double time, FramePositionsD& out) {
    const double twist = motion.twist_amplitude *
                         std::sin(2.0 * kPi * motion.twist_frequency * time + motion.twist_phase);
    const double curvature = motion.bend_amplitude *
                             std::sin(2.0 * kPi * motion.bend_frequency * time + motion.bend_phase);
    const double azimuth = motion.bend_azimuth + motion.bend_azimuth_rate * time;
    const double cos_azimuth = std::cos(azimuth), sin_azimuth = std::sin(azimuth);
    for (int v = 0; v < rest.vertex_count(); ++v) {
      const double x = rest.positions(v, 0), y = rest.positions(v, 1), z = rest.positions(v, 2);
      const double along = std::clamp(z, 0.0, kLength);  // arc length of the nearest axis point
      const double beyond = z - along;                   // offset past an end, in the caps
      const double angle = twist * along / kLength;
      const double twisted_x = std::cos(angle) * x - std::sin(angle) * y;
      const double twisted_y = std::sin(angle) * x + std::cos(angle) * y;
      // Coordinates in the bend plane: u towards the centre of curvature, w across it.
      const double u = cos_azimuth * twisted_x + sin_azimuth * twisted_y;
      const double w = -sin_azimuth * twisted_x + cos_azimuth * twisted_y;
      const double theta = curvature * along;
      const double sin_theta = std::sin(theta), cos_theta = std::cos(theta);
      // Axis point of the arc; (1 - cos θ)/κ written as 2 sin²(θ/2)/κ stays accurate as κ → 0.
      double axis_u = 0.0, axis_z = along;
      if (std::abs(curvature) > 1e-12) {
        const double half = std::sin(0.5 * theta);
        axis_u = 2.0 * half * half / curvature;
        axis_z = sin_theta / curvature;
      }
      const double bent_u = axis_u + u * cos_theta + beyond * sin_theta;
      const double bent_z = axis_z - u * sin_theta + beyond * cos_theta;
      out(v, 0) = cos_azimuth * bent_u - sin_azimuth * w;
      out(v, 1) = sin_azimuth * bent_u + cos_azimuth * w;
      out(v, 2) = bent_z;
    }
  });
}

}  // namespace dmc::synth
