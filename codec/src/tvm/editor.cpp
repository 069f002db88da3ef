// TvmEditor: the operations of Sections IV and V (rigid transform of centres, vertex-based
// editing, inflation/deflation, loop closing) and their application to centres and surfaces.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "dmc/tvm.h"

namespace dmc::tvm {

StatusOr<TvmEditor> TvmEditor::Create(TimeVaryingMesh mesh, CentreTrajectories centres,
                                      const DeformationOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateTimeVaryingMesh(mesh));
  DMC_RETURN_IF_ERROR(ValidateCentres(centres, mesh.frame_count()));
  if (options.kabsch_neighbours < 1) {
    return InvalidArgumentError("the Kabsch neighbourhood must hold at least 1 centre, got " +
                                std::to_string(options.kabsch_neighbours));
  }
  const SurfaceOptions& surface = options.surface;
  if (surface.neighbours < 1) {
    return InvalidArgumentError("the surface neighbourhood must hold at least 1 centre, got " +
                                std::to_string(surface.neighbours));
  }
  if (!(surface.sigma > 0.0) || !std::isfinite(surface.sigma)) {
    return InvalidArgumentError("sigma must be finite and > 0, got " +
                                std::to_string(surface.sigma));
  }
  if (!(surface.relative_epsilon > 0.0)) {
    return InvalidArgumentError("the smooth-minimum epsilon must be > 0");
  }
  if (!(surface.subdivision_angle > 0.0) || surface.subdivision_angle > 3.14159265358979323846) {
    return InvalidArgumentError("the subdivision angle zeta must be in (0, pi] radians, got " +
                                std::to_string(surface.subdivision_angle));
  }
  if (surface.subdivision_iterations < 0) {
    return InvalidArgumentError("subdivision iterations must be >= 0, got " +
                                std::to_string(surface.subdivision_iterations));
  }
  // One affinity neighbourhood serves both the Kabsch and the surface sets.
  AffinityOptions affinity = options.affinity;
  affinity.neighbours =
      std::max({affinity.neighbours, options.kabsch_neighbours, surface.neighbours});
  DMC_ASSIGN_OR_RETURN(AffinityGraph graph, AffinityGraph::Build(centres, affinity));
  return TvmEditor(std::move(mesh), std::move(graph), options);
}

void TvmEditor::PrecomputeSurfaceWeights() {
  weights_.resize(mesh_.frames.size());
  // Frames in parallel; ComputeSurfaceWeights is itself parallel over vertices (TBB nests).
  tbb::parallel_for(0, mesh_.frame_count(), [&](int f) {
    weights_[static_cast<size_t>(f)] = ComputeSurfaceWeights(
        graph_, f, mesh_.frames[static_cast<size_t>(f)].positions, options_.surface);
  });
}

Status TvmEditor::CheckFrame(int frame) const {
  if (frame < 0 || frame >= mesh_.frame_count()) {
    return InvalidArgumentError("frame " + std::to_string(frame) + " is outside [0, " +
                                std::to_string(mesh_.frame_count()) + ")");
  }
  return Status::Ok();
}

Status TvmEditor::CheckDecay(const TimeDecay& decay) const {
  if (decay.kind != DecayKind::kNone && !(decay.radius > 0.0 && std::isfinite(decay.radius))) {
    return InvalidArgumentError("the time decay radius must be finite and > 0 frames, got " +
                                std::to_string(decay.radius));
  }
  return Status::Ok();
}

StatusOr<CentreTransforms> TvmEditor::TransformCentres(const TransformEdit& edit) const {
  DMC_RETURN_IF_ERROR(CheckFrame(edit.frame));
  DMC_RETURN_IF_ERROR(CheckDecay(edit.decay));
  DMC_RETURN_IF_ERROR(CheckRigid(edit.transform, "the transform"));
  if (edit.centres.empty()) return InvalidArgumentError("no centre is selected");
  std::vector<int32_t> effectors = edit.centres;
  std::sort(effectors.begin(), effectors.end());
  effectors.erase(std::unique(effectors.begin(), effectors.end()), effectors.end());
  for (const int32_t centre : effectors) {
    if (centre < 0 || centre >= graph_.centre_count()) {
      return InvalidArgumentError("centre " + std::to_string(centre) + " is outside [0, " +
                                  std::to_string(graph_.centre_count()) + ")");
    }
  }
  const std::vector<DualQuaternion> user(effectors.size(),
                                         DualQuaternion::FromIsometry(edit.transform));
  const auto blended = BlendIntraFrame(graph_, effectors, user, options_.anchor_to_identity);
  return PropagateToFrames(graph_, edit.frame, blended, edit.decay, options_.kabsch_neighbours);
}

