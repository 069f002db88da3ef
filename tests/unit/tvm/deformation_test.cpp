// The deformation model of the TVM editor against the properties the paper states: rigid-motion
// invariance (IV-E), interpolating local partition-of-unity weights (IV-C), affinity separating
// bodies that only come close (IV-A), time decay and loop closing (IV-B, V-B).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <vector>

#include "dmc/tvm.h"
#include "unit/tvm/tvm_fixtures.h"

namespace dmc::tvm {
namespace {

using testing::MakeRigidBody;
using testing::MakeTwoBodies;
using testing::RigidMotion;

std::vector<int32_t> AllCentres(int n) {
  std::vector<int32_t> all(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) all[static_cast<size_t>(i)] = i;
  return all;
}

double MaxVertexError(const TvmFrame& actual, const TvmFrame& original,
                      const Eigen::Isometry3d& expected_motion) {
  double worst = 0.0;
  for (int v = 0; v < original.vertex_count(); ++v) {
    const Eigen::Vector3d expected = expected_motion * Eigen::Vector3d(original.positions.row(v));
    worst = std::max(worst, (Eigen::Vector3d(actual.positions.row(v)) - expected).norm());
  }
  return worst;
}

TEST(RigidInvarianceTest, OneTransformOnEveryCentreMovesEveryVertexOfAStaticSequence) {
  const auto body = MakeRigidBody(4, [](int) { return Eigen::Isometry3d::Identity(); });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok()) << editor.status().ToString();
  TransformEdit edit;
  edit.centres = AllCentres(body.centres.centre_count());
  edit.frame = 1;
  edit.transform = RigidMotion(0.8, {1, -2, 0.5}, {0.3, 2.0, -1.0});
  const auto transforms = editor->TransformCentres(edit);
  ASSERT_TRUE(transforms.ok()) << transforms.status().ToString();
  const auto result = editor->Apply(*transforms);
  ASSERT_TRUE(result.ok());
  for (int f = 0; f < 4; ++f) {
    EXPECT_LT(MaxVertexError(result->mesh.frames[f], body.mesh.frames[f], edit.transform), 1e-9)
        << "frame " << f;
  }
}

TEST(RigidInvarianceTest, OnARigidlyMovingBodyEachFrameGetsTheEditInItsOwnPose) {
  // Frame g = M_g * rest. An edit T in frame f must act in frame g as M_g M_f^-1 T M_f M_g^-1:
  // the composition of the imposed transform with the frames' own rigid motion (Section IV-E).
  const auto body = MakeRigidBody(6, [](int f) {
    return RigidMotion(0.35 * f, {0.2, 0.1, 1.0}, {0.4 * f, -0.1 * f * f, 0.2});
  });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok()) << editor.status().ToString();
  TransformEdit edit;
  edit.centres = AllCentres(body.centres.centre_count());
  edit.frame = 2;
  edit.transform = RigidMotion(-0.6, {0, 1, 1}, {1.0, 0.0, 0.5});
  const auto result = editor->Apply(*editor->TransformCentres(edit));
  ASSERT_TRUE(result.ok());
  for (int g = 0; g < 6; ++g) {
    const Eigen::Isometry3d f_to_g = body.motions[g] * body.motions[2].inverse();
    const Eigen::Isometry3d expected = f_to_g * edit.transform * f_to_g.inverse();
    EXPECT_LT(MaxVertexError(result->mesh.frames[g], body.mesh.frames[g], expected), 1e-9)
        << "frame " << g;
    for (int i = 0; i < body.centres.centre_count(); ++i) {
      EXPECT_LT((result->centres.position(i, g) - expected * body.centres.position(i, g)).norm(),
                1e-9);
    }
  }
}

