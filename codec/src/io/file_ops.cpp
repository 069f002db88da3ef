// Atomic single-file writes: write a temporary sibling completely, then rename it over the target.
#include "io/file_ops.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "dmc/io.h"

namespace dmc::io_internal {

Status IoErrorFromErrno(const std::string& what, const std::filesystem::path& path, int error) {
  return IoError(what + " " + path.string() + ": " + std::strerror(error));
}

Status CheckParentDirectory(const std::filesystem::path& path) {
  const std::filesystem::path parent = path.parent_path();
  if (parent.empty()) return Status::Ok();
  struct stat info {};
  if (::stat(parent.c_str(), &info) != 0) {
    return IoError("cannot write " + path.string() + ": the directory " + parent.string() +
                   " does not exist");
  }
  if (!S_ISDIR(info.st_mode)) {
    return IoError("cannot write " + path.string() + ": " + parent.string() +
                   " is not a directory");
  }
  return Status::Ok();
}

std::filesystem::path TemporarySibling(const std::filesystem::path& path) {
  static std::atomic<uint64_t> counter{0};
  return path.parent_path() /
         fmt::format(".{}.dmc-tmp-{}-{}", path.filename().string(), ::getpid(), counter++);
}

Status WriteNewFile(const std::filesystem::path& path, std::span<const uint8_t> bytes, bool sync) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) return IoErrorFromErrno("cannot create", path, errno);
  size_t done = 0;
  int error = 0;
  while (done < bytes.size()) {
    const ssize_t wrote = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      error = wrote < 0 ? errno : EIO;
      break;
    }
    done += static_cast<size_t>(wrote);
  }
  if (error == 0 && sync && ::fsync(fd) != 0) error = errno;
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    ::unlink(path.c_str());
    return IoErrorFromErrno("cannot write", path, error);
  }
  return Status::Ok();
}

Status RenameIntoPlace(const std::filesystem::path& from, const std::filesystem::path& to) {
  struct stat target {};
  if (::stat(to.c_str(), &target) == 0) {
    if (S_ISDIR(target.st_mode)) {
      ::unlink(from.c_str());
      return IoErrorFromErrno("cannot replace", to, EISDIR);
    }
    // Keep the permissions of the file being replaced.
    ::chmod(from.c_str(), target.st_mode & 07777);
  }
  if (std::rename(from.c_str(), to.c_str()) != 0) {
    const int error = errno;
    ::unlink(from.c_str());
    return IoErrorFromErrno("cannot rename a temporary file onto", to, error);
  }
  return Status::Ok();
}

}  // namespace dmc::io_internal

namespace dmc {

Status WriteFileAtomically(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  if (path.empty() || !path.has_filename()) {
    return InvalidArgumentError("cannot write to '" + path.string() + "': not a file name");
  }
  DMC_RETURN_IF_ERROR(io_internal::CheckParentDirectory(path));
  const std::filesystem::path temporary = io_internal::TemporarySibling(path);
  DMC_RETURN_IF_ERROR(io_internal::WriteNewFile(temporary, bytes, /*sync=*/true));
  return io_internal::RenameIntoPlace(temporary, path);
}

}  // namespace dmc
