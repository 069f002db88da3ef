// Spacetime as-rigid-as-possible editing on the 3D+t Laplacian (spacetime.h).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "dmc/spacetime.h"

namespace dmc {
namespace {

Status ValidateArapOptions(const SpacetimeArapOptions& options, int f_count) {
  if (!(options.alpha > 0.0) || !std::isfinite(options.alpha)) {
    return InvalidArgumentError("spacetime-arap: alpha must be a finite value > 0");
  }
  if (options.window < 1) return InvalidArgumentError("spacetime-arap: window must be >= 1");
  if (options.key_frame < 0 || options.key_frame >= f_count) {
    return InvalidArgumentError("spacetime-arap: key frame " + std::to_string(options.key_frame) +
                                " outside the sequence's " + std::to_string(f_count) + " frames");
  }
  if (!(options.tolerance > 0.0) || !(options.constraint_weight > 0.0) ||
      options.max_iterations < 0) {
    return InvalidArgumentError(
        "spacetime-arap: tolerance and constraint weight must be > 0, max iterations >= 0");
  }
  return Status::Ok();
}

// The edited frames [first, last] and the key frame's index within them.
struct ArapWindow {
  int first = 0, last = 0, key_local = 0;
  int frames() const { return last - first + 1; }
};

// [key − window, key + window] clipped to the sequence; an error when that leaves one frame.
StatusOr<ArapWindow> WindowAround(const SpacetimeArapOptions& options, int f_count) {
  ArapWindow window;
  window.first = std::max(0, options.key_frame - options.window);
  window.last = std::min(f_count - 1, options.key_frame + options.window);
  window.key_local = options.key_frame - window.first;
  if (window.frames() < 2) {
    return InvalidArgumentError(
        "spacetime-arap: the window holds one frame; the sequence needs "
        "at least two");
  }
  return window;
}

enum VertexRole : uint8_t { kFree = 0, kHandle = 1, kFixed = 2 };

// The role of every vertex; errors for no handle, an index outside [0, V) or a vertex that is
// both handle and fixed.
StatusOr<std::vector<uint8_t>> VertexRoles(const SpacetimeArapConstraints& constraints,
                                           int v_count) {
  if (constraints.handles.empty()) {
    return InvalidArgumentError("spacetime-arap: no handle vertex to edit");
  }
  std::vector<uint8_t> role(v_count, kFree);
  for (int32_t h : constraints.handles) {
    if (h < 0 || h >= v_count) {
      return InvalidArgumentError("spacetime-arap: handle " + std::to_string(h) + " outside [0, " +
                                  std::to_string(v_count) + ")");
    }
    role[h] = kHandle;
  }
  for (int32_t f : constraints.fixed) {
    if (f < 0 || f >= v_count) {
      return InvalidArgumentError("spacetime-arap: fixed vertex " + std::to_string(f) +
                                  " outside [0, " + std::to_string(v_count) + ")");
    }
    if (role[f] == kHandle) {
      return InvalidArgumentError("spacetime-arap: vertex " + std::to_string(f) +
                                  " is both a handle and fixed");
    }
    role[f] = kFixed;
  }
  return role;
}

// Times of every frame of the sequence: `frame_times` when given (one per frame), else from the
// frame rate, else the frame indices.
StatusOr<std::vector<double>> SequenceFrameTimes(const MeshSequence& sequence,
                                                 const std::vector<double>& frame_times) {
  const int f_count = sequence.frame_count();
  std::vector<double> times = frame_times;
  if (times.empty()) {
    for (int f = 0; f < f_count; ++f) {
      times.push_back(sequence.frame_rate > 0.0 ? f / sequence.frame_rate : f);
    }
  } else if (static_cast<int>(times.size()) != f_count) {
    return InvalidArgumentError("spacetime-arap: frame_times holds " +
                                std::to_string(times.size()) + " times for " +
                                std::to_string(f_count) + " frames");
  }
  return times;
}

// (√α·t_k, x, y, z) of every vertex of every frame, frame after frame: an (F·V) × 4 matrix.
Eigen::MatrixXd SpacetimePositions(const std::vector<FramePositionsD>& frames,
                                   const std::vector<double>& times, double root_alpha) {
  const Eigen::Index v_count = frames.front().rows();
  Eigen::MatrixXd positions(v_count * static_cast<Eigen::Index>(frames.size()), 4);
  for (size_t k = 0; k < frames.size(); ++k) {
    const Eigen::Index row = static_cast<Eigen::Index>(k) * v_count;
    positions.block(row, 0, v_count, 1).setConstant(root_alpha * times[k]);
    positions.block(row, 1, v_count, 3) = frames[k];
  }
  return positions;
}

// Whether the window's first and last frames are pinned whole (temporal boundary anchors).
struct ConstrainedFrames {
  bool first = false, last = false;
};

// 1 for every row (frame k, vertex v at k·V + v) held by a soft constraint: the handles in the
// key frame, the fixed vertices in every frame, the pinned boundary frames and, when neither
// boundary is pinned, every spatial component without a handle or fixed vertex (it would float).
std::vector<uint8_t> ConstrainedRows(const MeshTopology& topology,
                                     const std::vector<uint8_t>& roles,
                                     const SpacetimeArapConstraints& constraints,
                                     const ArapWindow& window, ConstrainedFrames pinned,
                                     int v_count) {
  const int window_frames = window.frames();
  std::vector<uint8_t> constrained(static_cast<size_t>(v_count) * window_frames, 0);
  const auto pin_frame = [&](int k) {
    std::fill(constrained.begin() + static_cast<Eigen::Index>(k) * v_count,
              constrained.begin() + static_cast<Eigen::Index>(k + 1) * v_count, 1);
  };
  for (int32_t h : constraints.handles) {
    constrained[static_cast<Eigen::Index>(window.key_local) * v_count + h] = 1;
  }
  for (int k = 0; k < window_frames; ++k) {
    for (int32_t f : constraints.fixed) constrained[static_cast<Eigen::Index>(k) * v_count + f] = 1;
  }
  if (pinned.first) pin_frame(0);
  if (pinned.last) pin_frame(window_frames - 1);
  if (!pinned.first && !pinned.last) {
    std::vector<uint8_t> held(topology.component_count, 0);
    for (int v = 0; v < v_count; ++v) {
      if (roles[v] != kFree) held[topology.component_of_vertex[v]] = 1;
    }
    for (int v = 0; v < v_count; ++v) {
      if (held[topology.component_of_vertex[v]]) continue;
      for (int k = 0; k < window_frames; ++k) {
        constrained[static_cast<Eigen::Index>(k) * v_count + v] = 1;
      }
    }
  }
  return constrained;
}

}  // namespace

struct SpacetimeArapEditor::Impl {
  MeshSequence input;
  SpacetimeArapOptions options;
  int vertex_count = 0, first = 0, last = 0, key_local = 0;
  double key_time_coordinate = 0.0;  // √α·t_K
  double bbox_diagonal = 0.0;
  std::vector<int32_t> handles;
  SpacetimeLaplacian laplacian;
  SparseMatrixD stiffness;       // K = −W: positive semidefinite, off-diagonals −w_ij
  Eigen::MatrixXd original;      // n × 4 input positions (√α·t, x, y, z)
  std::vector<int> constrained;  // rows with a soft constraint, sorted
  double lambda = 0.0;
  std::optional<SparseSpdSolver> cholesky;
  std::optional<BlockTridiagonalSolver> block;