TEST(SurfaceWeightsTest, AVertexOnACentreHasWeightOneForIt) {
  const auto body = MakeRigidBody(2, [](int f) {
    return RigidMotion(0.2 * f, {0, 0, 1}, Eigen::Vector3d::Zero());
  });
  const auto graph = AffinityGraph::Build(body.centres);
  ASSERT_TRUE(graph.ok());
  SurfaceOptions options;
  for (int i = 0; i < body.centres.centre_count(); i += 7) {
    std::vector<int32_t> centres;
    std::vector<double> weights;
    ComputeVertexWeights(*graph, 1, body.centres.position(i, 1), options, centres, weights);
    ASSERT_EQ(static_cast<int>(centres.size()), options.neighbours);
    EXPECT_EQ(centres[0], i);
    EXPECT_EQ(weights[0], 1.0);
    for (size_t j = 1; j < weights.size(); ++j) EXPECT_EQ(weights[j], 0.0);
  }
}

TEST(SurfaceWeightsTest, WeightsAreALocalPartitionOfUnity) {
  const auto body = MakeRigidBody(1, [](int) { return Eigen::Isometry3d::Identity(); });
  const auto graph = AffinityGraph::Build(body.centres);
  ASSERT_TRUE(graph.ok());
  SurfaceOptions options;
  const auto weights = ComputeSurfaceWeights(*graph, 0, body.mesh.frames[0].positions, options);
  ASSERT_EQ(weights.k, options.neighbours);
  const int k = weights.k;
  for (int v = 0; v < body.mesh.frames[0].vertex_count(); ++v) {
    double sum = 0.0;
    int zero = 0;
    double farthest_distance = -1.0, farthest_weight = -1.0;
    const Eigen::Vector3d vertex = body.mesh.frames[0].positions.row(v);
    for (int j = 0; j < k; ++j) {
      const double w = weights.weights[v * k + j];
      EXPECT_GE(w, 0.0);
      EXPECT_LE(w, 1.0);
      sum += w;
      zero += w == 0.0 ? 1 : 0;
      const double d = (body.centres.position(weights.centres[v * k + j], 0) - vertex).norm();
      if (d > farthest_distance) {
        farthest_distance = d;
        farthest_weight = w;
      }
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << "vertex " << v;
    // Locality: the farthest of the k centres carries no weight, so at most k-1 influence v.
    EXPECT_EQ(farthest_weight, 0.0) << "vertex " << v;
    EXPECT_GE(zero, 1);
    // The nearest centre comes first and weighs the most.
    const int nearest = graph->NearestCentre(0, vertex);
    EXPECT_EQ(weights.centres[v * k], nearest);
    EXPECT_EQ(
        *std::max_element(weights.weights.begin() + v * k, weights.weights.begin() + (v + 1) * k),
        weights.weights[v * k]);
  }
}

TEST(SurfaceWeightsTest, WeightsVaryContinuouslyAlongTheSurface) {
  // Moving a point a tiny step changes its weights a little when the set of centres is unchanged.
  const auto body = MakeRigidBody(1, [](int) { return Eigen::Isometry3d::Identity(); });
  const auto graph = AffinityGraph::Build(body.centres);
  ASSERT_TRUE(graph.ok());
  SurfaceOptions options;
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d p = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d q = p + 1e-7 * Eigen::Vector3d(1, 1, 1);
    std::vector<int32_t> cp, cq;
    std::vector<double> wp, wq;
    ComputeVertexWeights(*graph, 0, p, options, cp, wp);
    ComputeVertexWeights(*graph, 0, q, options, cq, wq);
    if (cp != cq) continue;
    ++compared;
    for (size_t j = 0; j < wp.size(); ++j) EXPECT_NEAR(wp[j], wq[j], 1e-5);
  }
  EXPECT_GT(compared, 150);
}

