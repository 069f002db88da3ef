// Internal: file I/O for the streaming encoder and decoder, which never hold a whole sequence.
//
//  - StagedFile: an output written piece by piece under a temporary name beside its destination
//    and renamed into place only when complete, so a failure (or a crash) never leaves a
//    half-written file under the destination's name and never destroys an existing one.
//  - Pc2FrameReader: random access to the frames of a PC2 point cache (layout in pc2_format.h)
//    without reading the rest of it.
//  - Pc2PairWriter: writes a PC2 cache and its connectivity mesh frame block by frame block; the
//    files are byte for byte those WriteSequence writes for the same sequence.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/status.h"
#include "io/file_ops.h"
#include "io/pc2_format.h"

namespace dmc::io_internal {

class StagedFile {
 public:
  // Checks that the destination's directory exists and creates the temporary sibling
  // (TemporaryPath) exclusively. kIoError naming the path when either fails.
  static StatusOr<StagedFile> Create(const std::filesystem::path& destination);

  StagedFile(StagedFile&& other) noexcept;
  StagedFile& operator=(StagedFile&& other) noexcept;
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  // An uncommitted file is closed and its temporary removed.
  ~StagedFile();

  // Appends `bytes` at the end. kIoError naming the destination (disk full, ...).
  Status Append(std::span<const uint8_t> bytes);
  // Flushes the content to disk (fsync), so that Commit's rename publishes complete data.
  Status Sync();
  // Sync, close and rename over the destination (keeping an existing file's permissions). After a
  // failure the temporary is removed. Appending after Commit is an error.
  Status Commit();

  const std::filesystem::path& destination() const { return destination_; }
  uint64_t size() const { return size_; }

 private:
  StagedFile(std::filesystem::path destination, TemporaryPath temporary, int fd)
      : destination_(std::move(destination)), temporary_(std::move(temporary)), fd_(fd) {}
  void Discard();

  std::filesystem::path destination_;
  TemporaryPath temporary_;
  int fd_ = -1;
  uint64_t size_ = 0;
  bool synced_ = false;
};

class Pc2FrameReader {
 public:
  // Opens `path` and checks its header against the file's size (ReadPc2Header's errors).
  static StatusOr<Pc2FrameReader> Open(const std::filesystem::path& path);

  Pc2FrameReader(Pc2FrameReader&& other) noexcept;
  Pc2FrameReader& operator=(Pc2FrameReader&& other) noexcept;
  Pc2FrameReader(const Pc2FrameReader&) = delete;
  Pc2FrameReader& operator=(const Pc2FrameReader&) = delete;
  ~Pc2FrameReader();

  const Pc2Header& header() const { return header_; }
  const std::filesystem::path& path() const { return path_; }

  // Reads samples [first, first + count) into `out` (count × points × 3 floats, sample after
  // sample). kInvalidArgument for a range outside [0, sample_count); kParseError
  // "<path>: the file ends within frame N (...)" when the file has been cut since Open;
  // kIoError when the system refuses the read.
  Status ReadFrames(int first, int count, float* out) const;

 private:
  Pc2FrameReader(std::filesystem::path path, Pc2Header header, int fd)
      : path_(std::move(path)), header_(header), fd_(fd) {}

  std::filesystem::path path_;
  Pc2Header header_;
  int fd_ = -1;
};

class Pc2PairWriter {
 public:
  // Starts writing `output` (.pc2, startFrame 0, sampleRate 1, `frame_count` samples of
  // `vertex_count` points) and <output stem>.obj beside it (the triangles, frame 0's positions and
  // `frame_rate` when > 0), both as StagedFiles. frame_count must be positive.
  static StatusOr<Pc2PairWriter> Create(const std::filesystem::path& output, int vertex_count,
                                        int frame_count, Triangles triangles, double frame_rate);

  // Appends the next `count` frames (count × V × 3 floats). The first call also writes the mesh
  // file from the first frame. kInvalidSequence naming the frame and vertex for a non-finite
  // coordinate; kInvalidArgument for more frames than announced.
  Status AppendFrames(const float* frames, int count);

  // After all announced frames: flushes both files and renames them into place, the mesh first
  // (so a cache never appears beside a stale mesh of another vertex count), as WriteSequence does.
  // kInvalidArgument when frames are missing.
  Status Commit();

  int frames_written() const { return frames_written_; }

 private:
  Pc2PairWriter(StagedFile cache, StagedFile mesh, int vertex_count, int frame_count,
                Triangles triangles, double frame_rate)
      : cache_(std::move(cache)),
        mesh_(std::move(mesh)),
        vertex_count_(vertex_count),
        frame_count_(frame_count),
        triangles_(std::move(triangles)),
        frame_rate_(frame_rate) {}

  StagedFile cache_;
  StagedFile mesh_;
  int vertex_count_;
  int frame_count_;
  Triangles triangles_;
  double frame_rate_;
  int frames_written_ = 0;
  std::vector<uint8_t> scratch_;  // little-endian bytes of the frames being appended
};

}  // namespace dmc::io_internal