  Eigen::Index rows() const { return original.rows(); }

  // The window's Laplacian (frame times of the whole sequence given), its stiffness and the
  // spacetime positions of the window's vertices.
  Status BuildWindowOperator(const MeshSequence& sequence, const MeshTopology& topology,
                             const std::vector<double>& times) {
    SpacetimeOptions st_options;
    st_options.alpha = options.alpha;
    st_options.spatial_dual = options.spatial_dual;
    st_options.frame_times.assign(times.begin() + first, times.begin() + last + 1);
    std::vector<FramePositionsD> frames;
    for (int f = first; f <= last; ++f) frames.push_back(sequence.frame_d(f));
    DMC_ASSIGN_OR_RETURN(
        laplacian, BuildSpacetimeLaplacian(topology, sequence.triangles(), frames, st_options));
    stiffness = -laplacian.stiffness;
    const double root_alpha = std::sqrt(options.alpha);
    original = SpacetimePositions(frames, st_options.frame_times, root_alpha);
    key_time_coordinate = root_alpha * st_options.frame_times[key_local];
    return Status::Ok();
  }

  // Rows without dual volume join `constrained` (nothing else holds them); λ is then set from
  // the mean positive diagonal, and K + λ·(constrained rows' diagonal) is factorised.
  Status FactorConstrainedSystem(std::vector<uint8_t> constrained_rows) {
    const Eigen::VectorXd diagonal = stiffness.diagonal();
    double diagonal_sum = 0.0;
    int diagonal_count = 0;
    for (Eigen::Index r = 0; r < rows(); ++r) {
      if (diagonal[r] > 0.0) {
        diagonal_sum += diagonal[r];
        ++diagonal_count;
      } else {
        constrained_rows[r] = 1;
      }
    }
    lambda = options.constraint_weight * (diagonal_count > 0 ? diagonal_sum / diagonal_count : 1.0);
    SparseMatrixD system = stiffness;
    for (Eigen::Index r = 0; r < rows(); ++r) {
      if (!constrained_rows[r]) continue;
      constrained.push_back(static_cast<int>(r));
      system.coeffRef(r, r) += lambda;  // the diagonal entry exists: no reallocation
    }
    if (options.solver == SpacetimeSolverKind::kBlockLdlt) {
      DMC_ASSIGN_OR_RETURN(BlockTridiagonalSolver factor,
                           BlockTridiagonalSolver::Factor(system, vertex_count));
      block.emplace(std::move(factor));
    } else {
      DMC_ASSIGN_OR_RETURN(SparseSpdSolver factor, SparseSpdSolver::Factor(system));
      cholesky.emplace(std::move(factor));
    }
    return Status::Ok();
  }