StatusOr<CentreTransforms> TvmEditor::TransformVertices(const VertexEdit& edit) const {
  DMC_RETURN_IF_ERROR(CheckFrame(edit.frame));
  DMC_RETURN_IF_ERROR(CheckDecay(edit.decay));
  if (edit.vertices.empty()) return InvalidArgumentError("no vertex is selected");
  if (edit.transforms.size() != 1 && edit.transforms.size() != edit.vertices.size()) {
    return InvalidArgumentError(
        "give one transform per vertex or one for all: " + std::to_string(edit.transforms.size()) +
        " transforms for " + std::to_string(edit.vertices.size()) + " vertices");
  }
  for (size_t t = 0; t < edit.transforms.size(); ++t) {
    DMC_RETURN_IF_ERROR(CheckRigid(edit.transforms[t], "transform " + std::to_string(t)));
  }
  const TvmFrame& frame = mesh_.frames[static_cast<size_t>(edit.frame)];
  // Each vertex votes for its nearest centre; a centre's transform is the blend of its votes.
  std::vector<std::vector<DualQuaternion>> votes(static_cast<size_t>(graph_.centre_count()));
  for (size_t v = 0; v < edit.vertices.size(); ++v) {
    const int32_t vertex = edit.vertices[v];
    if (vertex < 0 || vertex >= frame.vertex_count()) {
      return InvalidArgumentError("vertex " + std::to_string(vertex) + " is outside [0, " +
                                  std::to_string(frame.vertex_count()) + ") in frame " +
                                  std::to_string(edit.frame));
    }
    const int centre = graph_.NearestCentre(edit.frame, frame.positions.row(vertex).transpose());
    votes[static_cast<size_t>(centre)].push_back(
        DualQuaternion::FromIsometry(edit.transforms[edit.transforms.size() == 1 ? 0 : v]));
  }
  std::vector<int32_t> effectors;
  std::vector<DualQuaternion> transforms;
  for (int c = 0; c < graph_.centre_count(); ++c) {
    const auto& centre_votes = votes[static_cast<size_t>(c)];
    if (centre_votes.empty()) continue;
    effectors.push_back(c);
    const std::vector<double> equal(centre_votes.size(), 1.0);
    transforms.push_back(BlendDualQuaternions(centre_votes, equal));
  }
  const auto blended = BlendIntraFrame(graph_, effectors, transforms, options_.anchor_to_identity);
  return PropagateToFrames(graph_, edit.frame, blended, edit.decay, options_.kabsch_neighbours);
}

StatusOr<CentreTransforms> TvmEditor::Inflate(const InflateEdit& edit) const {
  DMC_RETURN_IF_ERROR(CheckFrame(edit.frame));
  DMC_RETURN_IF_ERROR(CheckDecay(edit.decay));
  if (edit.centre < 0 || edit.centre >= graph_.centre_count()) {
    return InvalidArgumentError("centre " + std::to_string(edit.centre) + " is outside [0, " +
                                std::to_string(graph_.centre_count()) + ")");
  }
  if (!std::isfinite(edit.beta)) return InvalidArgumentError("beta must be finite");
  const FramePositionsD& positions = graph_.centres().positions[static_cast<size_t>(edit.frame)];
  std::vector<DualQuaternion> transforms(static_cast<size_t>(graph_.centre_count()));
  const Eigen::Vector3d origin = positions.row(edit.centre).transpose();
  // T_j = beta a(i, j) (x_j - x_i) eps: a pure translation away from (or towards) the centre.
  graph_.ForEachAffine(edit.centre, [&](int j, double affinity) {
    transforms[static_cast<size_t>(j)] = DualQuaternion::FromTranslation(
        edit.beta * affinity * (positions.row(j).transpose() - origin));
  });
  return PropagateToFrames(graph_, edit.frame, transforms, edit.decay, options_.kabsch_neighbours);
}

