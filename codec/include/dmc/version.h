// The library's version: the one place it is written. CMakeLists.txt reads these three numbers for
// project(VERSION), the package files and the Python module's __version__; `dmc --version` prints
// them; the package.json files and the spec's "Reference implementation" line (major.minor) must
// say the same (ctest version.consistent). The stream format has its own version
// (bitstream-spec/dmc-format.md §4.1), independent of this.
#pragma once

#define DMC_VERSION_MAJOR 0
#define DMC_VERSION_MINOR 1
#define DMC_VERSION_PATCH 0

#define DMC_VERSION_STRINGIFY_(x) #x
#define DMC_VERSION_STRINGIFY(x) DMC_VERSION_STRINGIFY_(x)
// "0.1.0"
#define DMC_VERSION_STRING                 \
  DMC_VERSION_STRINGIFY(DMC_VERSION_MAJOR) \
  "." DMC_VERSION_STRINGIFY(DMC_VERSION_MINOR) "." DMC_VERSION_STRINGIFY(DMC_VERSION_PATCH)

namespace dmc {

struct Version {
  int major, minor, patch;
};
// The version of the library linked at run time (the macros give the one compiled against).
Version LibraryVersion();
// LibraryVersion() as "major.minor.patch".
const char* LibraryVersionString();

}  // namespace dmc
