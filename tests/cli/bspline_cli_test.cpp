// dmc laplacian --operator bspline: the spectrum through the built binary (JSON key eigenvalues,
// ascending with the zero mode, the unit sphere's 2 and 6 groups), the element operator's report
// (the registry row, OperatorDomain::kElement), the per-vertex processing methods' refusal of
// it, and the exit codes of bad options.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc::testing {
namespace {

// A unit icosphere (level 3, 642 vertices) written as OBJ.
std::filesystem::path WriteSphere(const std::filesystem::path& dir) {
  const MeshSequence sphere = Icosphere(3);
  const auto path = dir / "sphere.obj";
  std::ofstream out(path);
  out.precision(9);
  for (int v = 0; v < sphere.vertex_count(); ++v) {
    out << "v " << sphere.frame(0)(v, 0) << ' ' << sphere.frame(0)(v, 1) << ' '
        << sphere.frame(0)(v, 2) << '\n';
  }
  for (int t = 0; t < sphere.triangle_count(); ++t) {
    out << "f " << sphere.triangles()(t, 0) + 1 << ' ' << sphere.triangles()(t, 1) + 1 << ' '
        << sphere.triangles()(t, 2) + 1 << '\n';
  }
  return path;
}

TEST(BsplineCli, SpectrumOfTheUnitSphere) {
  const auto dir = FreshTempDir("bspline_cli");
  const auto input = WriteSphere(dir);
  const CliResult result =
      RunDmc("laplacian " + Quoted(input) + " --operator bspline --depth 4 --spectrum 9 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = nlohmann::json::parse(result.out);
  EXPECT_EQ(report["operator"].get<std::string>(), "bspline");
  EXPECT_EQ(report["domain"].get<std::string>(), "element");
  EXPECT_EQ(report["depth"].get<int>(), 4);
  EXPECT_GT(report["dimension"].get<int>(), 0);
  const auto values = report["eigenvalues"].get<std::vector<double>>();
  ASSERT_EQ(values.size(), 9u);
  for (size_t k = 1; k < values.size(); ++k) EXPECT_LE(values[k - 1], values[k]);
  EXPECT_NEAR(values[0], 0.0, 1e-6);
  for (size_t k = 1; k <= 3; ++k) EXPECT_NEAR(values[k], 2.0, 0.1) << k;  // l = 1
  for (size_t k = 4; k <= 8; ++k) EXPECT_NEAR(values[k], 6.0, 0.3) << k;  // l = 2

  // The same through the text output.
  const CliResult text =
      RunDmc("laplacian " + Quoted(input) + " --operator bspline --depth 4 --spectrum 4");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("eigenvalues of operator bspline"), std::string::npos) << text.out;
}

// Area of the level-3 icosphere (642 vertices) inscribed in the unit sphere: a little under 4π.
double IcosphereArea(const MeshSequence& sphere) {
  double area = 0.0;
  for (int t = 0; t < sphere.triangle_count(); ++t) {
    const Eigen::Vector3f a = sphere.frame(0).row(sphere.triangles()(t, 0)).transpose();
    const Eigen::Vector3f b = sphere.frame(0).row(sphere.triangles()(t, 1)).transpose();
    const Eigen::Vector3f c = sphere.frame(0).row(sphere.triangles()(t, 2)).transpose();
    area += 0.5 * static_cast<double>((b - a).cross(c - a).norm());
  }
  return area;
}

TEST(BsplineCli, ElementReportAndCotanSpectrum) {
  const auto dir = FreshTempDir("bspline_cli");
  const auto input = WriteSphere(dir);
  const CliResult report =
      RunDmc("laplacian " + Quoted(input) + " --operator bspline --depth 3 --json");
  ASSERT_EQ(report.exit_code, 0) << report.err;
  const auto json = nlohmann::json::parse(report.out);
  EXPECT_EQ(json["operator"].get<std::string>(), "bspline");
  EXPECT_EQ(json["domain"].get<std::string>(), "element");
  EXPECT_EQ(json["depth"].get<int>(), 3);
  EXPECT_EQ(json["vertices"].get<int>(), 642);
  EXPECT_GT(json["dimension"].get<int>(), 0);
  EXPECT_EQ(json["symmetry_error"].get<double>(), 0.0);
  EXPECT_LT(json["max_row_sum"].get<double>(), 1e-9);
  EXPECT_LE(json["diagonal_max"].get<double>(), 0.0);
  EXPECT_LT(json["evaluation_partition_error"].get<double>(), 1e-12);
  EXPECT_NEAR(json["mass_total"].get<double>(), IcosphereArea(Icosphere(3)), 1e-5);
  EXPECT_TRUE(json["delta_mean"].is_null());  // element coefficients, not vertices
  // The text report names the domain.
  const CliResult text = RunDmc("laplacian " + Quoted(input) + " --operator bspline --depth 3");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("element domain"), std::string::npos) << text.out;
  // Other symmetric operators use their vertex mass: cotan-sym also finds λ₁ ≈ 2.
  const auto cotan = nlohmann::json::parse(
      RunDmc("laplacian " + Quoted(input) + " --operator cotan-sym --spectrum 2 --json").out);
  EXPECT_NEAR(cotan["eigenvalues"][1].get<double>(), 2.0, 0.05);
}

