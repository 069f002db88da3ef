// Editing time-varying meshes (TVMs: every frame has its own vertices and triangles) from the
// trajectories of sparse volume centres, after Hácha, Dvořák, Káčereková and Váša, "Editing Mesh
// Sequences with Varying Connectivity" (seeds/editing-time-varying-meshes.txt). Section numbers
// below refer to that paper.
//
// Pipeline of one edit (Section III):
//  1. the user transforms a set E of centres in one frame f (rigid transforms as unit dual
//     quaternions), or asks for inflation, a loop closure, or transforms given on vertices;
//  2. intra-frame blending (IV-A) gives every centre of frame f a transform, weighted by the
//     affinity a(i, j) = exp(-(alpha * max_g |x_i,g - x_j,g|)^2), which is low for centres that
//     are ever far apart, so bodies that only touch do not drag each other;
//  3. inter-frame propagation (IV-B) moves each centre's transform into every other frame g through
//     the local frame of its K most affine neighbours (weighted Kabsch), blended towards the
//     identity by a time decay;
//  4. the surface of each frame (IV-C) follows its nearest centre and that centre's k-1 most affine
//     neighbours with Boltzmann smooth-minimum weights and dual-quaternion blending; edges whose
//     ends rotate too differently are split (IV-D, threshold zeta, at most S rounds).
//
// Conventions: frames and centres are 0-based; positions are double precision in memory (files
// hold float32 frames and decimal centres); all functions are deterministic and thread-safe on
// const objects. Nothing here throws across the API; failures are Status values.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc::tvm {

// ---------------------------------------------------------------------------------------------
// Data model (header-only, so generators outside dmc_tvm can build it).

// One frame of a time-varying mesh: its own vertex positions and its own triangles (0-based
// indices into `positions`).
struct TvmFrame {
  FramePositionsD positions;
  Triangles triangles;

  int vertex_count() const { return static_cast<int>(positions.rows()); }
  int triangle_count() const { return static_cast<int>(triangles.rows()); }
};

// A sequence of frames whose vertex counts and connectivity may all differ.
struct TimeVaryingMesh {
  std::string name;
  double frame_rate = 0.0;  // frames per second; 0 when unknown
  std::vector<TvmFrame> frames;

  int frame_count() const { return static_cast<int>(frames.size()); }
};

// Trajectories of n volume centres over F frames: positions[f] is the n x 3 matrix of frame f
// (row i is x_i,f). Every frame has the same n: centre i is the same volume element throughout.
struct CentreTrajectories {
  std::vector<FramePositionsD> positions;

  int frame_count() const { return static_cast<int>(positions.size()); }
  int centre_count() const { return positions.empty() ? 0 : static_cast<int>(positions[0].rows()); }
  Eigen::Vector3d position(int centre, int frame) const {
    return positions[static_cast<size_t>(frame)].row(centre).transpose();
  }
};

// ---------------------------------------------------------------------------------------------
// Files.

// Name of the centres file that `dmc synth prism|collision` writes beside the frames and that
// `dmc edit tvm` writes beside its output frames.
inline constexpr std::string_view kCentresFileName = "centres.txt";

// Checks a TVM: at least one frame; every frame has at least one vertex and one triangle, finite
// coordinates, and triangle indices in [0, V_f). Errors (kInvalidSequence) name the frame and the
// vertex or triangle at fault.
Status ValidateTimeVaryingMesh(const TimeVaryingMesh& mesh);

// Checks centres: at least one frame and one centre, the same centre count in every frame, finite
// coordinates (kInvalidSequence naming frame and centre). With expected_frames > 0 the frame count
// must equal it (kMismatch).
Status ValidateCentres(const CentreTrajectories& centres, int expected_frames = 0);

// Reads a TVM from a directory of per-frame .obj, .off or .ply files (one format; hidden files and
// other files, such as centres.txt, are ignored), in natural order (2.obj before 10.obj), with the
// strict parsers of dmc/io.h. Frames may have any vertex count and connectivity. The result has
// passed ValidateTimeVaryingMesh; `name` is the directory's name. Errors: kIoError (cannot list or
// read), kParseError ("<path>:<line>: ..."), kInvalidSequence (no frame files, bad indices,
// non-finite values), kInvalidArgument (mixed formats).
StatusOr<TimeVaryingMesh> ReadTimeVaryingMesh(const std::filesystem::path& directory);

