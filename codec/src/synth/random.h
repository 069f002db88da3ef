// Seeded random numbers for the synthetic generators.
//
// Contract: a (seed, stream) pair always yields the same numbers on every platform and run.
// std::mt19937_64's raw output is pinned by the standard, but the std:: distributions are not,
// so the conversion to doubles is done here by hand. Each generator draws its parameters from its
// own stream, so adding a draw in one generator never shifts the numbers of another.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace dmc::synth {

class SeededRandom {
 public:
  SeededRandom(uint64_t seed, uint64_t stream) : engine_(Mix(seed ^ Mix(stream + 1))) {}

  // Uniform in [low, high), from the top 53 bits of one engine draw.
  double Uniform(double low, double high) {
    const double unit = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
    return low + (high - low) * unit;
  }
  // Uniform angle in [0, 2π).
  double Phase() { return Uniform(0.0, 2.0 * std::numbers::pi); }
  // A uniformly distributed unit vector (Archimedes: uniform z and azimuth).
  Eigen::Vector3d UnitVector() {
    const double z = Uniform(-1.0, 1.0);
    const double azimuth = Phase();
    const double planar = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {planar * std::cos(azimuth), planar * std::sin(azimuth), z};
  }

 private:
  // SplitMix64 finaliser: spreads nearby seeds (1, 2, 3, …) over unrelated engine states.
  static uint64_t Mix(uint64_t x) {
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
  }

  std::mt19937_64 engine_;
};

}  // namespace dmc::synth
