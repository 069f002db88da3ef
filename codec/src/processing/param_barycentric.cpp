// param-barycentric: Tutte / Floater barycentric mapping of a disk-topology mesh (thesis 3.3).
//
// The boundary loop is pinned to a circle, to a regular convex polygon (both by arc length), or
// to its own positions projected onto the best-fitting plane ("input"); every interior vertex is
// the weighted average of its neighbours with the operator's weights:
//   L_II u_I = −L_IB u_B   (I interior, B boundary),
// solved once per frame with one sparse LU factorisation (L_II is not symmetric for tutte,
// cotan, mean-value). Positive weights (tutte, kirchhoff, mean-value) guarantee an embedding with
// a convex boundary (Tutte, Floater); mean-value weights have linear precision, so a planar mesh
// with boundary "input" is reproduced up to a rigid motion. The output geometry is (u, v, 0).
// Measurements: flipped_triangles (signed uv area opposite to the boundary's orientation),
// degenerate_triangles (zero uv area) and the mean / max absolute corner-angle difference between
// the input and the map, in degrees (angle distortion).
#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseLU>
#include <cmath>
#include <numbers>

#include "dmc/processing.h"
#include "processing/processing_util.h"

namespace dmc {
namespace {

using LuSolver = Eigen::SparseLU<SparseMatrixD, Eigen::COLAMDOrdering<int>>;

// The single boundary loop, in the direction of the triangles' orientation (each boundary edge
// a→b as it appears in its triangle). Fails with kUnsupported unless the mesh is a topological
// disk: one component, manifold, one boundary loop, Euler characteristic 1.
StatusOr<std::vector<int>> BoundaryLoop(const MeshTopology& topology, const Triangles& triangles) {
  const int referenced = topology.vertex_count - topology.isolated_vertex_count;
  if (topology.component_count - topology.isolated_vertex_count != 1 || !topology.is_manifold() ||
      topology.boundary_loop_count != 1 || topology.euler_characteristic != 1 || referenced < 3) {
    return UnsupportedError(fmt::format(
        "param-barycentric needs a disk (one manifold component, one boundary loop, Euler "
        "characteristic 1); this mesh has {} components, {} boundary loops, {} non-manifold "
        "edges, Euler characteristic {}",
        topology.component_count - topology.isolated_vertex_count, topology.boundary_loop_count,
        topology.non_manifold_edge_count, topology.euler_characteristic));
  }
  std::vector<int> next(topology.vertex_count, -1);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      const int a = triangles(t, corner), b = triangles(t, (corner + 1) % 3);
      const int slot = RingSlot(topology, a, b);
      if (slot >= 0 && topology.edge_face_count[topology.ring_edges[slot]] == 1) next[a] = b;
    }
  }
  int start = -1;
  for (int v = 0; v < topology.vertex_count && start < 0; ++v) {
    if (next[v] >= 0) start = v;
  }
  std::vector<int> loop;
  for (int v = start; v >= 0 && static_cast<int>(loop.size()) <= topology.vertex_count;
       v = next[v]) {
    loop.push_back(v);
    if (next[v] == start) return loop;
  }
  return UnsupportedError("param-barycentric: the boundary does not form one simple loop");
}

// Boundary positions by normalised arc length s ∈ [0, 1) on the unit circle or on a regular
// polygon inscribed in it, counter-clockwise.
Eigen::Vector2d BoundaryPoint(double s, int sides) {
  const double two_pi = 2.0 * std::numbers::pi;
  if (sides <= 0) return {std::cos(two_pi * s), std::sin(two_pi * s)};
  const double side_position = s * sides;
  const int side = std::min(static_cast<int>(side_position), sides - 1);
  const double f = side_position - side;
  const Eigen::Vector2d a(std::cos(two_pi * side / sides), std::sin(two_pi * side / sides));
  const Eigen::Vector2d b(std::cos(two_pi * (side + 1) / sides),
                          std::sin(two_pi * (side + 1) / sides));
  return (1.0 - f) * a + f * b;
}