StatusOr<CentreTransforms> TvmEditor::CloseLoop(const LoopEdit& edit) const {
  const int last = mesh_.frame_count() - 1;
  if (last < 1) return InvalidArgumentError("closing a loop needs at least 2 frames");
  TimeDecay decay = edit.decay;
  if (decay.kind == DecayKind::kNone) decay = {DecayKind::kLinear, static_cast<double>(last)};
  DMC_RETURN_IF_ERROR(CheckDecay(decay));

  if (edit.mode == LoopMode::kSemiAutomatic) {
    if (edit.semi.frame != 0 && edit.semi.frame != last) {
      return InvalidArgumentError("a semi-automatic loop edits the first or the last frame (0 or " +
                                  std::to_string(last) + "), got frame " +
                                  std::to_string(edit.semi.frame));
    }
    TransformEdit semi = edit.semi;
    semi.decay = decay;
    return TransformCentres(semi);
  }

  // Automatic: each centre follows its neighbourhood's rigid motion from the last frame back to
  // the first, x -> R (x - o_last) + o_first.
  const CentreTrajectories& centres = graph_.centres();
  const int n = graph_.centre_count();
  const int k = std::max(1, std::min(options_.kabsch_neighbours, graph_.neighbour_count()));
  std::vector<DualQuaternion> transforms(static_cast<size_t>(n));
  tbb::parallel_for(0, n, [&](int i) {
    const auto neighbours = graph_.Neighbours(i).first(static_cast<size_t>(k));
    const auto weights = graph_.NeighbourAffinities(i).first(static_cast<size_t>(k));
    FramePositionsD source(k, 3), target(k, 3);
    Eigen::Vector3d source_origin = Eigen::Vector3d::Zero(), target_origin = source_origin;
    double total = 0.0;
    for (int j = 0; j < k; ++j) {
      source.row(j) = centres.positions[static_cast<size_t>(last)].row(neighbours[j]);
      target.row(j) = centres.positions.front().row(neighbours[j]);
      source_origin += weights[j] * source.row(j).transpose();
      target_origin += weights[j] * target.row(j).transpose();
      total += weights[j];
    }
    source_origin /= total;
    target_origin /= total;
    Eigen::Quaterniond rotation(WeightedKabsch(source, target, weights));
    rotation.normalize();
    transforms[static_cast<size_t>(i)] = DualQuaternion::FromTranslation(target_origin) *
                                         DualQuaternion::FromRotation(rotation) *
                                         DualQuaternion::FromTranslation(-source_origin);
  });
  return PropagateToFrames(graph_, last, transforms, decay, options_.kabsch_neighbours);
}

StatusOr<EditResult> TvmEditor::Apply(const CentreTransforms& transforms) const {
  const int frames = mesh_.frame_count();
  const int n = graph_.centre_count();
  if (static_cast<int>(transforms.size()) != frames) {
    return MismatchError("transforms for " + std::to_string(transforms.size()) +
                         " frames, the mesh has " + std::to_string(frames));
  }
  for (int f = 0; f < frames; ++f) {
    if (static_cast<int>(transforms[static_cast<size_t>(f)].size()) != n) {
      return MismatchError("frame " + std::to_string(f) + " has transforms for " +
                           std::to_string(transforms[static_cast<size_t>(f)].size()) +
                           " centres, expected " + std::to_string(n));
    }
  }
  EditResult result;
  result.transforms = transforms;
  result.mesh.name = mesh_.name;
  result.mesh.frame_rate = mesh_.frame_rate;
  result.mesh.frames.resize(static_cast<size_t>(frames));
  result.centres = graph_.centres();
  std::vector<int> added(static_cast<size_t>(frames), 0);
  tbb::parallel_for(0, frames, [&](int f) {
    const auto& frame_transforms = transforms[static_cast<size_t>(f)];
    FramePositionsD& centres = result.centres.positions[static_cast<size_t>(f)];
    for (int i = 0; i < n; ++i) {
      centres.row(i) = frame_transforms[static_cast<size_t>(i)].Apply(centres.row(i).transpose());
    }
    const SurfaceWeights* weights = weights_.empty() ? nullptr : &weights_[static_cast<size_t>(f)];
    result.mesh.frames[static_cast<size_t>(f)] =
        DeformFrame(graph_, f, mesh_.frames[static_cast<size_t>(f)], frame_transforms,
                    options_.surface, weights, &added[static_cast<size_t>(f)]);
  });
  for (const int count : added) result.vertices_added += count;
  return result;
}

}  // namespace dmc::tvm
