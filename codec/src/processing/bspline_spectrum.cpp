// spectrum: the first k eigenpairs of the restricted B-spline Laplace–Beltrami operator,
// −L η = λ D η (Chuang et al. 2009; dmc/bspline.h), computed once on the reference frame with
// Spectra. Geometry passes through unchanged; the output is one eigenfunction evaluated at the
// vertices (vertex scalar "eigenfunction", --mode picks which, 0 being the constant) and the
// eigenvalues as measurements eigenvalue_0 … eigenvalue_{k−1} (ascending, the zero mode first).
#include <fmt/format.h>

#include "dmc/bspline.h"
#include "dmc/processing.h"

namespace dmc {
namespace {

class PreparedSpectrum final : public PreparedMethod {
 public:
  PreparedSpectrum(Eigen::VectorXd eigenvalues, Eigen::VectorXd eigenfunction, int dimension)
      : PreparedMethod("eigenfunction"),
        eigenvalues_(std::move(eigenvalues)),
        eigenfunction_(std::move(eigenfunction)),
        dimension_(dimension) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints*) const override {
    if (positions.rows() != eigenfunction_.size()) {
      return MismatchError(fmt::format("frame has {} vertices, the operator's mesh {}",
                                       positions.rows(), eigenfunction_.size()));
    }
    FrameOutput output;
    output.positions = positions;
    output.vertex_scalar = eigenfunction_;
    for (Eigen::Index k = 0; k < eigenvalues_.size(); ++k) {
      output.measurements.push_back(
          {frame_index, fmt::format("eigenvalue_{}", k), eigenvalues_[k]});
    }
    output.measurements.push_back({frame_index, "dimension", static_cast<double>(dimension_)});
    return output;
  }

 private:
  Eigen::VectorXd eigenvalues_;
  Eigen::VectorXd eigenfunction_;  // the chosen eigenfunction at the vertices
  int dimension_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const int depth, context.parameters.Integer("depth"));
  DMC_ASSIGN_OR_RETURN(const int k, context.parameters.Integer("k"));
  DMC_ASSIGN_OR_RETURN(const int mode, context.parameters.Integer("mode"));
  if (depth < 0 || depth > 10) {
    return InvalidArgumentError(fmt::format("--depth must be in [0, 10], got {}", depth));
  }
  if (k < 1) return InvalidArgumentError(fmt::format("--k must be >= 1, got {}", k));
  if (mode < 0 || mode >= k) {
    return InvalidArgumentError(fmt::format("--mode must be in [0, {}), got {}", k, mode));
  }
  const Triangles& triangles = context.sequence.triangles();
  BsplineOptions options;
  options.depth = depth > 0 ? depth : AutomaticBsplineDepth(triangles, context.reference_frame);
  options.coarsest_depth = options.depth;  // the spectrum needs no multigrid levels
  DMC_ASSIGN_OR_RETURN(const BsplineOperator op,
                       BuildBsplineOperator(triangles, context.reference_frame, options));
  DMC_ASSIGN_OR_RETURN(const GeneralizedSpectrum spectrum, ComputeBsplineSpectrum(op, k));
  Eigen::VectorXd eigenfunction = op.evaluation * spectrum.eigenvectors.col(mode);
  return std::unique_ptr<PreparedMethod>(
      new PreparedSpectrum(spectrum.eigenvalues, std::move(eigenfunction), op.dimension()));
}

constexpr ParameterSpec kParameters[] = {
    {"depth", ParameterType::kInteger, "5",
     "octree depth of the B-spline elements (0: voxel about one mean edge long)"},
    {"k", ParameterType::kInteger, "16", "number of eigenpairs (smallest first)"},
    {"mode", ParameterType::kInteger, "1", "eigenfunction written as the vertex scalar"},
};

}  // namespace

MethodInfo BsplineSpectrumMethod() {
  return {.name = "spectrum",
          .description =
              "first k eigenpairs of the restricted B-spline Laplace-Beltrami operator "
              "(-L x = lambda D x, octree elements, Spectra); one eigenfunction as vertex scalar",
          .needs_operator = false,
          .vertex_scalar = "eigenfunction",
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc
