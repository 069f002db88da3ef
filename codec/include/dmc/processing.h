// Laplacian mesh processing methods behind one registry (dmc_processing): editing, smoothing,
// parameterisation, morphing, least-squares meshes, curvature, spectral filtering, and whatever
// other engineers plug in (spacetime ARAP, B-spline spectra, ...).
//
// Design (libigl's precompute/solve split):
//  - A method is one row of the registry (codec/src/processing/registry.cpp): a stable name, a
//    description, its declared parameters (name, type, default, help — the CLI builds its options
//    from them) and a precompute function.
//  - Precompute runs ONCE per connectivity, operator, selection and parameter set: it receives a
//    ProcessingContext (topology, the one Laplace operator, the whole input sequence, the
//    selection, the parameters) and returns a PreparedMethod holding every factorisation it needs.
//  - The PreparedMethod is then applied many times: to each frame of a dynamic mesh (Apply), to
//    new constraint targets for the same frame (Apply with FrameConstraints: interactive editing
//    re-solves without re-factorising), or, for methods that consume a whole sequence (morphing,
//    spacetime ARAP), to the sequence at once (ApplySequence).
//  - One operator serves the whole sequence (RunMethod builds it from OperatorSource::
//    SourceFromSequence: a geometric operator from the mean frame or a chosen frame, a DDL fitted
//    to all frames), so per-frame results stay temporally consistent.
//
// Adding a method is one .cpp file in codec/src/processing defining `MethodInfo <Name>Method()`
// plus one declaration and one row in registry.cpp's table.
//
// Coordinates are processed in double precision; outputs are converted to the float32 storage of
// MeshSequence only at the end. Every sparse factorisation uses SparseSpdSolver (operators.h).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dmc/operators.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

// ---------------------------------------------------------------------------------------------
// Selections: which vertices are handles, which are fixed, and how the handles move.

// JSON form: {"handles": [3, 17, ...], "fixed": [...], "transform": [16 numbers, row-major 4×4]}
// with the optional extras "free": [...] (the thesis's unconstrained set U: when given, every
// vertex in neither "handles" nor "free" is fixed, and "fixed" must be absent), "anchors": [...]
// (soft anchor rows of laplacian-edit) and "weights": [...] (one positive weight per handle:
// ls-mesh control point weights). A plain-text selection file holds whitespace-separated vertex
// indices (handles; '#' starts a comment to the end of the line).
struct Selection {
  std::vector<int32_t> handles;  // H: moved by `transform` (or by FrameConstraints)
  std::vector<int32_t> fixed;    // F: keep their input positions
  std::vector<int32_t> anchors;  // soft x′_a = x_a rows (editing); must not be handles or fixed
  std::vector<double> handle_weights;  // empty, or one positive weight per handle
  // Applied to the handles' input positions: x′ = (T·[x; 1]).head(3). Must be affine (last row
  // 0 0 0 1).
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  std::optional<std::vector<int32_t>> free;  // U as given in JSON; resolved by ValidateSelection
};

// Parses the JSON form. kParseError on malformed JSON or a wrong element type (naming the key),
// kInvalidArgument on a transform without 16 finite numbers or an unknown key.
StatusOr<Selection> ParseSelectionJson(std::string_view text);
// Reads a selection file: JSON when its first non-blank character is '{', else a vertex index
// list. kIoError when unreadable, kParseError on a malformed index list.
StatusOr<Selection> ReadSelectionFile(const std::filesystem::path& path);
// Checks a selection against a mesh of `vertex_count` vertices and normalises it in place:
// resolves "free" into `fixed`, sorts and de-duplicates every index list (handle weights follow
// their handles). kInvalidArgument (naming the index) on an index outside [0, V), a vertex both a
// handle and fixed, an anchor that is a handle or fixed, a weight count that does not match the
// handle count, a non-positive weight, or a transform that is not affine and finite.
Status ValidateSelection(Selection& selection, int vertex_count);
// The handles' target positions for one frame: `transform` applied to positions(handles), |H|×3.
Eigen::MatrixXd TransformedHandlePositions(const Selection& selection,
                                           const FramePositionsD& positions);

// ---------------------------------------------------------------------------------------------
// Method parameters, declared per method so the CLI and the Python bindings can expose them.

enum class ParameterType : uint8_t {
  kNumber,   // finite double
  kInteger,  // int
  kText,     // free text (methods validate choices, e.g. "linear|rotation")
  kFlag,     // boolean; "true"/"false"/"1"/"0"; the CLI exposes it as a flag
};

