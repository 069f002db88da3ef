// dmc laplacian: builds one discrete Laplace operator of the registry for a sequence and reports
// its properties — symmetry, row sums, diagonal range, negative weights, the size of δ = L·X over
// all frames, whether the reduced matrix admits a Cholesky factorisation (thesis 6.1.2), the build
// time, and the thesis's normal-matrix conditioning experiment (6.3.3) — in the operator's own
// domain (operators.h: OperatorDomain), plus the spacetime and element operators' own identities.
#include <fmt/format.h>

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
  double alpha = 1.0;                                       // spacetime: the metric's time weight
  double max_cotangent = GeometricOptions().max_cotangent;  // geometric operators' clamp
  bool json = false;
  int depth = 0;     // bspline: octree depth, 0 = automatic
  int spectrum = 0;  // > 0: print this many smallest eigenvalues instead of the report
  GltfReadFlags gltf;
};

struct Properties {
  double symmetry_error = 0.0;  // max |L_ij − L_ji| / max |L_ij|
  double max_row_sum = 0.0;
  double diagonal_min = 0.0, diagonal_max = 0.0;
  double negative_weight_share = 0.0;
  std::optional<double> delta_mean, delta_max;  // empty where δ has no per-row meaning
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

nlohmann::json OptionalJson(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json();
}

// The keys every operator report shares, whatever its domain.
nlohmann::json PropertiesJson(const Properties& p, const LaplacianArgs& args) {
  nlohmann::json document = {
      {"symmetry_error", p.symmetry_error},
      {"max_row_sum", p.max_row_sum},
      {"diagonal_min", p.diagonal_min},
      {"diagonal_max", p.diagonal_max},
      {"negative_weight_share", p.negative_weight_share},
      {"delta_mean", OptionalJson(p.delta_mean)},
      {"delta_max", OptionalJson(p.delta_max)},
      {"cholesky_ok", p.cholesky_ok ? nlohmann::json(*p.cholesky_ok) : nlohmann::json()},
      {"conditioning_delta", OptionalJson(p.conditioning_delta)},
      {"anchors", p.anchor_set.size()},
      {"perturbation", args.perturbation},
  };
  if (!p.conditioning_error.empty()) document["conditioning_error"] = p.conditioning_error;
  return document;
}

// Mean and largest norm of the rows of `delta` taken `width` columns at a time (one vertex in one
// frame per block).
void DeltaStatistics(const Eigen::MatrixXd& delta, int width, Properties& p) {
  double sum = 0.0, largest = 0.0;
  const Eigen::Index blocks = delta.cols() / width;
  for (Eigen::Index r = 0; r < delta.rows(); ++r) {
    for (Eigen::Index b = 0; b < blocks; ++b) {
      const double norm = delta.block(r, b * width, 1, width).norm();
      sum += norm;
      largest = std::max(largest, norm);
    }
  }
  const double count = static_cast<double>(delta.rows() * blocks);
  p.delta_mean = count > 0 ? sum / count : 0.0;
  p.delta_max = largest;
}

// The connected components of the reported matrix's rows: what the reduced Cholesky test and the
// anchor choice need, in every domain.
struct RowComponents {
  int rows = 0;
  int count = 0;
  std::vector<int32_t> of_row;
};

RowComponents VertexComponents(const MeshTopology& topology) {
  return {topology.vertex_count, topology.component_count, topology.component_of_vertex};
}

// Spacetime rows k·V + i: temporal edges join every vertex to itself across frames, so each mesh
// component is one component through all frames.
RowComponents SpacetimeComponents(const MeshTopology& topology, int frame_count) {
  RowComponents components{topology.vertex_count * frame_count, topology.component_count, {}};
  components.of_row.reserve(components.rows);
  for (int k = 0; k < frame_count; ++k) {
    components.of_row.insert(components.of_row.end(), topology.component_of_vertex.begin(),
                             topology.component_of_vertex.end());
  }
  return components;
}

// Components of the matrix's own sparsity graph (element operators have no mesh behind them).
RowComponents PatternComponents(const SparseMatrixD& matrix) {
  RowComponents components{static_cast<int>(matrix.rows()), 0, {}};
  components.of_row.assign(components.rows, -1);
  std::vector<int> stack;
  for (int seed = 0; seed < components.rows; ++seed) {
    if (components.of_row[seed] >= 0) continue;
    components.of_row[seed] = components.count;
    stack.push_back(seed);
    while (!stack.empty()) {
      const int column = stack.back();
      stack.pop_back();
      for (SparseMatrixD::InnerIterator it(matrix, column); it; ++it) {
        if (components.of_row[it.row()] < 0) {
          components.of_row[it.row()] = components.count;
          stack.push_back(static_cast<int>(it.row()));
        }
      }
    }
    ++components.count;
  }
  return components;
}

// Thesis 6.1.2: a symmetric Laplacian is semidefinite iff the matrix left after removing one row
// and column per connected component admits a Cholesky factorisation. Our convention has a
// negative diagonal, so the candidate is −L. The solver's factorisation with no pivot-ratio floor
// answers exactly that question: false when it finds a non-positive pivot, an error for anything
// else (a resource limit, say). CHOLMOD's supernodal LLᵀ, when the build has it, is the faster
// (Eigen's simplicial LLᵀ made the report of a 100k-row spacetime operator, 10k vertices × 10
// frames, take 69 s instead of 27 s).
StatusOr<bool> ReducedCholeskyOk(const SparseMatrixD& matrix, const RowComponents& components) {
  std::vector<int> kept_index(components.rows, -1);
  std::vector<char> component_seen(components.count, 0);
  int kept = 0;
  for (int v = 0; v < components.rows; ++v) {
    const int component = components.of_row[v];
    if (!component_seen[component]) {
      component_seen[component] = 1;  // the first row of each component is removed
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
  SolverOptions options;
  options.backend = SolverBackend::kAuto;
  options.min_pivot_ratio = 0.0;  // positive definite is the whole test
  const Status factored = SparseSpdSolver::Factor(reduced, options).status();
  if (factored.code() == ErrorCode::kNumericalFailure) return false;
  DMC_RETURN_IF_ERROR(factored);
  return true;
}

// Anchors: the first row of every component (so N is never singular by construction), then rows
// at evenly spaced indices up to the requested count (more when there are more components, fewer
// when there are fewer rows).
std::vector<int32_t> ChooseAnchors(const RowComponents& components, int count) {
  std::vector<char> chosen(components.rows, 0);
  std::vector<char> component_seen(components.count, 0);
  std::vector<int32_t> anchors;
  for (int v = 0; v < components.rows; ++v) {
    if (!component_seen[components.of_row[v]]) {
      component_seen[components.of_row[v]] = 1;
      chosen[v] = 1;
      anchors.push_back(v);
    }
  }
  const int wanted = std::min(std::max(count, static_cast<int>(anchors.size())), components.rows);
  const int extra = wanted - static_cast<int>(anchors.size());
  for (int k = 0; k < extra; ++k) {
    // Midpoints of `extra` equal index ranges; a collision takes the next free index.
    int v = static_cast<int>((2L * k + 1) * components.rows / (2L * extra));
    while (chosen[v]) v = (v + 1) % components.rows;
    chosen[v] = 1;
    anchors.push_back(v);
  }
  std::sort(anchors.begin(), anchors.end());
  return anchors;
}

// Thesis 6.3.3: x uniform in [−1, 1]^n, b = N·x, b′ = b + c with c uniform in [−k, k]^n, solve
// N·x′ = b′, report ‖x − x′‖. It simulates quantisation noise on the decoder's right-hand side.
void ConditioningExperiment(const SparseMatrixD& matrix, const RowComponents& components,
                            const LaplacianArgs& args, Properties& p) {
  p.anchor_set = ChooseAnchors(components, args.anchors);
  const SparseMatrixD normal = BuildNormalMatrix(matrix, p.anchor_set);
  std::mt19937_64 rng(args.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd x(components.rows), noise(components.rows);
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

Status ValidateArgs(const LaplacianArgs& args) {
  if (args.rank < 0) return InvalidArgumentError("--rank must be >= 0 (0: all frames)");
  if (!(args.mu >= 0.0) || !std::isfinite(args.mu)) {
    return InvalidArgumentError("--mu must be a finite value >= 0");
  }
  if (args.reference != "tutte" && args.reference != "cotan") {
    return InvalidArgumentError("--reference must be tutte or cotan, got '" + args.reference + "'");
  }
  if (!(args.alpha > 0.0) || !std::isfinite(args.alpha)) {
    return InvalidArgumentError("--alpha must be a finite value > 0");
  }
  if (args.anchors < 1) return InvalidArgumentError("--anchors must be >= 1");
  if (args.depth < 0 || args.depth > 10) return InvalidArgumentError("--depth must be in [0, 10]");
  if (args.spectrum < 0) return InvalidArgumentError("--spectrum must be >= 0");
  if (!(args.perturbation >= 0.0) || !std::isfinite(args.perturbation)) {
    return InvalidArgumentError("--perturbation must be a finite value >= 0");
  }
  return FindOperator(args.operator_name).status();
}

// --spectrum K: the K smallest eigenvalues of −L η = λ M η with the operator's own mass (bspline:
// the element Gram matrix D, so these are the element operator's eigenvalues; spacetime: ⋆0).
int RunSpectrum(const LaplacianArgs& args, const MeshTopology& topology,
                const OperatorSource& source, const OperatorOptions& options) {
  constexpr std::string_view kCommand = "laplacian";
  const auto start = std::chrono::steady_clock::now();
  auto op = BuildOperator(args.operator_name, topology, source, options);
  if (!op.ok()) return ReportError(kCommand, op.status(), args.json);
  StatusOr<GeneralizedSpectrum> spectrum = LaplacianSpectrum(*op, args.spectrum);
  if (!spectrum.ok()) return ReportError(kCommand, spectrum.status(), args.json);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<double> values(spectrum->eigenvalues.data(),
                                   spectrum->eigenvalues.data() + spectrum->eigenvalues.size());
  const int depth = op->domain == OperatorDomain::kElement ? options.bspline.depth : 0;
  const auto dimension = op->matrix.rows();
  if (args.json) {
    nlohmann::json document = {{"operator", args.operator_name},
                               {"domain", OperatorDomainName(op->domain)},
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

// What the report says about operators that do not act on the mesh's vertices, beyond the
// shared keys.
struct DomainReport {
  nlohmann::json json = nlohmann::json::object();
  std::vector<std::pair<std::string, std::string>> rows;  // text output: label, value
};

// Spacetime: the report describes the paper's symmetrised Δ = M^{−1/2}·W·M^{−1/2} (the registry
// row's matrix is W), on the graph of the whole sequence, plus its identities: the residual of
// Δ·⋆0^{1/2}·1 and the unsymmetrised operator's row sums (both ~0), the nonzero count against
// F·(V + 2E) + 2V(F − 1), and the largest temporal coupling.
DomainReport SpacetimeReport(const LaplaceOperator& op, const MeshTopology& topology,
                             const MeshSequence& sequence, const LaplacianArgs& args,
                             const SparseMatrixD& symmetrised, Properties& p) {
  const int v_count = topology.vertex_count, f_count = op.frame_count;
  Eigen::MatrixXd stacked(symmetrised.rows(), 3);
  for (int k = 0; k < f_count; ++k) {
    stacked.middleRows(static_cast<Eigen::Index>(k) * v_count, v_count) = sequence.frame_d(k);
  }
  DeltaStatistics(symmetrised * stacked, 3, p);
  const double null_space_residual = (symmetrised * op.mass.cwiseSqrt()).cwiseAbs().maxCoeff();
  const double unsymmetrised_row_sum =
      MatrixProperties(UnsymmetrisedSpacetimeLaplacian(op.matrix, op.mass)).max_row_sum;
  const int64_t expected_nonzeros = SpacetimeNonzeroCount(topology, f_count);
  double coupling_max = 0.0;
  for (int k = 0; k + 1 < f_count; ++k) {
    const SparseMatrixD coupling = SpacetimeBlock(symmetrised, v_count, k, k + 1);
    for (int c = 0; c < coupling.outerSize(); ++c) {
      for (SparseMatrixD::InnerIterator it(coupling, c); it; ++it) {
        coupling_max = std::max(coupling_max, std::abs(it.value()));
      }
    }
  }
  DomainReport report;
  report.json = {
      {"alpha", args.alpha},
      {"nonzeros", symmetrised.nonZeros()},
      {"expected_nonzeros", expected_nonzeros},
      {"null_space_residual", null_space_residual},
      {"unsymmetrised_max_row_sum", unsymmetrised_row_sum},
      {"temporal_coupling_max", coupling_max},
  };
  report.rows = {
      {"reported matrix", "symmetrised M^-1/2 W M^-1/2"},
      {"nonzeros (expected)", fmt::format("{} ({})", symmetrised.nonZeros(), expected_nonzeros)},
      {"|L sqrt(M) 1| max", fmt::format("{:.3g}", null_space_residual)},
      {"unsymmetrised max |row sum|", fmt::format("{:.3g}", unsymmetrised_row_sum)},
      {"temporal coupling max", fmt::format("{:.6g}", coupling_max)},
  };
  return report;
}

// Elements: δ has no per-vertex meaning (delta_* are null); the report adds the octree depth,
// the partition of unity of the evaluation matrix over the vertices in triangles, and 1ᵀD1, the
// surface area the mass matrix integrates.
DomainReport ElementReport(const LaplaceOperator& op, const MeshTopology& topology, int depth) {
  const Eigen::VectorXd evaluation_sums =
      op.evaluation * Eigen::VectorXd::Ones(op.evaluation.cols());
  double partition_error = 0.0;
  for (int v = 0; v < topology.vertex_count; ++v) {
    if (topology.degree(v) > 0) {
      partition_error = std::max(partition_error, std::abs(evaluation_sums[v] - 1.0));
    }
  }
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(op.mass_matrix.rows());
  const double mass_total = ones.dot(op.mass_matrix * ones);
  DomainReport report;
  report.json = {
      {"depth", depth},
      {"nonzeros", op.matrix.nonZeros()},
      {"evaluation_partition_error", partition_error},
      {"mass_total", mass_total},
  };
  report.rows = {
      {"octree depth", fmt::format("{}", depth)},
      {"nonzeros", fmt::format("{}", op.matrix.nonZeros())},
      {"evaluation max |row sum - 1|", fmt::format("{:.3g}", partition_error)},
      {"1^T D 1 (surface area)", fmt::format("{:.6g}", mass_total)},
  };
  return report;
}

int RunLaplacian(const LaplacianArgs& args) {
  constexpr std::string_view kCommand = "laplacian";
  // Options and the operator name first: a typo should not cost a sequence read.
  if (Status valid = ValidateArgs(args); !valid.ok()) {
    return ReportError(kCommand, valid, args.json);
  }
  const OperatorInfo* info = *FindOperator(args.operator_name);

  WarnIfGltfOptionsUnused(kCommand, args.gltf, {args.input});
  ReadOptions read_options;
  read_options.gltf = args.gltf.options;
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
  // --rank fits the DDL operators to PCA coefficients; spacetime reads its trajectories as frames.
  const bool fitted = info->needs_trajectories && info->domain == OperatorDomain::kVertex;
  if (fitted && args.rank > 0) {
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
  options.spacetime.alpha = args.alpha;
  options.geometric.max_cotangent = args.max_cotangent;
  options.spacetime.frame_rate = sequence->frame_rate;
  // The automatic depth is resolved here so that the report can name it.
  if (info->domain == OperatorDomain::kElement) {
    options.bspline.depth =
        args.depth > 0 ? args.depth
                       : AutomaticBsplineDepth(sequence->triangles(), *source.reference_frame);
  }
  options.allow_any_domain = true;  // every report below reads op->domain

  if (args.spectrum > 0) return RunSpectrum(args, topology, source, options);

  const auto start = Clock::now();
  StatusOr<LaplaceOperator> op = BuildOperator(info->name, topology, source, options);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!op.ok()) return ReportError(kCommand, op.status(), args.json);

  // The matrix the shared keys describe, and the graph of its rows.
  SparseMatrixD symmetrised;
  if (op->domain == OperatorDomain::kSpacetime) {
    symmetrised = SymmetrisedSpacetimeLaplacian(op->matrix, op->mass);
  }
  const SparseMatrixD& reported =
      op->domain == OperatorDomain::kSpacetime ? symmetrised : op->matrix;
  const RowComponents components =
      op->domain == OperatorDomain::kVertex      ? VertexComponents(topology)
      : op->domain == OperatorDomain::kSpacetime ? SpacetimeComponents(topology, op->frame_count)
                                                 : PatternComponents(op->matrix);
  Properties p = MatrixProperties(reported);
  DomainReport domain_report;
  switch (op->domain) {
    case OperatorDomain::kVertex:
      DeltaStatistics(op->matrix * TrajectoryMatrix(*sequence), 3, p);
      break;
    case OperatorDomain::kSpacetime:
      domain_report = SpacetimeReport(*op, topology, *sequence, args, symmetrised, p);
      break;
    case OperatorDomain::kElement:
      domain_report = ElementReport(*op, topology, options.bspline.depth);
      break;
  }
  if (op->symmetric) {
    const StatusOr<bool> cholesky_ok = ReducedCholeskyOk(reported, components);
    if (!cholesky_ok.ok()) return ReportError(kCommand, cholesky_ok.status(), args.json);
    p.cholesky_ok = *cholesky_ok;
  }
  ConditioningExperiment(reported, components, args, p);

  const OperatorStats& s = op->stats;
  if (args.json) {
    nlohmann::json document = {
        {"operator", op->name},
        {"domain", OperatorDomainName(op->domain)},
        {"dimension", reported.rows()},
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
          {"constraint_error", s.constraint_error},
          {"short_spatial_edges", s.short_spatial_edges},
          {"empty_vertex_duals", s.empty_vertex_duals}}},
    };
    document.update(PropertiesJson(p, args));
    document.update(domain_report.json);
    PrintJson(document);
    return 0;
  }

  fmt::print("{}: operator {} ({}) on {} frame(s) of {} vertices, {} domain, {}×{}\n", args.input,
             op->name, info->description, sequence->frame_count(), sequence->vertex_count(),
             OperatorDomainName(op->domain), reported.rows(), reported.rows());
  if (fitted) fmt::print("  fitted to {}\n", trajectories);
  const auto row = [](std::string_view label, const std::string& value) {
    fmt::print("  {:<30}{}\n", label, value);
  };
  row("build time (s)", fmt::format("{:.4f}", seconds));
  if (pca_seconds > 0.0) row("PCA time (s)", fmt::format("{:.4f}", pca_seconds));
  for (const auto& [label, value] : domain_report.rows) row(label, value);
  row("symmetry error (relative)", fmt::format("{:.3g}", p.symmetry_error));
  row("max |row sum|", fmt::format("{:.3g}", p.max_row_sum));
  row("diagonal min / max", fmt::format("{:.6g} / {:.6g}", p.diagonal_min, p.diagonal_max));
  row("negative weight share", fmt::format("{:.4f}", p.negative_weight_share));
  row("|delta| mean / max", p.delta_mean
                                ? fmt::format("{:.6g} / {:.6g}", *p.delta_mean, *p.delta_max)
                                : "n/a (element coefficients, not vertices)");
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
  if (s.short_spatial_edges + s.empty_vertex_duals > 0) {
    row("repairs", fmt::format("{} short spatial edges, {} empty vertex duals",
                               s.short_spatial_edges, s.empty_vertex_duals));
  }
  if (fitted) {
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
                  "one mesh file, a .pc2 cache, or a .glb/.gltf animation")
      ->required();
  std::string names;
  for (const OperatorInfo& info : OperatorRegistry()) {
    names += (names.empty() ? "" : ", ") + std::string(info.name);
  }
  app->add_option("--operator", args->operator_name,
                  "Operator from the registry: " + names +
                      " (spacetime: VF x VF over all frames, see --alpha; bspline: N x N over "
                      "octree elements, see --depth)")
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
  app->add_option("--max-cotangent", args->max_cotangent,
                  "Geometric operators: cotangents (mean value: tan(a/2)) are clamped to this, "
                  "cot 1 degree by default (robust next to slivers, at the cost of linear "
                  "precision there); a large value turns the clamp off")
      ->check(CLI::PositiveNumber)
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
                  "first; JSON key eigenvalues) instead of the report, with the operator's own "
                  "mass: bspline its element mass matrix at --depth, spacetime its dual volumes, "
                  "other symmetric operators their vertex areas (identity without)")
      ->capture_default_str();
  AddGltfReadOptions(app, &args->gltf);
  app->add_flag("--json", args->json,
                "Print a JSON object with keys operator, symmetry_error, max_row_sum, "
                "negative_weight_share, delta_mean, delta_max (null for bspline), cholesky_ok "
                "(null when not symmetric), conditioning_delta (null when N cannot be factored), "
                "seconds, domain (vertex, spacetime, element), dimension, and more "
                "(diagonal_min/max, rank, mu, anchors, stats; spacetime: nonzeros, "
                "expected_nonzeros, null_space_residual, unsymmetrised_max_row_sum; bspline: "
                "depth, evaluation_partition_error, mass_total)");
  return {app, [args] { return RunLaplacian(*args); }};
}

}  // namespace dmc::cli
