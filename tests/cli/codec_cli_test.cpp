// dmc encode / decode end to end through the built binary: outputs, JSON keys, exit codes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

class CodecCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshTempDir("codec_cli");
    input_ = dir_ / "blob.pc2";
    const CliResult made =
        RunDmc("synth blob -o " + Quoted(input_) + " --frames 12 --resolution 600");
    ASSERT_EQ(made.exit_code, 0) << made.err;
  }
  std::filesystem::path dir_, input_;
};

// --no-ddl-fallback keeps the fitted DDL in every segment; short segments (2 frames) cannot pay for
// fitted weights, so with the fallback some segment takes another operator, and the text report
// says which.
TEST_F(CodecCli, DdlFallbackCanBeTurnedOffAndIsReported) {
  const auto stream = dir_ / "blob.dmc";
  const std::string encode =
      "encode " + Quoted(input_) + " -o " + Quoted(stream) + " --segment-frames 2";
  const CliResult fitted = RunDmc(encode + " --no-ddl-fallback --json");
  ASSERT_EQ(fitted.exit_code, 0) << fitted.err;
  EXPECT_EQ(nlohmann::json::parse(fitted.out)["segment_operators"],
            nlohmann::json(std::vector<std::string>(6, "ddl")));
  // Every switch is --name and --no-name.
  const CliResult fitted_too = RunDmc(encode + " --ddl-fallback --no-ddl-fallback --json");
  ASSERT_EQ(fitted_too.exit_code, 0) << fitted_too.err;
  EXPECT_EQ(nlohmann::json::parse(fitted_too.out)["segment_operators"],
            nlohmann::json(std::vector<std::string>(6, "ddl")));
  const CliResult fallback = RunDmc(encode + " --ddl-fallback --json");
  ASSERT_EQ(fallback.exit_code, 0) << fallback.err;
  const auto operators = nlohmann::json::parse(fallback.out)["segment_operators"];
  ASSERT_EQ(operators.size(), 6u);
  EXPECT_NE(operators, nlohmann::json(std::vector<std::string>(6, "ddl")));
  const CliResult text = RunDmc(encode);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("operator ddl (segments: "), std::string::npos) << text.out;
}

// --no-rank-search keeps the rank of --rank-threshold; by default the encoder also tries the lower
// ranks of larger thresholds and, on this blob at 10 bits, keeps a lower one that costs fewer
// bytes at a lower STED.
TEST_F(CodecCli, RankSearchCanBeTurnedOff) {
  const auto input = dir_ / "blob16.pc2";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(input) + " --frames 16 --resolution 1500").exit_code,
            0);
  const std::string encode =
      "encode " + Quoted(input) + " -o " + Quoted(dir_ / "b.dmc") + " --residual-bits 10 --json";
  const CliResult searched = RunDmc(encode);
  ASSERT_EQ(searched.exit_code, 0) << searched.err;
  const CliResult plain = RunDmc(encode + " --no-rank-search");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto with = nlohmann::json::parse(searched.out), without = nlohmann::json::parse(plain.out);
  EXPECT_LT(with["rank"].get<int>(), without["rank"].get<int>());
  EXPECT_LT(with["bytes"].get<uint64_t>(), without["bytes"].get<uint64_t>());
  EXPECT_LT(with["sted"].get<double>(), without["sted"].get<double>());
}

