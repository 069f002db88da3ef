// How hard one encode searches a segment's rank and operator: EncoderOptions::effort read
// together with the switches that restrict the search (rank, rank_search, ddl_fallback, the
// operator). The levels' figures (rate at equal STED and time per level) are in RD.md, "Effort".
#pragma once

#include <vector>

#include "dmc/encoder.h"
#include "dmc/wire_ids.h"

namespace dmc {

struct SearchPlan {
  // The automatic rank's candidates as multiples of EncoderOptions::rank_threshold, ascending
  // (so the highest rank, which is coded first, comes first); {1} codes the threshold's rank
  // alone (and always for a fixed rank).
  std::vector<double> rank_scales = {1.0};
  // ddl: also code the segment with kirchhoff, tutte and mean-value and keep the coding with the
  // lowest rate at equal STED (operator_choice.h).
  bool fallback = false;
  // With several ranks: every candidate operator at every rank, or (false) only the operator the
  // top rank chose, whose factorisation then serves every lower rank (unless refitted).
  bool operators_at_every_rank = false;
  // With several ranks: a DDL fit at every rank, or (false) the top rank's fitted weights for
  // the lower ranks too (a lower rank's coefficients are nearly the top rank's first columns).
  bool refit_at_every_rank = false;
  // Frames of a segment the candidates are decoded and measured on (every k-th frame).
  int measured_frames = 32;
  // A candidate whose payload exceeds the smallest candidate's by more than a STED this many
  // times lower could buy (at the operator choice's rate–distortion slope) is not measured; 0 =
  // every candidate measured.
  double prune_sted_ratio = 0.0;
};

// What `options` (valid, see ValidateOptions) ask of a segment coded with `operator_id`. The
// switches only restrict: rank != 0 codes that rank alone, rank_search = false the threshold's
// rank alone, ddl_fallback = false (or an operator other than ddl) no fallback; and, as before
// the effort existed, the rank search needs the fallback, whose measurement compares the ranks.
SearchPlan PlanSearch(const EncoderOptions& options, OperatorId operator_id);

}  // namespace dmc