  StatusOr<Eigen::MatrixXd> SolveSystem(const Eigen::MatrixXd& rhs) const {
    return cholesky ? cholesky->Solve(rhs) : block->Solve(rhs);
  }

  // Calls row(i) for every row i, rows spread over tasks; each call writes only its own outputs.
  template <typename RowFunction>
  void ForEachRow(const RowFunction& row) const {
    tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(rows()), 256),
                      [&](const tbb::blocked_range<int>& range) {
                        for (int i = range.begin(); i < range.end(); ++i) row(i);
                      });
  }

  // Local step: the best rotation of every cell for the current positions.
  std::vector<Eigen::Matrix4d> FitRotations(const Eigen::MatrixXd& current) const {
    std::vector<Eigen::Matrix4d> rotations(static_cast<size_t>(rows()));
    ForEachRow([&](int i) {
      Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
      for (SparseMatrixD::InnerIterator it(stiffness, i); it; ++it) {
        if (it.row() == i) continue;
        const double w = -it.value();
        const Eigen::Vector4d rest = (original.row(i) - original.row(it.row())).transpose();
        const Eigen::Vector4d now = (current.row(i) - current.row(it.row())).transpose();
        covariance.noalias() += w * rest * now.transpose();
      }
      const Eigen::JacobiSVD<Eigen::Matrix4d> svd(covariance,
                                                  Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::Matrix4d u = svd.matrixU();
      Eigen::Matrix4d rotation = svd.matrixV() * u.transpose();
      if (rotation.determinant() < 0.0) {
        u.col(3) = -u.col(3);  // flip the axis of the smallest singular value
        rotation = svd.matrixV() * u.transpose();
      }
      rotations[i] = rotation;
    });
    return rotations;
  }

  // b_i = Σ_j w_ij/2·(R_i + R_j)·(p_i − p_j).
  Eigen::MatrixXd RotatedRightHandSide(const std::vector<Eigen::Matrix4d>& rotations) const {
    Eigen::MatrixXd rhs(rows(), 4);
    ForEachRow([&](int i) {
      Eigen::Vector4d sum = Eigen::Vector4d::Zero();
      for (SparseMatrixD::InnerIterator it(stiffness, i); it; ++it) {
        if (it.row() == i) continue;
        const Eigen::Vector4d rest = (original.row(i) - original.row(it.row())).transpose();
        sum += (-0.5 * it.value()) * (rotations[i] + rotations[it.row()]) * rest;
      }
      rhs.row(i) = sum.transpose();
    });
    return rhs;
  }

  double Energy(const Eigen::MatrixXd& current, const std::vector<Eigen::Matrix4d>& rotations,
                const Eigen::MatrixXd& targets) const {
    double energy = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, static_cast<int>(rows()), 256), 0.0,
        [&](const tbb::blocked_range<int>& range, double sum) {
          for (int i = range.begin(); i < range.end(); ++i) {
            for (SparseMatrixD::InnerIterator it(stiffness, i); it; ++it) {
              if (it.row() == i) continue;
              const Eigen::Vector4d rest = (original.row(i) - original.row(it.row())).transpose();
              const Eigen::Vector4d now = (current.row(i) - current.row(it.row())).transpose();
              sum += -it.value() * (now - rotations[i] * rest).squaredNorm();
            }
          }
          return sum;
        },
        [](double a, double b) { return a + b; });
    for (int row : constrained) {
      energy += 2.0 * lambda * (current.row(row) - targets.row(row)).squaredNorm();
    }
    return energy;
  }
};

