#include "sweep/sweep.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <string_view>
#include <type_traits>
#include <variant>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/encoder_options.h"
#include "dmc/operator_registry.h"

namespace dmc::sweep {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string Describe(const Status& status) {
  return std::string(ErrorCodeName(status.code())) + ": " + status.message();
}

// "ddl:2 tutte:1": each operator with its segment count, in order of first use.
std::string CountOperators(const std::vector<std::string>& segment_operators) {
  std::vector<std::pair<std::string, int>> counts;
  for (const std::string& name : segment_operators) {
    const auto found = std::find_if(counts.begin(), counts.end(),
                                    [&](const auto& count) { return count.first == name; });
    if (found == counts.end()) {
      counts.emplace_back(name, 1);
    } else {
      ++found->second;
    }
  }
  std::string text;
  for (const auto& [name, count] : counts) {
    text += fmt::format("{}{}:{}", text.empty() ? "" : " ", name, count);
  }
  return text;
}

// Encodes, decodes and measures one dmc rung. kUnsupported and kNotFound come back as errors
// (the caller drops the curve); everything else too, but the caller only skips the point.
StatusOr<RdPoint> RunDmcPoint(const MeshSequence& sequence, const DistortionMeter& meter,
                              const std::string& operator_name, double residual_bits,
                              int basis_bits, const SweepOptions& sweep, double diagonal) {
  EncoderOptions options = sweep.encoder;
  options.operator_name = operator_name;
  // Fractional bits through the absolute step (which overrides EncoderOptions::residual_bits).
  options.residual_step = diagonal * std::exp2(-residual_bits);
  options.basis_bits = basis_bits;
  options.effort = sweep.effort;
  options.measure = false;  // measured below with the shared meter, outside the timing
  EncodeReport report;
  const Clock::time_point encode_start = Clock::now();
  DMC_ASSIGN_OR_RETURN(const std::vector<uint8_t> bytes, Encode(sequence, options, &report));
  const double encode_s = SecondsSince(encode_start);
  const Clock::time_point decode_start = Clock::now();
  DMC_ASSIGN_OR_RETURN(const MeshSequence decoded, Decode(bytes));
  const double decode_s = SecondsSince(decode_start);
  DMC_ASSIGN_OR_RETURN(const DistortionReport distortion, meter.Measure(decoded));

  RdPoint point;
  point.codec = "dmc";
  point.operator_name = operator_name;
  point.rank = report.rank;
  point.basis_bits = basis_bits;
  point.residual_bits = residual_bits;
  point.anchors = report.anchors;
  point.segments = report.segments;
  point.segment_operators = CountOperators(report.segment_operators);
  point.bytes = bytes.size();
  point.header_bytes = report.header_bytes;
  point.connectivity_bytes = report.connectivity_bytes;
  point.mean_bytes = report.mean_bytes;
  point.basis_bytes = report.basis_bytes;
  point.operator_bytes = report.operator_bytes;
  point.anchor_bytes = report.anchor_bytes;
  point.residual_bytes = report.residual_bytes;
  point.bpfv = report.bpfv;
  point.kg = distortion.kg;
  point.sted = distortion.sted;
  point.encode_s = encode_s;
  point.decode_s = decode_s;
  return point;
}

StatusOr<RdPoint> RunBaselinePoint(const MeshSequence& sequence, const DistortionMeter& meter,
                                   BaselineKind kind, int bits) {
  const Clock::time_point encode_start = Clock::now();
  DMC_ASSIGN_OR_RETURN(const BaselineStream stream, EncodeBaseline(kind, sequence, bits));
  const double encode_s = SecondsSince(encode_start);
  const Clock::time_point decode_start = Clock::now();
  DMC_ASSIGN_OR_RETURN(const MeshSequence decoded, DecodeBaseline(kind, stream.bytes));
  DMC_ASSIGN_OR_RETURN(const MeshSequence restored,
                       RestoreInputOrder(decoded, stream.input_vertex));
  const double decode_s = SecondsSince(decode_start);
  DMC_ASSIGN_OR_RETURN(const DistortionReport distortion, meter.Measure(restored));

  RdPoint point;
  point.codec = std::string(BaselineName(kind));
  point.residual_bits = bits;
  point.bytes = stream.bytes.size();
  point.bpfv = 8.0 * static_cast<double>(stream.bytes.size()) /
               (static_cast<double>(sequence.frame_count()) * sequence.vertex_count());
  point.kg = distortion.kg;
  point.sted = distortion.sted;
  point.encode_s = encode_s;
  point.decode_s = decode_s;
  return point;
}

}  // namespace

std::string RdPoint::Curve() const {
  return operator_name.empty() ? codec : codec + "/" + operator_name;
}

