// Text from untrusted bytes for writers that require UTF-8 (glTF's JSON, the CLI's --json): a
// stream's name is bytes (spec §3, "UTF-8 by convention; not checked"), and a file name or an OBJ
// comment can hold any byte.
#pragma once

#include <string>
#include <string_view>

namespace dmc::io_internal {

// `bytes` with every byte that does not belong to a well-formed UTF-8 sequence (RFC 3629: no
// overlong forms, no surrogates, nothing above U+10FFFF) replaced by U+FFFD; valid text is
// returned unchanged.
std::string ReplaceInvalidUtf8(std::string_view bytes);

}  // namespace dmc::io_internal
