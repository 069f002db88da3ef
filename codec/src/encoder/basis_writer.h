// Quantisation and coding of the basis chunk (spec §8.3; the mirror of decoder/basis_reader.h).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "bitstream/format.h"

namespace dmc::syntax {

// Format 1.0 syntax: every basis column (entries in [-1, 1]) quantised to 2^(bits-1)-1 levels of
// header.basis_bits and coded with a per-column first- or second-order temporal prediction
// (whichever is cheaper); returns the dequantised basis in `decoded`.
std::vector<uint8_t> WriteBasis(const Eigen::MatrixXd& basis, const format::SegmentHeader& header,
                                Eigen::MatrixXd* decoded);

// Format 1.1 syntax: column k quantised with its own bit depth depths[k] (in
// [format::kMinBasisBits, header.basis_bits]), coded in the payload, and a per-column choice of
// temporal predictor. `depths` has at least header.rank entries; a column's decoded values
// depend only on its own samples and depth, so a lower rank's decoded basis is the first columns
// of a higher rank's with the same depths.
std::vector<uint8_t> WriteBasis(const Eigen::MatrixXd& basis, const format::SegmentHeader& header,
                                std::span<const uint8_t> depths, Eigen::MatrixXd* decoded);

// Encoder choice (not normative): the bit depth of each of the first `rank` components from its
// eigenvalue λ_k (the squared singular value, Σ over the V vertices of its squared coefficient).
// Quantising a unit basis column with step s adds about λ_k · s² · 3F / 12 of squared error,
// against the residuals' V · 3F · Δ² / 12: the depth gives the coarsest step with
// λ_k · s² <= kBasisErrorShare · V · Δ², within [kMinBasisBits, max_bits].
// 1/4: measured on crane-full, cow, horse-gallop, chicken-crossing and samba against 1, 1/8,
// 1/16 and 1/64 (1/8 and below cost KG on samba; 1 costs KG on crane-full).
inline constexpr double kBasisErrorShare = 0.25;
std::vector<uint8_t> ChooseBasisDepths(std::span<const double> eigenvalues, int rank,
                                       int vertex_count, double residual_step, int max_bits);

}  // namespace dmc::syntax
