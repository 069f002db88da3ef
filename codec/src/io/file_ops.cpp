// Atomic single-file writes: write a temporary sibling completely, then rename it over the target.
#include "io/file_ops.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <utility>

#include "dmc/io.h"

namespace dmc::io_internal {
namespace {

// ---- The registry of live temporaries ----------------------------------------------------------
//
// A fixed array of slots, so a signal handler can walk it without locks or allocation. A slot's
// word is generation << 8 | state; only its owner (the TemporaryPath) changes it after claiming it
// from kFree, and every change bumps the generation. The handler copies a live slot's paths and
// uses the copy only when the word is unchanged after copying (a seqlock), so a slot released and
// reclaimed by another thread meanwhile is never read torn. The handler never writes a slot.
constexpr uint64_t kFree = 0;
constexpr uint64_t kClaimed = 0xff;  // being filled in: not yet readable
constexpr int kRegistrySlots = 64;
constexpr size_t kRegistryPathBytes = PATH_MAX;  // including the terminating NUL

struct RegistrySlot {
  std::atomic<uint64_t> word{kFree};
  std::atomic<pid_t> owner{0};  // a forked child must not remove its parent's temporaries
  std::atomic<char> path[kRegistryPathBytes];
  std::atomic<char> destination[kRegistryPathBytes];  // kMovedAside only
};
static_assert(std::atomic<uint64_t>::is_always_lock_free &&
              std::atomic<char>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free);

RegistrySlot g_registry[kRegistrySlots];

uint64_t NextWord(uint64_t word, uint64_t state) { return (((word >> 8) + 1) << 8) | state; }

void StoreString(std::atomic<char>* target, const std::string& text) {
  for (size_t i = 0; i < text.size(); ++i) target[i].store(text[i], std::memory_order_relaxed);
  target[text.size()].store('\0', std::memory_order_relaxed);
}

void LoadString(const std::atomic<char>* source, char* out) {
  for (size_t i = 0; i < kRegistryPathBytes; ++i) {
    out[i] = source[i].load(std::memory_order_relaxed);
    if (out[i] == '\0') return;
  }
  out[kRegistryPathBytes - 1] = '\0';
}

// Claims a free slot and publishes the paths in it; -1 when every slot is taken or a path is too
// long (the temporary is then still removed on error paths, only not by a signal handler).
int Register(const std::string& path, const std::string& destination, TemporaryPath::Kind kind,
             uint64_t& word) {
  if (path.size() >= kRegistryPathBytes || destination.size() >= kRegistryPathBytes) return -1;
  for (int i = 0; i < kRegistrySlots; ++i) {
    RegistrySlot& slot = g_registry[i];
    uint64_t seen = slot.word.load(std::memory_order_relaxed);
    if ((seen & 0xff) != kFree) continue;
    const uint64_t claimed = NextWord(seen, kClaimed);
    if (!slot.word.compare_exchange_strong(seen, claimed, std::memory_order_relaxed)) continue;
    std::atomic_thread_fence(std::memory_order_release);
    StoreString(slot.path, path);
    StoreString(slot.destination, destination);
    slot.owner.store(::getpid(), std::memory_order_relaxed);
    word = NextWord(claimed, static_cast<uint64_t>(kind));
    slot.word.store(word, std::memory_order_release);
    return i;
  }
  return -1;
}

void SetSlotState(int slot, uint64_t& word, uint64_t state) {
  if (slot < 0) return;
  word = NextWord(word, state);
  g_registry[slot].word.store(word, std::memory_order_release);
}

// Async-signal-safe from here on: system calls on C strings, no allocation, errno preserved by
// the caller.

// Removes the files in `path`, then the directory. Entries are listed with getdents64 (opendir
// allocates, so it is not async-signal-safe); a pass can miss entries created or renamed while it
// lists, so rmdir's ENOTEMPTY gives another pass.
void RemoveFlatDirectory(const char* path) {
  for (int pass = 0; pass < 3; ++pass) {
    const int fd = ::open(path, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return;
    alignas(8) char entries[4096];
    for (;;) {
      const long got = ::syscall(SYS_getdents64, fd, entries, sizeof entries);
      if (got <= 0) break;
      // struct linux_dirent64: u64 d_ino, s64 d_off, u16 d_reclen, u8 d_type, char d_name[].
      constexpr size_t kReclenOffset = 16, kNameOffset = 19;
      for (long at = 0; at < got;) {
        uint16_t length = 0;
        std::memcpy(&length, entries + at + kReclenOffset, sizeof length);
        const char* name = entries + at + kNameOffset;
        const bool dots =
            name[0] == '.' && (name[1] == '\0' || (name[1] == '.' && name[2] == '\0'));
        if (!dots) ::unlinkat(fd, name, 0);
        if (length == 0) break;
        at += length;
      }
    }
    ::close(fd);
    if (::rmdir(path) == 0 || (errno != ENOTEMPTY && errno != EEXIST)) return;
  }
}

void RemoveTemporary(const char* path, TemporaryPath::Kind kind, const char* destination) {
  switch (kind) {
    case TemporaryPath::Kind::kFile:
      ::unlink(path);
      return;
    case TemporaryPath::Kind::kDirectory:
      RemoveFlatDirectory(path);
      return;
    case TemporaryPath::Kind::kMovedAside:
      // Put the old output back; when the new one is already in place (rename refuses to replace
      // a non-empty directory), the old one is what is left to remove.
      if (std::rename(path, destination) == 0) return;
      if (errno == ENOTEMPTY || errno == EEXIST) RemoveFlatDirectory(path);
      return;
  }
}

std::string TemporaryName(const std::filesystem::path& destination) {
  static std::atomic<uint64_t> counter{0};
  return fmt::format(".{}.dmc-tmp-{}-{}", destination.filename().string(), ::getpid(), counter++);
}

}  // namespace

// ---- TemporaryPath -----------------------------------------------------------------------------

TemporaryPath::TemporaryPath(const std::filesystem::path& destination, Kind kind)
    : path_(destination.parent_path() / TemporaryName(destination)),
      destination_(kind == Kind::kMovedAside ? destination : std::filesystem::path()),
      kind_(kind),
      active_(true) {
  slot_ = Register(path_.string(), destination_.string(), kind_, word_);
}

TemporaryPath::TemporaryPath(TemporaryPath&& other) noexcept
    : path_(std::move(other.path_)),
      destination_(std::move(other.destination_)),
      kind_(other.kind_),
      slot_(std::exchange(other.slot_, -1)),
      word_(other.word_),
      active_(std::exchange(other.active_, false)) {}

TemporaryPath& TemporaryPath::operator=(TemporaryPath&& other) noexcept {
  if (this != &other) {
    Abandon();
    path_ = std::move(other.path_);
    destination_ = std::move(other.destination_);
    kind_ = other.kind_;
    slot_ = std::exchange(other.slot_, -1);
    word_ = other.word_;
    active_ = std::exchange(other.active_, false);
  }
  return *this;
}

TemporaryPath::~TemporaryPath() { Abandon(); }

void TemporaryPath::Release() {
  if (!active_) return;
  SetSlotState(slot_, word_, kFree);
  slot_ = -1;
  active_ = false;
}

void TemporaryPath::RemoveInsteadOfRestoring() {
  if (kind_ != Kind::kMovedAside) return;
  kind_ = Kind::kDirectory;
  if (active_) SetSlotState(slot_, word_, static_cast<uint64_t>(kind_));
}

void TemporaryPath::Abandon() {
  if (!active_) return;
  // Removed before unregistering, so a signal in between finds it still listed.
  RemoveTemporary(path_.c_str(), kind_, destination_.c_str());
  Release();
}

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
  io_internal::TemporaryPath temporary(path, io_internal::TemporaryPath::Kind::kFile);
  DMC_RETURN_IF_ERROR(io_internal::WriteNewFile(temporary.path(), bytes, /*sync=*/true));
  DMC_RETURN_IF_ERROR(io_internal::RenameIntoPlace(temporary.path(), path));
  temporary.Release();
  return Status::Ok();
}

void RemoveTemporaryFiles() noexcept {
  using io_internal::g_registry;
  const int saved_errno = errno;
  const pid_t self = ::getpid();
  char path[io_internal::kRegistryPathBytes];
  char destination[io_internal::kRegistryPathBytes];
  for (io_internal::RegistrySlot& slot : g_registry) {
    // A slot changing while it is copied is read again; its owner changes it a few times at most.
    for (int attempt = 0; attempt < 4; ++attempt) {
      const uint64_t before = slot.word.load(std::memory_order_acquire);
      const uint64_t state = before & 0xff;
      if (state == io_internal::kFree || state == io_internal::kClaimed) break;
      if (slot.owner.load(std::memory_order_relaxed) != self) break;
      io_internal::LoadString(slot.path, path);
      io_internal::LoadString(slot.destination, destination);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (slot.word.load(std::memory_order_relaxed) != before) continue;
      io_internal::RemoveTemporary(path, static_cast<io_internal::TemporaryPath::Kind>(state),
                                   destination);
      break;
    }
  }
  errno = saved_errno;
}

namespace {

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};
struct sigaction g_previous_actions[std::size(kCleanupSignals)];

extern "C" void RemoveTemporariesAndReraise(int signal_number) {
  RemoveTemporaryFiles();
  for (size_t i = 0; i < std::size(kCleanupSignals); ++i) {
    if (kCleanupSignals[i] == signal_number) {
      ::sigaction(signal_number, &g_previous_actions[i], nullptr);
    }
  }
  // Blocked while this handler runs: delivered, under the restored disposition, when it returns.
  ::raise(signal_number);
}

}  // namespace

Status InstallTemporaryFileCleanupOnSignals() {
  static std::mutex mutex;
  static bool installed = false;
  const std::lock_guard<std::mutex> lock(mutex);
  if (installed) return Status::Ok();
  struct sigaction action {};
  action.sa_handler = RemoveTemporariesAndReraise;
  sigemptyset(&action.sa_mask);
  for (const int signal_number : kCleanupSignals) sigaddset(&action.sa_mask, signal_number);
  action.sa_flags = SA_RESTART;
  for (size_t i = 0; i < std::size(kCleanupSignals); ++i) {
    struct sigaction& previous = g_previous_actions[i];
    if (::sigaction(kCleanupSignals[i], &action, &previous) != 0) {
      return InternalError(std::string("cannot install a handler for ") +
                           ::strsignal(kCleanupSignals[i]) + ": " + std::strerror(errno));
    }
    // An ignored signal (nohup) stays ignored; if it comes in between, the handler restores
    // SIG_IGN and the re-raised signal is ignored as before.
    if (!(previous.sa_flags & SA_SIGINFO) && previous.sa_handler == SIG_IGN) {
      ::sigaction(kCleanupSignals[i], &previous, nullptr);
    }
  }
  installed = true;
  return Status::Ok();
}

}  // namespace dmc