Status SetEncoderOption(EncoderOptions* options, std::string_view setting) {
  const size_t equals = setting.find('=');
  const std::string quoted = "--encoder-option '" + std::string(setting) + "'";
  if (equals == std::string_view::npos) {
    return InvalidArgumentError(quoted + ": expected NAME=VALUE");
  }
  const std::string_view name = setting.substr(0, equals);
  const std::string value(setting.substr(equals + 1));
  static constexpr std::string_view kLadderSets[] = {
      "operator", "residual_bits", "residual_step", "basis_bits",
      "effort",   "measure",       "target_bpfv",   "target_sted"};
  for (const std::string_view taken : kLadderSets) {
    if (name == taken) {
      return InvalidArgumentError(quoted + ": the sweep sets " + std::string(name) +
                                  " itself (--operators, the ladder, --basis-bits, --effort)");
    }
  }
  const EncoderOptionSpec* spec = FindEncoderOption(name);
  if (spec == nullptr) {
    return InvalidArgumentError(quoted + ": no encoder option is called " + std::string(name) +
                                " (the names of dmc encode's flags, with '_' for '-')");
  }
  const auto bad_value = [&](const char* type) {
    return InvalidArgumentError(quoted + ": " + std::string(name) + " takes " + type);
  };
  return std::visit(
      [&](auto field) -> Status {
        auto& target = options->*field;
        using T = std::remove_reference_t<decltype(target)>;
        if constexpr (std::is_same_v<T, bool>) {
          if (value == "true" || value == "on" || value == "1") {
            target = true;
          } else if (value == "false" || value == "off" || value == "0") {
            target = false;
          } else {
            return bad_value("true or false");
          }
        } else if constexpr (std::is_same_v<T, std::string>) {
          target = value;
        } else {
          T parsed{};
          const char* end = value.data() + value.size();
          const auto [stop, error] = std::from_chars(value.data(), end, parsed);
          if (value.empty() || error != std::errc() || stop != end) {
            return bad_value(std::is_same_v<T, int> ? "an integer" : "a number");
          }
          target = parsed;
        }
        return Status::Ok();
      },
      spec->field);
}

Status ValidateSweepOptions(const SweepOptions& options) {
  if (options.points < 2) {
    return InvalidArgumentError("--points must be at least 2, got " +
                                std::to_string(options.points));
  }
  const auto bits_ok = [](double bits) { return std::isfinite(bits) && bits >= 1 && bits <= 30; };
  if (!bits_ok(options.min_residual_bits) || !bits_ok(options.max_residual_bits) ||
      options.min_residual_bits > options.max_residual_bits) {
    return InvalidArgumentError("residual bits range must satisfy 1 <= min <= max <= 30");
  }
  for (const double bits : options.ladder) {
    if (!bits_ok(bits)) {
      return InvalidArgumentError(fmt::format("--ladder rungs must be in [1, 30], got {}", bits));
    }
  }
  if (options.basis_bits != 0 && (options.basis_bits < 2 || options.basis_bits > 16)) {
    return InvalidArgumentError("--basis-bits must be 0 (follow the rung) or in [2, 16], got " +
                                std::to_string(options.basis_bits));
  }
  if (Status encoder = ValidateOptions(options.encoder); !encoder.ok()) {
    return InvalidArgumentError("--encoder-option: " + encoder.message());
  }
  if (options.effort < 0 || options.effort > kMaxEffort) {
    return InvalidArgumentError("--effort must be in [0, " + std::to_string(kMaxEffort) +
                                "], got " + std::to_string(options.effort));
  }
  if (options.min_baseline_bits < kMinBaselineBits ||
      options.max_baseline_bits > kMaxBaselineBits ||
      options.min_baseline_bits > options.max_baseline_bits) {
    return InvalidArgumentError("baseline bits range must satisfy " +
                                std::to_string(kMinBaselineBits) +
                                " <= min <= max <= " + std::to_string(kMaxBaselineBits));
  }
  if (options.operators.empty() && options.baselines.empty()) {
    return InvalidArgumentError("nothing to sweep: no operator and no baseline");
  }
  return ValidateStedOptions(options.sted);
}

std::vector<double> ResidualBitsLadder(const SweepOptions& options) {
  if (!options.ladder.empty()) {
    std::vector<double> ladder = options.ladder;
    std::sort(ladder.begin(), ladder.end());
    ladder.erase(std::unique(ladder.begin(), ladder.end()), ladder.end());
    return ladder;
  }
  std::vector<double> ladder;
  for (int k = 0; k < options.points; ++k) {
    ladder.push_back(options.min_residual_bits +
                     (options.max_residual_bits - options.min_residual_bits) * k /
                         (options.points - 1));
  }
  ladder.erase(std::unique(ladder.begin(), ladder.end()), ladder.end());
  return ladder;
}

