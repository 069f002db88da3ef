#include "sweep/rd_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dmc::sweep {
namespace {

int Sign(double value) { return (value > 0.0) - (value < 0.0); }

// Fritsch–Carlson end slope (the three-point formula, kept shape preserving), as SciPy's
// PchipInterpolator does.
double EndSlope(double h0, double h1, double delta0, double delta1) {
  const double slope = ((2.0 * h0 + h1) * delta0 - h0 * delta1) / (h0 + h1);
  if (Sign(slope) != Sign(delta0)) return 0.0;
  if (Sign(delta0) != Sign(delta1) && std::abs(slope) > 3.0 * std::abs(delta0)) {
    return 3.0 * delta0;
  }
  return slope;
}

// ∫₀ˢ of the cubic Hermite piece with end values y0, y1 and end slopes m0, m1 over a piece of
// width h, in units of x (t = (x − x0)/h runs over [0, s]).
double PieceIntegral(double h, double y0, double y1, double m0, double m1, double s) {
  const double s2 = s * s, s3 = s2 * s, s4 = s3 * s;
  const double h00 = s4 / 2.0 - s3 + s;
  const double h10 = s4 / 4.0 - 2.0 * s3 / 3.0 + s2 / 2.0;
  const double h01 = -s4 / 2.0 + s3;
  const double h11 = s4 / 4.0 - s3 / 3.0;
  return h * (h00 * y0 + h10 * h * m0 + h01 * y1 + h11 * h * m1);
}

}  // namespace

Pchip::Pchip(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
  const size_t n = x_.size();
  slope_.assign(n, 0.0);
  if (n < 2) return;
  std::vector<double> h(n - 1), delta(n - 1);
  for (size_t k = 0; k + 1 < n; ++k) {
    h[k] = x_[k + 1] - x_[k];
    delta[k] = (y_[k + 1] - y_[k]) / h[k];
  }
  if (n == 2) {
    slope_[0] = slope_[1] = delta[0];
    return;
  }
  for (size_t k = 1; k + 1 < n; ++k) {
    // A local extremum (or a flat side) gets a zero slope; otherwise the weighted harmonic mean
    // of the two secants keeps the interpolant monotone.
    if (Sign(delta[k - 1]) * Sign(delta[k]) <= 0) continue;
    const double w1 = 2.0 * h[k] + h[k - 1];
    const double w2 = h[k] + 2.0 * h[k - 1];
    slope_[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]);
  }
  slope_[0] = EndSlope(h[0], h[1], delta[0], delta[1]);
  slope_[n - 1] = EndSlope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
}

double Pchip::operator()(double at) const {
  if (x_.empty()) return 0.0;
  if (at <= x_.front()) return y_.front();
  if (at >= x_.back()) return y_.back();
  const size_t k = static_cast<size_t>(std::upper_bound(x_.begin(), x_.end(), at) - x_.begin()) - 1;
  const double h = x_[k + 1] - x_[k];
  const double t = (at - x_[k]) / h;
  const double t2 = t * t, t3 = t2 * t;
  return (2 * t3 - 3 * t2 + 1) * y_[k] + (t3 - 2 * t2 + t) * h * slope_[k] +
         (-2 * t3 + 3 * t2) * y_[k + 1] + (t3 - t2) * h * slope_[k + 1];
}

double Pchip::Integral(double a, double b) const {
  // ∫ from x_0 to `at`, summing whole pieces and the part of the last one.
  const auto from_start = [this](double at) {
    double total = 0.0;
    for (size_t k = 0; k + 1 < x_.size() && at > x_[k]; ++k) {
      const double h = x_[k + 1] - x_[k];
      const double s = std::min(1.0, (at - x_[k]) / h);
      total += PieceIntegral(h, y_[k], y_[k + 1], slope_[k], slope_[k + 1], s);
    }
    return total;
  };
  return from_start(b) - from_start(a);
}

std::vector<RdSample> ParetoFront(std::vector<RdSample> samples) {
  std::erase_if(samples, [](const RdSample& s) {
    return !(std::isfinite(s.rate) && std::isfinite(s.distortion) && s.rate > 0.0 &&
             s.distortion > 0.0);
  });
  std::sort(samples.begin(), samples.end(), [](const RdSample& a, const RdSample& b) {
    return a.rate != b.rate ? a.rate < b.rate : a.distortion < b.distortion;
  });
  std::vector<RdSample> front;
  for (const RdSample& sample : samples) {
    if (front.empty() || sample.distortion < front.back().distortion) front.push_back(sample);
  }
  return front;
}

RateAtTarget RateForDistortion(const std::vector<RdSample>& front, double target) {
  if (front.empty()) return {RateAtTarget::Kind::kAboveRange, 0.0};
  if (front.front().distortion <= target) {
    return {RateAtTarget::Kind::kBelowRange, front.front().rate};
  }
  for (size_t k = 0; k + 1 < front.size(); ++k) {
    const RdSample& cheap = front[k];
    const RdSample& dear = front[k + 1];
    if (dear.distortion <= target) {
      const double t = (std::log(target) - std::log(cheap.distortion)) /
                       (std::log(dear.distortion) - std::log(cheap.distortion));
      return {RateAtTarget::Kind::kInterpolated,
              std::exp(std::log(cheap.rate) + t * (std::log(dear.rate) - std::log(cheap.rate)))};
    }
  }
  return {RateAtTarget::Kind::kAboveRange, front.back().rate};
}

std::optional<double> BjontegaardDeltaRate(const std::vector<RdSample>& anchor,
                                           const std::vector<RdSample>& test) {
  if (anchor.size() < 2 || test.size() < 2) return std::nullopt;
  // x = log10 D increasing: a front lists distortion decreasing, so walk it backwards.
  const auto curve = [](const std::vector<RdSample>& front) {
    std::vector<double> x, y;
    for (auto it = front.rbegin(); it != front.rend(); ++it) {
      x.push_back(std::log10(it->distortion));
      y.push_back(std::log(it->rate));
    }
    return Pchip(std::move(x), std::move(y));
  };
  const double low =
      std::max(std::log10(anchor.back().distortion), std::log10(test.back().distortion));
  const double high =
      std::min(std::log10(anchor.front().distortion), std::log10(test.front().distortion));
  if (!(high > low)) return std::nullopt;
  const double mean_difference =
      (curve(test).Integral(low, high) - curve(anchor).Integral(low, high)) / (high - low);
  return 100.0 * (std::exp(mean_difference) - 1.0);
}

}  // namespace dmc::sweep
