// dmc laplacian --operator spacetime and dmc edit spacetime-arap through the built binary, on
// sequences from dmc synth: the report's keys and identities, the edit's window and handles, the
// codec's and per-vertex methods' refusal of the spacetime registry row, and exit codes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli/cli_runner.h"
#include "dmc/io.h"

namespace dmc::testing {
namespace {

TEST(SpacetimeCli, LaplacianReportsTheOperatorsIdentities) {
  const auto dir = FreshTempDir("spacetime_cli");
  const auto input = dir / "blob.pc2";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(input) + " --frames 4 --resolution 300").exit_code, 0);
  const CliResult result =
      RunDmc("laplacian " + Quoted(input) + " --operator spacetime --alpha 0.5 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = nlohmann::json::parse(result.out);
  for (const char* key :
       {"operator", "symmetry_error", "max_row_sum", "negative_weight_share", "delta_mean",
        "delta_max", "cholesky_ok", "conditioning_delta", "seconds", "nonzeros",
        "expected_nonzeros", "null_space_residual", "unsymmetrised_max_row_sum"}) {
    EXPECT_TRUE(report.contains(key)) << "lacks " << key;
  }
  EXPECT_EQ(report["operator"].get<std::string>(), "spacetime");
  EXPECT_EQ(report["domain"].get<std::string>(), "spacetime");
  EXPECT_EQ(report["frames"].get<int>(), 4);
  EXPECT_EQ(report["dimension"].get<int>(), 4 * report["vertices"].get<int>());
  EXPECT_EQ(report["nonzeros"].get<int64_t>(), report["expected_nonzeros"].get<int64_t>());
  EXPECT_EQ(report["symmetry_error"].get<double>(), 0.0);
  const double scale = std::abs(report["diagonal_min"].get<double>());
  EXPECT_LT(report["null_space_residual"].get<double>(), 1e-9 * scale);
  EXPECT_LT(report["unsymmetrised_max_row_sum"].get<double>(), 1e-9 * scale);
  EXPECT_EQ(report["negative_weight_share"].get<double>(), 0.0);  // barycentric duals
  EXPECT_TRUE(report["cholesky_ok"].get<bool>());
  EXPECT_LE(report["diagonal_max"].get<double>(), 0.0);  // dmc's sign convention

  EXPECT_EQ(RunDmc("laplacian " + Quoted(input) + " --operator spacetime --alpha 0").exit_code, 11);
  const auto single = dir / "single.obj";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(single) + " --frames 1 --resolution 300").exit_code,
            0);
  EXPECT_EQ(RunDmc("laplacian " + Quoted(single) + " --operator spacetime").exit_code, 11);
}

// The row has no wire ID: a decoder could not rebuild it, so the encoder refuses it by name, and
// the per-vertex processing methods refuse its VF×VF matrix.
TEST(SpacetimeCli, CodecAndPerVertexMethodsRefuseTheSpacetimeOperator) {
  const auto dir = FreshTempDir("spacetime_cli");
  const auto input = dir / "blob.pc2";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(input) + " --frames 3 --resolution 300").exit_code, 0);
  const auto stream = dir / "blob.dmc";
  const CliResult encode =
      RunDmc("encode " + Quoted(input) + " -o " + Quoted(stream) + " --operator spacetime");
  EXPECT_EQ(encode.exit_code, 16) << encode.err;  // unsupported, not unknown
  EXPECT_NE(encode.err.find("'spacetime' cannot be used by the codec"), std::string::npos)
      << encode.err;
  EXPECT_FALSE(std::filesystem::exists(stream));
  const CliResult smooth = RunDmc("edit smooth-explicit " + Quoted(input) + " -o " +
                                  Quoted(dir / "smooth.pc2") + " --operator spacetime");
  EXPECT_EQ(smooth.exit_code, 16) << smooth.err;
  EXPECT_NE(smooth.err.find("per-vertex"), std::string::npos) << smooth.err;
}

// The edit subcommand comes with the processing registry's CLI; skip cleanly without it.
bool HasEditCommand() { return RunDmc("edit spacetime-arap --help").exit_code == 0; }

