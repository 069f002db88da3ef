#include "encoder/search_plan.h"

#include <array>

#include "bitstream/format.h"

namespace dmc {
namespace {

// One row per effort level, cheapest first. Level 8 is the search every encode ran before the
// levels existed (its bytes are that encoder's); 9 is that search measured on every frame of the
// segment.
struct EffortRow {
  int rank_scales;  // how many of kScales
  bool fallback;
  bool operators_at_every_rank;
  bool refit_at_every_rank;
  int measured_frames;
  double prune_sted_ratio;
};

constexpr double kScales[] = {1.0, 2.0, 4.0};

constexpr std::array<EffortRow, 9> kEffortRows = {{
    {1, false, false, false, 32, 0.0},  // 0: one pass, the threshold's rank, the fitted weights
    {1, true, false, false, 8, 1.15},   // 1: the fallback at the threshold's rank
    {3, true, false, false, 8, 1.15},   // 2: the default
    {3, true, false, false, 16, 1.25},  // 3
    {3, true, false, true, 16, 1.25},   // 4
    {3, true, false, true, 32, 0.0},    // 5
    {3, true, true, false, 16, 1.25},   // 6
    {3, true, true, false, 32, 0.0},    // 7
    {3, true, true, true, 32, 0.0},     // 8: the exhaustive search
}};

static_assert(kEffortRows.size() == kMaxEffort, "one row per level but the last");
static_assert(!kEffortRows[0].fallback && kEffortRows[kFallbackEffort].fallback &&
              (kFallbackEffort == 0 || !kEffortRows[kFallbackEffort - 1].fallback));
static_assert(kEffortRows[kRankSearchEffort].rank_scales > 1 &&
              kEffortRows[kRankSearchEffort - 1].rank_scales == 1);

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
    plan.rank_scales.assign(kScales, kScales + row.rank_scales);
  }
  return plan;
}

}  // namespace dmc
