// Real spherical harmonics up to degree 4, for smooth deformations of a sphere.
#pragma once

#include <Eigen/Core>
#include <array>

namespace dmc::synth {

inline constexpr int kMaxHarmonicDegree = 4;
inline constexpr int kHarmonicCount = (kMaxHarmonicDegree + 1) * (kMaxHarmonicDegree + 1);

// Index of Y_l^m (−l ≤ m ≤ l) in the arrays below: l² + l + m.
constexpr int HarmonicIndex(int l, int m) { return l * l + l + m; }

// Evaluates the orthonormal real spherical harmonics Y_l^m, l ≤ 4, at the unit vector `u`
// (∫ Y_i Y_j dΩ = δ_ij over the unit sphere), in the Cartesian polynomial form (no trig).
// `u` must have unit length.
std::array<double, kHarmonicCount> RealSphericalHarmonics(const Eigen::Vector3d& u);

}  // namespace dmc::synth