struct ParameterSpec {
  std::string_view name;  // lower case with dashes; becomes the CLI option --name
  ParameterType type = ParameterType::kNumber;
  std::string_view default_value;  // as text, parsed like a user value
  std::string_view help;
};

// Option names the edit CLI reserves for itself; no method may declare them.
std::span<const std::string_view> ReservedParameterNames();

// The values of one method's parameters: defaults overridden by user text. Typed getters return
// kInternal for a name the method did not declare or a type mismatch (a bug in the method).
class ParameterValues {
 public:
  ParameterValues() = default;
  // Defaults of `specs`, then every override (name → text). kNotFound for an override the method
  // does not declare (listing the declared ones), kInvalidArgument for a value that does not
  // parse as the declared type (naming the parameter).
  static StatusOr<ParameterValues> Create(std::span<const ParameterSpec> specs,
                                          const std::map<std::string, std::string>& overrides = {});

  StatusOr<double> Number(std::string_view name) const;
  StatusOr<int> Integer(std::string_view name) const;
  StatusOr<std::string> Text(std::string_view name) const;
  StatusOr<bool> Flag(std::string_view name) const;

  // Every parameter as name → value text (for reports).
  const std::map<std::string, std::string, std::less<>>& values() const { return values_; }

 private:
  StatusOr<const std::string*> Find(std::string_view name, ParameterType type) const;
  std::map<std::string, std::string, std::less<>> values_;
  std::map<std::string, ParameterType, std::less<>> types_;
};

// ---------------------------------------------------------------------------------------------
// The method interface.

// Everything precompute may read. References are valid only during the precompute call: a
// PreparedMethod copies (or factorises) what it keeps.
struct ProcessingContext {
  const MeshSequence& sequence;  // the whole input; a single mesh is a one-frame sequence
  const MeshTopology& topology;  // of sequence.triangles()
  // The one operator for every frame (see the top of this file). Null exactly when the method's
  // row sets needs_operator = false (it builds its own, e.g. a spacetime operator).
  const LaplaceOperator* laplace = nullptr;
  // The geometry the operator was built from: the mean frame, or frame `operator_frame`.
  const FramePositionsD& reference_frame;
  const Selection& selection;  // validated; empty lists when no selection was given
  const ParameterValues& parameters;
  std::string_view operator_name;  // as requested (methods building their own operator use it)
  const OperatorOptions& operator_options;
};

// A named number a method reports, e.g. {frame 0, "flipped_triangles", 0}.
struct Measurement {
  int frame = 0;
  std::string name;
  double value = 0.0;
};

// Apply-time overrides of the selection's constraints, for re-solving with the same factor.
struct FrameConstraints {
  // |handles|×3 target positions replacing the selection's transformed handles; empty = unused.
  Eigen::MatrixXd handle_positions;
};

// The result of one frame.
struct FrameOutput {
  FramePositionsD positions;  // V×3, the processed geometry (same connectivity)
  Eigen::VectorXd
      vertex_scalar;  // V values when the method's row names a vertex_scalar, else empty
  std::vector<Measurement> measurements;  // `frame` = the frame index given to Apply
};

// The result of a whole run.
struct ProcessingResult {
  MeshSequence sequence;    // same triangles as the input; the frame count may differ (morph)
  std::string scalar_name;  // non-empty exactly when vertex_scalars holds one vector per frame
  std::vector<Eigen::VectorXd> vertex_scalars;
  std::vector<Measurement> measurements;
};

// A method after precompute. Apply and ApplySequence are const and may be called any number of
// times (they reuse the precomputed factorisations). Not safe to call concurrently.
class PreparedMethod {
 public:
  virtual ~PreparedMethod() = default;
  // Processes one frame given as V×3 positions; `frame_index` is its index in the sequence
  // (reported in measurements, and used by methods with per-frame data). `constraints` (may be
  // null) overrides the selection's handle targets. Default: kUnsupported (whole-sequence
  // methods).
  virtual StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                                      const FrameConstraints* constraints = nullptr) const;
  // Processes a whole sequence. Default: Apply on every frame in order, collected into a result
  // with the input's triangles, name and frame rate. Whole-sequence methods override it.
  virtual StatusOr<ProcessingResult> ApplySequence(const MeshSequence& sequence) const;

 protected:
  // Name of the per-vertex scalar the default ApplySequence stores ("" = none).
  explicit PreparedMethod(std::string scalar_name = {}) : scalar_name_(std::move(scalar_name)) {}

 private:
  std::string scalar_name_;
};

