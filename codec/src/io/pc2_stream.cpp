#include "io/pc2_stream.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <system_error>
#include <utility>

#include "dmc/io.h"
#include "io/file_ops.h"
#include "io/mesh_formats.h"

namespace dmc::io_internal {
namespace {

// Writes all of `bytes` to `fd`, retrying short writes; 0 or the errno of the failure.
int WriteAll(int fd, std::span<const uint8_t> bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t wrote = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) return wrote < 0 ? errno : EIO;
    done += static_cast<size_t>(wrote);
  }
  return 0;
}

std::span<const uint8_t> AsBytes(const fmt::memory_buffer& text) {
  return {reinterpret_cast<const uint8_t*>(text.data()), text.size()};
}

}  // namespace

// ---- StagedFile --------------------------------------------------------------------------------

StatusOr<StagedFile> StagedFile::Create(const std::filesystem::path& destination) {
  if (destination.empty() || !destination.has_filename()) {
    return InvalidArgumentError("cannot write to '" + destination.string() + "': not a file name");
  }
  DMC_RETURN_IF_ERROR(CheckParentDirectory(destination));
  TemporaryPath temporary(destination, TemporaryPath::Kind::kFile);
  const int fd = ::open(temporary.path().c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int error = errno;
    // Not ours: an existing file of that name is left alone.
    temporary.Release();
    return IoErrorFromErrno("cannot create", temporary.path(), error);
  }
  return StagedFile(destination, std::move(temporary), fd);
}

StagedFile::StagedFile(StagedFile&& other) noexcept
    : destination_(std::move(other.destination_)),
      temporary_(std::move(other.temporary_)),
      fd_(std::exchange(other.fd_, -1)),
      size_(other.size_),
      synced_(other.synced_) {}

StagedFile& StagedFile::operator=(StagedFile&& other) noexcept {
  if (this != &other) {
    Discard();
    destination_ = std::move(other.destination_);
    temporary_ = std::move(other.temporary_);
    fd_ = std::exchange(other.fd_, -1);
    size_ = other.size_;
    synced_ = other.synced_;
  }
  return *this;
}

StagedFile::~StagedFile() { Discard(); }

void StagedFile::Discard() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  temporary_.Abandon();
}

Status StagedFile::Append(std::span<const uint8_t> bytes) {
  if (fd_ < 0) return InternalError("StagedFile: append to a closed file");
  if (const int error = WriteAll(fd_, bytes); error != 0) {
    return IoErrorFromErrno("cannot write", destination_, error);
  }
  size_ += bytes.size();
  synced_ = false;
  return Status::Ok();
}

Status StagedFile::Sync() {
  if (fd_ < 0) return InternalError("StagedFile: sync of a closed file");
  if (!synced_ && ::fsync(fd_) != 0) return IoErrorFromErrno("cannot write", destination_, errno);
  synced_ = true;
  return Status::Ok();
}

Status StagedFile::Commit() {
  DMC_RETURN_IF_ERROR(Sync());
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) return IoErrorFromErrno("cannot write", destination_, errno);
  // RenameIntoPlace removes the temporary itself when it fails.
  DMC_RETURN_IF_ERROR(RenameIntoPlace(temporary_.path(), destination_));
  temporary_.Release();
  return Status::Ok();
}

// ---- Pc2FrameReader ----------------------------------------------------------------------------

StatusOr<Pc2FrameReader> Pc2FrameReader::Open(const std::filesystem::path& path) {
  DMC_ASSIGN_OR_RETURN(const Pc2Header header, ReadPc2Header(path));
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return IoErrorFromErrno("cannot open", path, errno);
  return Pc2FrameReader(path, header, fd);
}

Pc2FrameReader::Pc2FrameReader(Pc2FrameReader&& other) noexcept
    : path_(std::move(other.path_)), header_(other.header_), fd_(std::exchange(other.fd_, -1)) {}

