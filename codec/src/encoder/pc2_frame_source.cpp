// OpenPc2FrameSource: a PC2 point cache as the streaming encoder's FrameSource.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "dmc/encoder.h"
#include "dmc/io.h"
#include "io/pc2_stream.h"

namespace dmc {
namespace {

class Pc2FrameSource final : public FrameSource {
 public:
  Pc2FrameSource(io_internal::Pc2FrameReader reader, Triangles triangles, double frame_rate,
                 std::string name)
      : reader_(std::move(reader)),
        triangles_(std::move(triangles)),
        frame_rate_(frame_rate),
        name_(std::move(name)) {}

  int vertex_count() const override { return reader_.header().point_count; }
  int frame_count() const override { return reader_.header().sample_count; }
  const Triangles& triangles() const override { return triangles_; }
  double frame_rate() const override { return frame_rate_; }
  const std::string& name() const override { return name_; }

  Status ReadFrames(int first, int count, float* out) override {
    DMC_RETURN_IF_ERROR(reader_.ReadFrames(first, count, out));
    // ReadSequence's check of a cache, worded as it words it.
    const size_t per_frame = static_cast<size_t>(vertex_count()) * 3;
    const size_t values = per_frame * static_cast<size_t>(count);
    for (size_t i = 0; i < values; ++i) {
      if (!std::isfinite(out[i])) {
        return InvalidSequenceError("frame " + std::to_string(first + i / per_frame) + " (" +
                                    reader_.path().string() + "), vertex " +
                                    std::to_string((i % per_frame) / 3) + ": coordinate " +
                                    "xyz"[i % 3] + " is not finite");
      }
    }
    return Status::Ok();
  }

 private:
  io_internal::Pc2FrameReader reader_;
  Triangles triangles_;
  double frame_rate_;
  std::string name_;
};

}  // namespace

StatusOr<std::unique_ptr<FrameSource>> OpenPc2FrameSource(const std::filesystem::path& cache,
                                                          const std::filesystem::path& connectivity,
                                                          std::vector<std::string>* warnings) {
  DMC_ASSIGN_OR_RETURN(io_internal::Pc2FrameReader reader,
                       io_internal::Pc2FrameReader::Open(cache));
  std::filesystem::path mesh_path = connectivity;
  if (mesh_path.empty()) {
    DMC_ASSIGN_OR_RETURN(mesh_path, FindPc2Connectivity(cache));
  }
  // The mesh as a one-frame sequence: triangles checked against its vertex count, warnings
  // (fan triangulation, degenerate triangles) worded as ReadSequence words them.
  ReadReport mesh_report;
  DMC_ASSIGN_OR_RETURN(MeshSequence mesh, ReadSequence(mesh_path, {}, &mesh_report));
  const io_internal::Pc2Header& header = reader.header();
  if (mesh.vertex_count() != header.point_count) {
    return MismatchError(cache.string() + ": " + std::to_string(header.point_count) +
                         " points, but the connectivity mesh " + mesh_path.string() + " has " +
                         std::to_string(mesh.vertex_count()) + " vertices");
  }
  if (warnings) {
    warnings->insert(warnings->end(), mesh_report.warnings.begin(), mesh_report.warnings.end());
  }
  // sampleRate is the spacing of samples in scene frames; the mesh carries the scene's rate when
  // dmc wrote the pair (ReadSequence's rule).
  double frame_rate = 0.0;
  if (mesh.frame_rate > 0.0 && std::isfinite(header.sample_rate) && header.sample_rate > 0.0f) {
    frame_rate = mesh.frame_rate / static_cast<double>(header.sample_rate);
  }
  return std::unique_ptr<FrameSource>(std::make_unique<Pc2FrameSource>(
      std::move(reader), mesh.triangles(), frame_rate, cache.stem().string()));
}

}  // namespace dmc