enum class MethodScope : uint8_t {
  kPerFrame,       // Apply works on single frames (and single meshes)
  kWholeSequence,  // needs the whole sequence: only ApplySequence is meaningful
};

using PrecomputeFunction = StatusOr<std::unique_ptr<PreparedMethod>> (*)(const ProcessingContext&);

// One row of the processing registry.
struct MethodInfo {
  std::string_view name{};  // stable, lower case: "laplacian-edit"
  std::string_view description{};
  MethodScope scope = MethodScope::kPerFrame;
  bool needs_operator = true;        // RunMethod builds --operator once and passes it
  bool needs_selection = false;      // at least one handle required
  std::string_view vertex_scalar{};  // per-vertex scalar output name, e.g. "mean_curvature"
  std::span<const ParameterSpec> parameters{};
  PrecomputeFunction precompute = nullptr;
};

// The table in a fixed order, and lookup by name (kNotFound listing every method).
std::span<const MethodInfo> ProcessingRegistry();
StatusOr<const MethodInfo*> FindMethod(std::string_view name);

// ---------------------------------------------------------------------------------------------
// Running a method.

struct RunOptions {
  std::string operator_name = "cotan";
  OperatorOptions operator_options;
  // Source of the one operator: -1 = mean frame (geometric) and all frames (DDL trajectories);
  // f ≥ 0 = frame f as the geometric reference (DDL still fits all frames).
  int operator_frame = -1;
  Selection selection;                            // validated by Prepare
  std::map<std::string, std::string> parameters;  // overrides of the method's defaults
};

// A method ready to be applied: owns the topology, the operator and the precomputed state.
struct PreparedRun {
  const MethodInfo* method = nullptr;
  MeshTopology topology;
  std::optional<LaplaceOperator> laplace;  // set when the method needs an operator
  Selection selection;                     // validated copy
  ParameterValues parameters;
  std::unique_ptr<PreparedMethod> prepared;
};

// Looks the method up, checks the selection and parameters, builds the operator once for the
// whole sequence and runs precompute. kNotFound for an unknown method or operator,
// kInvalidArgument for a bad selection, parameter or a missing required selection, and whatever
// precompute reports (kNumericalFailure for a singular system, kUnsupported for a mesh the method
// cannot handle, e.g. a non-disk for param-barycentric).
StatusOr<PreparedRun> Prepare(std::string_view method, const MeshSequence& sequence,
                              const RunOptions& options);
// Prepare + ApplySequence.
StatusOr<ProcessingResult> RunMethod(std::string_view method, const MeshSequence& sequence,
                                     const RunOptions& options);
// A single mesh (one frame): Prepare + Apply.
StatusOr<FrameOutput> RunMethodOnMesh(std::string_view method, const Triangles& triangles,
                                      const FramePositionsD& positions, const RunOptions& options);

// ---------------------------------------------------------------------------------------------
// Morphing helpers (the morph method; public so they can be tested and reused).

enum class DeltaInterpolation : uint8_t {
  kLinear,    // (1 − t)·d1 + t·d2: the same as interpolating positions (thesis 3.5)
  kRotation,  // length (1 − t)|d1| + t|d2|, direction rotated from d1 toward d2 by t·α about
              // n = d1×d2/|d1×d2| (Rodrigues); rows where either vector is ~0 fall back to linear
};

// Interpolates differential coordinates row by row (from, to: n×3). t = 0 gives `from`, t = 1
// gives `to` (to rounding); with kRotation every row's length lies between the two inputs'.
Eigen::MatrixXd InterpolateDeltas(const Eigen::MatrixXd& from, const Eigen::MatrixXd& to, double t,
                                  DeltaInterpolation mode);

// ---------------------------------------------------------------------------------------------
// Output with a per-vertex scalar.

// Writes one frame as an ASCII PLY with per-vertex float x y z, the float property
// `scalar_name` and uchar red green blue from a blue–white–red diverging colour map symmetric
// about zero (|value| at the 98th percentile of |scalars| saturates, so a few outliers do not
// wash the map out). Atomic like every dmc writer. kInvalidArgument on a size mismatch or an
// empty / non-identifier scalar name.
Status WriteScalarPly(const std::filesystem::path& path, const Triangles& triangles,
                      const FramePositionsD& positions, const Eigen::VectorXd& scalars,
                      std::string_view scalar_name);
// RGB (0..255) of `value` on the map above for a saturation magnitude `range` > 0.
std::array<uint8_t, 3> DivergingColour(double value, double range);

}  // namespace dmc