TEST(AffinityTest, MatchesTheDefinitionAndFindsTheMostAffineNeighboursExactly) {
  const auto bodies = MakeTwoBodies(5, 0.3);
  AffinityOptions options;
  options.neighbours = 10;
  const auto graph = AffinityGraph::Build(bodies.centres, options);
  ASSERT_TRUE(graph.ok());
  EXPECT_NEAR(graph->alpha(), 1.0 / 0.2, 1e-12);  // lattice step 0.2
  const int n = graph->centre_count();
  for (int i = 0; i < n; i += 5) {
    // Brute force: max distance over frames, sorted.
    std::vector<std::pair<double, int>> all;
    for (int j = 0; j < n; ++j) {
      double max_distance = 0.0;
      for (int f = 0; f < 5; ++f) {
        max_distance = std::max(
            max_distance, (bodies.centres.position(i, f) - bodies.centres.position(j, f)).norm());
      }
      all.emplace_back(max_distance, j);
    }
    std::sort(all.begin(), all.end());
    const auto neighbours = graph->Neighbours(i);
    const auto affinities = graph->NeighbourAffinities(i);
    EXPECT_EQ(neighbours[0], i);
    EXPECT_EQ(affinities[0], 1.0);
    for (int slot = 0; slot < 10; ++slot) {
      EXPECT_EQ(neighbours[slot], all[slot].second);
      const double expected = std::exp(-std::pow(graph->alpha() * all[slot].first, 2));
      EXPECT_NEAR(affinities[slot], expected < 1e-12 ? 0.0 : expected, 1e-15);
      EXPECT_EQ(graph->Affinity(i, neighbours[slot]), affinities[slot]);
    }
  }
}

TEST(AffinityTest, BadOptionsAndCoincidingCentresNameTheProblem) {
  const auto bodies = MakeTwoBodies(3, 0.3);
  const auto message = [&](const CentreTrajectories& centres, const AffinityOptions& options) {
    const Status status = AffinityGraph::Build(centres, options).status();
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
    return status.message();
  };
  AffinityOptions options;
  options.neighbours = 0;
  EXPECT_EQ(message(bodies.centres, options),
            "the affinity neighbourhood must hold at least 1 centre, got 0");
  options.neighbours = 4;
  options.alpha = -1.0;
  EXPECT_EQ(message(bodies.centres, options),
            "alpha must be finite and >= 0 (0 = automatic), got -1.000000");
  options.alpha = 0.0;
  options.min_affinity = 1.0;
  EXPECT_EQ(message(bodies.centres, options), "min_affinity must be in (0, 1), got 1.000000");
  options.min_affinity = AffinityOptions{}.min_affinity;
  CentreTrajectories coinciding = bodies.centres;
  for (FramePositionsD& frame : coinciding.positions) {
    const Eigen::RowVector3d first = frame.row(0);
    frame.rowwise() = first;
  }
  EXPECT_EQ(message(coinciding, options),
            "cannot choose alpha automatically: the median distance between neighbouring centres "
            "in frame 0 is 0 (coinciding centres); give alpha explicitly");
}

TEST(AffinityTest, BodiesThatComeCloseButSeparateDoNotDragEachOther) {
  // Closest gap 0.12, less than the centre spacing 0.2: the bodies' centres are as close as
  // neighbours within a body at that frame, yet they are ever 2 apart, so a(A, B) = 0.
  const auto bodies = MakeTwoBodies(7, 0.12);
  auto editor = TvmEditor::Create(bodies.mesh, bodies.centres);
  ASSERT_TRUE(editor.ok()) << editor.status().ToString();
  // Every A-B pair is 2 apart at the first frame: their affinity is exactly 0.
  EXPECT_EQ(editor->graph().Affinity(0, bodies.a_count), 0.0);
  TransformEdit edit;
  for (int i = 0; i < bodies.a_count; ++i) edit.centres.push_back(i);
  edit.frame = 3;  // the frame where they are closest
  edit.transform = RigidMotion(0.0, {0, 0, 1}, {0.0, 0.4, 0.0});  // lift A
  const auto result = editor->Apply(*editor->TransformCentres(edit));
  ASSERT_TRUE(result.ok());
  const int n = bodies.centres.centre_count();
  for (int f = 0; f < 7; ++f) {
    for (int i = bodies.a_count; i < n; ++i) {
      EXPECT_LT((result->centres.position(i, f) - bodies.centres.position(i, f)).norm(), 1e-12);
    }
    const TvmFrame& edited = result->mesh.frames[f];
    const TvmFrame& original = bodies.mesh.frames[f];
    double b_moved = 0.0, a_moved = 1e9;
    for (int v = 0; v < original.vertex_count(); ++v) {
      const double moved = (edited.positions.row(v) - original.positions.row(v)).norm();
      if (v < bodies.a_vertices[f]) {
        a_moved = std::min(a_moved, moved);
      } else {
        b_moved = std::max(b_moved, moved);
      }
    }
    EXPECT_LT(b_moved, 1e-12) << "frame " << f << ": B moved";
    EXPECT_GT(a_moved, 0.39) << "frame " << f << ": A did not follow its centres";
  }
}