TEST(SpacetimeCli, EditMovesTheKeyFrameHandlesAndOnlyTheWindow) {
  if (!HasEditCommand()) GTEST_SKIP() << "dmc edit spacetime-arap is not built";
  const auto dir = FreshTempDir("spacetime_cli");
  const auto input = dir / "cloth.pc2";
  ASSERT_EQ(RunDmc("synth cloth -o " + Quoted(input) + " --frames 8 --resolution 300").exit_code,
            0);
  const auto sequence = ReadSequence(input);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  // Handles: the free end of the flag (largest x) in key frame 4; fixed: its pinned edge.
  const int key = 4;
  const FramePositionsD frame = sequence->frame_d(key);
  const double x_min = frame.col(0).minCoeff(), x_max = frame.col(0).maxCoeff();
  nlohmann::json selection = {{"handles", nlohmann::json::array()},
                              {"fixed", nlohmann::json::array()},
                              {"transform", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.1, 0, 0, 0, 1}}};
  std::vector<int> handles;
  for (int v = 0; v < sequence->vertex_count(); ++v) {
    if (frame(v, 0) > x_max - 0.1 * (x_max - x_min)) {
      selection["handles"].push_back(v);
      handles.push_back(v);
    }
    if (frame(v, 0) < x_min + 0.1 * (x_max - x_min)) selection["fixed"].push_back(v);
  }
  ASSERT_FALSE(handles.empty());
  const auto selection_path = dir / "selection.json";
  std::ofstream(selection_path) << selection.dump();
  const auto output = dir / "edited.pc2";
  const CliResult result =
      RunDmc("edit spacetime-arap " + Quoted(input) + " -o " + Quoted(output) +
             " --key-frame 4 --selection " + Quoted(selection_path) + " --alpha 0.01 --window 2");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto edited = ReadSequence(output);
  ASSERT_TRUE(edited.ok()) << edited.status().ToString();
  ASSERT_EQ(edited->frame_count(), 8);
  // Outside the window [2, 6] nothing moves; the handles rise by about 0.1 in the key frame.
  for (int f : {0, 1, 7}) {
    EXPECT_EQ((edited->frame_d(f) - sequence->frame_d(f)).cwiseAbs().maxCoeff(), 0.0) << f;
  }
  for (int v : handles) {
    EXPECT_NEAR(edited->frame_d(key)(v, 2) - frame(v, 2), 0.1, 0.01) << v;
  }
  // Small α spreads the edit to the neighbouring frames.
  const double neighbour_change =
      (edited->frame_d(key + 1) - sequence->frame_d(key + 1)).cwiseAbs().maxCoeff();
  EXPECT_GT(neighbour_change, 0.02);

  // The identity transform is no edit at all.
  selection["transform"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::ofstream(selection_path) << selection.dump();
  const auto unchanged = dir / "unchanged.pc2";
  ASSERT_EQ(RunDmc("edit spacetime-arap " + Quoted(input) + " -o " + Quoted(unchanged) +
                   " --key-frame 4 --selection " + Quoted(selection_path) + " --window 2")
                .exit_code,
            0);
  const auto same = ReadSequence(unchanged);
  ASSERT_TRUE(same.ok());
  for (int f = 0; f < 8; ++f) {
    EXPECT_LE((same->frame_d(f) - sequence->frame_d(f)).cwiseAbs().maxCoeff(), 1e-5) << f;
  }

  // Bad options: window 0, key frame outside the sequence.
  EXPECT_EQ(RunDmc("edit spacetime-arap " + Quoted(input) + " -o " + Quoted(unchanged) +
                   " --selection " + Quoted(selection_path) + " --window 0")
                .exit_code,
            11);
  EXPECT_EQ(RunDmc("edit spacetime-arap " + Quoted(input) + " -o " + Quoted(unchanged) +
                   " --selection " + Quoted(selection_path) + " --key-frame 8")
                .exit_code,
            11);
}

}  // namespace
}  // namespace dmc::testing
