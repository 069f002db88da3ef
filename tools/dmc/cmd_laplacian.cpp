// dmc laplacian: builds one discrete Laplace operator for a sequence and reports its properties —
// symmetry, row sums, diagonal range, negative weights, the size of δ = L·X over all frames,
// whether the reduced matrix admits a Cholesky factorisation (thesis 6.1.2), the build time, and
// the thesis's normal-matrix conditioning experiment (6.3.3).
#include <fmt/format.h>

#include <Eigen/SparseCholesky>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "dmc/bspline.h"
#include "dmc/io.h"
#include "dmc/operators.h"
#include "dmc/pca.h"
#include "dmc/spacetime.h"

namespace dmc::cli {
namespace {

struct LaplacianArgs {
  std::string input;
  std::string operator_name;
  int rank = 0;     // 0: DDL from all frames' positions
  double mu = 0.0;  // DDL Tikhonov weight
  std::string reference = "tutte";
  int reference_frame = -1;  // geometric operators: -1 = mean frame
  int anchors = 100;
  double perturbation = 1e-3;
  unsigned seed = 1;
  double alpha = 1.0;  // spacetime: the metric's time weight
  bool json = false;
  int depth = 0;     // bspline: octree depth, 0 = automatic
  int spectrum = 0;  // > 0: print this many smallest eigenvalues instead of the report
};

struct Properties {
  double symmetry_error = 0.0;  // max |L_ij − L_ji| / max |L_ij|
  double max_row_sum = 0.0;
  double diagonal_min = 0.0, diagonal_max = 0.0;
  double negative_weight_share = 0.0;
  double delta_mean = 0.0, delta_max = 0.0;
  std::optional<bool> cholesky_ok;  // empty for non-symmetric operators (undefined there)
  std::optional<double> conditioning_delta;
  std::string conditioning_error;
  std::vector<int32_t> anchor_set;
};

Properties MatrixProperties(const SparseMatrixD& matrix) {
  Properties p;
  const Eigen::Index v_count = matrix.rows();
  Eigen::VectorXd row_sum = Eigen::VectorXd::Zero(v_count);
  double max_abs = 0.0;
  long off_diagonal = 0, negative = 0;
  for (int c = 0; c < matrix.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      row_sum[it.row()] += it.value();
      max_abs = std::max(max_abs, std::abs(it.value()));
      if (it.row() != it.col()) {
        ++off_diagonal;
        if (it.value() < 0.0) ++negative;
      }
    }
  }
  const SparseMatrixD asymmetry = SparseMatrixD(matrix.transpose()) - matrix;
  double max_asymmetry = 0.0;
  for (int c = 0; c < asymmetry.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(asymmetry, c); it; ++it) {
      max_asymmetry = std::max(max_asymmetry, std::abs(it.value()));
    }
  }
  p.symmetry_error = max_abs > 0.0 ? max_asymmetry / max_abs : 0.0;
  p.max_row_sum = v_count > 0 ? row_sum.cwiseAbs().maxCoeff() : 0.0;
  const Eigen::VectorXd diagonal = matrix.diagonal();
  p.diagonal_min = v_count > 0 ? diagonal.minCoeff() : 0.0;
  p.diagonal_max = v_count > 0 ? diagonal.maxCoeff() : 0.0;
  p.negative_weight_share =
      off_diagonal > 0 ? static_cast<double>(negative) / static_cast<double>(off_diagonal) : 0.0;
  return p;
}

// The keys every operator report shares, spacetime or not.
nlohmann::json PropertiesJson(const Properties& p, const LaplacianArgs& args) {
  nlohmann::json document = {
      {"symmetry_error", p.symmetry_error},
      {"max_row_sum", p.max_row_sum},
      {"diagonal_min", p.diagonal_min},
      {"diagonal_max", p.diagonal_max},
      {"negative_weight_share", p.negative_weight_share},
      {"delta_mean", p.delta_mean},
      {"delta_max", p.delta_max},
      {"cholesky_ok", p.cholesky_ok ? nlohmann::json(*p.cholesky_ok) : nlohmann::json()},
      {"conditioning_delta",
       p.conditioning_delta ? nlohmann::json(*p.conditioning_delta) : nlohmann::json()},
      {"anchors", p.anchor_set.size()},
      {"perturbation", args.perturbation},
  };
  if (!p.conditioning_error.empty()) document["conditioning_error"] = p.conditioning_error;
  return document;
}