SpacetimeArapEditor::SpacetimeArapEditor(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SpacetimeArapEditor::SpacetimeArapEditor(SpacetimeArapEditor&&) noexcept = default;
SpacetimeArapEditor& SpacetimeArapEditor::operator=(SpacetimeArapEditor&&) noexcept = default;
SpacetimeArapEditor::~SpacetimeArapEditor() = default;

int SpacetimeArapEditor::first_frame() const { return impl_->first; }
int SpacetimeArapEditor::last_frame() const { return impl_->last; }
int SpacetimeArapEditor::unknowns() const { return static_cast<int>(impl_->rows()); }
const SpacetimeLaplacian& SpacetimeArapEditor::laplacian() const { return impl_->laplacian; }

StatusOr<SpacetimeArapEditor> SpacetimeArapEditor::Create(
    const MeshSequence& sequence, const SpacetimeArapConstraints& constraints,
    const SpacetimeArapOptions& options) {
  const int v_count = sequence.vertex_count();
  const int f_count = sequence.frame_count();
  DMC_RETURN_IF_ERROR(ValidateArapOptions(options, f_count));
  DMC_ASSIGN_OR_RETURN(const ArapWindow window, WindowAround(options, f_count));
  DMC_ASSIGN_OR_RETURN(const std::vector<uint8_t> roles, VertexRoles(constraints, v_count));
  DMC_ASSIGN_OR_RETURN(const std::vector<double> times,
                       SequenceFrameTimes(sequence, options.frame_times));

  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->vertex_count = v_count;
  impl->first = window.first;
  impl->last = window.last;
  impl->key_local = window.key_local;
  impl->handles = constraints.handles;
  const MeshTopology topology = BuildTopology(sequence.triangles(), v_count);
  DMC_RETURN_IF_ERROR(impl->BuildWindowOperator(sequence, topology, times));
  impl->bbox_diagonal = ComputeBoundingBox(sequence).diagonal();

  const ConstrainedFrames pinned{
      .first = options.anchor_temporal_boundary && window.first > 0,
      .last = options.anchor_temporal_boundary && window.last < f_count - 1};
  std::vector<uint8_t> constrained =
      ConstrainedRows(topology, roles, constraints, window, pinned, v_count);
  DMC_RETURN_IF_ERROR(impl->FactorConstrainedSystem(std::move(constrained)));
  impl->input = sequence;
  return SpacetimeArapEditor(std::move(impl));
}

StatusOr<SpacetimeArapResult> SpacetimeArapEditor::Solve(
    const Eigen::MatrixXd& handle_targets) const {
  const Impl& s = *impl_;
  if (handle_targets.rows() != static_cast<Eigen::Index>(s.handles.size()) ||
      handle_targets.cols() != 3) {
    return MismatchError("spacetime-arap: " + std::to_string(handle_targets.rows()) + "×" +
                         std::to_string(handle_targets.cols()) + " handle targets for " +
                         std::to_string(s.handles.size()) + " handles (need |H|×3)");
  }
  if (!handle_targets.allFinite()) {
    return InvalidArgumentError("spacetime-arap: non-finite handle target");
  }
  const int v_count = s.vertex_count;
  Eigen::MatrixXd targets = s.original;
  for (size_t h = 0; h < s.handles.size(); ++h) {
    const Eigen::Index row = static_cast<Eigen::Index>(s.key_local) * v_count + s.handles[h];
    targets(row, 0) = s.key_time_coordinate;
    targets.block<1, 3>(row, 1) = handle_targets.row(static_cast<Eigen::Index>(h));
  }
  Eigen::MatrixXd anchored = Eigen::MatrixXd::Zero(s.rows(), 4);
  for (int row : s.constrained) anchored.row(row) = s.lambda * targets.row(row);

  // Initial guess: identity rotations, b = K·p.
  DMC_ASSIGN_OR_RETURN(Eigen::MatrixXd current, s.SolveSystem(s.stiffness * s.original + anchored));
  SpacetimeArapResult result;
  const double tolerance = s.options.tolerance * std::max(s.bbox_diagonal, 1e-300);
  std::vector<Eigen::Matrix4d> rotations = s.FitRotations(current);
  result.energies.push_back(s.Energy(current, rotations, targets));
  for (int iteration = 0; iteration < s.options.max_iterations; ++iteration) {
    DMC_ASSIGN_OR_RETURN(Eigen::MatrixXd next,
                         s.SolveSystem(s.RotatedRightHandSide(rotations) + anchored));
    result.last_move = (next.rightCols<3>() - current.rightCols<3>()).rowwise().norm().maxCoeff();
    current = std::move(next);
    ++result.iterations;
    rotations = s.FitRotations(current);
    result.energies.push_back(s.Energy(current, rotations, targets));
    if (result.last_move < tolerance) {
      result.converged = true;
      break;
    }
  }

  // Snap the time coordinates back: keep x, y, z of every window frame.
  result.sequence = s.input;
  result.first_frame = s.first;
  result.last_frame = s.last;
  for (int f = s.first; f <= s.last; ++f) {
    result.sequence.frame(f) =
        current.block(static_cast<Eigen::Index>(f - s.first) * v_count, 1, v_count, 3)
            .cast<float>();
  }
  for (size_t h = 0; h < s.handles.size(); ++h) {
    const Eigen::Index row = static_cast<Eigen::Index>(s.key_local) * v_count + s.handles[h];
    result.max_handle_error = std::max(
        result.max_handle_error,
        (current.block<1, 3>(row, 1) - handle_targets.row(static_cast<Eigen::Index>(h))).norm());
  }
  return result;
}

}  // namespace dmc
