// Mesh readers on hostile files found by the fuzz targets (tests/fuzz). Each case runs in a child
// process with a wall-clock and address-space limit, so a reader that loops forever fails the test
// instead of hanging the suite.
//
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <functional>
#include <string>

#include "dmc/status.h"
#include "io/mesh_formats.h"
#include "test_support.h"

namespace dmc {
namespace {

// Runs `work` in a child process limited to `seconds` of wall time and 1 GiB of address space
// (not under ASan, which reserves far more). True when the child returned 0 in time.
bool FinishesInTime(const std::function<int()>& work, unsigned seconds) {
  const pid_t child = ::fork();
  if (child == 0) {
    if (!DMC_SANITIZER_OWNS_ALLOCATOR) {
      const rlimit limit{rlim_t{1} << 30, rlim_t{1} << 30};
      ::setrlimit(RLIMIT_AS, &limit);
    }
    ::alarm(seconds);  // SIGALRM ends the child
    ::_exit(work());
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

TEST(HostileFiles, BinaryPlyHeaderParsesQuickly) {
  // The well-formed twin of the case below: a one-vertex binary PLY.
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n" +
      std::string(12, '\0');
  EXPECT_TRUE(FinishesInTime(
      [&] {
        const auto mesh = io_internal::ParsePly(ply);
        return mesh.ok() && mesh->vertex_count() == 1 ? 0 : 1;
      },
      2));
}

TEST(HostileFiles, CarriageReturnInsideAPlyHeaderLineIsAParseError) {
  // Found by ply_fuzz: dmc's header parser split tokens on spaces and tabs only, read
  // "element a\rb 1" as element "a\rb" with 1 item and handed the file to OpenMesh's binary PLY
  // reader, which tokenises '\r' as white space, fails to read "b" as the count and then never
  // leaves its header loop (growing its element list). Now a parse error, at once.
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement a\rb 1\nproperty float x\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n" +
      std::string(16, '\0');
  EXPECT_TRUE(FinishesInTime(
      [&] {
        const auto mesh = io_internal::ParsePly(ply);
        return !mesh.ok() && mesh.status().code() == ErrorCode::kParseError ? 0 : 1;
      },
      2))
      << "ParsePly did not report a parse error within 2 s";
}

}  // namespace
}  // namespace dmc
