#include "encoder/search_plan.h"

#include <array>
#include <iterator>

#include "bitstream/format.h"

namespace dmc {
namespace {

// One row per effort level, cheapest first. Level 8 is the search every encode ran before the
// levels existed (the same plan, with today's search ranks); 9 is that search measured on every
// frame of the segment.
struct EffortRow {
  bool rank_search;  // code the ranks of kSearchScales, not the threshold's alone
  bool fallback;
  bool operators_at_every_rank;
  bool refit_at_every_rank;
  int measured_frames;
  double prune_sted_ratio;
};

// The rank search's thresholds as multiples of the rank threshold, highest rank first: one rank
// above the threshold's and two below. With the rank criterion's elasticity 1.3
// (segment_encoder.cpp) the quarter gained 1.6–10 points of BD-rate (STED) on the whole captures
// and up to 7.5 on the short excerpts (0.3 lost on horse-collapse) against {1, 2, 4} and 0.8
// (RD.md, "Rank search").
constexpr double kSearchScales[] = {0.25, 1.0, 2.0, 4.0};

constexpr std::array<EffortRow, 9> kEffortRows = {{
    {false, false, false, false, 32, 0.0},  // 0: one pass, the threshold's rank, the fitted weights
    {false, true, false, false, 8, 1.15},   // 1: the fallback at the threshold's rank
    {true, true, false, false, 8, 1.15},    // 2: the default
    {true, true, false, false, 16, 1.25},   // 3
    {true, true, false, true, 16, 1.25},    // 4
    {true, true, false, true, 32, 0.0},     // 5
    {true, true, true, false, 16, 1.25},    // 6
    {true, true, true, false, 32, 0.0},     // 7
    {true, true, true, true, 32, 0.0},      // 8: the exhaustive search
}};

static_assert(kEffortRows.size() == kMaxEffort, "one row per level but the last");
static_assert(!kEffortRows[0].fallback && kEffortRows[kFallbackEffort].fallback &&
              (kFallbackEffort == 0 || !kEffortRows[kFallbackEffort - 1].fallback));
static_assert(kEffortRows[kRankSearchEffort].rank_search &&
              !kEffortRows[kRankSearchEffort - 1].rank_search);

}  // namespace

SearchPlan PlanSearch(const EncoderOptions& options, OperatorId operator_id) {
  SearchPlan plan;
  const bool every_frame = options.effort >= static_cast<int>(kEffortRows.size());
  const EffortRow& row = kEffortRows[every_frame ? kEffortRows.size() - 1 : options.effort];
  plan.fallback = row.fallback && operator_id == OperatorId::kDdl && options.ddl_fallback;
  plan.operators_at_every_rank = row.operators_at_every_rank;
  plan.refit_at_every_rank = row.refit_at_every_rank;
  plan.measured_frames =
      every_frame ? static_cast<int>(format::kMaxSegmentFrames) : row.measured_frames;
  plan.prune_sted_ratio = row.prune_sted_ratio;
  if (options.rank == 0 && plan.fallback && options.rank_search) {
    if (row.rank_search)
      plan.rank_scales.assign(std::begin(kSearchScales), std::end(kSearchScales));
  }
  return plan;
}

}  // namespace dmc