Pc2FrameReader& Pc2FrameReader::operator=(Pc2FrameReader&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    header_ = other.header_;
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

Pc2FrameReader::~Pc2FrameReader() {
  if (fd_ >= 0) ::close(fd_);
}

Status Pc2FrameReader::ReadFrames(int first, int count, float* out) const {
  if (first < 0 || count < 0 || first > header_.sample_count - count) {
    return InvalidArgumentError(fmt::format("{}: frames [{}, {}) are outside the cache's {} frames",
                                            path_.string(), first, first + count,
                                            header_.sample_count));
  }
  const uint64_t frame_bytes = static_cast<uint64_t>(header_.point_count) * 12u;
  const uint64_t offset = kPc2HeaderBytes + static_cast<uint64_t>(first) * frame_bytes;
  const uint64_t size = static_cast<uint64_t>(count) * frame_bytes;
  auto* target = reinterpret_cast<uint8_t*>(out);
  uint64_t done = 0;
  while (done < size) {
    const ssize_t got = ::pread(fd_, target + done, static_cast<size_t>(size - done),
                                static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return IoErrorFromErrno("cannot read", path_, errno);
    if (got == 0) {
      // The size was checked at Open: the file has been cut (or is being rewritten) since.
      const uint64_t cut_frame = first + done / frame_bytes;
      return ParseError(fmt::format(
          "{}: the file ends within frame {} (the header declares {} frames of {} points, {} "
          "bytes; it was truncated while being read)",
          path_.string(), cut_frame, header_.sample_count, header_.point_count,
          kPc2HeaderBytes + static_cast<uint64_t>(header_.sample_count) * frame_bytes));
    }
    done += static_cast<uint64_t>(got);
  }
  if constexpr (std::endian::native != std::endian::little) {
    const size_t values = static_cast<size_t>(size / 4);
    for (size_t i = 0; i < values; ++i) {
      out[i] = std::bit_cast<float>(LoadLittleEndian32(target + 4 * i));
    }
  }
  return Status::Ok();
}

// ---- Pc2PairWriter -----------------------------------------------------------------------------

StatusOr<Pc2PairWriter> Pc2PairWriter::Create(const std::filesystem::path& output, int vertex_count,
                                              int frame_count, Triangles triangles,
                                              double frame_rate) {
  if (vertex_count <= 0 || frame_count <= 0) {
    return InvalidArgumentError(fmt::format("cannot write {}: {} vertices and {} frames",
                                            output.string(), vertex_count, frame_count));
  }
  std::filesystem::path mesh_path = output;
  mesh_path.replace_extension(".obj");
  DMC_ASSIGN_OR_RETURN(StagedFile cache, StagedFile::Create(output));
  DMC_ASSIGN_OR_RETURN(StagedFile mesh, StagedFile::Create(mesh_path));
  DMC_RETURN_IF_ERROR(cache.Append(EncodePc2Header(vertex_count, frame_count)));
  return Pc2PairWriter(std::move(cache), std::move(mesh), vertex_count, frame_count,
                       std::move(triangles), frame_rate);
}

Status Pc2PairWriter::AppendFrames(const float* frames, int count) {
  if (count < 0 || count > frame_count_ - frames_written_) {
    return InvalidArgumentError(fmt::format("{}: {} more frames exceed the {} announced",
                                            cache_.destination().string(), count, frame_count_));
  }
  const size_t values = static_cast<size_t>(count) * static_cast<size_t>(vertex_count_) * 3;
  for (size_t i = 0; i < values; ++i) {
    if (!std::isfinite(frames[i])) {
      const size_t per_frame = static_cast<size_t>(vertex_count_) * 3;
      return InvalidSequenceError(
          fmt::format("cannot write {}: frame {}, vertex {}: coordinate {} is not finite",
                      cache_.destination().string(), frames_written_ + i / per_frame,
                      (i % per_frame) / 3, "xyz"[i % 3]));
    }
  }
  if (frames_written_ == 0 && count > 0) {
    fmt::memory_buffer text;
    AppendMeshText(MeshFormat::kObj, {frames, static_cast<size_t>(vertex_count_) * 3},
                   {triangles_.data(), static_cast<size_t>(triangles_.size())}, frame_rate_, text);
    DMC_RETURN_IF_ERROR(mesh_.Append(AsBytes(text)));
  }
  std::span<const uint8_t> bytes(reinterpret_cast<const uint8_t*>(frames), values * 4);
  if constexpr (std::endian::native != std::endian::little) {
    scratch_.resize(values * 4);
    for (size_t i = 0; i < values; ++i) {
      StoreLittleEndian32(std::bit_cast<uint32_t>(frames[i]), scratch_.data() + 4 * i);
    }
    bytes = scratch_;
  }
  DMC_RETURN_IF_ERROR(cache_.Append(bytes));
  frames_written_ += count;
  return Status::Ok();
}

Status Pc2PairWriter::Commit() {
  if (frames_written_ != frame_count_) {
    return InvalidArgumentError(fmt::format("{}: {} of the {} announced frames written",
                                            cache_.destination().string(), frames_written_,
                                            frame_count_));
  }
  // Both flushed before either is renamed: the pair appears complete or not at all (short of a
  // failing rename of the cache after the mesh's).
  DMC_RETURN_IF_ERROR(cache_.Sync());
  DMC_RETURN_IF_ERROR(mesh_.Sync());
  DMC_RETURN_IF_ERROR(mesh_.Commit());
  return cache_.Commit();
}

}  // namespace dmc::io_internal

namespace dmc {

StatusOr<std::filesystem::path> FindPc2Connectivity(const std::filesystem::path& cache) {
  for (const char* extension : {".obj", ".off", ".ply"}) {
    std::filesystem::path candidate = cache;
    candidate.replace_extension(extension);
    std::error_code error;
    if (std::filesystem::is_regular_file(candidate, error)) return candidate;
  }
  std::filesystem::path obj = cache;
  obj.replace_extension(".obj");
  return IoError(cache.string() + " needs a connectivity mesh: " + obj.string() +
                 " (or .off/.ply) does not exist; name one with --connectivity");
}

}  // namespace dmc