// Writes frame_0000.<fmt>, frame_0001.<fmt>, ... (4 digits, more from 10000 frames) into
// `directory`, each file atomically, float32 coordinates in shortest round-trip form.
// frame_format is "obj", "off" or "ply" (ASCII). The directory is created when missing (its parent
// must exist); an existing one may only hold frame_* files and centres.txt, which are removed
// first so no stale frame survives (kIoError otherwise, so a typo cannot wipe unrelated files).
// The mesh must pass ValidateTimeVaryingMesh.
Status WriteTimeVaryingMesh(const TimeVaryingMesh& mesh, const std::filesystem::path& directory,
                            std::string_view frame_format = "obj");

// Centres text format (version 1), UTF-8/ASCII, whitespace separated, '#' starts a comment that
// runs to the end of the line:
//
//   dmc-centres 1
//   <n> <F>
//   x_0,0 y_0,0 z_0,0  x_0,1 y_0,1 z_0,1  ...  x_0,F-1 y_0,F-1 z_0,F-1
//   ...                                          (n lines, one trajectory c_i in R^3F per line)
//
// i.e. an n x F x 3 array, centre-major, as the paper writes c_i = [x_i,1, ..., x_i,F]. Line
// breaks are not significant beyond readability; exactly 3nF finite decimal numbers must follow
// the header. Errors: kParseError "<path>:<line>: ..." for a bad token, a missing or extra number,
// or a wrong magic/version; kIoError when the file cannot be read.
StatusOr<CentreTrajectories> ReadCentres(const std::filesystem::path& path);
StatusOr<CentreTrajectories> ParseCentres(std::string_view text);  // same, from memory
// Writes the format above atomically (doubles in shortest round-trip form, bit-exact on reading).
Status WriteCentres(const CentreTrajectories& centres, const std::filesystem::path& path);

// ---------------------------------------------------------------------------------------------
// Unit dual quaternions (Section III): q = r + eps d with eps^2 = 0. A rigid motion
// x -> R x + t is r = rotation quaternion, d = 1/2 t r (t as a pure quaternion).

class DualQuaternion {
 public:
  DualQuaternion() : real_(Eigen::Quaterniond::Identity()), dual_(0.0, 0.0, 0.0, 0.0) {}
  DualQuaternion(const Eigen::Quaterniond& real, const Eigen::Quaterniond& dual)
      : real_(real), dual_(dual) {}

  static DualQuaternion Identity() { return {}; }
  // x -> rotation * x + translation (rotation must be a unit quaternion).
  static DualQuaternion FromRigid(const Eigen::Quaterniond& rotation,
                                  const Eigen::Vector3d& translation);
  static DualQuaternion FromTranslation(const Eigen::Vector3d& translation);
  static DualQuaternion FromRotation(const Eigen::Quaterniond& rotation);
  // The rotation part of `isometry` must be orthonormal with determinant +1.
  static DualQuaternion FromIsometry(const Eigen::Isometry3d& isometry);

  const Eigen::Quaterniond& real() const { return real_; }
  const Eigen::Quaterniond& dual() const { return dual_; }

  // Composition: (a * b)(x) = a(b(x)).
  DualQuaternion operator*(const DualQuaternion& other) const;
  // Linear combination of the 8 coefficients (blending); the result is generally not unit.
  DualQuaternion operator+(const DualQuaternion& other) const;
  DualQuaternion operator*(double scale) const;

  // Quaternion conjugate of both parts; the inverse motion for a unit dual quaternion.
  DualQuaternion Conjugate() const { return {real_.conjugate(), dual_.conjugate()}; }
  // |r|, the dual quaternion norm's real part (what blending divides by).
  double Norm() const { return real_.norm(); }
  // The nearest unit dual quaternion: r/|r|, and d/|r| without its component along r, so
  // r.d = 0 holds exactly as far as rounding allows. Requires Norm() > 0.
  DualQuaternion Normalized() const;
  // Dot product of the real parts as 4-vectors (sign alignment before blending).
  double RealDot(const DualQuaternion& other) const {
    return real_.coeffs().dot(other.real_.coeffs());
  }

  Eigen::Quaterniond Rotation() const { return real_; }
  Eigen::Vector3d Translation() const;
  Eigen::Isometry3d ToIsometry() const;
  // Rotation angle in [0, pi] (the sign of q does not matter).
  double RotationAngle() const;
  // Applies the rigid motion to a point.
  Eigen::Vector3d Apply(const Eigen::Vector3d& point) const;

 private:
  Eigen::Quaterniond real_;
  Eigen::Quaterniond dual_;
};