// ‖δ‖ per vertex and frame, δ = L·X_f on the sequence's positions.
void DeltaStatistics(const SparseMatrixD& matrix, const MeshSequence& sequence, Properties& p) {
  const Eigen::MatrixXd delta = matrix * TrajectoryMatrix(sequence);
  double sum = 0.0, largest = 0.0;
  for (Eigen::Index v = 0; v < delta.rows(); ++v) {
    for (int f = 0; f < sequence.frame_count(); ++f) {
      const double norm = delta.block<1, 3>(v, 3 * f).norm();
      sum += norm;
      largest = std::max(largest, norm);
    }
  }
  const double count = static_cast<double>(delta.rows()) * sequence.frame_count();
  p.delta_mean = count > 0 ? sum / count : 0.0;
  p.delta_max = largest;
}

// Thesis 6.1.2: a symmetric Laplacian is semidefinite iff the matrix left after removing one row
// and column per connected component admits a Cholesky factorisation. Our convention has a
// negative diagonal, so the candidate is −L.
bool ReducedCholeskyOk(const SparseMatrixD& matrix, const MeshTopology& topology) {
  std::vector<int> kept_index(topology.vertex_count, -1);
  std::vector<char> component_seen(topology.component_count, 0);
  int kept = 0;
  for (int v = 0; v < topology.vertex_count; ++v) {
    const int component = topology.component_of_vertex[v];
    if (!component_seen[component]) {
      component_seen[component] = 1;  // the first vertex of each component is removed
      continue;
    }
    kept_index[v] = kept++;
  }
  if (kept == 0) return true;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int c = 0; c < matrix.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      const int row = kept_index[it.row()], col = kept_index[it.col()];
      if (row >= 0 && col >= 0) triplets.emplace_back(row, col, -it.value());
    }
  }
  SparseMatrixD reduced(kept, kept);
  reduced.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLLT<SparseMatrixD> cholesky(reduced);
  return cholesky.info() == Eigen::Success;
}

// Anchors: the first vertex of every component (so N is never singular by construction), then
// vertices at evenly spaced indices up to the requested count (more when there are more
// components, fewer when there are fewer vertices).
std::vector<int32_t> ChooseAnchors(const MeshTopology& topology, int count) {
  std::vector<char> chosen(topology.vertex_count, 0);
  std::vector<char> component_seen(topology.component_count, 0);
  std::vector<int32_t> anchors;
  for (int v = 0; v < topology.vertex_count; ++v) {
    if (!component_seen[topology.component_of_vertex[v]]) {
      component_seen[topology.component_of_vertex[v]] = 1;
      chosen[v] = 1;
      anchors.push_back(v);
    }
  }
  const int wanted =
      std::min(std::max(count, static_cast<int>(anchors.size())), topology.vertex_count);
  const int extra = wanted - static_cast<int>(anchors.size());
  for (int k = 0; k < extra; ++k) {
    // Midpoints of `extra` equal index ranges; a collision takes the next free index.
    int v = static_cast<int>((2L * k + 1) * topology.vertex_count / (2L * extra));
    while (chosen[v]) v = (v + 1) % topology.vertex_count;
    chosen[v] = 1;
    anchors.push_back(v);
  }
  std::sort(anchors.begin(), anchors.end());
  return anchors;
}