double CornerAngle(const Eigen::Vector3d& at, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d a = p - at, b = q - at;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

class PreparedBarycentric final : public PreparedMethod {
 public:
  PreparedBarycentric(Triangles triangles, std::vector<int> boundary, std::vector<int> interior,
                      std::vector<int> interior_index, SparseMatrixD interior_boundary,
                      std::unique_ptr<LuSolver> solver, std::string boundary_shape, int sides)
      : triangles_(std::move(triangles)),
        boundary_(std::move(boundary)),
        interior_(std::move(interior)),
        interior_index_(std::move(interior_index)),
        interior_boundary_(std::move(interior_boundary)),
        solver_(std::move(solver)),
        boundary_shape_(std::move(boundary_shape)),
        sides_(sides) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints*) const override {
    if (positions.rows() != static_cast<Eigen::Index>(interior_index_.size())) {
      return MismatchError("frame size differs from the mesh's");
    }
    const Eigen::MatrixXd boundary_uv = BoundaryUv(positions);
    FrameOutput output;
    output.positions = FramePositionsD::Zero(positions.rows(), 3);
    for (size_t k = 0; k < boundary_.size(); ++k) {
      output.positions.row(boundary_[k]).head<2>() = boundary_uv.row(static_cast<Eigen::Index>(k));
    }
    if (!interior_.empty()) {
      const Eigen::MatrixXd rhs = -(interior_boundary_ * boundary_uv);
      const Eigen::MatrixXd uv = solver_->solve(rhs);
      if (solver_->info() != Eigen::Success || !uv.allFinite()) {
        return NumericalFailureError("param-barycentric: the interior solve failed");
      }
      for (size_t k = 0; k < interior_.size(); ++k) {
        output.positions.row(interior_[k]).head<2>() = uv.row(static_cast<Eigen::Index>(k));
      }
    }
    Measure(positions, output, frame_index);
    return output;
  }

 private:
  Eigen::MatrixXd BoundaryUv(const FramePositionsD& positions) const {
    const Eigen::Index count = static_cast<Eigen::Index>(boundary_.size());
    Eigen::MatrixXd uv(count, 2);
    if (boundary_shape_ == "input") {
      // Projection onto the best-fitting plane of the boundary (PCA), keeping its orientation.
      Eigen::MatrixXd points(count, 3);
      for (Eigen::Index k = 0; k < count; ++k) points.row(k) = positions.row(boundary_[k]);
      const Eigen::RowVector3d centre = points.colwise().mean();
      const Eigen::MatrixXd centred = points.rowwise() - centre;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(centred.transpose() * centred);
      Eigen::Vector3d e1 = eigen.eigenvectors().col(2), e2 = eigen.eigenvectors().col(1);
      uv.col(0) = centred * e1;
      uv.col(1) = centred * e2;
      // Orient the loop counter-clockwise in uv (positive shoelace area).
      double area = 0.0;
      for (Eigen::Index k = 0; k < count; ++k) {
        const Eigen::Index n = (k + 1) % count;
        area += uv(k, 0) * uv(n, 1) - uv(n, 0) * uv(k, 1);
      }
      if (area < 0.0) uv.col(1) = -uv.col(1);
      return uv;
    }
    std::vector<double> arc(static_cast<size_t>(count) + 1, 0.0);
    for (Eigen::Index k = 0; k < count; ++k) {
      const Eigen::Index n = (k + 1) % count;
      arc[k + 1] = arc[k] + (positions.row(boundary_[n]) - positions.row(boundary_[k])).norm();
    }
    for (Eigen::Index k = 0; k < count; ++k) {
      const double s = arc[count] > 0.0 ? arc[k] / arc[count] : static_cast<double>(k) / count;
      uv.row(k) = BoundaryPoint(s, boundary_shape_ == "polygon" ? sides_ : 0).transpose();
    }
    return uv;
  }

  void Measure(const FramePositionsD& input, FrameOutput& output, int frame_index) const {
    int flipped = 0, degenerate = 0;
    double angle_sum = 0.0, angle_max = 0.0, total_area = 0.0;
    std::vector<double> areas(static_cast<size_t>(triangles_.rows()));
    for (Eigen::Index t = 0; t < triangles_.rows(); ++t) {
      const Eigen::Vector2d a = output.positions.row(triangles_(t, 0)).head<2>().transpose();
      const Eigen::Vector2d b = output.positions.row(triangles_(t, 1)).head<2>().transpose();
      const Eigen::Vector2d c = output.positions.row(triangles_(t, 2)).head<2>().transpose();
      const Eigen::Vector2d ab = b - a, ac = c - a;
      areas[t] = 0.5 * (ab.x() * ac.y() - ab.y() * ac.x());
      total_area += std::abs(areas[t]);
    }
    for (Eigen::Index t = 0; t < triangles_.rows(); ++t) {
      if (std::abs(areas[t]) <= 1e-14 * total_area) {
        ++degenerate;
      } else if (areas[t] < 0.0) {
        ++flipped;
      }
      for (int corner = 0; corner < 3; ++corner) {
        const int i = triangles_(t, corner), j = triangles_(t, (corner + 1) % 3),
                  k = triangles_(t, (corner + 2) % 3);
        const double before = CornerAngle(input.row(i).transpose(), input.row(j).transpose(),
                                          input.row(k).transpose());
        const double after =
            CornerAngle(output.positions.row(i).transpose(), output.positions.row(j).transpose(),
                        output.positions.row(k).transpose());
        const double difference = std::abs(after - before) * 180.0 / std::numbers::pi;
        angle_sum += difference;
        angle_max = std::max(angle_max, difference);
      }
    }
    output.measurements.push_back({frame_index, "flipped_triangles", static_cast<double>(flipped)});
    output.measurements.push_back(
        {frame_index, "degenerate_triangles", static_cast<double>(degenerate)});
    output.measurements.push_back(
        {frame_index, "angle_distortion_mean_deg",
         triangles_.rows() > 0 ? angle_sum / (3.0 * static_cast<double>(triangles_.rows())) : 0.0});
    output.measurements.push_back({frame_index, "angle_distortion_max_deg", angle_max});
  }

  Triangles triangles_;
  std::vector<int> boundary_;
  std::vector<int> interior_;
  std::vector<int> interior_index_;  // size V; -1 on boundary and isolated vertices
  SparseMatrixD interior_boundary_;  // L_IB, columns in boundary_ order
  std::unique_ptr<LuSolver> solver_;
  std::string boundary_shape_;
  int sides_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const std::string shape, context.parameters.Text("boundary"));
  DMC_ASSIGN_OR_RETURN(const int sides, context.parameters.Integer("sides"));
  if (shape != "circle" && shape != "polygon" && shape != "input") {
    return InvalidArgumentError(
        fmt::format("--boundary must be circle, polygon or input, got '{}'", shape));
  }
  if (shape == "polygon" && sides < 3) return InvalidArgumentError("--sides must be >= 3");
  const MeshTopology& topology = context.topology;
  const Triangles& triangles = context.sequence.triangles();
  DMC_ASSIGN_OR_RETURN(std::vector<int> boundary, BoundaryLoop(topology, triangles));

  const int v_count = topology.vertex_count;
  std::vector<int> boundary_index(v_count, -1), interior_index(v_count, -1);
  for (size_t k = 0; k < boundary.size(); ++k) boundary_index[boundary[k]] = static_cast<int>(k);
  std::vector<int> interior;
  for (int v = 0; v < v_count; ++v) {
    if (boundary_index[v] < 0 && topology.degree(v) > 0) {
      interior_index[v] = static_cast<int>(interior.size());
      interior.push_back(v);
    }
  }
  const SparseMatrixD& laplacian = context.laplace->matrix;
  const int interior_count = static_cast<int>(interior.size());
  const SparseMatrixD interior_rows =
      processing::SelectRows(laplacian, interior_index, interior_count);
  SparseMatrixD interior_boundary =
      processing::SelectColumns(interior_rows, boundary_index, static_cast<int>(boundary.size()));
  auto solver = std::make_unique<LuSolver>();
  if (interior_count > 0) {
    const SparseMatrixD interior_interior =
        processing::SelectColumns(interior_rows, interior_index, interior_count);
    solver->compute(interior_interior);
    if (solver->info() != Eigen::Success) {
      return NumericalFailureError(
          fmt::format("param-barycentric: the interior system of operator {} is singular ({})",
                      context.laplace->name, solver->lastErrorMessage()));
    }
  }
  return std::unique_ptr<PreparedMethod>(new PreparedBarycentric(
      triangles, std::move(boundary), std::move(interior), std::move(interior_index),
      std::move(interior_boundary), std::move(solver), shape, sides));
}

constexpr ParameterSpec kParameters[] = {
    {"boundary", ParameterType::kText, "circle",
     "boundary placement: circle, polygon (regular, --sides) or input (the boundary's own "
     "positions projected onto its best-fitting plane)"},
    {"sides", ParameterType::kInteger, "4", "corners of the regular polygon boundary"},
};

}  // namespace

MethodInfo ParamBarycentricMethod() {
  return {.name = "param-barycentric",
          .description =
              "Tutte/Floater barycentric mapping of a disk onto a circle or convex "
              "polygon; reports flipped triangles and angle distortion",
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc
