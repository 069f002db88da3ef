// Selections: the JSON and plain index-list forms, validation and handle transforms.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <set>
#include <sstream>

#include "dmc/processing.h"

namespace dmc {
namespace {

StatusOr<std::vector<int32_t>> IndexList(const nlohmann::json& value, std::string_view key) {
  if (!value.is_array()) {
    return ParseError(fmt::format("selection: \"{}\" must be an array of vertex indices", key));
  }
  std::vector<int32_t> indices;
  indices.reserve(value.size());
  for (size_t k = 0; k < value.size(); ++k) {
    const nlohmann::json& element = value[k];
    if (!element.is_number_integer()) {
      return ParseError(fmt::format("selection: \"{}\"[{}] is not an integer", key, k));
    }
    const int64_t index = element.get<int64_t>();
    if (index < 0 || index > INT32_MAX) {
      return InvalidArgumentError(
          fmt::format("selection: \"{}\"[{}] = {} is not a vertex index", key, k, index));
    }
    indices.push_back(static_cast<int32_t>(index));
  }
  return indices;
}

// Sorts and de-duplicates `indices`, carrying `weights` (when non-empty) along; a duplicated
// index keeps its first weight.
void SortUnique(std::vector<int32_t>& indices, std::vector<double>* weights) {
  std::vector<size_t> order(indices.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return indices[a] < indices[b]; });
  std::vector<int32_t> sorted;
  std::vector<double> sorted_weights;
  for (size_t k : order) {
    if (!sorted.empty() && sorted.back() == indices[k]) continue;
    sorted.push_back(indices[k]);
    if (weights != nullptr && !weights->empty()) sorted_weights.push_back((*weights)[k]);
  }
  indices = std::move(sorted);
  if (weights != nullptr && !weights->empty()) *weights = std::move(sorted_weights);
}

Status CheckRange(const std::vector<int32_t>& indices, std::string_view what, int vertex_count) {
  for (int32_t index : indices) {
    if (index < 0 || index >= vertex_count) {
      return InvalidArgumentError(
          fmt::format("selection: {} vertex {} is outside [0, {})", what, index, vertex_count));
    }
  }
  return Status::Ok();
}

}  // namespace

StatusOr<Selection> ParseSelectionJson(std::string_view text) {
  const nlohmann::json document = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded()) return ParseError("selection: malformed JSON");
  if (!document.is_object()) return ParseError("selection: the JSON document must be an object");
  Selection selection;
  for (const auto& [key, value] : document.items()) {
    if (key == "handles") {
      DMC_ASSIGN_OR_RETURN(selection.handles, IndexList(value, key));
    } else if (key == "fixed") {
      DMC_ASSIGN_OR_RETURN(selection.fixed, IndexList(value, key));
    } else if (key == "anchors") {
      DMC_ASSIGN_OR_RETURN(selection.anchors, IndexList(value, key));
    } else if (key == "free") {
      DMC_ASSIGN_OR_RETURN(selection.free, IndexList(value, key));
    } else if (key == "weights") {
      if (!value.is_array()) return ParseError("selection: \"weights\" must be an array");
      for (size_t k = 0; k < value.size(); ++k) {
        if (!value[k].is_number()) {
          return ParseError(fmt::format("selection: \"weights\"[{}] is not a number", k));
        }
        selection.handle_weights.push_back(value[k].get<double>());
      }
    } else if (key == "transform") {
      if (!value.is_array() || value.size() != 16) {
        return InvalidArgumentError(
            "selection: \"transform\" must be an array of 16 numbers (row-major 4x4)");
      }
      for (int k = 0; k < 16; ++k) {
        if (!value[k].is_number() || !std::isfinite(value[k].get<double>())) {
          return InvalidArgumentError(
              fmt::format("selection: \"transform\"[{}] is not a finite number", k));
        }
        selection.transform(k / 4, k % 4) = value[k].get<double>();
      }
    } else {
      return InvalidArgumentError(fmt::format(
          "selection: unknown key \"{}\" (known: handles, fixed, free, anchors, weights, "
          "transform)",
          key));
    }
  }
  if (selection.free.has_value() && document.contains("fixed")) {
    return InvalidArgumentError(
        "selection: give either \"fixed\" or \"free\" (the rest is then fixed), not both");
  }
  return selection;
}

