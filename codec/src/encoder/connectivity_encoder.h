// Coding of the connectivity chunk (payload syntax in decoder/connectivity_decoder.h).
//
// Three methods:
//  - kIndexed: the triangle list as given, range-coded index deltas. Represents anything, keeps
//    triangle order; costs about 25 bits per triangle.
//  - kDracoWithVertexOrder: Draco's edgebreaker (about 1-2 bits per triangle) plus the vertex
//    labels that restore the input vertex order; triangle order and the rotation of each
//    triangle's indices may differ from the input, the set of oriented triangles does not.
//  - kDracoReordered: Draco's edgebreaker alone; the output vertex order is Draco's.
// Draco cannot represent every triangle list exactly (it drops isolated vertices and degenerate
// triangles and splits non-manifold vertices), so every Draco payload is decoded again here and
// compared with the input; a method that does not reproduce it is never chosen.
#pragma once

#include <cstdint>
#include <vector>

#include "bitstream/format.h"
#include "decoder/connectivity_decoder.h"
#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc {

struct ConnectivityCode {
  std::vector<uint8_t> payload;  // the chunk payload; starts with the method byte
  // Empty unless the method reorders vertices; then output vertex i = input vertex
  // vertex_order[i], and the caller must code positions in that order.
  std::vector<int32_t> vertex_order;
  // Exactly the triangle list DecodeConnectivity returns for `payload` (output labels).
  Triangles triangles;

  ConnectivityCoding method() const { return static_cast<ConnectivityCoding>(payload.front()); }
};

// Codes `triangles` (indices in [0, vertex_count)) with the smallest method that reproduces them:
// kIndexed or kDracoWithVertexOrder, and also kDracoReordered when `allow_reorder`.
// Fails with kInvalidArgument on an index outside [0, vertex_count) or a negative vertex count.
// `version_minor` is the minor format version of the stream the payload goes into (the label
// kernels of kDracoWithVertexOrder need 1.1).
StatusOr<ConnectivityCode> EncodeConnectivity(const Triangles& triangles, int vertex_count,
                                              bool allow_reorder,
                                              uint8_t version_minor = format::kVersionMinor);

// Codes with the given method only (tests, benchmarks, measurements). Fails with kUnsupported
// when a Draco method cannot reproduce the triangle set exactly.
StatusOr<ConnectivityCode> EncodeConnectivityWithMethod(
    const Triangles& triangles, int vertex_count, ConnectivityCoding method,
    uint8_t version_minor = format::kVersionMinor);

// Codes with kDracoWithVertexOrder and the label model of wire value `label_model` (spec §7.3)
// instead of the smallest: conformance vectors of a given model. kInvalidArgument for a model the
// version does not have, kUnsupported when Draco cannot reproduce the triangle set.
StatusOr<ConnectivityCode> EncodeConnectivityWithLabelModel(
    const Triangles& triangles, int vertex_count, uint8_t label_model,
    uint8_t version_minor = format::kVersionMinor);

}  // namespace dmc
