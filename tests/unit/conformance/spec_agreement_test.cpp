// The normative spec (bitstream-spec/dmc-format.md) and the frozen-ID header (dmc/wire_ids.h)
// must agree entry for entry: every table marked `<!-- wire-ids: NAME -->` in the spec is parsed
// and compared with the header's tables, the error-code names, the format limits and version,
// and with what the decoder actually accepts.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/connectivity_decoder.h"
#include "decoder/syntax_reader.h"
#include "dmc/operator_traits.h"
#include "dmc/operators.h"
#include "dmc/status.h"
#include "dmc/wire_ids.h"
#include "encoder/syntax_writer.h"

namespace dmc {
namespace {

std::string SourceText(const std::string& path) {
  std::ifstream in(std::string(DMC_SOURCE_DIR) + "/" + path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string SpecText() { return SourceText("bitstream-spec/dmc-format.md"); }

// The spec's section titles by number: "12.2" -> "Syntax digests" (from "### 12.2 Syntax digests").
std::map<std::string, std::string> SpecSections(const std::string& spec) {
  std::map<std::string, std::string> sections;
  std::istringstream lines(spec);
  const std::regex heading(R"(^#{2,4} ([0-9]+(?:\.[0-9]+)*)\.? (.*)$)");
  std::smatch match;
  for (std::string line; std::getline(lines, line);) {
    if (std::regex_match(line, match, heading)) sections[match[1]] = match[2];
  }
  return sections;
}

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(" \t");
  return text.substr(begin, end - begin + 1);
}

std::vector<std::string> Cells(const std::string& row) {
  std::vector<std::string> cells;
  std::string cell;
  // The row starts and ends with '|'; cells are between.
  for (size_t i = 1; i < row.size(); ++i) {
    if (row[i] == '|') {
      cells.push_back(Trim(cell));
      cell.clear();
    } else {
      cell += row[i];
    }
  }
  return cells;
}

std::string Unquote(const std::string& cell) {
  if (cell.size() >= 2 && cell.front() == '`' && cell.back() == '`') {
    return cell.substr(1, cell.size() - 2);
  }
  return cell;
}

// Rows of the table that follows `<!-- wire-ids: marker -->`: header and separator skipped,
// each row as its cells. Empty when the marker is absent.
std::vector<std::vector<std::string>> SpecTable(const std::string& spec,
                                                const std::string& marker) {
  std::vector<std::vector<std::string>> rows;
  const std::string tag = "<!-- wire-ids: " + marker + " -->";
  const size_t at = spec.find(tag);
  if (at == std::string::npos) return rows;
  std::istringstream lines(spec.substr(at + tag.size()));
  std::string line;
  int table_line = 0;
  while (std::getline(lines, line)) {
    if (table_line == 0 && Trim(line).empty()) continue;  // blank lines before the table
    if (Trim(line).empty() || Trim(line)[0] != '|') break;
    if (table_line++ >= 2) rows.push_back(Cells(Trim(line)));
  }
  return rows;
}

// (ID, name) pairs of a spec table whose first two columns are the ID and the `name`.
std::map<int, std::string> IdNames(const std::vector<std::vector<std::string>>& rows) {
  std::map<int, std::string> pairs;
  for (const auto& row : rows) {
    EXPECT_GE(row.size(), 2u);
    if (row.size() < 2) continue;
    const int id = std::stoi(row[0]);
    EXPECT_EQ(pairs.count(id), 0u) << "ID " << id << " appears twice in the spec";
    pairs[id] = Unquote(row[1]);
  }
  return pairs;
}

template <typename Enum, size_t N>
std::map<int, std::string> HeaderIdNames(const std::array<WireName<Enum>, N>& table) {
  std::map<int, std::string> pairs;
  for (const WireName<Enum>& row : table) {
    EXPECT_EQ(pairs.count(static_cast<int>(row.value)), 0u) << row.name << " listed twice";
    pairs[static_cast<int>(row.value)] = std::string(row.name);
  }
  return pairs;
}

class SpecAgreement : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { spec_ = new std::string(SpecText()); }
  static void TearDownTestSuite() { delete spec_; }
  static const std::string& spec() { return *spec_; }

 private:
  static std::string* spec_;
};
std::string* SpecAgreement::spec_ = nullptr;

TEST_F(SpecAgreement, SpecIsPresentAndNamesTheFormatVersion) {
  ASSERT_FALSE(spec().empty()) << "bitstream-spec/dmc-format.md is missing";
  const std::string version =
      std::to_string(format::kVersionMajor) + "." + std::to_string(format::kVersionMinor);
  EXPECT_NE(spec().find("| Format version | **" + version + "** |"), std::string::npos)
      << "the spec's title table must name format version " << version;
  EXPECT_NE(spec().find("| Document revision | " + version + "-r"), std::string::npos);
  // The magic of §4.1 is the header's.
  char magic[32];
  std::snprintf(magic, sizeof magic, "`%02X %02X %02X %02X`", format::kMagic[0], format::kMagic[1],
                format::kMagic[2], format::kMagic[3]);
  EXPECT_NE(spec().find(magic), std::string::npos) << "magic " << magic << " not in the spec";
}

// conformance/README.md cites the spec by section: every number it cites is a section, and the
// ones it names by subject are the sections of that subject (they were off by one once).
TEST_F(SpecAgreement, ConformanceReadmeCitesTheRightSections) {
  const std::string readme = SourceText("conformance/README.md");
  ASSERT_FALSE(readme.empty());
  const std::map<std::string, std::string> sections = SpecSections(spec());
  ASSERT_GT(sections.size(), 40u);
  const std::regex citation(R"(§([0-9]+(?:\.[0-9]+)*))");
  int cited = 0;
  for (std::sregex_iterator it(readme.begin(), readme.end(), citation), end; it != end; ++it) {
    const std::string number = (*it)[1];
    EXPECT_TRUE(sections.count(number))
        << "conformance/README.md cites §" << number << ", which the spec does not have";
    ++cited;
  }
  EXPECT_GT(cited, 5);
  for (const auto& [number, title] :
       std::map<std::string, std::string>{{"12", "Conformance"},
                                          {"12.2", "Syntax digests"},
                                          {"12.3", "Tolerance"},
                                          {"11.1", "Error codes"},
                                          {"11.3", "Summary of invalid conditions"},
                                          {"4.2", "Chunk framing"}}) {
    ASSERT_TRUE(sections.count(number)) << "§" << number;
    EXPECT_EQ(sections.at(number), title) << "§" << number;
    EXPECT_NE(readme.find("§" + number), std::string::npos)
        << "conformance/README.md no longer cites §" << number << " (" << title << ")";
  }
}

TEST_F(SpecAgreement, OperatorIdsMatchTheHeaderAndTheRegistryNames) {
  const auto rows = SpecTable(spec(), "operator");
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(IdNames(rows), HeaderIdNames(kOperatorIdNames));
  for (const WireName<OperatorId>& row : kOperatorIdNames) {
    if (row.value == OperatorId::kInvalid) continue;
    EXPECT_EQ(OperatorIdName(row.value), row.name) << "registry name of ID " << int(row.value);
  }
}

std::string SpecChunkColumn(OperatorSideInfo side_info) {
  switch (side_info) {
    case OperatorSideInfo::kNotCarried:
      return "—";
    case OperatorSideInfo::kNone:
      return "empty";
    case OperatorSideInfo::kReferenceFrame:
      return "reference frame";
    case OperatorSideInfo::kEdgeWeights:
      return "DDL weights";
  }
  return "?";
}

// The spec's "Codec operator in 1.0 and 1.1" and "Operator chunk" columns are kOperatorTraits'
// rows.
TEST_F(SpecAgreement, OperatorColumnsMatchTheTraitsTable) {
  const auto rows = SpecTable(spec(), "operator");
  ASSERT_FALSE(rows.empty());
  int listed = 0;
  for (const auto& row : rows) {
    ASSERT_GE(row.size(), 4u);
    const auto id = static_cast<OperatorId>(std::stoi(row[0]));
    const OperatorTraits* traits = FindOperatorTraits(id);
    if (id == OperatorId::kInvalid) {
      EXPECT_EQ(traits, nullptr);
      continue;
    }
    ASSERT_NE(traits, nullptr) << "ID " << row[0] << " has no traits row";
    ++listed;
    EXPECT_EQ(traits->name, Unquote(row[1]));
    EXPECT_EQ(row[2], traits->codec() ? "yes" : "no") << traits->name;
    EXPECT_EQ(row[3], SpecChunkColumn(traits->side_info)) << traits->name;
    EXPECT_EQ(format::IsCodecOperator(static_cast<uint8_t>(id)), traits->codec());
    EXPECT_EQ(format::IsGeometricOperator(static_cast<uint8_t>(id)), row[3] == "reference frame");
  }
  // Every traits row with a wire ID is in the spec.
  int with_id = 0;
  for (const OperatorTraits& traits : kOperatorTraits) with_id += traits.id != OperatorId::kInvalid;
  EXPECT_EQ(listed, with_id);
}

TEST_F(SpecAgreement, CodecOperatorColumnMatchesWhatTheDecoderAccepts) {
  const auto rows = SpecTable(spec(), "operator");
  ASSERT_FALSE(rows.empty());
  for (const auto& row : rows) {
    ASSERT_GE(row.size(), 3u);
    const int id = std::stoi(row[0]);
    format::SegmentHeader header;
    header.frame_count = 4;
    header.rank = 2;
    header.operator_id = static_cast<uint8_t>(id);
    header.anchor_count = 1;
    header.mean_step = header.residual_step = header.anchor_step = header.anchor_weight = 0.5;
    const auto parsed = syntax::ReadSegmentHeader(syntax::WriteSegmentHeader(header), 0, 4, 10);
    if (row[2] == "yes") {
      EXPECT_TRUE(parsed.ok()) << "operator " << id << ": " << parsed.status().ToString();
    } else {
      ASSERT_FALSE(parsed.ok()) << "operator " << id << " is accepted but the spec says no";
      EXPECT_EQ(parsed.status().code(), ErrorCode::kUnsupported);
    }
  }
  // An ID the spec does not list at all is unsupported too.
  format::SegmentHeader header;
  header.frame_count = 1;
  header.operator_id = 200;
  header.anchor_count = 1;
  header.mean_step = header.residual_step = header.anchor_step = header.anchor_weight = 1.0;
  EXPECT_EQ(syntax::ReadSegmentHeader(syntax::WriteSegmentHeader(header), 0, 1, 10).status().code(),
            ErrorCode::kUnsupported);
}

TEST_F(SpecAgreement, ChunkTypesMatchTheHeader) {
  const auto rows = SpecTable(spec(), "chunk-type");
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(IdNames(rows), HeaderIdNames(kChunkTypeNames));
  // format.h uses the same enum (an alias, not a copy).
  static_assert(std::is_same_v<format::ChunkType, ChunkType>);
}

TEST_F(SpecAgreement, ConnectivityMethodsMatchTheHeaderAndTheDecoder) {
  const auto rows = SpecTable(spec(), "connectivity-method");
  ASSERT_FALSE(rows.empty());
  const auto spec_methods = IdNames(rows);
  EXPECT_EQ(spec_methods, HeaderIdNames(kConnectivityMethodNames));
  static_assert(std::is_same_v<ConnectivityCoding, ConnectivityMethod>);
  // A listed method byte alone is a truncated payload; any other byte is an unknown method.
  for (int method = 0; method < 256; ++method) {
    const std::vector<uint8_t> payload = {static_cast<uint8_t>(method)};
    const ErrorCode code = DecodeConnectivity(payload, 3, 1).status().code();
    if (spec_methods.count(method) > 0) {
      EXPECT_EQ(code, ErrorCode::kTruncatedStream) << "method " << method;
    } else {
      EXPECT_EQ(code, ErrorCode::kUnsupported) << "method " << method;
    }
  }
}

TEST_F(SpecAgreement, ErrorCodesMatchTheHeaderNamesAndExitCodes) {
  const auto rows = SpecTable(spec(), "error-code");
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(IdNames(rows), HeaderIdNames(kErrorCodeNames));
  for (const WireName<ErrorCode>& row : kErrorCodeNames) {
    EXPECT_EQ(ErrorCodeName(row.value), row.name);
    if (row.value != ErrorCode::kOk) {
      EXPECT_EQ(ExitCodeFor(row.value), 10 + static_cast<int>(row.value));
    }
  }
}

TEST_F(SpecAgreement, LimitsMatchTheFormatHeader) {
  const auto rows = SpecTable(spec(), "limits");
  ASSERT_FALSE(rows.empty());
  std::map<std::string, uint64_t> limits;
  for (const auto& row : rows) {
    ASSERT_GE(row.size(), 2u);
    limits[Unquote(row[0])] = std::stoull(row[1]);
  }
  const std::map<std::string, uint64_t> expected = {
      {"kMaxVertices", format::kMaxVertices}, {"kMaxTriangles", format::kMaxTriangles},
      {"kMaxFrames", format::kMaxFrames},     {"kMaxSegmentFrames", format::kMaxSegmentFrames},
      {"kMaxRank", format::kMaxRank},         {"kMaxNameLength", format::kMaxNameLength}};
  EXPECT_EQ(limits, expected);
}

TEST_F(SpecAgreement, EntropyCoderConstantsMatch) {
  // §5.3 names the binarisation's constants; a change in the header must change the spec.
  EXPECT_NE(spec().find("kUnaryLength = " + std::to_string(IntegerContexts::kUnaryLength)),
            std::string::npos);
  EXPECT_NE(spec().find("kEscapeContexts = " + std::to_string(IntegerContexts::kEscapeContexts)),
            std::string::npos);
  EXPECT_NE(spec().find("if n > " + std::to_string(IntegerContexts::kMaxEscapeBits) + ":"),
            std::string::npos);
}

}  // namespace
}  // namespace dmc
