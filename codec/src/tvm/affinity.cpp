// AffinityGraph: a(i, j) = exp(-(alpha max_f |x_i,f - x_j,f|)^2) without O(n^2 F) work.
//
// The key bound: max_f |x_i,f - x_j,f| >= |x_i,0 - x_j,0|, so every centre within max-distance r
// of centre i lies within distance r of it in frame 0, where a kd-tree finds it. The K most affine
// centres are found exactly by taking the K nearest in frame 0, using the K-th smallest of their
// max-distances as r, and scanning frame-0 neighbours within r.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "dmc/tvm.h"
#include "tvm/kd_tree.h"

namespace dmc::tvm {
namespace {

Status ValidateAffinityOptions(const AffinityOptions& options) {
  if (options.neighbours < 1) {
    return InvalidArgumentError("the affinity neighbourhood must hold at least 1 centre, got " +
                                std::to_string(options.neighbours));
  }
  if (!(options.alpha >= 0.0) || !std::isfinite(options.alpha)) {
    return InvalidArgumentError("alpha must be finite and >= 0 (0 = automatic), got " +
                                std::to_string(options.alpha));
  }
  if (!(options.min_affinity > 0.0 && options.min_affinity < 1.0)) {
    return InvalidArgumentError("min_affinity must be in (0, 1), got " +
                                std::to_string(options.min_affinity));
  }
  return Status::Ok();
}

// The alpha asked for, or for 0 the automatic 1 / spacing (any value for a single centre, which
// has affinity 1 with itself whatever alpha is).
StatusOr<double> ChooseAlpha(double requested, int centre_count, double spacing) {
  if (requested != 0.0) return requested;
  if (centre_count == 1) return 1.0;
  if (spacing <= 0.0) {
    return InvalidArgumentError(
        "cannot choose alpha automatically: the median distance between neighbouring centres "
        "in frame 0 is 0 (coinciding centres); give alpha explicitly");
  }
  return 1.0 / spacing;
}

}  // namespace

struct AffinityGraph::Impl {
  CentreTrajectories centres;
  double alpha = 0.0;
  double min_affinity = 0.0;
  double cutoff_distance = 0.0;  // max-distance beyond which the affinity is below min_affinity
  double spacing = 0.0;
  int neighbour_count = 0;
  std::vector<int32_t> neighbours;          // n x neighbour_count
  std::vector<double> affinities;           // n x neighbour_count
  std::vector<tvm_internal::KdTree> trees;  // one per frame

  // max_f |x_i,f - x_j,f|, stopping early once it exceeds `limit`.
  double MaxDistance(int i, int j, double limit = std::numeric_limits<double>::infinity()) const {
    double max_squared = 0.0;
    const double limit_squared = limit * limit;
    for (const FramePositionsD& frame : centres.positions) {
      max_squared = std::max(max_squared, (frame.row(i) - frame.row(j)).squaredNorm());
      if (max_squared > limit_squared) break;
    }
    return std::sqrt(max_squared);
  }
  double AffinityOfDistance(double distance) const {
    const double x = alpha * distance;
    const double affinity = std::exp(-x * x);
    return affinity < min_affinity ? 0.0 : affinity;
  }

  // Median nearest-neighbour spacing in frame 0, the natural length scale of the centres (0 for
  // a single centre). Needs the frame trees.
  double MedianSpacing() const {
    const int n = centres.centre_count();
    if (n <= 1) return 0.0;
    const FramePositionsD& first = centres.positions.front();
    std::vector<double> nearest(static_cast<size_t>(n));
    tbb::parallel_for(0, n, [&](int i) {
      const auto two = trees.front().KNearest(first.row(i).transpose(), 2);
      nearest[static_cast<size_t>(i)] = std::sqrt(two.back().first);
    });
    std::nth_element(nearest.begin(), nearest.begin() + n / 2, nearest.end());
    return nearest[static_cast<size_t>(n / 2)];
  }