TEST(AffinityTest, AtTheContactFrameOnlyVerticesNearTheContactCanFollowTheOtherBody) {
  // The paper's limitation (Fig. 15): where the surfaces touch, a vertex's nearest centre may lie
  // in the other body. Centres never mix (affinity), and surface leakage stays within one centre
  // spacing of the contact point.
  const auto bodies = MakeTwoBodies(7, 0.0);
  auto editor = TvmEditor::Create(bodies.mesh, bodies.centres);
  ASSERT_TRUE(editor.ok()) << editor.status().ToString();
  TransformEdit edit;
  for (int i = 0; i < bodies.a_count; ++i) edit.centres.push_back(i);
  edit.frame = 0;
  edit.transform = RigidMotion(0.0, {0, 0, 1}, {0.0, 0.4, 0.0});
  const auto result = editor->Apply(*editor->TransformCentres(edit));
  ASSERT_TRUE(result.ok());
  const int n = bodies.centres.centre_count();
  for (int f = 0; f < 7; ++f) {
    for (int i = bodies.a_count; i < n; ++i) {
      EXPECT_LT((result->centres.position(i, f) - bodies.centres.position(i, f)).norm(), 1e-12);
    }
    const TvmFrame& original = bodies.mesh.frames[f];
    for (int v = bodies.a_vertices[f]; v < original.vertex_count(); ++v) {
      const double moved =
          (result->mesh.frames[f].positions.row(v) - original.positions.row(v)).norm();
      if (moved > 1e-12) {
        EXPECT_LT(original.positions.row(v).norm(), 0.2) << "frame " << f << ", vertex " << v;
      }
    }
  }
}

TEST(IntraFrameTest, EffectorsKeepTheirTransformAndFarCentresStay) {
  const auto body = MakeRigidBody(
      1, [](int) { return Eigen::Isometry3d::Identity(); }, 2.0, 0.25);
  const auto graph = AffinityGraph::Build(body.centres);
  ASSERT_TRUE(graph.ok());
  const int n = graph->centre_count();
  const int effector = graph->NearestCentre(0, {0, 0, 1.5});
  const DualQuaternion lift = DualQuaternion::FromTranslation({0, 0, 0.3});
  const std::vector<int32_t> effectors{effector};
  const auto blended = BlendIntraFrame(*graph, effectors, std::span(&lift, 1));
  ASSERT_EQ(static_cast<int>(blended.size()), n);
  EXPECT_LT((blended[effector].Translation() - Eigen::Vector3d(0, 0, 0.3)).norm(), 1e-15);
  const Eigen::Vector3d source = body.centres.position(effector, 0);
  // The lift decays with affinity: a(i, e) of the anchored blend is the translated fraction.
  for (int i = 0; i < n; ++i) {
    const double fraction = blended[i].Translation().z() / 0.3;
    const double affinity = graph->Affinity(i, effector);
    EXPECT_NEAR(fraction, affinity, 1e-12) << "centre " << i;
    // Past sqrt(-ln 1e-12) / alpha = 1.31 (alpha = 4) the affinity is exactly 0.
    if ((body.centres.position(i, 0) - source).norm() > 1.35) {
      EXPECT_EQ(fraction, 0.0);
    }
  }
  // Without the anchor, Eq. (2) as printed moves every affine centre with the single effector.
  const auto unanchored = BlendIntraFrame(*graph, effectors, std::span(&lift, 1), false);
  const int neighbour = graph->Neighbours(effector)[1];
  EXPECT_LT((unanchored[neighbour].Translation() - Eigen::Vector3d(0, 0, 0.3)).norm(), 1e-15);
}