// Dual-quaternion linear blending (Kavan et al.): sum_i w_i s_i q_i normalised, where s_i = +-1
// puts every q_i in the hemisphere of the first one with a non-zero weight (q and -q are the same
// motion). Weights must be non-negative with a positive sum; the result is a unit dual quaternion.
DualQuaternion BlendDualQuaternions(std::span<const DualQuaternion> transforms,
                                    std::span<const double> weights);

// Weighted Kabsch (Sorkine-Hornung & Rabinovich): the rotation R minimising
// sum_j w_j |R (s_j - s_bar) - (t_j - t_bar)|^2 with weighted centroids s_bar, t_bar; always a
// proper rotation (det +1). Returns the identity when the weighted source is a single point.
// `source` and `target` are m x 3 with m = weights.size().
Eigen::Matrix3d WeightedKabsch(const Eigen::Ref<const FramePositionsD>& source,
                               const Eigen::Ref<const FramePositionsD>& target,
                               std::span<const double> weights);

// ---------------------------------------------------------------------------------------------
// Affinity (Section IV-A).

struct AffinityOptions {
  // Shape parameter alpha of a(i, j) = exp(-(alpha * max_f |x_i,f - x_j,f|)^2), in inverse length
  // units. 0 picks 1 / h, h = median distance from a centre to its nearest other centre in
  // frame 0: affinity is e^-1 at one centre spacing and below 1e-12 (exactly 0, see
  // min_affinity) past 5.3 spacings, so parts that are ever that far apart never interact.
  double alpha = 0.0;
  // Neighbourhood size kept per centre (itself included): the K most affine centres, exactly,
  // found with a kd-tree (candidates within the K-th best max-distance in frame 0, since
  // max_f d >= d_0). Must cover both the Kabsch and the surface neighbourhoods. Cost is about
  // n log n + n m F with m the candidates per centre: near-linear while centres keep their
  // neighbours, up to O(n^2 F) if the K-th most affine centre is ever as far as the whole set.
  int neighbours = 16;
  // Affinities below this are treated as exactly 0 (bodies that separate do not interact at all).
  double min_affinity = 1e-12;
};

// The affinity structure of a set of centre trajectories: alpha, each centre's most affine
// neighbours (sorted by decreasing affinity, the centre itself first), and a spatial index over
// frame 0 to find every centre with non-negligible affinity to a given one without O(n^2 F) work.
class AffinityGraph {
 public:
  // Errors: kInvalidSequence for invalid centres; kInvalidArgument for neighbours < 1, alpha < 0,
  // min_affinity outside (0, 1), or an automatic alpha on centres that all coincide in frame 0.
  static StatusOr<AffinityGraph> Build(const CentreTrajectories& centres,
                                       const AffinityOptions& options = {});

  double alpha() const;
  int centre_count() const;
  // Neighbour count per centre: min(options.neighbours, centre_count()).
  int neighbour_count() const;
  // The K most affine centres of `centre` (ties broken by index) and their affinities.
  std::span<const int32_t> Neighbours(int centre) const;
  std::span<const double> NeighbourAffinities(int centre) const;
  // a(i, j) from the definition, O(F); exactly 0 below min_affinity.
  double Affinity(int i, int j) const;
  // Calls visit(j, a(i, j)) for every centre j (i included) with a(i, j) >= min_affinity, in
  // increasing j.
  void ForEachAffine(int centre, const std::function<void(int, double)>& visit) const;
  // Centre nearest to `point` among frame `frame`'s positions (ties: lower index).
  int NearestCentre(int frame, const Eigen::Vector3d& point) const;
  // Median nearest-neighbour spacing of the centres in frame 0 (0 for a single centre).
  double spacing() const;

  const CentreTrajectories& centres() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// Deformation of the centres (Sections IV-A, IV-B).

enum class DecayKind {
  kNone,    // the edit reaches every frame with full weight
  kLinear,  // psi(t) = max(0, 1 - |t - t0| / r): C0
  kSmooth,  // psi = s^3 (10 - 15 s + 6 s^2), s = max(0, 1 - |t - t0| / r): C2 at both ends
};

// Time decay: the weight psi(t) in [0, 1] with which the propagated transform is kept in frame t
// (the rest goes to the identity): T = normalise(psi T + (1 - psi) e). psi(t0) = 1 and psi = 0
// from |t - t0| >= radius on, so the window's ends are left exactly unedited. (The paper's
// phi(t) = max(0, r - |t - t0|) is the same linear profile before scaling to [0, 1].)
struct TimeDecay {
  DecayKind kind = DecayKind::kNone;
  double radius = 0.0;  // frames; must be > 0 unless kind == kNone