// Thesis 6.3.3: x uniform in [−1, 1]^V, b = N·x, b′ = b + c with c uniform in [−k, k]^V, solve
// N·x′ = b′, report ‖x − x′‖. It simulates quantisation noise on the decoder's right-hand side.
void ConditioningExperiment(const SparseMatrixD& matrix, const MeshTopology& topology,
                            const LaplacianArgs& args, Properties& p) {
  p.anchor_set = ChooseAnchors(topology, args.anchors);
  const SparseMatrixD normal = BuildNormalMatrix(matrix, p.anchor_set);
  std::mt19937_64 rng(args.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd x(topology.vertex_count), noise(topology.vertex_count);
  for (Eigen::Index v = 0; v < x.size(); ++v) x[v] = unit(rng);
  for (Eigen::Index v = 0; v < x.size(); ++v) noise[v] = args.perturbation * unit(rng);
  const auto solver = SparseSpdSolver::Factor(normal);
  if (!solver.ok()) {
    p.conditioning_error = solver.status().ToString();
    return;
  }
  const auto solved = solver->Solve(normal * x + noise);
  if (!solved.ok()) {
    p.conditioning_error = solved.status().ToString();
    return;
  }
  p.conditioning_delta = (x - solved->col(0)).norm();
}

// The spacetime operator (dmc/spacetime.h) is VF×VF, so it has no row in the registry's V×V
// table; it is reported here with the same keys on the graph of the whole sequence (row k·V + i
// is vertex i of frame k; each mesh component spans all frames), plus its own identities: the
// residual of Δ·⋆0^{1/2}·1 and the unsymmetrised operator's row sums (both ~0), and the nonzero
// count against F·(V + 2E) + 2V(F − 1). Frame times come from the frame rate (else 0..F−1).
int RunSpacetimeLaplacian(const LaplacianArgs& args) {
  constexpr std::string_view kCommand = "laplacian";
  if (!(args.alpha > 0.0) || !std::isfinite(args.alpha)) {
    return ReportError(kCommand, InvalidArgumentError("--alpha must be a finite value > 0"),
                       args.json);
  }
  if (args.anchors < 1) {
    return ReportError(kCommand, InvalidArgumentError("--anchors must be >= 1"), args.json);
  }
  StatusOr<MeshSequence> sequence = ReadSequence(args.input);
  if (!sequence.ok()) return ReportError(kCommand, sequence.status(), args.json);
  SpacetimeOptions options;
  options.alpha = args.alpha;
  const auto start = std::chrono::steady_clock::now();
  StatusOr<SpacetimeLaplacian> op = BuildSpacetimeLaplacian(*sequence, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!op.ok()) return ReportError(kCommand, op.status(), args.json);

  const int v_count = sequence->vertex_count(), f_count = sequence->frame_count();
  const MeshTopology mesh = BuildTopology(sequence->triangles(), v_count);
  MeshTopology graph;  // only what ReducedCholeskyOk and the anchor choice read
  graph.vertex_count = static_cast<int>(op->matrix.rows());
  graph.component_count = mesh.component_count;
  graph.component_of_vertex.resize(graph.vertex_count);
  Eigen::MatrixXd stacked(op->matrix.rows(), 3);
  for (int k = 0; k < f_count; ++k) {
    for (int v = 0; v < v_count; ++v) {
      graph.component_of_vertex[k * v_count + v] = mesh.component_of_vertex[v];
    }
    stacked.middleRows(static_cast<Eigen::Index>(k) * v_count, v_count) = sequence->frame_d(k);
  }
  Properties p = MatrixProperties(op->matrix);
  const Eigen::VectorXd delta_norms = (op->matrix * stacked).rowwise().norm();
  p.delta_mean = delta_norms.mean();
  p.delta_max = delta_norms.maxCoeff();
  p.cholesky_ok = ReducedCholeskyOk(op->matrix, graph);
  ConditioningExperiment(op->matrix, graph, args, p);
  const double null_space_residual = (op->matrix * op->mass.cwiseSqrt()).cwiseAbs().maxCoeff();
  const double unsymmetrised_row_sum =
      MatrixProperties(UnsymmetrisedSpacetimeLaplacian(*op)).max_row_sum;
  const int64_t expected_nonzeros = SpacetimeNonzeroCount(mesh, f_count);
  double coupling_max = 0.0;
  for (int k = 0; k + 1 < f_count; ++k) {
    const SparseMatrixD coupling = SpacetimeBlock(op->matrix, v_count, k, k + 1);
    for (int c = 0; c < coupling.outerSize(); ++c) {
      for (SparseMatrixD::InnerIterator it(coupling, c); it; ++it) {
        coupling_max = std::max(coupling_max, std::abs(it.value()));
      }
    }
  }
  const SpacetimeStats& s = op->geometry.stats;
  if (args.json) {
    nlohmann::json document = {
        {"operator", "spacetime"},
        {"seconds", seconds},
        {"vertices", v_count},
        {"frames", f_count},
        {"alpha", args.alpha},
        {"dimension", op->matrix.rows()},
        {"nonzeros", op->matrix.nonZeros()},
        {"expected_nonzeros", expected_nonzeros},
        {"null_space_residual", null_space_residual},
        {"unsymmetrised_max_row_sum", unsymmetrised_row_sum},
        {"temporal_coupling_max", coupling_max},
        {"symmetric", true},
        {"unit_sum", false},
        {"stats",
         {{"short_spatial_edges", s.short_spatial_edges},
          {"empty_vertex_duals", s.empty_vertex_duals},
          {"clamped_cotangents", s.clamped_cotangents}}},
    };
    document.update(PropertiesJson(p, args));
    PrintJson(document);
    return 0;
  }
  fmt::print(
      "{}: operator spacetime (3D+t DEC Laplacian, alpha {:g}) on {} frame(s) of {} "
      "vertices, {}×{}\n",
      args.input, args.alpha, f_count, v_count, op->matrix.rows(), op->matrix.rows());
  const auto row = [](std::string_view label, const std::string& value) {
    fmt::print("  {:<30}{}\n", label, value);
  };
  row("build time (s)", fmt::format("{:.4f}", seconds));
  row("nonzeros (expected)", fmt::format("{} ({})", op->matrix.nonZeros(), expected_nonzeros));
  row("symmetry error (relative)", fmt::format("{:.3g}", p.symmetry_error));
  row("|L sqrt(M) 1| max", fmt::format("{:.3g}", null_space_residual));
  row("unsymmetrised max |row sum|", fmt::format("{:.3g}", unsymmetrised_row_sum));
  row("diagonal min / max", fmt::format("{:.6g} / {:.6g}", p.diagonal_min, p.diagonal_max));
  row("temporal coupling max", fmt::format("{:.6g}", coupling_max));
  row("|delta| mean / max", fmt::format("{:.6g} / {:.6g}", p.delta_mean, p.delta_max));
  row("reduced Cholesky", *p.cholesky_ok ? "ok" : "fails");
  row(fmt::format("conditioning delta (k={:g})", args.perturbation),
      p.conditioning_delta
          ? fmt::format("{:.6g} with {} anchors", *p.conditioning_delta, p.anchor_set.size())
          : "failed: " + p.conditioning_error);
  return 0;
}

Status ValidateArgs(const LaplacianArgs& args) {
  if (args.rank < 0) return InvalidArgumentError("--rank must be >= 0 (0: all frames)");
  if (!(args.mu >= 0.0) || !std::isfinite(args.mu)) {
    return InvalidArgumentError("--mu must be a finite value >= 0");
  }
  if (args.reference != "tutte" && args.reference != "cotan") {
    return InvalidArgumentError("--reference must be tutte or cotan, got '" + args.reference + "'");
  }
  if (args.anchors < 1) return InvalidArgumentError("--anchors must be >= 1");
  if (args.depth < 0 || args.depth > 10) return InvalidArgumentError("--depth must be in [0, 10]");
  if (args.spectrum < 0) return InvalidArgumentError("--spectrum must be >= 0");
  if (!(args.perturbation >= 0.0) || !std::isfinite(args.perturbation)) {
    return InvalidArgumentError("--perturbation must be a finite value >= 0");
  }
  if (args.operator_name == "bspline") return Status::Ok();  // see LookUpOperator
  return FindOperator(args.operator_name).status();
}

// The B-spline operator's row, for as long as the operator registry does not list it (its row
// waits for the registry tests to accept an operator without wire ID and with a stencil wider
// than the one-ring). Its per-vertex form is built here with --depth.
const OperatorInfo* LookUpOperator(std::string_view name) {
  static constexpr OperatorInfo kBsplineInfo{
      "bspline",
      std::nullopt,
      "restricted B-spline Laplace-Beltrami (octree elements) on vertices: R^T L R, with mass",
      true,
      false,
      true,
      false,
      nullptr};
  const auto found = FindOperator(name);
  if (found.ok()) return *found;
  return name == "bspline" ? &kBsplineInfo : nullptr;
}

// --spectrum K: the K smallest eigenvalues of −L η = λ M η. For bspline these are the element
// operator's (−L η = λ D η at --depth), not its per-vertex form's.
int RunSpectrum(const LaplacianArgs& args, const MeshTopology& topology,
                const MeshSequence& sequence, const OperatorSource& source,
                const OperatorOptions& options) {
  constexpr std::string_view kCommand = "laplacian";
  const auto start = std::chrono::steady_clock::now();
  StatusOr<GeneralizedSpectrum> spectrum = InternalError("no spectrum");
  int dimension = topology.vertex_count, depth = 0;
  if (args.operator_name == "bspline") {
    BsplineOptions bspline;
    bspline.depth = args.depth > 0
                        ? args.depth
                        : AutomaticBsplineDepth(sequence.triangles(), *source.reference_frame);
    bspline.coarsest_depth = bspline.depth;
    depth = bspline.depth;
    auto op = BuildBsplineOperator(sequence.triangles(), *source.reference_frame, bspline);
    if (!op.ok()) return ReportError(kCommand, op.status(), args.json);
    dimension = op->dimension();
    spectrum = ComputeBsplineSpectrum(*op, args.spectrum);
  } else {
    auto op = BuildOperator(args.operator_name, topology, source, options);
    if (!op.ok()) return ReportError(kCommand, op.status(), args.json);
    spectrum = LaplacianSpectrum(*op, args.spectrum);
  }
  if (!spectrum.ok()) return ReportError(kCommand, spectrum.status(), args.json);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<double> values(spectrum->eigenvalues.data(),
                                   spectrum->eigenvalues.data() + spectrum->eigenvalues.size());
  if (args.json) {
    nlohmann::json document = {{"operator", args.operator_name},
                               {"eigenvalues", values},
                               {"dimension", dimension},
                               {"seconds", seconds}};
    if (depth > 0) document["depth"] = depth;
    PrintJson(document);
    return 0;
  }
  fmt::print("{}: {} smallest eigenvalues of operator {} (dimension {}{}), {:.3f} s\n", args.input,
             values.size(), args.operator_name, dimension,
             depth > 0 ? fmt::format(", depth {}", depth) : "", seconds);
  for (size_t k = 0; k < values.size(); ++k) fmt::print("  {:>4}  {:.8g}\n", k, values[k]);
  return 0;
}

int RunLaplacian(const LaplacianArgs& args) {
  if (args.operator_name == "spacetime") return RunSpacetimeLaplacian(args);
  constexpr std::string_view kCommand = "laplacian";
  // Options and the operator name first: a typo should not cost a sequence read.
  if (Status valid = ValidateArgs(args); !valid.ok()) {
    return ReportError(kCommand, valid, args.json);
  }
  const OperatorInfo* info = LookUpOperator(args.operator_name);

  ReadOptions read_options;
  std::optional<Progress> progress;
  read_options.progress = [&progress](int done, int total) {
    if (!progress) progress.emplace("reading", total);
    progress->Update(done);
  };
  ReadReport report;
  StatusOr<MeshSequence> sequence = ReadSequence(args.input, read_options, &report);
  progress.reset();
  if (!sequence.ok()) return ReportError(kCommand, sequence.status(), args.json);
  if (!args.json) {
    for (const std::string& warning : report.warnings) ReportWarning(kCommand, warning);
  }
  if (args.reference_frame >= sequence->frame_count()) {
    return ReportError(
        kCommand,
        InvalidArgumentError(fmt::format("--reference-frame {} but the sequence "
                                         "has {} frames",
                                         args.reference_frame, sequence->frame_count())),
        args.json);
  }
  const MeshTopology topology = BuildTopology(sequence->triangles(), sequence->vertex_count());

  using Clock = std::chrono::steady_clock;
  OperatorSource source = SourceFromSequence(*sequence, args.reference_frame);
  double pca_seconds = 0.0;
  int rank_used = 0;
  std::string trajectories = "positions of all frames";
  if (info->needs_trajectories && args.rank > 0) {
    const auto start = Clock::now();
    StatusOr<TrajectoryPca> pca = ComputeTrajectoryPca(*sequence, args.rank);
    if (!pca.ok()) return ReportError(kCommand, pca.status(), args.json);
    pca_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    rank_used = static_cast<int>(pca->coefficients.cols());
    source.trajectories = std::move(pca->coefficients);
    trajectories = fmt::format("PCA coefficients, rank {}", rank_used);
  }
  OperatorOptions options;
  options.ddl.mu = args.mu;
  options.ddl.reference = args.reference == "cotan" ? DdlReference::kCotan : DdlReference::kTutte;

  if (args.spectrum > 0) return RunSpectrum(args, topology, *sequence, source, options);

  const auto start = Clock::now();
  StatusOr<LaplaceOperator> op =
      info->name == "bspline"
          ? BuildBsplineVertexOperator(topology, *source.reference_frame, args.depth)
          : BuildOperator(info->name, topology, source, options);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!op.ok()) return ReportError(kCommand, op.status(), args.json);

  Properties p = MatrixProperties(op->matrix);
  DeltaStatistics(op->matrix, *sequence, p);
  if (op->symmetric) p.cholesky_ok = ReducedCholeskyOk(op->matrix, topology);
  ConditioningExperiment(op->matrix, topology, args, p);

  const OperatorStats& s = op->stats;
  if (args.json) {
    nlohmann::json document = {
        {"operator", op->name},
        {"seconds", seconds},
        {"pca_seconds", pca_seconds},
        {"vertices", sequence->vertex_count()},
        {"frames", sequence->frame_count()},
        {"rank", rank_used},
        {"mu", args.mu},
        {"symmetric", op->symmetric},
        {"unit_sum", op->unit_sum},
        {"stats",
         {{"clamped_cotangents", s.clamped_cotangents},
          {"degenerate_triangles", s.degenerate_triangles},
          {"fallback_rows", s.fallback_rows},
          {"clamped_areas", s.clamped_areas},
          {"isolated_vertices", s.isolated_vertices},
          {"dropped_constraints", s.dropped_constraints},
          {"inconsistent_rows", s.inconsistent_rows},
          {"solver_iterations", s.solver_iterations},
          {"fit_residual", s.fit_residual},
          {"constraint_error", s.constraint_error}}},
    };
    document.update(PropertiesJson(p, args));
    PrintJson(document);
    return 0;
  }

  fmt::print("{}: operator {} ({}) on {} frame(s) of {} vertices\n", args.input, op->name,
             info->description, sequence->frame_count(), sequence->vertex_count());
  if (info->needs_trajectories) fmt::print("  fitted to {}\n", trajectories);
  const auto row = [](std::string_view label, const std::string& value) {
    fmt::print("  {:<30}{}\n", label, value);
  };
  row("build time (s)", fmt::format("{:.4f}", seconds));
  if (pca_seconds > 0.0) row("PCA time (s)", fmt::format("{:.4f}", pca_seconds));
  row("symmetry error (relative)", fmt::format("{:.3g}", p.symmetry_error));
  row("max |row sum|", fmt::format("{:.3g}", p.max_row_sum));
  row("diagonal min / max", fmt::format("{:.6g} / {:.6g}", p.diagonal_min, p.diagonal_max));
  row("negative weight share", fmt::format("{:.4f}", p.negative_weight_share));
  row("|delta| mean / max", fmt::format("{:.6g} / {:.6g}", p.delta_mean, p.delta_max));
  row("reduced Cholesky",
      p.cholesky_ok ? (*p.cholesky_ok ? "ok" : "fails") : "n/a (not symmetric)");
  row(fmt::format("conditioning delta (k={:g})", args.perturbation),
      p.conditioning_delta
          ? fmt::format("{:.6g} with {} anchors", *p.conditioning_delta, p.anchor_set.size())
          : "failed: " + p.conditioning_error);
  if (s.clamped_cotangents + s.degenerate_triangles + s.fallback_rows + s.clamped_areas > 0) {
    row("repairs", fmt::format("{} clamped cotangents, {} degenerate triangles, {} fallback "
                               "rows, {} floored areas",
                               s.clamped_cotangents, s.degenerate_triangles, s.fallback_rows,
                               s.clamped_areas));
  }
  if (info->needs_trajectories) {
    row("fit residual sum |delta|^2", fmt::format("{:.6g}", s.fit_residual));
    row("constraint error", fmt::format("{:.3g}", s.constraint_error));
  }
  if (s.dropped_constraints > 0) {
    row("dropped constraints",
        fmt::format("{} ({} rows without unit sum)", s.dropped_constraints, s.inconsistent_rows));
  }
  return 0;
}

}  // namespace