TEST(TimeDecayTest, ReachesTheIdentityAtTheWindowEnds) {
  for (const DecayKind kind : {DecayKind::kLinear, DecayKind::kSmooth}) {
    const TimeDecay decay{kind, 3.0};
    EXPECT_EQ(decay.Weight(5, 5), 1.0);
    EXPECT_EQ(decay.Weight(2, 5), 0.0);
    EXPECT_EQ(decay.Weight(8, 5), 0.0);
    EXPECT_EQ(decay.Weight(0, 5), 0.0);
    EXPECT_GT(decay.Weight(4, 5), decay.Weight(3, 5));
    EXPECT_NEAR(decay.Weight(4, 5), decay.Weight(6, 5), 0.0);
  }
  EXPECT_NEAR((TimeDecay{DecayKind::kLinear, 4.0}.Weight(3, 5)), 0.5, 1e-15);
  EXPECT_NEAR((TimeDecay{DecayKind::kSmooth, 4.0}.Weight(3, 5)), 0.5, 1e-15);

  const auto body = MakeRigidBody(9, [](int f) {
    return RigidMotion(0.1 * f, {0, 0, 1}, Eigen::Vector3d::Zero());
  });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok());
  TransformEdit edit;
  edit.centres = {0, 1, 2, 3};
  edit.frame = 4;
  edit.transform = RigidMotion(0.5, {1, 0, 0}, {0.2, 0.2, 0.2});
  edit.decay = {DecayKind::kLinear, 3.0};
  const auto transforms = editor->TransformCentres(edit);
  ASSERT_TRUE(transforms.ok());
  const auto result = editor->Apply(*transforms);
  ASSERT_TRUE(result.ok());
  for (int f : {0, 1, 7, 8}) {
    for (const DualQuaternion& q : (*transforms)[f]) {
      EXPECT_EQ(q.real().w(), 1.0);
      EXPECT_EQ(q.dual().coeffs().norm(), 0.0);
    }
    EXPECT_EQ(result->mesh.frames[f].positions, body.mesh.frames[f].positions) << f;
  }
  EXPECT_NE(result->mesh.frames[4].positions, body.mesh.frames[4].positions);
  EXPECT_NE(result->mesh.frames[3].positions, body.mesh.frames[3].positions);
}

TEST(LoopTest, AutomaticClosingMakesTheLastFramesCentresMatchTheFirst) {
  // A body that rotates and drifts: the last frame is far from the first.
  const auto body = MakeRigidBody(8, [](int f) {
    return RigidMotion(0.15 * f, {0.3, 0.0, 1.0}, {0.1 * f, 0.05 * f, 0.0});
  });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok());
  const auto transforms = editor->CloseLoop(LoopEdit{});
  ASSERT_TRUE(transforms.ok()) << transforms.status().ToString();
  const auto result = editor->Apply(*transforms);
  ASSERT_TRUE(result.ok());
  double before = 0.0, after = 0.0;
  for (int i = 0; i < body.centres.centre_count(); ++i) {
    before = std::max(before, (body.centres.position(i, 7) - body.centres.position(i, 0)).norm());
    after = std::max(after, (result->centres.position(i, 7) - body.centres.position(i, 0)).norm());
    // The first frame is the other end of the decay window: untouched.
    EXPECT_EQ(result->centres.position(i, 0), body.centres.position(i, 0));
  }
  EXPECT_GT(before, 0.5);
  EXPECT_LT(after, 1e-9);
  // The surface follows: the last frame now sits where the first one was (the frames'
  // tessellations differ, so compare each last-frame vertex against the rest shape's pose).
  const Eigen::Isometry3d last_to_first = body.motions[0] * body.motions[7].inverse();
  EXPECT_LT(MaxVertexError(result->mesh.frames[7], body.mesh.frames[7], last_to_first), 1e-9);
}

TEST(LoopTest, SemiAutomaticPropagatesTheUsersEndFrameEditTowardsTheOtherEnd) {
  const auto body = MakeRigidBody(5, [](int f) {
    return RigidMotion(0.0, {0, 0, 1}, {0.2 * f, 0, 0});
  });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok());
  LoopEdit loop;
  loop.mode = LoopMode::kSemiAutomatic;
  loop.semi.centres = AllCentres(body.centres.centre_count());
  loop.semi.frame = 0;
  loop.semi.transform = RigidMotion(0.0, {0, 0, 1}, {0.8, 0, 0});  // frame 0 onto frame 4
  const auto result = editor->Apply(*editor->CloseLoop(loop));
  ASSERT_TRUE(result.ok());
  for (int i = 0; i < body.centres.centre_count(); ++i) {
    EXPECT_LT((result->centres.position(i, 0) - body.centres.position(i, 4)).norm(), 1e-9);
    EXPECT_EQ(result->centres.position(i, 4), body.centres.position(i, 4));
  }
  loop.semi.frame = 2;
  EXPECT_EQ(editor->CloseLoop(loop).status().code(), ErrorCode::kInvalidArgument);
}