  double Weight(int frame, int edit_frame) const;
};

// Transforms of every centre in every frame: transforms[f][i] maps x_i,f to its edited position.
using CentreTransforms = std::vector<std::vector<DualQuaternion>>;

// Intra-frame blending, Eq. (2): effectors keep their transforms; every other centre i gets
// normalise(sum_e a(i,e) T_e + w_0 e) with w_0 = max(0, 1 - sum_e a(i,e)) when
// anchor_to_identity, else w_0 = 0 (Eq. (2) as printed; centres without any affine effector then
// stay put). Why the anchor: Eq. (2) normalises by sum_e a(i,e), so a single effector would move
// every centre of the sequence rigidly; the paper's interface pairs edits with static regions, and
// the anchor is that static region wherever the effectors' affinity fades. Where
// sum_e a(i,e) >= 1 (notably next to a dense edited set) both forms agree, so a global rigid
// transform on all centres stays exactly rigid (Section IV-E).
std::vector<DualQuaternion> BlendIntraFrame(const AffinityGraph& graph,
                                            std::span<const int32_t> effectors,
                                            std::span<const DualQuaternion> effector_transforms,
                                            bool anchor_to_identity = true);

// Inter-frame propagation (IV-B) of the transforms of frame `edit_frame` to all frames:
//   T_i,g = O_i,g R_i O*_i,f T_i,f O_i,f R*_i O*_i,g,   then   normalise(psi T_i,g + (1-psi) e)
// where O_i,h translates to the affinity-weighted centroid of centre i's `kabsch_neighbours` most
// affine neighbours in frame h, and R_i is their weighted Kabsch rotation from frame f to frame g.
// Frames where psi = 0 get exact identities, and frame f keeps T_i,f.
CentreTransforms PropagateToFrames(const AffinityGraph& graph, int edit_frame,
                                   std::span<const DualQuaternion> edit_transforms,
                                   const TimeDecay& decay, int kabsch_neighbours);

// ---------------------------------------------------------------------------------------------
// Surface deformation (Sections IV-C, IV-D).

struct SurfaceOptions {
  int neighbours = 8;  // k: the nearest centre plus its k-1 most affine centres
  double sigma = 2.0;  // smoothness of the Boltzmann smooth-minimum pseudo-weights
  // epsilon of the smooth minimum, relative to the centre spacing: exp(-d_i / (sigma d_1 + eps)).
  double relative_epsilon = 1e-9;
  // Adaptive subdivision: an edge is split when the rotation angle of T_i T_j* exceeds
  // subdivision_angle (zeta, radians; the paper uses 0.1 pi), at most subdivision_iterations (S)
  // rounds; 0 rounds disables it.
  double subdivision_angle = 0.1 * 3.14159265358979323846;
  int subdivision_iterations = 0;
};

// Per-vertex blending weights of one frame: vertex v uses centres[v*k .. v*k+k) with weights
// weights[v*k .. v*k+k); the weights are non-negative and sum to 1, the set's farthest centre has
// weight 0 (so a centre's influence is local), and a vertex exactly on its nearest centre has
// weight 1 for it (interpolation).
struct SurfaceWeights {
  int k = 0;
  std::vector<int32_t> centres;
  std::vector<double> weights;
};

// The weights of one vertex position in frame `frame` (k entries appended to the outputs).
void ComputeVertexWeights(const AffinityGraph& graph, int frame, const Eigen::Vector3d& vertex,
                          const SurfaceOptions& options, std::vector<int32_t>& centres,
                          std::vector<double>& weights);
// The weights of every vertex of a frame (in parallel over vertices).
SurfaceWeights ComputeSurfaceWeights(const AffinityGraph& graph, int frame,
                                     const Eigen::Ref<const FramePositionsD>& positions,
                                     const SurfaceOptions& options);

// Deforms one frame: each vertex by the blend of its centres' transforms, then (when enabled)
// adaptive subdivision. `weights` may be null (computed here) or precomputed for `frame_mesh`.
// Returns the edited frame (new vertices are appended after the original ones) and counts the
// vertices added in *vertices_added when given.
TvmFrame DeformFrame(const AffinityGraph& graph, int frame, const TvmFrame& frame_mesh,
                     std::span<const DualQuaternion> transforms, const SurfaceOptions& options,
                     const SurfaceWeights* weights = nullptr, int* vertices_added = nullptr);

// ---------------------------------------------------------------------------------------------
// Operations (Sections IV, V) and the editor that ties them together.

struct DeformationOptions {
  AffinityOptions affinity;
  SurfaceOptions surface;
  int kabsch_neighbours = 16;      // K of the inter-frame Kabsch neighbourhoods
  bool anchor_to_identity = true;  // see BlendIntraFrame
};

// Rigid transform of a set of centres in one frame.
struct TransformEdit {
  std::vector<int32_t> centres;  // E; empty is an error
  int frame = 0;
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // in frame `frame`'s coordinates
  TimeDecay decay;
};

// Vertex-based editing (V-C): each listed vertex of frame `frame` is assigned to its nearest
// centre; a centre's transform is the blend (equal weights) of its vertices' transforms.
struct VertexEdit {
  std::vector<int32_t> vertices;
  std::vector<Eigen::Isometry3d> transforms;  // one per vertex, or exactly one shared by all
  int frame = 0;
  TimeDecay decay;
};

// Inflation/deflation by centre attraction (V-A): centre j moves by
// beta * a(i, j) * (x_j,f - x_i,f) (a pure translation); beta > 0 inflates, beta < 0 deflates.
struct InflateEdit {
  int centre = 0;
  int frame = 0;
  double beta = 0.0;
  TimeDecay decay;
};

enum class LoopMode {
  // V-B automatic: each centre's transform from the last frame to the first is its neighbourhood's
  // Kabsch motion x -> R (x - o_last) + o_first, applied to the last frame and propagated back.
  kAutomatic,
  // V-B semi-automatic: the user's transform of `semi.centres` in an end frame (0 or F-1) is
  // propagated towards the other end.
  kSemiAutomatic,
};

struct LoopEdit {
  LoopMode mode = LoopMode::kAutomatic;
  TransformEdit semi;  // kSemiAutomatic only; semi.decay is ignored (see `decay`)
  // Decay away from the edited end frame; kind kNone means the default: linear with radius F-1,
  // so the opposite end is untouched.
  TimeDecay decay;
};

struct EditResult {
  TimeVaryingMesh mesh;         // edited frames (subdivided where enabled)
  CentreTrajectories centres;   // edited centre trajectories x_bar
  CentreTransforms transforms;  // per frame, per centre
  int vertices_added = 0;       // by adaptive subdivision, over all frames
};

// Holds a TVM, its centres and their affinity graph; computes edits. Surface weights can be
// precomputed once (the costly step) and reused by every later edit, as the paper does.
class TvmEditor {
 public:
  // Errors: invalid mesh or centres (see Validate*), kMismatch when the frame counts differ,
  // kInvalidArgument for impossible options (neighbour counts < 1, sigma <= 0, zeta <= 0,
  // S < 0).
  static StatusOr<TvmEditor> Create(TimeVaryingMesh mesh, CentreTrajectories centres,
                                    const DeformationOptions& options = {});

