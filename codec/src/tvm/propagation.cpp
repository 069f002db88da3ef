// Deformation of the centres: intra-frame blending (Section IV-A, Eq. 2), time decay and
// inter-frame propagation through weighted-Kabsch local frames (Section IV-B).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "dmc/tvm.h"

namespace dmc::tvm {

double TimeDecay::Weight(int frame, int edit_frame) const {
  if (kind == DecayKind::kNone) return 1.0;
  const double s = std::max(0.0, 1.0 - std::abs(frame - edit_frame) / radius);
  if (kind == DecayKind::kLinear) return s;
  return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
}

std::vector<DualQuaternion> BlendIntraFrame(const AffinityGraph& graph,
                                            std::span<const int32_t> effectors,
                                            std::span<const DualQuaternion> effector_transforms,
                                            bool anchor_to_identity) {
  const int n = graph.centre_count();
  // Accumulate sum_e a(i,e) T_e by scattering from each effector to the centres it reaches; the
  // sign of each term follows the first effector's hemisphere (q and -q are the same motion).
  std::vector<DualQuaternion> sums(static_cast<size_t>(n),
                                   DualQuaternion({0, 0, 0, 0}, {0, 0, 0, 0}));
  std::vector<double> affinity_sums(static_cast<size_t>(n), 0.0);
  std::vector<char> is_effector(static_cast<size_t>(n), 0);
  for (size_t e = 0; e < effectors.size(); ++e) {
    is_effector[static_cast<size_t>(effectors[e])] = 1;
    const DualQuaternion& transform = effector_transforms[e];
    const double sign = transform.RealDot(effector_transforms[0]) < 0.0 ? -1.0 : 1.0;
    graph.ForEachAffine(effectors[e], [&](int i, double affinity) {
      sums[static_cast<size_t>(i)] = sums[static_cast<size_t>(i)] + transform * (sign * affinity);
      affinity_sums[static_cast<size_t>(i)] += affinity;
    });
  }
  std::vector<DualQuaternion> result(static_cast<size_t>(n));
  tbb::parallel_for(0, n, [&](int i) {
    const size_t at = static_cast<size_t>(i);
    if (is_effector[at] || affinity_sums[at] == 0.0) return;  // effectors set below; else identity
    DualQuaternion blend = sums[at];
    if (anchor_to_identity && affinity_sums[at] < 1.0) {
      const DualQuaternion identity =
          DualQuaternion::Identity() * (blend.RealDot(DualQuaternion::Identity()) < 0 ? -1 : 1);
      blend = blend + identity * (1.0 - affinity_sums[at]);
    }
    result[at] = blend.Normalized();
  });
  for (size_t e = 0; e < effectors.size(); ++e) {
    result[static_cast<size_t>(effectors[e])] = effector_transforms[e];
  }
  return result;
}

namespace {

bool IsIdentity(const DualQuaternion& q) {
  return q.real().vec().isZero(0.0) && q.dual().coeffs().isZero(0.0);
}

// normalise(psi T + (1 - psi) e), with T taken in the identity's hemisphere.
DualQuaternion Decayed(const DualQuaternion& transform, double psi) {
  if (psi >= 1.0) return transform;
  if (psi <= 0.0) return DualQuaternion::Identity();
  const double sign = transform.real().w() < 0.0 ? -1.0 : 1.0;
  return (transform * (sign * psi) + DualQuaternion::Identity() * (1.0 - psi)).Normalized();
}

}  // namespace

CentreTransforms PropagateToFrames(const AffinityGraph& graph, int edit_frame,
                                   std::span<const DualQuaternion> edit_transforms,
                                   const TimeDecay& decay, int kabsch_neighbours) {
  const CentreTrajectories& centres = graph.centres();
  const int n = centres.centre_count();
  const int frames = centres.frame_count();
  const int k = std::max(1, std::min(kabsch_neighbours, graph.neighbour_count()));
  CentreTransforms result(static_cast<size_t>(frames),
                          std::vector<DualQuaternion>(static_cast<size_t>(n)));
  tbb::parallel_for(0, n, [&](int i) {
    const DualQuaternion& edit = edit_transforms[static_cast<size_t>(i)];
    result[static_cast<size_t>(edit_frame)][static_cast<size_t>(i)] = edit;
    if (IsIdentity(edit)) return;  // nothing to carry: every frame keeps the identity
    const auto neighbours = graph.Neighbours(i).first(static_cast<size_t>(k));
    const auto weights = graph.NeighbourAffinities(i).first(static_cast<size_t>(k));
    FramePositionsD source(k, 3), target(k, 3);
    for (int j = 0; j < k; ++j) source.row(j) = centres.positions[edit_frame].row(neighbours[j]);
    auto centroid = [&](const FramePositionsD& points) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      double total = 0.0;
      for (int j = 0; j < k; ++j) {
        sum += weights[j] * points.row(j).transpose();
        total += weights[j];
      }
      return Eigen::Vector3d(sum / total);
    };
    const Eigen::Vector3d source_origin = centroid(source);
    // O*_f T O_f: the edit expressed in the neighbourhood's local frame at the edited frame.
    const DualQuaternion local_edit = DualQuaternion::FromTranslation(-source_origin) * edit *
                                      DualQuaternion::FromTranslation(source_origin);
    for (int g = 0; g < frames; ++g) {
      if (g == edit_frame) continue;
      const double psi = decay.Weight(g, edit_frame);
      if (psi <= 0.0) continue;  // the identity, exactly
      for (int j = 0; j < k; ++j) target.row(j) = centres.positions[g].row(neighbours[j]);
      const Eigen::Vector3d target_origin = centroid(target);
      Eigen::Quaterniond rotation(WeightedKabsch(source, target, weights));
      rotation.normalize();
      // O_g R (O*_f T O_f) R* O*_g.
      const DualQuaternion to_target =
          DualQuaternion::FromTranslation(target_origin) * DualQuaternion::FromRotation(rotation);
      const DualQuaternion propagated = to_target * local_edit * to_target.Conjugate();
      result[static_cast<size_t>(g)][static_cast<size_t>(i)] = Decayed(propagated, psi);
    }
  });
  return result;
}

}  // namespace dmc::tvm