TEST(InflateTest, CentresMoveAwayFromTheChosenCentreInProportionToAffinity) {
  const auto body = MakeRigidBody(3, [](int) { return Eigen::Isometry3d::Identity(); });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok());
  const int chosen = editor->graph().NearestCentre(1, {0, 0, 0});
  const InflateEdit inflate{chosen, 1, 0.5, {}};
  const auto result = editor->Apply(*editor->Inflate(inflate));
  ASSERT_TRUE(result.ok());
  const Eigen::Vector3d origin = body.centres.position(chosen, 1);
  for (int j = 0; j < body.centres.centre_count(); ++j) {
    const Eigen::Vector3d offset = body.centres.position(j, 1) - origin;
    const Eigen::Vector3d expected =
        body.centres.position(j, 1) + 0.5 * editor->graph().Affinity(chosen, j) * offset;
    EXPECT_LT((result->centres.position(j, 1) - expected).norm(), 1e-12);
  }
  // The surface grows: every vertex moves outwards (away from the chosen centre at the origin).
  const TvmFrame& edited = result->mesh.frames[1];
  for (int v = 0; v < edited.vertex_count(); ++v) {
    EXPECT_GT(edited.positions.row(v).norm(), body.mesh.frames[1].positions.row(v).norm());
  }
  // Deflation shrinks.
  const auto deflated = editor->Apply(*editor->Inflate({chosen, 1, -0.3, {}}));
  ASSERT_TRUE(deflated.ok());
  EXPECT_LT(deflated->mesh.frames[1].positions.rowwise().norm().maxCoeff(), 1.0);
}

TEST(VertexEditTest, VertexTransformsActThroughTheirNearestCentres) {
  const auto body = MakeRigidBody(2, [](int) { return Eigen::Isometry3d::Identity(); });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok());
  VertexEdit edit;
  edit.frame = 0;
  const Eigen::Isometry3d push = RigidMotion(0.0, {0, 0, 1}, {0, 0, 0.2});
  edit.transforms = {push};
  std::vector<int32_t> nearest;
  for (int v = 0; v < body.mesh.frames[0].vertex_count(); ++v) {
    if (body.mesh.frames[0].positions(v, 2) > 0.8) {
      edit.vertices.push_back(v);
      nearest.push_back(
          editor->graph().NearestCentre(0, body.mesh.frames[0].positions.row(v).transpose()));
    }
  }
  ASSERT_FALSE(edit.vertices.empty());
  TransformEdit same;
  same.centres = nearest;
  same.frame = 0;
  same.transform = push;
  const auto by_vertices = editor->TransformVertices(edit);
  const auto by_centres = editor->TransformCentres(same);
  ASSERT_TRUE(by_vertices.ok() && by_centres.ok());
  for (int f = 0; f < 2; ++f) {
    for (int i = 0; i < body.centres.centre_count(); ++i) {
      EXPECT_LT(
          ((*by_vertices)[f][i].Apply({0, 0, 0}) - (*by_centres)[f][i].Apply({0, 0, 0})).norm(),
          1e-14);
    }
  }
  edit.vertices.push_back(1 << 20);
  EXPECT_EQ(editor->TransformVertices(edit).status().code(), ErrorCode::kInvalidArgument);
}

