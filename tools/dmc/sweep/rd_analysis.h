// Reading rate–distortion curves: the efficient points of a sweep, the rate a curve needs for a
// target distortion, and the Bjøntegaard delta rate between two curves.
//
// Rates and distortions are positive (bpfv and STED or KG). Curves are compared in the log–log
// plane, where codec curves are close to straight lines: interpolation is linear in
// (log distortion, log rate), and the BD-rate integrates log rate over log distortion.
#pragma once

#include <optional>
#include <vector>

namespace dmc::sweep {

struct RdSample {
  double rate = 0.0;        // bpfv
  double distortion = 0.0;  // STED or KG
};

// The efficient points: sorted by increasing rate, each with a strictly lower distortion than
// every cheaper point (a point that costs more for no gain is dropped; of equal rates the lowest
// distortion is kept). Samples with a non-positive or non-finite rate or distortion are ignored.
std::vector<RdSample> ParetoFront(std::vector<RdSample> samples);

// The rate a curve needs to reach `target` distortion.
struct RateAtTarget {
  enum class Kind {
    kInterpolated,  // `rate` interpolated between the two front points around the target
    kBelowRange,    // even the cheapest point is at or under the target: `rate` is that point's
                    // rate, an upper bound of what is needed
    kAboveRange,    // no point reaches the target: `rate` is the largest rate swept (a lower
                    // bound), or 0 for an empty front
  };
  Kind kind = Kind::kAboveRange;
  double rate = 0.0;
};

// `front` must come from ParetoFront. log(rate) is interpolated linearly in log(distortion).
RateAtTarget RateForDistortion(const std::vector<RdSample>& front, double target);

// Bjøntegaard delta rate of `test` against `anchor`, in percent: the average rate difference at
// equal distortion, exp(mean over the common log-distortion range of (ln R_test − ln R_anchor))
// − 1, times 100. Negative means `test` needs less rate. Both are Pareto fronts (ParetoFront);
// ln R is interpolated over log10 D by monotone piecewise cubic Hermite (PCHIP, Fritsch–Carlson),
// the method of current video-coding BD-rate tools, and integrated exactly piece by piece (the
// Hermite cubics are integrated in closed form). nullopt when a front has fewer than two points
// or the two distortion ranges do not overlap.
std::optional<double> BjontegaardDeltaRate(const std::vector<RdSample>& anchor,
                                           const std::vector<RdSample>& test);

// Monotone piecewise cubic Hermite interpolation through (x[i], y[i]), x strictly increasing,
// at least two points. Exposed for tests.
class Pchip {
 public:
  Pchip(std::vector<double> x, std::vector<double> y);
  double operator()(double at) const;  // clamped to [x.front(), x.back()]
  // ∫ from a to b (a ≤ b, both inside [x.front(), x.back()]), exact for the piecewise cubic.
  double Integral(double a, double b) const;

 private:
  std::vector<double> x_, y_, slope_;
};

}  // namespace dmc::sweep
