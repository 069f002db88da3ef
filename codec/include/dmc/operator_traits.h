// Every Laplace operator dmc knows by name, its wire ID and what a .dmc stream carries for it: the
// one table the encoder (which names it may take), the bitstream syntax (which IDs a segment may
// name), the decoder (what to rebuild the operator from), RebuildOperator and the operator
// registry read. Header-only, so that reading it links nothing.
//
// The wire-ID rows follow bitstream-spec/dmc-format.md §9.1 ("Codec operator in 1.0 and 1.1" and
// "Operator chunk" columns; tests/unit/conformance checks them); their names are the frozen ones of
// dmc/wire_ids.h. Rows without a wire ID are operators only the registry builds.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "dmc/wire_ids.h"

namespace dmc {

// What a segment's operator chunk carries for an operator (spec §8.4).
enum class OperatorSideInfo : uint8_t {
  kNotCarried,      // not a codec operator: no stream of this format version names it
  kNone,            // empty chunk: the operator is built from the connectivity alone
  kReferenceFrame,  // a coded reference frame, from which the decoder computes geometric weights
  kEdgeWeights,     // the DDL weights, one per edge
};

struct OperatorTraits {
  std::string_view name;                 // the registry name
  OperatorId id = OperatorId::kInvalid;  // kInvalid: no wire ID
  OperatorSideInfo side_info = OperatorSideInfo::kNotCarried;

  // A format 1.0 stream may name it.
  constexpr bool codec() const { return side_info != OperatorSideInfo::kNotCarried; }
  // Its weights are computed from the reference frame the stream carries.
  constexpr bool geometric() const { return side_info == OperatorSideInfo::kReferenceFrame; }
};

namespace operator_traits_detail {
consteval OperatorTraits Wire(OperatorId id, OperatorSideInfo side_info) {
  return {WireNameOf(kOperatorIdNames, id), id, side_info};
}
}  // namespace operator_traits_detail

// The codec operators first, in the order the encoder lists them (its default first).
inline constexpr OperatorTraits kOperatorTraits[] = {
    operator_traits_detail::Wire(OperatorId::kDdl, OperatorSideInfo::kEdgeWeights),
    operator_traits_detail::Wire(OperatorId::kTutte, OperatorSideInfo::kNone),
    operator_traits_detail::Wire(OperatorId::kKirchhoff, OperatorSideInfo::kNone),
    operator_traits_detail::Wire(OperatorId::kCotan, OperatorSideInfo::kReferenceFrame),
    operator_traits_detail::Wire(OperatorId::kCotanArea, OperatorSideInfo::kReferenceFrame),
    operator_traits_detail::Wire(OperatorId::kCotanSym, OperatorSideInfo::kReferenceFrame),
    operator_traits_detail::Wire(OperatorId::kMeanValue, OperatorSideInfo::kReferenceFrame),
    operator_traits_detail::Wire(OperatorId::kDdlAsym, OperatorSideInfo::kNotCarried),
    {"spacetime"},
    {"bspline"},
};

// The row of `name`, or nullptr.
constexpr const OperatorTraits* FindOperatorTraits(std::string_view name) {
  for (const OperatorTraits& traits : kOperatorTraits) {
    if (traits.name == name) return &traits;
  }
  return nullptr;
}

// The row of wire ID `id`, or nullptr (always for kInvalid and for IDs no row holds).
constexpr const OperatorTraits* FindOperatorTraits(OperatorId id) {
  if (id == OperatorId::kInvalid) return nullptr;
  for (const OperatorTraits& traits : kOperatorTraits) {
    if (traits.id == id) return &traits;
  }
  return nullptr;
}

namespace operator_traits_detail {
consteval bool EveryWireIdHasOneRowAndNamesAreUnique() {
  for (const WireName<OperatorId>& wire : kOperatorIdNames) {
    if (wire.value == OperatorId::kInvalid) continue;
    int rows = 0;
    for (const OperatorTraits& traits : kOperatorTraits) rows += traits.id == wire.value;
    if (rows != 1) return false;
  }
  for (const OperatorTraits& traits : kOperatorTraits) {
    if (traits.name.empty() || FindOperatorTraits(traits.name) != &traits) return false;
    // Only a wire ID can be carried.
    if (traits.codec() && traits.id == OperatorId::kInvalid) return false;
  }
  return true;
}
}  // namespace operator_traits_detail

static_assert(
    operator_traits_detail::EveryWireIdHasOneRowAndNamesAreUnique(),
    "kOperatorTraits must hold every wire ID of kOperatorIdNames once, under unique names");

}  // namespace dmc