TEST(SubdivisionTest, SplitsOnlyEdgesWhoseEndsRotateApartAndKeepsTheMeshValid) {
  // Twist the top of a ball by 90 degrees: edges across the twist zone rotate a lot.
  const auto body = MakeRigidBody(
      1, [](int) { return Eigen::Isometry3d::Identity(); }, 1.0, 0.2);
  DeformationOptions options;
  options.surface.subdivision_iterations = 2;
  auto editor = TvmEditor::Create(body.mesh, body.centres, options);
  ASSERT_TRUE(editor.ok());
  TransformEdit edit;
  for (int i = 0; i < body.centres.centre_count(); ++i) {
    if (body.centres.position(i, 0).z() > 0.3) edit.centres.push_back(i);
  }
  edit.transform = RigidMotion(std::numbers::pi / 2, {0, 0, 1}, Eigen::Vector3d::Zero());
  const auto transforms = editor->TransformCentres(edit);
  ASSERT_TRUE(transforms.ok());
  const auto result = editor->Apply(*transforms);
  ASSERT_TRUE(result.ok());
  EXPECT_GT(result->vertices_added, 0);
  const TvmFrame& frame = result->mesh.frames[0];
  EXPECT_EQ(frame.vertex_count(), body.mesh.frames[0].vertex_count() + result->vertices_added);
  EXPECT_TRUE(ValidateTimeVaryingMesh(result->mesh).ok());
  // Closed before, closed after: every edge still has exactly two opposite triangles
  // (red-green refinement leaves no T-junction), with consistent orientation.
  std::map<std::pair<int, int>, int> directed;
  for (int t = 0; t < frame.triangle_count(); ++t) {
    for (int c = 0; c < 3; ++c)
      directed[{frame.triangles(t, c), frame.triangles(t, (c + 1) % 3)}]++;
  }
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
  // Without subdivision nothing is added.
  DeformationOptions plain;
  auto plain_editor = TvmEditor::Create(body.mesh, body.centres, plain);
  const auto plain_result = plain_editor->Apply(*transforms);
  EXPECT_EQ(plain_result->vertices_added, 0);
}

TEST(EditorTest, PrecomputedWeightsGiveTheSameResult) {
  const auto body = MakeRigidBody(3, [](int f) {
    return RigidMotion(0.2 * f, {0, 0, 1}, Eigen::Vector3d::Zero());
  });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok());
  TransformEdit edit;
  edit.centres = {0, 5, 9};
  edit.frame = 1;
  edit.transform = RigidMotion(0.4, {1, 1, 0}, {0.1, 0, 0});
  const auto transforms = editor->TransformCentres(edit);
  const auto fresh = editor->Apply(*transforms);
  editor->PrecomputeSurfaceWeights();
  const auto cached = editor->Apply(*transforms);
  ASSERT_TRUE(fresh.ok() && cached.ok());
  for (int f = 0; f < 3; ++f)
    EXPECT_EQ(fresh->mesh.frames[f].positions, cached->mesh.frames[f].positions);
}

TEST(EditorTest, ImpossibleRequestsAreInvalidArguments) {
  const auto body = MakeRigidBody(2, [](int) { return Eigen::Isometry3d::Identity(); });
  auto editor = TvmEditor::Create(body.mesh, body.centres);
  ASSERT_TRUE(editor.ok());
  TransformEdit edit;
  edit.centres = {0};
  edit.frame = 2;
  EXPECT_EQ(editor->TransformCentres(edit).status().code(), ErrorCode::kInvalidArgument);
  edit.frame = 0;
  edit.centres = {99999};
  EXPECT_EQ(editor->TransformCentres(edit).status().code(), ErrorCode::kInvalidArgument);
  edit.centres = {0};
  edit.transform.linear() *= 2.0;  // a scale is not rigid
  EXPECT_EQ(editor->TransformCentres(edit).status().code(), ErrorCode::kInvalidArgument);
  edit.transform = Eigen::Isometry3d::Identity();
  edit.decay = {DecayKind::kLinear, 0.0};
  EXPECT_EQ(editor->TransformCentres(edit).status().code(), ErrorCode::kInvalidArgument);

  CentreTrajectories short_centres = body.centres;
  short_centres.positions.pop_back();
  EXPECT_EQ(TvmEditor::Create(body.mesh, short_centres).status().code(), ErrorCode::kMismatch);
  DeformationOptions bad;
  bad.surface.sigma = 0.0;
  EXPECT_EQ(TvmEditor::Create(body.mesh, body.centres, bad).status().code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc::tvm
