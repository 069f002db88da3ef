#include "io/pc2_format.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstring>
#include <vector>

#include "io/file_ops.h"

namespace dmc::io_internal {
namespace {

constexpr char kMagic[12] = {'P', 'O', 'I', 'N', 'T', 'C', 'A', 'C', 'H', 'E', '2', '\0'};

int32_t LoadInt32(const uint8_t* bytes) { return static_cast<int32_t>(LoadLittleEndian32(bytes)); }
float LoadFloat(const uint8_t* bytes) { return std::bit_cast<float>(LoadLittleEndian32(bytes)); }

// Reads exactly `size` bytes at `offset`.
Status ReadAt(int fd, const std::filesystem::path& path, uint64_t offset, void* out, size_t size) {
  auto* target = static_cast<uint8_t*>(out);
  size_t done = 0;
  while (done < size) {
    const ssize_t got = ::pread(fd, target + done, size - done, static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return IoErrorFromErrno("cannot read", path, errno);
    if (got == 0) return ParseError(path.string() + ": the file ends early");
    done += static_cast<size_t>(got);
  }
  return Status::Ok();
}

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

StatusOr<Pc2Header> ParsePc2Header(const uint8_t* bytes, size_t size, uint64_t file_size) {
  if (size < kPc2HeaderBytes) {
    return ParseError("the file has " + std::to_string(size) + " bytes, less than the " +
                      std::to_string(kPc2HeaderBytes) + "-byte PC2 header");
  }
  if (std::memcmp(bytes, kMagic, sizeof(kMagic)) != 0) {
    return ParseError("not a PC2 point cache (the first 12 bytes are not \"POINTCACHE2\\0\")");
  }
  const int32_t version = LoadInt32(bytes + 12);
  if (version != 1) {
    return UnsupportedError("PC2 version " + std::to_string(version) + " (only 1 is defined)");
  }
  Pc2Header header;
  header.point_count = LoadInt32(bytes + 16);
  header.start_frame = LoadFloat(bytes + 20);
  header.sample_rate = LoadFloat(bytes + 24);
  header.sample_count = LoadInt32(bytes + 28);
  if (header.point_count <= 0 || header.sample_count < 0) {
    return ParseError("the header declares " + std::to_string(header.point_count) + " points and " +
                      std::to_string(header.sample_count) +
                      " samples; points must be positive and samples not negative");
  }
  // 64-bit arithmetic: int32 x int32 x 12 cannot overflow it.
  const uint64_t expected = kPc2HeaderBytes + static_cast<uint64_t>(header.point_count) *
                                                  static_cast<uint64_t>(header.sample_count) * 12u;
  if (expected != file_size) {
    return ParseError("the header declares " + std::to_string(header.sample_count) +
                      " samples of " + std::to_string(header.point_count) + " points (" +
                      std::to_string(expected) + " bytes) but the file has " +
                      std::to_string(file_size) + " bytes" +
                      (file_size < expected ? " (truncated)" : ""));
  }
  return header;
}

StatusOr<Pc2Header> ReadPc2Header(const std::filesystem::path& path) {
  const FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.get() < 0) return IoErrorFromErrno("cannot open", path, errno);
  struct stat info {};
  if (::fstat(file.get(), &info) != 0) return IoErrorFromErrno("cannot stat", path, errno);
  if (!S_ISREG(info.st_mode)) return IoError("cannot read " + path.string() + ": not a file");
  const uint64_t file_size = static_cast<uint64_t>(info.st_size);
  uint8_t bytes[kPc2HeaderBytes] = {};
  const size_t available = file_size < kPc2HeaderBytes ? file_size : kPc2HeaderBytes;
  DMC_RETURN_IF_ERROR(ReadAt(file.get(), path, 0, bytes, available));
  StatusOr<Pc2Header> header = ParsePc2Header(bytes, available, file_size);
  if (!header.ok()) return header.status().WithContext(path.string());
  return header;
}

std::array<uint8_t, kPc2HeaderBytes> EncodePc2Header(int point_count, int sample_count) {
  std::array<uint8_t, kPc2HeaderBytes> header{};
  std::memcpy(header.data(), kMagic, sizeof(kMagic));
  StoreLittleEndian32(1, header.data() + 12);
  StoreLittleEndian32(static_cast<uint32_t>(point_count), header.data() + 16);
  StoreLittleEndian32(std::bit_cast<uint32_t>(0.0f), header.data() + 20);  // startFrame
  StoreLittleEndian32(std::bit_cast<uint32_t>(1.0f), header.data() + 24);  // sampleRate
  StoreLittleEndian32(static_cast<uint32_t>(sample_count), header.data() + 28);
  return header;
}

std::string EncodePc2(const MeshSequence& sequence) {
  const size_t value_count = sequence.position_value_count();
  const auto header = EncodePc2Header(sequence.vertex_count(), sequence.frame_count());
  std::string out(kPc2HeaderBytes + value_count * 4, '\0');
  std::memcpy(out.data(), header.data(), kPc2HeaderBytes);
  auto* samples = reinterpret_cast<uint8_t*>(out.data() + kPc2HeaderBytes);
  const float* values = sequence.data();
  for (size_t i = 0; i < value_count; ++i) {
    StoreLittleEndian32(std::bit_cast<uint32_t>(values[i]), samples + 4 * i);
  }
  return out;
}

}  // namespace dmc::io_internal
