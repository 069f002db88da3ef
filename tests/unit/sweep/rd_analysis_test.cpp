// Rate–distortion analysis: efficient points, interpolated rates and BD-rates checked on curves
// whose answers are known in closed form.
#include "sweep/rd_analysis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace dmc::sweep {
namespace {

TEST(ParetoFront, KeepsOnlyPointsThatBuyLowerDistortion) {
  const std::vector<RdSample> front = ParetoFront({
      {4.0, 0.02},
      {1.0, 0.10},
      {2.0, 0.12},  // dearer than (1, 0.10) and worse: dropped
      {2.0, 0.05},
      {8.0, 0.02},  // same distortion as a cheaper point: dropped
      {0.0, 0.50},  // a rate a log axis cannot hold: ignored
      {3.0, NAN},   // not finite: ignored
  });
  ASSERT_EQ(front.size(), 3u);
  EXPECT_EQ(front[0].rate, 1.0);
  EXPECT_EQ(front[1].rate, 2.0);
  EXPECT_EQ(front[1].distortion, 0.05);
  EXPECT_EQ(front[2].rate, 4.0);
}

TEST(RateForDistortion, InterpolatesOnTheLogLogLine) {
  // rate · distortion = 0.1 on both points, so the log–log line is exact: D = 0.05 → R = 2.
  const std::vector<RdSample> front = ParetoFront({{1.0, 0.1}, {4.0, 0.025}});
  const RateAtTarget rate = RateForDistortion(front, 0.05);
  EXPECT_EQ(rate.kind, RateAtTarget::Kind::kInterpolated);
  EXPECT_NEAR(rate.rate, 2.0, 1e-12);
  // At a point exactly.
  EXPECT_NEAR(RateForDistortion(front, 0.025).rate, 4.0, 1e-12);
}

TEST(RateForDistortion, SaysWhenTheTargetIsOutsideTheSweep) {
  const std::vector<RdSample> front = ParetoFront({{1.0, 0.1}, {4.0, 0.025}});
  const RateAtTarget easy = RateForDistortion(front, 0.2);
  EXPECT_EQ(easy.kind, RateAtTarget::Kind::kBelowRange);
  EXPECT_EQ(easy.rate, 1.0);
  const RateAtTarget hard = RateForDistortion(front, 0.01);
  EXPECT_EQ(hard.kind, RateAtTarget::Kind::kAboveRange);
  EXPECT_EQ(hard.rate, 4.0);
  EXPECT_EQ(RateForDistortion({}, 0.01).rate, 0.0);
}

TEST(BjontegaardDeltaRate, AConstantRateRatioIsTheBdRate) {
  // ln R_test − ln R_anchor = ln 0.8 everywhere, so the BD-rate is −20 % whatever the curve shape.
  std::vector<RdSample> anchor, test;
  for (const auto& [rate, distortion] :
       std::vector<std::pair<double, double>>{{0.5, 0.2}, {1.0, 0.07}, {2.0, 0.03}, {5.0, 0.01}}) {
    anchor.push_back({rate, distortion});
    test.push_back({0.8 * rate, distortion});
  }
  const auto bd = BjontegaardDeltaRate(ParetoFront(anchor), ParetoFront(test));
  ASSERT_TRUE(bd.has_value());
  EXPECT_NEAR(*bd, -20.0, 1e-9);
  const auto reverse = BjontegaardDeltaRate(ParetoFront(test), ParetoFront(anchor));
  EXPECT_NEAR(*reverse, 25.0, 1e-9);  // 1 / 0.8 − 1
}

TEST(BjontegaardDeltaRate, OnlyTheCommonDistortionRangeCounts) {
  // Test costs twice the anchor over D in [0.01, 0.1] and goes on to D = 0.001, where the anchor
  // has no data: only the overlap, where the ratio is 2, counts (both are log–log lines).
  const std::vector<RdSample> anchor = ParetoFront({{1.0, 0.1}, {10.0, 0.01}});
  const std::vector<RdSample> test = ParetoFront({{2.0, 0.1}, {20.0, 0.01}, {200.0, 0.001}});
  EXPECT_NEAR(*BjontegaardDeltaRate(anchor, test), 100.0, 1e-9);
}

TEST(BjontegaardDeltaRate, UndefinedWithoutOverlapOrWithTooFewPoints) {
  const std::vector<RdSample> high = ParetoFront({{1.0, 0.5}, {2.0, 0.2}});
  const std::vector<RdSample> low = ParetoFront({{4.0, 0.05}, {8.0, 0.01}});
  EXPECT_FALSE(BjontegaardDeltaRate(high, low).has_value());
  EXPECT_FALSE(BjontegaardDeltaRate(high, ParetoFront({{1.0, 0.3}})).has_value());
}

TEST(Pchip, ReproducesLinesAndIntegratesThemExactly) {
  const Pchip line({0.0, 1.0, 3.0, 4.0}, {1.0, 3.0, 7.0, 9.0});  // y = 2x + 1
  for (const double x : {0.0, 0.3, 1.0, 2.2, 3.9, 4.0}) EXPECT_NEAR(line(x), 2 * x + 1, 1e-12);
  // ∫₀.₅³·⁵ (2x + 1) dx = [x² + x] = 15.75 − 0.75.
  EXPECT_NEAR(line.Integral(0.5, 3.5), 15.0, 1e-12);
}

TEST(Pchip, StaysMonotoneAndItsIntegralMatchesQuadrature) {
  // Monotone data with a sharp step: PCHIP must not overshoot (a natural cubic spline would).
  const std::vector<double> x = {0.0, 1.0, 2.0, 3.0, 4.0, 6.0};
  const std::vector<double> y = {0.0, 0.1, 0.2, 2.0, 2.1, 2.2};
  const Pchip curve(x, y);
  double previous = curve(0.0), quadrature = 0.0;
  const int steps = 60000;
  for (int i = 1; i <= steps; ++i) {
    const double at = 6.0 * i / steps;
    const double value = curve(at);
    EXPECT_GE(value, previous - 1e-12) << at;
    quadrature += 0.5 * (value + previous) * (6.0 / steps);
    previous = value;
  }
  for (size_t k = 0; k < x.size(); ++k) EXPECT_NEAR(curve(x[k]), y[k], 1e-12);
  EXPECT_NEAR(curve.Integral(0.0, 6.0), quadrature, 1e-7);
  EXPECT_NEAR(curve.Integral(1.5, 4.5), curve.Integral(0.0, 4.5) - curve.Integral(0.0, 1.5), 1e-12);
}

}  // namespace
}  // namespace dmc::sweep
