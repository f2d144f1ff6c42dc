// The loader's parts: the scenario document (scenario_loader.cpp), its events
// (event_loader.cpp) and its criteria (criteria_loader.cpp), sharing the name tables' helpers.
#pragma once

#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gbdcs/sim/scenario.hpp"

namespace gbdcs::sim::detail {

template <class Enum, std::size_t N>
std::vector<std::string> names_of(const std::array<std::pair<Enum, std::string_view>, N>& table) {
  std::vector<std::string> out;
  for (const auto& [e, n] : table) out.emplace_back(n);
  return out;
}

template <class Enum, std::size_t N>
std::string_view name_in(const std::array<std::pair<Enum, std::string_view>, N>& table, Enum e) {
  for (const auto& [k, n] : table) {
    if (k == e) return n;
  }
  return "?";
}

template <class Enum, std::size_t N>
std::optional<Enum> find_in(const std::array<std::pair<Enum, std::string_view>, N>& table,
                            std::string_view s) {
  for (const auto& [k, n] : table) {
    if (n == s) return k;
  }
  return std::nullopt;
}

// events[i]: one timed event, strict (every error names the field and the fix).
ScenarioEvent read_event(const nlohmann::json& v, const std::string& origin,
                         const std::string& path, double timeout_s);
// criteria[i]: one criterion; `s` gives the events and timeout it may refer to.
Criterion read_criterion(const nlohmann::json& v, const std::string& origin,
                         const std::string& path, std::size_t index, const Scenario& s);

}  // namespace gbdcs::sim::detail
