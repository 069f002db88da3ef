#include "dmc/version.h"

namespace dmc {

Version LibraryVersion() { return {DMC_VERSION_MAJOR, DMC_VERSION_MINOR, DMC_VERSION_PATCH}; }

const char* LibraryVersionString() { return DMC_VERSION_STRING; }

}  // namespace dmc
