// Internal: the file-system steps behind atomic writes (temporary siblings, exclusive creation,
// rename into place). Never throw: every std::filesystem call uses the error_code overloads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "dmc/status.h"

namespace dmc::io_internal {

// A temporary beside `destination`, in the same directory (so rename is atomic), under a name no
// other writer in this or another process uses: "<dir>/.<name>.dmc-tmp-<pid>-<counter>". It is
// listed in the process-wide registry that RemoveTemporaryFiles (dmc/io.h) walks, from before it
// is created until it has been renamed into place or removed, so a signal handler can remove it.
// The destructor removes what is still there (every error path, exceptions included) unless
// Release was called. Creating the file or directory is the caller's job.
class TemporaryPath {
 public:
  enum class Kind : uint8_t {
    kFile = 1,
    kDirectory = 2,  // holds only files (the frame files being written)
    // An existing output directory moved aside while its replacement is renamed in: abandoned,
    // it is renamed back onto `destination`, or removed when `destination` exists again.
    kMovedAside = 3,
  };
  TemporaryPath(const std::filesystem::path& destination, Kind kind);
  TemporaryPath(TemporaryPath&& other) noexcept;
  TemporaryPath& operator=(TemporaryPath&& other) noexcept;
  TemporaryPath(const TemporaryPath&) = delete;
  TemporaryPath& operator=(const TemporaryPath&) = delete;
  ~TemporaryPath();

  const std::filesystem::path& path() const { return path_; }

  // The temporary has been renamed into place: nothing is left to remove.
  void Release();
  // kMovedAside only: the replacement is in place, so the old content is removed, not restored.
  void RemoveInsteadOfRestoring();
  // Removes the temporary now (as the destructor would) and unregisters it.
  void Abandon();

 private:
  std::filesystem::path path_;
  std::filesystem::path destination_;
  Kind kind_ = Kind::kFile;
  int slot_ = -1;  // registry slot, -1 when the registry was full or the path too long
  uint64_t word_ = 0;
  bool active_ = false;
};

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