  const TimeVaryingMesh& mesh() const { return mesh_; }
  const AffinityGraph& graph() const { return graph_; }
  const DeformationOptions& options() const { return options_; }

  // Computes and keeps the surface weights of every frame (parallel over frames).
  void PrecomputeSurfaceWeights();

  // Centre transforms of each operation, in every frame. Errors (kInvalidArgument) name the bad
  // index, frame, decay radius or non-rigid transform.
  StatusOr<CentreTransforms> TransformCentres(const TransformEdit& edit) const;
  StatusOr<CentreTransforms> TransformVertices(const VertexEdit& edit) const;
  StatusOr<CentreTransforms> Inflate(const InflateEdit& edit) const;
  StatusOr<CentreTransforms> CloseLoop(const LoopEdit& edit) const;

  // Applies centre transforms (one per centre per frame) to the centres and the surfaces.
  StatusOr<EditResult> Apply(const CentreTransforms& transforms) const;

 private:
  TvmEditor(TimeVaryingMesh mesh, AffinityGraph graph, DeformationOptions options)
      : mesh_(std::move(mesh)), graph_(std::move(graph)), options_(options) {}
  Status CheckFrame(int frame) const;
  Status CheckDecay(const TimeDecay& decay) const;

  TimeVaryingMesh mesh_;
  AffinityGraph graph_;
  DeformationOptions options_;
  std::vector<SurfaceWeights> weights_;  // per frame when precomputed
};

// Checks that `transform`'s linear part is a rotation (orthonormal within 1e-6, det +1) and its
// entries finite (kInvalidArgument naming `what` otherwise).
Status CheckRigid(const Eigen::Isometry3d& transform, std::string_view what);

}  // namespace dmc::tvm
