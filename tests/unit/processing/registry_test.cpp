// The processing registry, declared parameters and selections.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "dmc/processing.h"
#include "test_support.h"

namespace dmc {
namespace {

TEST(ProcessingRegistry, NamesAreUniqueAndEveryRowIsComplete) {
  std::set<std::string_view> names;
  for (const MethodInfo& method : ProcessingRegistry()) {
    EXPECT_TRUE(names.insert(method.name).second) << "duplicate method " << method.name;
    EXPECT_FALSE(method.description.empty()) << method.name;
    EXPECT_NE(method.precompute, nullptr) << method.name;
    // Names are CLI sub-subcommands: lower case, digits and dashes.
    for (char c : method.name) {
      EXPECT_TRUE((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-') << method.name;
    }
  }
  for (std::string_view expected :
       {"laplacian-edit", "smooth-explicit", "smooth-taubin", "smooth-implicit",
        "param-barycentric", "morph", "ls-mesh", "curvature", "spectral-filter"}) {
    EXPECT_TRUE(names.count(expected)) << expected;
  }
}

TEST(ProcessingRegistry, DeclaredParametersHaveValidDefaultsAndNoReservedNames) {
  const auto reserved = ReservedParameterNames();
  for (const MethodInfo& method : ProcessingRegistry()) {
    std::set<std::string_view> seen;
    for (const ParameterSpec& spec : method.parameters) {
      EXPECT_TRUE(seen.insert(spec.name).second) << method.name << " --" << spec.name;
      EXPECT_EQ(std::find(reserved.begin(), reserved.end(), spec.name), reserved.end())
          << method.name << " declares the reserved option --" << spec.name;
      EXPECT_FALSE(spec.help.empty()) << method.name << " --" << spec.name;
    }
    EXPECT_TRUE(ParameterValues::Create(method.parameters).ok()) << method.name;
  }
}

TEST(ProcessingRegistry, UnknownMethodListsTheKnownOnes) {
  const auto missing = FindMethod("no-such-method");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(missing.status().message().find("laplacian-edit"), std::string::npos);
  ASSERT_TRUE(FindMethod("curvature").ok());
  EXPECT_EQ((*FindMethod("curvature"))->vertex_scalar, "mean_curvature");
}

constexpr ParameterSpec kSpecs[] = {
    {"lambda", ParameterType::kNumber, "0.5", "a number"},
    {"iterations", ParameterType::kInteger, "3", "an integer"},
    {"mode", ParameterType::kText, "hard", "text"},
    {"verbose", ParameterType::kFlag, "false", "a flag"},
};

TEST(ParameterValues, DefaultsOverridesAndTypedAccess) {
  auto values = ParameterValues::Create(kSpecs, {{"lambda", "1.25"}, {"verbose", "true"}});
  ASSERT_TRUE(values.ok()) << values.status().ToString();
  EXPECT_DOUBLE_EQ(*values->Number("lambda"), 1.25);
  EXPECT_EQ(*values->Integer("iterations"), 3);
  EXPECT_EQ(*values->Text("mode"), "hard");
  EXPECT_TRUE(*values->Flag("verbose"));
  // Reading an undeclared name or with the wrong type is a bug in the method: kInternal.
  EXPECT_EQ(values->Number("missing").status().code(), ErrorCode::kInternal);
  EXPECT_EQ(values->Integer("lambda").status().code(), ErrorCode::kInternal);
}

TEST(ParameterValues, RejectsUnknownNamesAndMalformedValues) {
  const auto unknown = ParameterValues::Create(kSpecs, {{"lamda", "1"}});
  EXPECT_EQ(unknown.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(unknown.status().message().find("--lambda"), std::string::npos);
  EXPECT_EQ(ParameterValues::Create(kSpecs, {{"lambda", "abc"}}).status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(ParameterValues::Create(kSpecs, {{"lambda", "inf"}}).status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(ParameterValues::Create(kSpecs, {{"iterations", "2.5"}}).status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(ParameterValues::Create(kSpecs, {{"verbose", "yes"}}).status().code(),
            ErrorCode::kInvalidArgument);
}

TEST(Selection, ParsesTheJsonForm) {
  auto selection = ParseSelectionJson(
      R"({"handles": [5, 3, 5], "fixed": [0, 1], "transform": [1,0,0,0.5, 0,1,0,0, 0,0,1,-2, 0,0,0,1]})");
  ASSERT_TRUE(selection.ok()) << selection.status().ToString();
  ASSERT_TRUE(ValidateSelection(*selection, 10).ok());
  EXPECT_EQ(selection->handles, (std::vector<int32_t>{3, 5}));  // sorted, de-duplicated
  EXPECT_EQ(selection->fixed, (std::vector<int32_t>{0, 1}));
  FramePositionsD positions = FramePositionsD::Zero(10, 3);
  positions.row(3) << 1, 2, 3;
  const Eigen::MatrixXd targets = TransformedHandlePositions(*selection, positions);
  EXPECT_DOUBLE_EQ(targets(0, 0), 1.5);
  EXPECT_DOUBLE_EQ(targets(0, 1), 2.0);
  EXPECT_DOUBLE_EQ(targets(0, 2), 1.0);
  EXPECT_DOUBLE_EQ(targets(1, 2), -2.0);  // vertex 5 at the origin, translated
}

TEST(Selection, FreeSetMakesTheRestFixed) {
  auto selection = ParseSelectionJson(R"({"handles": [0], "free": [1, 2]})");
  ASSERT_TRUE(selection.ok());
  ASSERT_TRUE(ValidateSelection(*selection, 5).ok());
  EXPECT_EQ(selection->fixed, (std::vector<int32_t>{3, 4}));
  EXPECT_FALSE(selection->free.has_value());
}

TEST(Selection, RejectsMalformedAndInconsistentSelections) {
  EXPECT_EQ(ParseSelectionJson("{").status().code(), ErrorCode::kParseError);
  EXPECT_EQ(ParseSelectionJson(R"({"handles": [1.5]})").status().code(), ErrorCode::kParseError);
  EXPECT_EQ(ParseSelectionJson(R"({"handles": [-1]})").status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(ParseSelectionJson(R"({"transform": [1, 2, 3]})").status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(ParseSelectionJson(R"({"handel": [1]})").status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(ParseSelectionJson(R"({"fixed": [1], "free": [2]})").status().code(),
            ErrorCode::kInvalidArgument);
  const auto check = [](const char* json, int vertex_count) {
    auto selection = ParseSelectionJson(json);
    EXPECT_TRUE(selection.ok()) << json;
    return ValidateSelection(*selection, vertex_count).code();
  };
  EXPECT_EQ(check(R"({"handles": [7]})", 5), ErrorCode::kInvalidArgument);
  EXPECT_EQ(check(R"({"handles": [1], "fixed": [1]})", 5), ErrorCode::kInvalidArgument);
  EXPECT_EQ(check(R"({"handles": [1], "anchors": [1]})", 5), ErrorCode::kInvalidArgument);
  EXPECT_EQ(check(R"({"handles": [1, 2], "weights": [1]})", 5), ErrorCode::kInvalidArgument);
  EXPECT_EQ(check(R"({"handles": [1], "weights": [0]})", 5), ErrorCode::kInvalidArgument);
  EXPECT_EQ(check(R"({"transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 1,0,0,1]})", 5),
            ErrorCode::kInvalidArgument);  // projective
}

TEST(Selection, ReadsIndexListsAndJsonFiles) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "dmc_processing_selection_test";
  std::filesystem::create_directories(dir);
  {
    std::ofstream(dir / "list.txt") << "# handles\n4 2\n9  # trailing comment\n";
    std::ofstream(dir / "sel.json") << "  {\"handles\": [1], \"fixed\": [2]}";
    std::ofstream(dir / "bad.txt") << "1 2 x\n";
  }
  auto list = ReadSelectionFile(dir / "list.txt");
  ASSERT_TRUE(list.ok()) << list.status().ToString();
  EXPECT_EQ(list->handles, (std::vector<int32_t>{4, 2, 9}));
  auto json = ReadSelectionFile(dir / "sel.json");
  ASSERT_TRUE(json.ok());
  EXPECT_EQ(json->fixed, (std::vector<int32_t>{2}));
  const auto bad = ReadSelectionFile(dir / "bad.txt");
  EXPECT_EQ(bad.status().code(), ErrorCode::kParseError);
  EXPECT_NE(bad.status().message().find(":1:"), std::string::npos);
  EXPECT_EQ(ReadSelectionFile(dir / "missing.json").status().code(), ErrorCode::kIoError);
  std::filesystem::remove_all(dir);
}

TEST(ProcessingRun, RejectsBadRequestsBeforeWork) {
  const MeshSequence grid = testing::PlanarGrid(4);
  RunOptions options;
  EXPECT_EQ(RunMethod("nope", grid, options).status().code(), ErrorCode::kNotFound);
  options.operator_name = "nope";
  EXPECT_EQ(RunMethod("smooth-explicit", grid, options).status().code(), ErrorCode::kNotFound);
  options.operator_name = "tutte";
  // laplacian-edit needs handles.
  EXPECT_EQ(RunMethod("laplacian-edit", grid, options).status().code(),
            ErrorCode::kInvalidArgument);
  options.parameters = {{"lambda", "x"}};
  EXPECT_EQ(RunMethod("smooth-explicit", grid, options).status().code(),
            ErrorCode::kInvalidArgument);
  options.parameters = {};
  options.operator_frame = 3;
  EXPECT_EQ(RunMethod("smooth-explicit", grid, options).status().code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc
