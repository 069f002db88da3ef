// curvature: mean-curvature estimate from differential coordinates (thesis 3.1):
//   H_i = ‖δ_i‖ / 2, positive when δ_i points against the vertex normal (a sphere with outward
//   normals has H = +1/R), negative when along it.
// Only cotan-area approximates the true value (δ ≈ −2H·n); other operators give a distribution
// with the right relations between vertices but another scale (the thesis's point in 3.1).
// The output geometry is the input; the estimate is the per-vertex scalar "mean_curvature".
#include <fmt/format.h>

#include <cmath>
#include <optional>

#include "dmc/processing.h"
#include "processing/processing_util.h"

namespace dmc {
namespace {

// Area-weighted vertex normals (un-normalised sums of triangle cross products).
Eigen::MatrixXd VertexNormals(const Triangles& triangles, const FramePositionsD& positions) {
  Eigen::MatrixXd normals = Eigen::MatrixXd::Zero(positions.rows(), 3);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::RowVector3d a = positions.row(triangles(t, 0));
    const Eigen::RowVector3d b = positions.row(triangles(t, 1));
    const Eigen::RowVector3d c = positions.row(triangles(t, 2));
    const Eigen::RowVector3d cross = (b - a).cross(c - a);
    for (int corner = 0; corner < 3; ++corner) normals.row(triangles(t, corner)) += cross;
  }
  return normals;
}

class PreparedCurvature final : public PreparedMethod {
 public:
  PreparedCurvature(std::optional<SparseMatrixD> laplacian, MeshTopology topology,
                    Triangles triangles, std::string operator_name,
                    OperatorOptions operator_options)
      : PreparedMethod("mean_curvature"),
        laplacian_(std::move(laplacian)),
        topology_(std::move(topology)),
        triangles_(std::move(triangles)),
        operator_name_(std::move(operator_name)),
        operator_options_(operator_options) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints*) const override {
    if (positions.rows() != topology_.vertex_count) {
      return MismatchError(fmt::format("frame has {} vertices, the mesh {}", positions.rows(),
                                       topology_.vertex_count));
    }
    SparseMatrixD per_frame;
    const SparseMatrixD* laplacian = laplacian_ ? &*laplacian_ : nullptr;
    if (laplacian == nullptr) {
      // --frame-operator: the operator of this frame's own geometry.
      DMC_ASSIGN_OR_RETURN(
          LaplaceOperator built,
          BuildOperator(operator_name_, topology_, SourceFromFrame(positions), operator_options_));
      per_frame = std::move(built.matrix);
      laplacian = &per_frame;
    }
    const Eigen::MatrixXd delta = *laplacian * processing::ToDense(positions);
    const Eigen::MatrixXd normals = VertexNormals(triangles_, positions);
    FrameOutput output;
    output.positions = positions;
    output.vertex_scalar.resize(positions.rows());
    for (Eigen::Index v = 0; v < positions.rows(); ++v) {
      const double magnitude = delta.row(v).norm() / 2.0;
      output.vertex_scalar[v] = delta.row(v).dot(normals.row(v)) > 0.0 ? -magnitude : magnitude;
    }
    if (output.vertex_scalar.size() > 0) {
      output.measurements.push_back(
          {frame_index, "mean_curvature_min", output.vertex_scalar.minCoeff()});
      output.measurements.push_back(
          {frame_index, "mean_curvature_mean", output.vertex_scalar.mean()});
      output.measurements.push_back(
          {frame_index, "mean_curvature_max", output.vertex_scalar.maxCoeff()});
    }
    return output;
  }

 private:
  std::optional<SparseMatrixD> laplacian_;  // empty: rebuilt from every frame
  MeshTopology topology_;
  Triangles triangles_;
  std::string operator_name_;
  OperatorOptions operator_options_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const bool frame_operator, context.parameters.Flag("frame-operator"));
  std::optional<SparseMatrixD> laplacian;
  if (!frame_operator) laplacian = context.laplace->matrix;
  return std::unique_ptr<PreparedMethod>(
      new PreparedCurvature(std::move(laplacian), context.topology, context.sequence.triangles(),
                            std::string(context.operator_name), context.operator_options));
}

constexpr ParameterSpec kParameters[] = {
    {"frame-operator", ParameterType::kFlag, "false",
     "rebuild the operator from every frame's own geometry instead of one operator for the "
     "whole sequence (per-frame curvature of a dynamic mesh)"},
};

}  // namespace

MethodInfo CurvatureMethod() {
  return {.name = "curvature",
          .description =
              "mean curvature |delta|/2 signed by the normal, as a per-vertex scalar "
              "(PLY property and colours); cotan-area gives ~1/R on a sphere",
          .vertex_scalar = "mean_curvature",
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc
