#include "encoder/rate_control.h"

#include <cmath>

namespace dmc {

bool HasRateTarget(const EncoderOptions& options) {
  return options.target_bpfv > 0.0 || options.target_sted > 0.0;
}

bool MeetsRateTarget(const EncoderOptions& options, const EncodeReport& report) {
  // The motion's rate: a scene chunk is a fixed cost no step changes.
  return options.target_bpfv > 0.0 ? report.positions_bpfv <= options.target_bpfv
                                   : report.distortion.sted <= options.target_sted;
}

Status SearchResidualStep(const EncoderOptions& options, double diagonal,
                          const std::function<StatusOr<bool>(const EncoderOptions&)>& trial) {
  const bool prefer_finer = options.target_bpfv > 0.0;
  EncoderOptions trial_options = options;
  trial_options.target_bpfv = trial_options.target_sted = 0.0;
  double low = 1.0, high = 24.0;  // residual bits
  bool found = false;
  for (int iteration = 0; iteration < 12; ++iteration) {
    const double bits = 0.5 * (low + high);
    trial_options.residual_step = diagonal * std::pow(2.0, -bits);
    DMC_ASSIGN_OR_RETURN(const bool meets, trial(trial_options));
    found = found || meets;
    // Meeting a rate target: finer steps are better while they fit; meeting a distortion
    // target: coarser steps are better while they meet it.
    if (meets == prefer_finer) {
      low = bits;
    } else {
      high = bits;
    }
  }
  if (!found) {
    return InvalidArgumentError(prefer_finer ? "no parameters reach the target rate"
                                             : "no parameters reach the target distortion");
  }
  return Status::Ok();
}

}  // namespace dmc
