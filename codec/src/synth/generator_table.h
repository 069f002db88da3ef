// Lookups in a table of named generators (synth.cpp's animations, tvm_synth.cpp's time-varying
// examples): any array of entries with `name` and `description` members.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace dmc::synth {

// The entry called `name`, or nullptr.
template <typename Entry, std::size_t N>
const Entry* FindGenerator(const Entry (&table)[N], std::string_view name) {
  for (const Entry& entry : table) {
    if (entry.name == name) return &entry;
  }
  return nullptr;
}

// The names in table order.
template <typename Entry, std::size_t N>
std::vector<std::string_view> GeneratorNames(const Entry (&table)[N]) {
  std::vector<std::string_view> names;
  for (const Entry& entry : table) names.push_back(entry.name);
  return names;
}

// The description of `name`, empty when there is no such entry.
template <typename Entry, std::size_t N>
std::string_view GeneratorDescription(const Entry (&table)[N], std::string_view name) {
  const Entry* entry = FindGenerator(table, name);
  return entry ? entry->description : std::string_view();
}

// "a, b, c": the names for an error message.
template <typename Entry, std::size_t N>
std::string JoinedGeneratorNames(const Entry (&table)[N]) {
  std::string names;
  for (const Entry& entry : table) {
    if (!names.empty()) names += ", ";
    names += entry.name;
  }
  return names;
}

}  // namespace dmc::synth
