#include "arrays.h"

#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

#include "errors.h"

namespace dmc::python {
namespace {

// "(4, 3)" for an array of that shape.
std::string ShapeString(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t axis = 0; axis < array.ndim(); ++axis) {
    if (axis > 0) text += ", ";
    text += std::to_string(array.shape(axis));
  }
  return text + (array.ndim() == 1 ? ",)" : ")");
}

std::string DtypeString(const py::array& array) {
  return py::str(array.dtype()).cast<std::string>();
}

// numpy.asarray(object); a failure (ragged nested lists, ...) becomes INVALID_ARGUMENT.
py::array AsArray(const py::handle& object, std::string_view name) {
  try {
    return py::module_::import("numpy").attr("asarray")(object);
  } catch (py::error_already_set& error) {
    ThrowInvalidArgument(
        fmt::format("{} cannot be converted to a NumPy array: {}", name, error.what()));
  }
}

// Capsule deleting a heap object of type T when the last array viewing it goes away.
template <typename T>
py::capsule OwningCapsule(std::unique_ptr<T> owned) {
  return py::capsule(owned.release(), [](void* pointer) { delete static_cast<T*>(pointer); });
}

Triangles FacesFromArray(const py::handle& faces_object) {
  const py::array faces = AsArray(faces_object, "faces");
  if (faces.ndim() != 2 || faces.shape(1) != 3) {
    ThrowInvalidArgument(
        fmt::format("faces must have shape (T, 3) (one row of 3 vertex indices per triangle), "
                    "got shape {}",
                    ShapeString(faces)));
  }
  const char kind = faces.dtype().kind();
  if (kind != 'i' && kind != 'u') {
    ThrowInvalidArgument(
        fmt::format("faces must hold integers (vertex indices), got dtype {}", DtypeString(faces)));
  }
  const py::ssize_t triangle_count = faces.shape(0);
  if (triangle_count > std::numeric_limits<int32_t>::max()) {
    ThrowInvalidArgument(
        fmt::format("faces has {} rows, more than int32 can index", triangle_count));
  }
  Triangles triangles(triangle_count, 3);
  if (triangle_count == 0) return triangles;
  if (faces.dtype().is(py::dtype::of<int32_t>())) {
    // The common case: one memcpy out of a C-contiguous int32 array (converted if strided).
    const auto contiguous =
        py::array_t<int32_t, py::array::c_style | py::array::forcecast>::ensure(faces);
    std::memcpy(triangles.data(), contiguous.data(), sizeof(int32_t) * triangle_count * 3);
    return triangles;
  }
  // Any other integer type: widen to int64 (exact for every signed type; uint64 beyond 2^63
  // becomes negative and is caught below as out of range, never wrapped into a valid index).
  const auto wide = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(faces);
  const int64_t* values = wide.data();
  for (py::ssize_t k = 0; k < triangle_count * 3; ++k) {
    if (values[k] < std::numeric_limits<int32_t>::min() ||
        values[k] > std::numeric_limits<int32_t>::max()) {
      ThrowInvalidArgument(
          fmt::format("faces[{}, {}] = {} does not fit int32", k / 3, k % 3, values[k]));
    }
    triangles.data()[k] = static_cast<int32_t>(values[k]);
  }
  return triangles;
}

}  // namespace

MeshSequence SequenceFromArrays(const py::handle& frames_object, const py::handle& faces_object,
                                std::string_view frames_name) {
  const py::array frames = AsArray(frames_object, frames_name);
  if (!((frames.ndim() == 3 && frames.shape(2) == 3) ||
        (frames.ndim() == 2 && frames.shape(1) == 3))) {
    ThrowInvalidArgument(fmt::format(
        "{} must have shape (F, V, 3) (frames x vertices x xyz) or (V, 3) (one frame), got "
        "shape {}",
        frames_name, ShapeString(frames)));
  }
  const char kind = frames.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    ThrowInvalidArgument(fmt::format("{} must hold real numbers (float32 preferred), got dtype {}",
                                     frames_name, DtypeString(frames)));
  }
  const py::ssize_t frame_count = frames.ndim() == 3 ? frames.shape(0) : 1;
  const py::ssize_t vertex_count = frames.ndim() == 3 ? frames.shape(1) : frames.shape(0);
  constexpr py::ssize_t kIntMax = std::numeric_limits<int>::max();
  if (vertex_count > kIntMax / 3 || frame_count > kIntMax ||
      (vertex_count > 0 &&
       frame_count > std::numeric_limits<py::ssize_t>::max() / (3 * vertex_count))) {
    ThrowInvalidArgument(
        fmt::format("{} of shape {} is too large", frames_name, ShapeString(frames)));
  }
  MeshSequence sequence(static_cast<int>(vertex_count), FacesFromArray(faces_object),
                        static_cast<int>(frame_count));
  // float32 C-contiguous arrays pass through ensure() untouched; others are converted once.
  const auto positions =
      py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(frames);
  if (!positions) throw py::error_already_set();
  if (sequence.position_value_count() > 0) {
    std::memcpy(sequence.data(), positions.data(), sizeof(float) * sequence.position_value_count());
  }
  return sequence;
}

void ValidateOrThrow(const MeshSequence& sequence) { ThrowIfError(ValidateSequence(sequence)); }

py::tuple SequenceToArrays(MeshSequence&& sequence) {
  auto owned = std::make_unique<MeshSequence>(std::move(sequence));
  const MeshSequence& kept = *owned;
  const py::ssize_t frame_count = kept.frame_count(), vertex_count = kept.vertex_count(),
                    triangle_count = kept.triangle_count();
  float* positions = owned->data();
  int32_t* triangles = owned->mutable_triangles().data();
  const py::capsule owner = OwningCapsule(std::move(owned));
  py::array_t<float> frames({frame_count, vertex_count, py::ssize_t{3}}, positions, owner);
  py::array_t<int32_t> faces({triangle_count, py::ssize_t{3}}, triangles, owner);
  return py::make_tuple(std::move(frames), std::move(faces));
}

py::tuple CsrArrays(const Eigen::SparseMatrix<double>& matrix) {
  using RowMajorMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int32_t>;
  auto owned = std::make_unique<RowMajorMatrix>(matrix);
  owned->makeCompressed();
  const py::ssize_t rows = owned->rows(), nonzeros = owned->nonZeros();
  double* values = owned->valuePtr();
  int32_t* columns = owned->innerIndexPtr();
  int32_t* row_starts = owned->outerIndexPtr();
  const py::capsule owner = OwningCapsule(std::move(owned));
  py::array_t<double> data({nonzeros}, values, owner);
  py::array_t<int32_t> indices({nonzeros}, columns, owner);
  py::array_t<int32_t> indptr({rows + 1}, row_starts, owner);
  return py::make_tuple(std::move(data), std::move(indices), std::move(indptr));
}

py::array_t<double> VectorToArray(const Eigen::VectorXd& values) {
  py::array_t<double> array(values.size());
  if (values.size() > 0)
    std::memcpy(array.mutable_data(), values.data(), sizeof(double) * values.size());
  return array;
}

}  // namespace dmc::python
