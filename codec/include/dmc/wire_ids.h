// Frozen numeric identifiers that appear in .dmc streams or in what a decoder must report.
//
// Contract: every value in this header is part of the bitstream format (normative tables:
// bitstream-spec/dmc-format.md; tests/unit/conformance checks that the spec's tables and the
// tables below agree entry for entry). A value, once published, NEVER changes and is never reused
// for something else, even if the thing it names is retired; new entries are only appended with
// fresh values. 0 is reserved as "invalid / not set" in every enum so a zeroed field never decodes
// as a real choice — except ConnectivityMethod, whose value 0 (kIndexed) was published with format
// 1.0 and therefore stays.
//
// Each enum is followed by a table listing every enumerator with its stable name: C++ cannot
// enumerate an enum, and the table is what the spec-agreement test, WireNameOf() and the error
// messages that name a value read. Adding an enumerator means adding its table row and its row in
// the spec.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "dmc/status.h"

namespace dmc {

// ---------------------------------------------------------------------------------------------
// Discrete Laplace operators (what each computes: dmc/operators.h and the spec, §9). Which
// of them a stream may name and what its operator chunk then carries is kOperatorTraits in
// dmc/operator_traits.h: in format 1.0 every ID but kDdlAsym (a decoder reports kUnsupported for
// 0, 8 and unlisted IDs).
enum class OperatorId : uint8_t {
  kInvalid = 0,
  kKirchhoff = 1,  // graph Laplacian: w_ij = 1
  kTutte = 2,      // w_ij = 1 / deg(i)
  kCotan = 3,      // cotangent weights, each row scaled to unit sum
  kCotanArea = 4,  // cotangent weights / mixed Voronoi area
  kCotanSym = 5,   // symmetric cotangent weights (DEC operator)
  kMeanValue = 6,  // Floater's mean value weights, unit sum
  kDdl = 7,        // data-dependent Laplacian, symmetric (one weight per edge)
  kDdlAsym = 8,    // data-dependent Laplacian, asymmetric (one weight per directed edge)
};

// ---------------------------------------------------------------------------------------------
// Chunk types (the u8 in front of every chunk of the container). Value 0 is reserved and never
// assigned; values not listed are reserved for later versions and are kCorruptStream in 1.0.
enum class ChunkType : uint8_t {
  kSequenceHeader = 1,  // once, first
  kConnectivity = 2,    // once, second
  kSegmentHeader = 3,   // starts a segment
  kMean = 4,            // the segment's mean trajectory
  kBasis = 5,           // the segment's quantised PCA basis
  kOperator = 6,        // operator side information (DDL weights)
  kAnchors = 7,         // anchor vertex indices and coefficients
  kResiduals = 8,       // quantised delta-trajectories
  kScene = 9,           // format 1.3, optional, third: what a glTF input holds besides motion
  kEnd = 15,            // last chunk; payload: varint number of chunks before it
};

// ---------------------------------------------------------------------------------------------
// Connectivity coding methods (the first byte of the connectivity chunk's payload; the payload
// syntax is in codec/src/decoder/connectivity_decoder.h and the spec). Unknown values are
// kUnsupported.
enum class ConnectivityMethod : uint8_t {
  kIndexed = 0,               // range-coded triangle list, input order
  kDracoWithVertexOrder = 1,  // Draco edgebreaker + range-coded vertex labels (input order kept)
  kDracoReordered = 2,        // Draco edgebreaker alone (vertex order is Draco's)
};

// ---------------------------------------------------------------------------------------------
// Error codes. The enum itself is dmc::ErrorCode in dmc/status.h (every fallible call uses it);
// its values are frozen here because conformance vectors record the exact code a decoder must
// report, and the dmc CLI exits with 10 + code.
static_assert(static_cast<int>(ErrorCode::kOk) == 0);
static_assert(static_cast<int>(ErrorCode::kInvalidArgument) == 1);
static_assert(static_cast<int>(ErrorCode::kIoError) == 2);
static_assert(static_cast<int>(ErrorCode::kParseError) == 3);
static_assert(static_cast<int>(ErrorCode::kInvalidSequence) == 4);
static_assert(static_cast<int>(ErrorCode::kMismatch) == 5);
static_assert(static_cast<int>(ErrorCode::kUnsupported) == 6);
static_assert(static_cast<int>(ErrorCode::kCorruptStream) == 7);
static_assert(static_cast<int>(ErrorCode::kTruncatedStream) == 8);
static_assert(static_cast<int>(ErrorCode::kNumericalFailure) == 9);
static_assert(static_cast<int>(ErrorCode::kNotFound) == 10);
static_assert(static_cast<int>(ErrorCode::kInternal) == 11);
static_assert(static_cast<int>(ErrorCode::kResourceLimit) == 12);

// ---------------------------------------------------------------------------------------------
// Tables of every enumerator with its stable name (the names the spec's tables use).

template <typename Enum>
struct WireName {
  Enum value;
  std::string_view name;
};

inline constexpr std::array<WireName<OperatorId>, 9> kOperatorIdNames = {{
    {OperatorId::kInvalid, "invalid"},
    {OperatorId::kKirchhoff, "kirchhoff"},
    {OperatorId::kTutte, "tutte"},
    {OperatorId::kCotan, "cotan"},
    {OperatorId::kCotanArea, "cotan-area"},
    {OperatorId::kCotanSym, "cotan-sym"},
    {OperatorId::kMeanValue, "mean-value"},
    {OperatorId::kDdl, "ddl"},
    {OperatorId::kDdlAsym, "ddl-asym"},
}};

inline constexpr std::array<WireName<ChunkType>, 10> kChunkTypeNames = {{
    {ChunkType::kSequenceHeader, "sequence-header"},
    {ChunkType::kConnectivity, "connectivity"},
    {ChunkType::kSegmentHeader, "segment-header"},
    {ChunkType::kMean, "mean"},
    {ChunkType::kBasis, "basis"},
    {ChunkType::kOperator, "operator"},
    {ChunkType::kAnchors, "anchors"},
    {ChunkType::kResiduals, "residuals"},
    {ChunkType::kScene, "scene"},
    {ChunkType::kEnd, "end"},
}};

inline constexpr std::array<WireName<ConnectivityMethod>, 3> kConnectivityMethodNames = {{
    {ConnectivityMethod::kIndexed, "indexed"},
    {ConnectivityMethod::kDracoWithVertexOrder, "draco-with-vertex-order"},
    {ConnectivityMethod::kDracoReordered, "draco-reordered"},
}};

// Names as returned by ErrorCodeName().
inline constexpr std::array<WireName<ErrorCode>, 13> kErrorCodeNames = {{
    {ErrorCode::kOk, "ok"},
    {ErrorCode::kInvalidArgument, "invalid-argument"},
    {ErrorCode::kIoError, "io-error"},
    {ErrorCode::kParseError, "parse-error"},
    {ErrorCode::kInvalidSequence, "invalid-sequence"},
    {ErrorCode::kMismatch, "mismatch"},
    {ErrorCode::kUnsupported, "unsupported"},
    {ErrorCode::kCorruptStream, "corrupt-stream"},
    {ErrorCode::kTruncatedStream, "truncated-stream"},
    {ErrorCode::kNumericalFailure, "numerical-failure"},
    {ErrorCode::kNotFound, "not-found"},
    {ErrorCode::kInternal, "internal"},
    {ErrorCode::kResourceLimit, "resource-limit"},
}};

// The stable name of a listed value, or "" for a value no table row holds.
template <typename Enum, size_t N>
constexpr std::string_view WireNameOf(const std::array<WireName<Enum>, N>& table, Enum value) {
  for (const WireName<Enum>& row : table) {
    if (row.value == value) return row.name;
  }
  return {};
}

}  // namespace dmc