// The per-vertex processing methods refuse the element operator with the registry's reason.
TEST(BsplineCli, PerVertexMethodsRefuseTheElementOperator) {
  const auto dir = FreshTempDir("bspline_cli");
  const auto input = WriteSphere(dir);
  const CliResult smooth = RunDmc("edit smooth-explicit " + Quoted(input) + " -o " +
                                  Quoted(dir / "smooth.obj") + " --operator bspline");
  EXPECT_EQ(smooth.exit_code, 16) << smooth.err;  // unsupported
  EXPECT_NE(smooth.err.find("per-vertex"), std::string::npos) << smooth.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "smooth.obj"));
}

// The value of the first measurement called `name` in a dmc edit --json report.
double Measurement(const nlohmann::json& report, const std::string& name) {
  for (const auto& m : report["measurements"]) {
    if (m["name"].get<std::string>() == name) return m["value"].get<double>();
  }
  ADD_FAILURE() << "no measurement " << name;
  return 0.0;
}

TEST(BsplineCli, EditSpectrumAndPoissonFit) {
  const auto dir = FreshTempDir("bspline_cli");
  const auto input = WriteSphere(dir);
  const CliResult spectrum = RunDmc("edit spectrum " + Quoted(input) + " -o " +
                                    Quoted(dir / "mode.ply") + " --depth 4 --k 4 --json");
  ASSERT_EQ(spectrum.exit_code, 0) << spectrum.err;
  const auto spectrum_report = nlohmann::json::parse(spectrum.out);
  EXPECT_EQ(spectrum_report["scalar"].get<std::string>(), "eigenfunction");
  EXPECT_NEAR(Measurement(spectrum_report, "eigenvalue_0"), 0.0, 1e-6);
  EXPECT_NEAR(Measurement(spectrum_report, "eigenvalue_3"), 2.0, 0.1);
  EXPECT_TRUE(std::filesystem::exists(dir / "mode.ply"));

  // Fitting the coordinates to their own gradients and values changes the sphere very little.
  const CliResult fit = RunDmc("edit poisson-fit " + Quoted(input) + " -o " +
                               Quoted(dir / "fit.obj") + " --depth 4 --alpha 1 --cycles 20 --json");
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const auto fit_report = nlohmann::json::parse(fit.out);
  EXPECT_LT(Measurement(fit_report, "rms_change"), 1e-3);
  EXPECT_EQ(
      RunDmc("edit poisson-fit " + Quoted(input) + " -o " + Quoted(dir / "bad.obj") + " --field w")
          .exit_code,
      11);
}

TEST(BsplineCli, BadOptionsHaveTheirExitCodes) {
  const auto dir = FreshTempDir("bspline_cli");
  const auto input = WriteSphere(dir);
  EXPECT_EQ(RunDmc("laplacian " + Quoted(input) + " --operator bspline --depth 11 --spectrum 3")
                .exit_code,
            11);  // invalid argument
  EXPECT_EQ(RunDmc("laplacian " + Quoted(input) + " --operator bspline --spectrum -2").exit_code,
            11);
  // A non-symmetric operator has no generalized spectrum here.
  EXPECT_EQ(RunDmc("laplacian " + Quoted(input) + " --operator tutte --spectrum 3").exit_code,
            16);  // unsupported
}

}  // namespace
}  // namespace dmc::testing