StatusOr<Selection> ReadSelectionFile(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return IoError(fmt::format("cannot open selection file {}", path.string()));
  std::stringstream buffer;
  buffer << file.rdbuf();
  if (file.bad()) return IoError(fmt::format("cannot read selection file {}", path.string()));
  const std::string text = buffer.str();
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '{') {
    StatusOr<Selection> parsed = ParseSelectionJson(text);
    if (!parsed.ok()) return parsed.status().WithContext(path.string());
    return parsed;
  }
  // Plain list: whitespace-separated non-negative integers, '#' comments.
  Selection selection;
  std::istringstream lines(text);
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream tokens(line);
    std::string token;
    while (tokens >> token) {
      const bool digits =
          std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (!digits || token.size() > 10 || std::stoll(token) > INT32_MAX) {
        return ParseError(
            fmt::format("{}:{}: '{}' is not a vertex index", path.string(), line_number, token));
      }
      selection.handles.push_back(static_cast<int32_t>(std::stoll(token)));
    }
  }
  return selection;
}

Status ValidateSelection(Selection& selection, int vertex_count) {
  if (!selection.handle_weights.empty() &&
      selection.handle_weights.size() != selection.handles.size()) {
    return InvalidArgumentError(fmt::format("selection: {} weights for {} handles",
                                            selection.handle_weights.size(),
                                            selection.handles.size()));
  }
  for (double weight : selection.handle_weights) {
    if (!(weight > 0.0) || !std::isfinite(weight)) {
      return InvalidArgumentError(
          fmt::format("selection: handle weight {} is not a finite positive number", weight));
    }
  }
  if (!selection.transform.allFinite()) {
    return InvalidArgumentError("selection: the transform is not finite");
  }
  if (selection.transform.row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)) {
    return InvalidArgumentError("selection: the transform's last row must be 0 0 0 1 (affine)");
  }
  DMC_RETURN_IF_ERROR(CheckRange(selection.handles, "handle", vertex_count));
  DMC_RETURN_IF_ERROR(CheckRange(selection.fixed, "fixed", vertex_count));
  DMC_RETURN_IF_ERROR(CheckRange(selection.anchors, "anchor", vertex_count));
  SortUnique(selection.handles, &selection.handle_weights);
  if (selection.free.has_value()) {
    DMC_RETURN_IF_ERROR(CheckRange(*selection.free, "free", vertex_count));
    std::vector<uint8_t> constrained(vertex_count, 1);
    for (int32_t v : *selection.free) constrained[v] = 0;
    for (int32_t v : selection.handles) constrained[v] = 0;
    selection.fixed.clear();
    for (int v = 0; v < vertex_count; ++v) {
      if (constrained[v]) selection.fixed.push_back(v);
    }
    selection.free.reset();
  }
  SortUnique(selection.fixed, nullptr);
  SortUnique(selection.anchors, nullptr);
  std::vector<uint8_t> role(vertex_count, 0);  // 1 handle, 2 fixed
  for (int32_t v : selection.handles) role[v] = 1;
  for (int32_t v : selection.fixed) {
    if (role[v] == 1) {
      return InvalidArgumentError(
          fmt::format("selection: vertex {} is both a handle and fixed", v));
    }
    role[v] = 2;
  }
  for (int32_t v : selection.anchors) {
    if (role[v] != 0) {
      return InvalidArgumentError(fmt::format("selection: anchor vertex {} is also a {}", v,
                                              role[v] == 1 ? "handle" : "fixed vertex"));
    }
  }
  return Status::Ok();
}

Eigen::MatrixXd TransformedHandlePositions(const Selection& selection,
                                           const FramePositionsD& positions) {
  Eigen::MatrixXd targets(selection.handles.size(), 3);
  for (size_t k = 0; k < selection.handles.size(); ++k) {
    const Eigen::Vector3d point = selection.transform.topLeftCorner<3, 3>() *
                                      positions.row(selection.handles[k]).transpose() +
                                  selection.transform.topRightCorner<3, 1>();
    targets.row(static_cast<Eigen::Index>(k)) = point.transpose();
  }
  return targets;
}

}  // namespace dmc