Command AddLaplacianCommand(CLI::App& parent) {
  auto args = std::make_shared<LaplacianArgs>();
  CLI::App* app = parent.add_subcommand(
      "laplacian",
      "Build a discrete Laplace operator for INPUT and report its properties: symmetry, row "
      "sums, diagonal range, share of negative weights, |delta| over all vertices and frames, "
      "whether the reduced matrix admits a Cholesky factorisation, build time, and the "
      "normal-matrix conditioning experiment (random x, b = N x, b + noise, solve, |x - x'|)");
  app->add_option("input", args->input,
                  "A directory of .obj/.off/.ply frames, a glob such as 'dir/f_*.obj' (quoted), "
                  "one mesh file, or a .pc2 cache")
      ->required();
  std::string names;
  for (const OperatorInfo& info : OperatorRegistry()) {
    names += (names.empty() ? "" : ", ") + std::string(info.name);
  }
  if (!FindOperator("bspline").ok()) names += ", bspline";
  app->add_option("--operator", args->operator_name,
                  "Operator: " + names + ", spacetime (3D+t, VF x VF, see --alpha)")
      ->required();
  app->add_option("--alpha", args->alpha,
                  "spacetime: time weight of the 4D metric diag(alpha, 1, 1, 1), > 0")
      ->capture_default_str();
  app->add_option("--rank", args->rank,
                  "DDL operators: fit to the sequence's PCA coefficients of this rank; 0 fits "
                  "to the positions of all frames")
      ->capture_default_str();
  app->add_option("--mu", args->mu,
                  "DDL operators: Tikhonov weight toward the reference operator, relative to the "
                  "mean squared edge difference of the data")
      ->capture_default_str();
  app->add_option("--reference", args->reference, "DDL Tikhonov reference: tutte or cotan")
      ->capture_default_str();
  app->add_option("--reference-frame", args->reference_frame,
                  "Geometric operators: frame to build from; -1 uses the mean frame")
      ->capture_default_str();
  app->add_option("--anchors", args->anchors,
                  "Anchors of the conditioning experiment (one per component first, then "
                  "evenly spaced vertex indices)")
      ->capture_default_str();
  app->add_option("--perturbation", args->perturbation,
                  "Half-width k of the uniform noise added to b in the conditioning experiment")
      ->capture_default_str();
  app->add_option("--seed", args->seed, "Seed of the conditioning experiment's random vectors")
      ->capture_default_str();
  app->add_option("--depth", args->depth,
                  "bspline: octree depth (2^depth voxels per axis); 0 picks the depth whose voxel "
                  "is about one mean edge long")
      ->capture_default_str();
  app->add_option("--spectrum", args->spectrum,
                  "Print the K smallest eigenvalues of -L x = lambda M x (ascending, the zero mode "
                  "first; JSON key eigenvalues) instead of the report; bspline uses its element "
                  "operator at --depth, other symmetric operators their vertex mass")
      ->capture_default_str();
  app->add_flag("--json", args->json,
                "Print a JSON object with keys operator, symmetry_error, max_row_sum, "
                "negative_weight_share, delta_mean, delta_max, cholesky_ok (null when not "
                "symmetric), conditioning_delta (null when N cannot be factored), seconds, and "
                "more (diagonal_min/max, rank, mu, anchors, stats)");
  return {app, [args] { return RunLaplacian(*args); }};
}

}  // namespace dmc::cli
