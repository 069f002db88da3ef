// dmc laplacian through the built binary: the report's JSON keys, identities, exit codes.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

TEST(LaplacianCli, ReportsTheIssueKeysForEveryOperator) {
  const auto dir = FreshTempDir("laplacian_cli");
  const auto input = dir / "blob.pc2";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(input) + " --frames 6 --resolution 400").exit_code, 0);
  for (const char* op : {"kirchhoff", "tutte", "cotan", "mean-value", "ddl"}) {
    const CliResult result =
        RunDmc("laplacian " + Quoted(input) + " --operator " + op + " --rank 4 --json");
    ASSERT_EQ(result.exit_code, 0) << op << ": " << result.err;
    const auto report = nlohmann::json::parse(result.out);
    for (const char* key :
         {"operator", "symmetry_error", "max_row_sum", "negative_weight_share", "delta_mean",
          "delta_max", "cholesky_ok", "conditioning_delta", "seconds"}) {
      EXPECT_TRUE(report.contains(key)) << op << " lacks " << key;
    }
    EXPECT_EQ(report["operator"].get<std::string>(), op);
    EXPECT_LT(report["max_row_sum"].get<double>(), 1e-9) << op;  // rows sum to zero
  }
  const auto kirchhoff = nlohmann::json::parse(
      RunDmc("laplacian " + Quoted(input) + " --operator kirchhoff --json").out);
  EXPECT_EQ(kirchhoff["symmetry_error"].get<double>(), 0.0);
  EXPECT_TRUE(kirchhoff["cholesky_ok"].get<bool>());
}

// Issue 27: the cotangent clamp (cot 1° by default) is an option. On a planar sheet whose first
// two rows are 10^-4 apart (angles of 0.04°: cotangents near 1400) the default clamps the slivers'
// cotangents, and the report counts them; with --max-cotangent 1e12 nothing is clamped.
TEST(LaplacianCli, TheCotangentClampIsAnOptionAndItsRepairsAreReported) {
  const auto dir = FreshTempDir("laplacian_cli");
  const auto input = dir / "sheet.obj";
  {
    std::ofstream out(input);
    constexpr int n = 8;
    for (int row = 0; row < n; ++row) {
      const double y = row == 0 ? 0.0 : 1e-4 + (row - 1) / static_cast<double>(n - 2);
      for (int column = 0; column < n; ++column) {
        out << "v " << column / static_cast<double>(n - 1) << " " << y << " 0\n";
      }
    }
    for (int row = 0; row + 1 < n; ++row) {
      for (int column = 0; column + 1 < n; ++column) {
        const int a = row * n + column + 1, b = a + 1, c = a + n, d = c + 1;
        out << "f " << a << " " << b << " " << d << "\nf " << a << " " << d << " " << c << "\n";
      }
    }
  }
  const auto report = [&](const std::string& flags) {
    const CliResult result =
        RunDmc("laplacian " + Quoted(input) + " --operator cotan --json " + flags);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    return nlohmann::json::parse(result.out);
  };
  const auto clamped = report("");
  const auto exact = report("--max-cotangent 1e12");
  EXPECT_GT(clamped["stats"]["clamped_cotangents"].get<int>(), 0);
  EXPECT_EQ(exact["stats"]["clamped_cotangents"].get<int>(), 0);
  EXPECT_EQ(RunDmc("laplacian " + Quoted(input) + " --operator cotan --max-cotangent 0").exit_code,
            1);
}

TEST(LaplacianCli, UnknownOperatorAndBadOptionsHaveTheirExitCodes) {
  const auto dir = FreshTempDir("laplacian_cli");
  const auto input = dir / "blob.pc2";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(input) + " --frames 2 --resolution 300").exit_code, 0);
  const CliResult unknown = RunDmc("laplacian " + Quoted(input) + " --operator nope");
  EXPECT_EQ(unknown.exit_code, 20);
  EXPECT_NE(unknown.err.find("cotan-area"), std::string::npos) << unknown.err;
  EXPECT_EQ(RunDmc("laplacian " + Quoted(input) + " --operator ddl --mu -1").exit_code, 11);
  EXPECT_EQ(RunDmc("laplacian " + Quoted(dir / "missing.pc2") + " --operator tutte").exit_code, 12);
}

}  // namespace
}  // namespace dmc::testing
