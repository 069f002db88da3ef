// Helpers of the I/O tests: per-test scratch directories, writing small files, comparing sequences.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/io.h"
#include "dmc/sequence.h"

namespace dmc::testing {

// An empty directory unique to the running test, removed when the object dies.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    // Parameterised names hold '/' ("Formats/RoundTrip.Test/0"): keep one flat directory.
    std::string name = "dmc_io_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
                       std::to_string(::getpid());
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void WriteText(const std::filesystem::path& path, std::string_view text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  ASSERT_TRUE(out.good()) << path;
}

inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Names of the entries of a directory, sorted.
inline std::vector<std::string> ListNames(const std::filesystem::path& directory) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// Same triangles and bit-identical positions (so -0.0 differs from 0.0, as it should for a
// lossless round trip).
inline void ExpectIdentical(const MeshSequence& expected, const MeshSequence& actual) {
  ASSERT_EQ(expected.vertex_count(), actual.vertex_count());
  ASSERT_EQ(expected.frame_count(), actual.frame_count());
  ASSERT_EQ(expected.triangles(), actual.triangles());
  ASSERT_EQ(expected.position_value_count(), actual.position_value_count());
  for (size_t i = 0; i < expected.position_value_count(); ++i) {
    uint32_t a = 0, b = 0;
    std::memcpy(&a, expected.data() + i, 4);
    std::memcpy(&b, actual.data() + i, 4);
    ASSERT_EQ(a, b) << "value " << i << ": " << expected.data()[i] << " vs " << actual.data()[i];
  }
}

}  // namespace dmc::testing
