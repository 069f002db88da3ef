// Declared method parameters: defaults, user overrides and typed access.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <string>

#include "dmc/processing.h"

namespace dmc {
namespace {

std::string_view TypeName(ParameterType type) {
  switch (type) {
    case ParameterType::kNumber:
      return "a number";
    case ParameterType::kInteger:
      return "an integer";
    case ParameterType::kText:
      return "text";
    case ParameterType::kFlag:
      return "true or false";
  }
  return "?";
}

std::optional<double> ParseNumber(std::string_view text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<int> ParseInteger(std::string_view text) {
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<bool> ParseFlag(std::string_view text) {
  if (text == "true" || text == "1") return true;
  if (text == "false" || text == "0") return false;
  return std::nullopt;
}

bool Parses(ParameterType type, std::string_view text) {
  switch (type) {
    case ParameterType::kNumber:
      return ParseNumber(text).has_value();
    case ParameterType::kInteger:
      return ParseInteger(text).has_value();
    case ParameterType::kText:
      return true;
    case ParameterType::kFlag:
      return ParseFlag(text).has_value();
  }
  return false;
}

}  // namespace

std::span<const std::string_view> ReservedParameterNames() {
  static constexpr std::string_view kReserved[] = {"output",         "operator", "selection",
                                                   "operator-frame", "json",     "frame-format",
                                                   "help",           "ddl-mu",   "ddl-reference"};
  return kReserved;
}

StatusOr<ParameterValues> ParameterValues::Create(
    std::span<const ParameterSpec> specs, const std::map<std::string, std::string>& overrides) {
  ParameterValues values;
  for (const ParameterSpec& spec : specs) {
    if (!Parses(spec.type, spec.default_value)) {
      return InternalError(fmt::format("parameter --{}: default '{}' is not {}", spec.name,
                                       spec.default_value, TypeName(spec.type)));
    }
    values.values_[std::string(spec.name)] = std::string(spec.default_value);
    values.types_[std::string(spec.name)] = spec.type;
  }
  for (const auto& [name, text] : overrides) {
    const auto type = values.types_.find(name);
    if (type == values.types_.end()) {
      std::string known;
      for (const ParameterSpec& spec : specs) {
        known += known.empty() ? "" : ", ";
        known += fmt::format("--{}", spec.name);
      }
      return NotFoundError(fmt::format("unknown parameter --{}; this method takes: {}", name,
                                       known.empty() ? "none" : known));
    }
    if (!Parses(type->second, text)) {
      return InvalidArgumentError(
          fmt::format("parameter --{}: '{}' is not {}", name, text, TypeName(type->second)));
    }
    values.values_[name] = text;
  }
  return values;
}

StatusOr<const std::string*> ParameterValues::Find(std::string_view name,
                                                   ParameterType type) const {
  const auto value = values_.find(name);
  const auto declared = types_.find(name);
  if (value == values_.end() || declared == types_.end()) {
    return InternalError(fmt::format("parameter --{} was not declared by the method", name));
  }
  if (declared->second != type) {
    return InternalError(fmt::format("parameter --{} is {}, read as {}", name,
                                     TypeName(declared->second), TypeName(type)));
  }
  return &value->second;
}

StatusOr<double> ParameterValues::Number(std::string_view name) const {
  DMC_ASSIGN_OR_RETURN(const std::string* text, Find(name, ParameterType::kNumber));
  return *ParseNumber(*text);
}

StatusOr<int> ParameterValues::Integer(std::string_view name) const {
  DMC_ASSIGN_OR_RETURN(const std::string* text, Find(name, ParameterType::kInteger));
  return *ParseInteger(*text);
}

StatusOr<std::string> ParameterValues::Text(std::string_view name) const {
  DMC_ASSIGN_OR_RETURN(const std::string* text, Find(name, ParameterType::kText));
  return *text;
}

StatusOr<bool> ParameterValues::Flag(std::string_view name) const {
  DMC_ASSIGN_OR_RETURN(const std::string* text, Find(name, ParameterType::kFlag));
  return *ParseFlag(*text);
}

}  // namespace dmc