  // The k most affine centres of centre i as (max-distance, index), ascending, exactly (see the
  // file comment).
  std::vector<std::pair<double, int32_t>> MostAffine(int i, int k) const {
    const Eigen::Vector3d query = centres.positions.front().row(i).transpose();
    std::vector<std::pair<double, int32_t>> best;
    for (const auto& [d2, j] : trees.front().KNearest(query, k)) {
      best.emplace_back(MaxDistance(i, j), j);
    }
    std::sort(best.begin(), best.end());
    const double radius = best.back().first;
    std::vector<int32_t> candidates;
    trees.front().WithinRadius(query, radius * radius, candidates);
    for (const int32_t j : candidates) {
      const std::pair<double, int32_t> entry{MaxDistance(i, j, best.back().first), j};
      if (!(entry < best.back())) continue;
      if (std::find_if(best.begin(), best.end(), [j](const auto& e) { return e.second == j; }) !=
          best.end()) {
        continue;
      }
      best.insert(std::upper_bound(best.begin(), best.end(), entry), entry);
      best.pop_back();
    }
    return best;
  }

  // Fills the n × k neighbour and affinity tables. Needs alpha and min_affinity.
  void FindMostAffine(int k) {
    const int n = centres.centre_count();
    neighbour_count = k;
    neighbours.resize(static_cast<size_t>(n) * k);
    affinities.resize(static_cast<size_t>(n) * k);
    tbb::parallel_for(0, n, [&](int i) {
      const std::vector<std::pair<double, int32_t>> best = MostAffine(i, k);
      for (int slot = 0; slot < k; ++slot) {
        const size_t at = static_cast<size_t>(i) * k + slot;
        neighbours[at] = best[static_cast<size_t>(slot)].second;
        affinities[at] = AffinityOfDistance(best[static_cast<size_t>(slot)].first);
      }
    });
  }
};

StatusOr<AffinityGraph> AffinityGraph::Build(const CentreTrajectories& centres,
                                             const AffinityOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateCentres(centres));
  DMC_RETURN_IF_ERROR(ValidateAffinityOptions(options));
  auto impl = std::make_shared<Impl>();
  impl->centres = centres;
  impl->trees.resize(static_cast<size_t>(centres.frame_count()));
  tbb::parallel_for(0, centres.frame_count(), [&](int f) {
    impl->trees[static_cast<size_t>(f)] =
        tvm_internal::KdTree(centres.positions[static_cast<size_t>(f)]);
  });
  impl->spacing = impl->MedianSpacing();
  DMC_ASSIGN_OR_RETURN(impl->alpha,
                       ChooseAlpha(options.alpha, centres.centre_count(), impl->spacing));
  impl->min_affinity = options.min_affinity;
  impl->cutoff_distance = std::sqrt(-std::log(options.min_affinity)) / impl->alpha;
  impl->FindMostAffine(std::min(options.neighbours, centres.centre_count()));
  AffinityGraph graph;
  graph.impl_ = std::move(impl);
  return graph;
}

double AffinityGraph::alpha() const { return impl_->alpha; }
int AffinityGraph::centre_count() const { return impl_->centres.centre_count(); }
int AffinityGraph::neighbour_count() const { return impl_->neighbour_count; }
double AffinityGraph::spacing() const { return impl_->spacing; }
const CentreTrajectories& AffinityGraph::centres() const { return impl_->centres; }

std::span<const int32_t> AffinityGraph::Neighbours(int centre) const {
  return {impl_->neighbours.data() + static_cast<size_t>(centre) * impl_->neighbour_count,
          static_cast<size_t>(impl_->neighbour_count)};
}

std::span<const double> AffinityGraph::NeighbourAffinities(int centre) const {
  return {impl_->affinities.data() + static_cast<size_t>(centre) * impl_->neighbour_count,
          static_cast<size_t>(impl_->neighbour_count)};
}

double AffinityGraph::Affinity(int i, int j) const {
  return impl_->AffinityOfDistance(impl_->MaxDistance(i, j));
}

void AffinityGraph::ForEachAffine(int centre, const std::function<void(int, double)>& visit) const {
  std::vector<int32_t> candidates;
  const double cutoff = impl_->cutoff_distance;
  impl_->trees.front().WithinRadius(impl_->centres.position(centre, 0), cutoff * cutoff,
                                    candidates);
  std::sort(candidates.begin(), candidates.end());
  for (const int32_t j : candidates) {
    const double affinity = impl_->AffinityOfDistance(impl_->MaxDistance(centre, j, cutoff));
    if (affinity > 0.0) visit(j, affinity);
  }
}

int AffinityGraph::NearestCentre(int frame, const Eigen::Vector3d& point) const {
  return impl_->trees[static_cast<size_t>(frame)].Nearest(point);
}

}  // namespace dmc::tvm
