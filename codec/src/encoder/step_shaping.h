// STED-aware step shaping (format 1.2, spec §8.5.1): the encoder's choice of each anchor's step
// exponent. STED measures each edge's length change relative to the edge, so a residual error of
// one step moves STED more among short edges than among long ones. Scaling the step of a region
// by its edge length (to a power, the strength) spends the bits where STED is made. The decoder
// only reads the exponents; how they are chosen is the encoder's (spec Appendix A).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "dmc/topology.h"

namespace dmc {

// The automatic strength for a mesh whose vertices' mean incident edge lengths have standard
// deviation `log_spread` in their natural logarithm: 0 up to 0.25 (the Vlasic captures: 0.10–0.24,
// where shaping measured no gain), rising linearly to 1 at 0.6 (horse-gallop, chicken: 0.6–0.8).
double AutomaticStepShapingStrength(double log_spread);

// One exponent per anchor (|e| ≤ 8, format::StepFactor(e) = 2^(e/4)): e = round(4 · strength ·
// mean over the anchor's region (format::AnchorRegions) of log2(l_v / g)), l_v the mean length
// of vertex v's edges in `mean_shape` (V × 3) and g their geometric mean over the mesh; vertices
// without edges or with l_v = 0 are left out. `strength` < 0 = AutomaticStepShapingStrength.
// All zero when the strength is 0 or the mesh has no edge of positive length.
std::vector<int8_t> ChooseStepExponents(const Eigen::MatrixXd& mean_shape,
                                        const MeshTopology& topology,
                                        std::span<const int32_t> anchors, double strength);

}  // namespace dmc