std::vector<int> BaselineBitsLadder(const SweepOptions& options) {
  std::vector<int> ladder;
  for (int k = 0; k < options.points; ++k) {
    const double bits = options.min_baseline_bits +
                        static_cast<double>(options.max_baseline_bits - options.min_baseline_bits) *
                            k / (options.points - 1);
    ladder.push_back(static_cast<int>(std::lround(bits)));
  }
  ladder.erase(std::unique(ladder.begin(), ladder.end()), ladder.end());
  return ladder;
}

int BasisBitsFor(double residual_bits, int fixed_basis_bits) {
  if (fixed_basis_bits > 0) return fixed_basis_bits;
  return std::clamp(static_cast<int>(std::lround(residual_bits)), 10, 16);
}

StatusOr<SweepResult> RunSweep(const MeshSequence& sequence, const SweepOptions& options,
                               const SweepCallback& callback) {
  DMC_RETURN_IF_ERROR(ValidateSweepOptions(options));
  for (const std::string& name : options.operators) {
    DMC_RETURN_IF_ERROR(FindOperator(name).status());
  }
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  DMC_ASSIGN_OR_RETURN(const DistortionMeter meter,
                       DistortionMeter::Create(sequence, options.sted));
  // The encoder's own diagonal, so that residual_bits means what --residual-bits means.
  const double diagonal = std::max(ComputeBoundingBox(sequence).diagonal(), 1e-12);

  const std::vector<double> dmc_ladder = ResidualBitsLadder(options);
  const std::vector<int> baseline_ladder = BaselineBitsLadder(options);
  int total = static_cast<int>(options.operators.size() * dmc_ladder.size() +
                               options.baselines.size() * baseline_ladder.size());
  int done = 0;
  SweepResult result;
  const auto report = [&](const RdPoint* point, const std::string& warning) {
    if (!warning.empty()) result.warnings.push_back(warning);
    if (callback) callback(point, warning, done, total);
  };
  // A curve's remaining rungs leave the total when the codec cannot handle the input at all.
  const auto drop_curve = [&](const std::string& curve, size_t remaining, const Status& status) {
    total -= static_cast<int>(remaining);
    report(nullptr, curve + " skipped: " + Describe(status));
  };

  for (const std::string& name : options.operators) {
    for (size_t rung = 0; rung < dmc_ladder.size(); ++rung) {
      const double bits = dmc_ladder[rung];
      StatusOr<RdPoint> point = RunDmcPoint(
          sequence, meter, name, bits, BasisBitsFor(bits, options.basis_bits), options, diagonal);
      if (!point.ok() && point.status().code() == ErrorCode::kUnsupported) {
        drop_curve("dmc/" + name, dmc_ladder.size() - rung, point.status());
        break;
      }
      ++done;
      if (!point.ok()) {
        report(nullptr, fmt::format("dmc/{} at {:.2f} residual bits skipped: {}", name, bits,
                                    Describe(point.status())));
        continue;
      }
      result.points.push_back(*point);
      report(&result.points.back(), "");
    }
  }
  // The default settings' point, apart from the ladder.
  const EncoderOptions defaults;
  if (std::find(options.operators.begin(), options.operators.end(), defaults.operator_name) !=
      options.operators.end()) {
    SweepOptions default_sweep = options;
    default_sweep.effort = defaults.effort;
    StatusOr<RdPoint> point =
        RunDmcPoint(sequence, meter, defaults.operator_name, defaults.residual_bits,
                    defaults.basis_bits, default_sweep, diagonal);
    if (point.ok()) {
      result.default_point = *point;
    } else {
      report(nullptr, "the default settings' point skipped: " + Describe(point.status()));
    }
  }
  for (const BaselineKind kind : options.baselines) {
    const std::string name(BaselineName(kind));
    for (size_t rung = 0; rung < baseline_ladder.size(); ++rung) {
      StatusOr<RdPoint> point = RunBaselinePoint(sequence, meter, kind, baseline_ladder[rung]);
      if (!point.ok() && point.status().code() == ErrorCode::kUnsupported) {
        drop_curve(name, baseline_ladder.size() - rung, point.status());
        break;
      }
      ++done;
      if (!point.ok()) {
        report(nullptr, fmt::format("{} at {} bits skipped: {}", name, baseline_ladder[rung],
                                    Describe(point.status())));
        continue;
      }
      result.points.push_back(*point);
      report(&result.points.back(), "");
    }
  }
  return result;
}

}  // namespace dmc::sweep
