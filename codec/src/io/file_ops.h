// Internal: the file-system steps behind atomic writes (temporary siblings, exclusive creation,
// rename into place). Never throw: every std::filesystem call uses the error_code overloads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "dmc/status.h"

namespace dmc::io_internal {

// A path beside `path`, in the same directory (so rename is atomic), that no other writer in this
// or another process uses: "<dir>/.<name>.dmc-tmp-<pid>-<counter>".
std::filesystem::path TemporarySibling(const std::filesystem::path& path);

// Creates `path`, which must not exist, and writes `bytes` to it; with `sync`, flushes it to disk
// before closing. On failure the partial file is removed.
Status WriteNewFile(const std::filesystem::path& path, std::span<const uint8_t> bytes, bool sync);

// Renames `from` over `to` (replacing a file, never a directory). On failure `from` is removed.
Status RenameIntoPlace(const std::filesystem::path& from, const std::filesystem::path& to);

// kIoError "cannot write <path>: the directory <parent> does not exist" (or is not a directory);
// outputs are never given missing parent directories implicitly.
Status CheckParentDirectory(const std::filesystem::path& path);

// "<what> <path>: <system reason>" as kIoError.
Status IoErrorFromErrno(const std::string& what, const std::filesystem::path& path, int error);

}  // namespace dmc::io_internal