TEST_F(CodecCli, EncodeReportsTheRequiredJsonAndDecodeRebuildsTheSequence) {
  const auto stream = dir_ / "blob.dmc";
  const CliResult encoded =
      RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream) + " --json");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  const auto json = nlohmann::json::parse(encoded.out);
  for (const char* key :
       {"bpfv", "bytes", "frames", "vertices", "kg", "sted", "seconds", "breakdown"}) {
    EXPECT_TRUE(json.contains(key)) << key;
  }
  EXPECT_EQ(json["bytes"].get<uint64_t>(), std::filesystem::file_size(stream));
  EXPECT_EQ(json["frames"].get<int>(), 12);
  uint64_t breakdown_total = 0;
  for (const auto& [name, bytes] : json["breakdown"].items())
    breakdown_total += bytes.get<uint64_t>();
  EXPECT_EQ(breakdown_total, json["bytes"].get<uint64_t>());

  const CliResult info = RunDmc("info " + Quoted(stream) + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto stream_info = nlohmann::json::parse(info.out);
  EXPECT_EQ(stream_info["bytes"].get<uint64_t>(), json["bytes"].get<uint64_t>());
  EXPECT_EQ(stream_info["segments"].size(), 1u);
  // The ddl operator's fallback may code the segment with another operator; info names it.
  ASSERT_EQ(json["segment_operators"].size(), 1u);
  EXPECT_EQ(stream_info["segments"][0]["operator"], json["segment_operators"][0]);
  EXPECT_EQ(json["operator"].get<std::string>(), "ddl");
  EXPECT_EQ(stream_info["segments"][0]["rank"].get<int>(), json["rank"].get<int>());

  const auto decoded = dir_ / "decoded.pc2";
  const CliResult decode = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(decoded));
  ASSERT_EQ(decode.exit_code, 0) << decode.err;
  const CliResult metrics = RunDmc("metrics " + Quoted(input_) + " " + Quoted(decoded) + " --json");
  ASSERT_EQ(metrics.exit_code, 0) << metrics.err;
  const auto measured = nlohmann::json::parse(metrics.out);
  // The encoder's reported distortion is that of the decoded file (up to float32 storage).
  EXPECT_NEAR(measured["kg"].get<double>(), json["kg"].get<double>(), 1e-4);
  EXPECT_NEAR(measured["sted"].get<double>(), json["sted"].get<double>(), 1e-5);
}

TEST_F(CodecCli, BadOptionsAndDamagedStreamsGiveDistinctExitCodes) {
  const auto stream = dir_ / "blob.dmc";
  const std::string encode = "encode " + Quoted(input_) + " -o " + Quoted(stream);
  // The library names options (basis_bits); the CLI shows its flags instead.
  const CliResult coarse = RunDmc(encode + " --basis-bits 1");
  EXPECT_EQ(coarse.exit_code, 11);
  EXPECT_NE(coarse.err.find("--basis-bits must be in [2, 16], got 1"), std::string::npos)
      << coarse.err;
  const CliResult both = RunDmc(encode + " --target-bpfv 2 --target-sted 0.01");
  EXPECT_EQ(both.exit_code, 11);
  EXPECT_NE(both.err.find("give --target-bpfv or --target-sted, not both"), std::string::npos)
      << both.err;
  const CliResult mu = RunDmc(encode + " --ddl-mu -1 --json");
  EXPECT_EQ(mu.exit_code, 11);
  EXPECT_NE(mu.out.find("--ddl-mu must be >= 0"), std::string::npos) << mu.out;
  const CliResult unknown =
      RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream) + " --operator nope");
  EXPECT_EQ(unknown.exit_code, 20);
  EXPECT_NE(unknown.err.find("ddl"), std::string::npos) << unknown.err;  // lists what exists
  EXPECT_FALSE(std::filesystem::exists(stream));

  ASSERT_EQ(
      RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream) + " --no-measure").exit_code, 0);
  std::ifstream in(stream, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  const auto truncated = dir_ / "truncated.dmc";
  std::ofstream(truncated, std::ios::binary).write(bytes.data(), bytes.size() / 2);
  const CliResult short_read =
      RunDmc("decode " + Quoted(truncated) + " -o " + Quoted(dir_ / "t.pc2"));
  EXPECT_EQ(short_read.exit_code, 18) << short_read.err;
  auto corrupt_bytes = bytes;
  corrupt_bytes[corrupt_bytes.size() / 2] ^= 0x40;
  const auto corrupt = dir_ / "corrupt.dmc";
  std::ofstream(corrupt, std::ios::binary).write(corrupt_bytes.data(), corrupt_bytes.size());
  const CliResult damaged = RunDmc("decode " + Quoted(corrupt) + " -o " + Quoted(dir_ / "c.pc2"));
  EXPECT_EQ(damaged.exit_code, 17) << damaged.err;
  EXPECT_NE(damaged.err.find("checksum"), std::string::npos) << damaged.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "c.pc2"));
}

TEST_F(CodecCli, TargetRateIsMetAndReorderingIsOptIn) {
  const auto stream = dir_ / "target.dmc";
  const CliResult target =
      RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream) + " --target-bpfv 3 --json");
  ASSERT_EQ(target.exit_code, 0) << target.err;
  EXPECT_LE(nlohmann::json::parse(target.out)["bpfv"].get<double>(), 3.0);
  const CliResult reordered =
      RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream) + " --allow-reorder --json");
  ASSERT_EQ(reordered.exit_code, 0) << reordered.err;
  EXPECT_GT(nlohmann::json::parse(reordered.out)["sted"].get<double>(), 0.0);
}

}  // namespace
}  // namespace dmc::testing
