#include "gbdcs/adapters/registry.hpp"

#include <functional>
#include <stdexcept>
#include <utility>

#include "gbdcs/adapters/airsim_adapter.hpp"
#include "gbdcs/adapters/dummy_adapter.hpp"
#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/adapters/xfly_profile.hpp"

namespace gbdcs::adapters {
namespace {

using Maker = std::function<std::unique_ptr<control::DroneAdapter>(const contracts::Clock&,
                                                                   const nlohmann::json&)>;

const std::vector<std::pair<std::string, Maker>>& entries() {
  static const std::vector<std::pair<std::string, Maker>> kEntries = {
      {"dummy",
       [](const contracts::Clock& clock, const nlohmann::json& options) {
         return std::make_unique<DummyDroneAdapter>(
             clock, options.is_null() ? DummyOptions{} : DummyOptions::from_json(options));
       }},
      {"airsim",
       [](const contracts::Clock& clock, const nlohmann::json& options) {
         return std::make_unique<AirSimAdapter>(clock, AirSimOptions::from_json(options));
       }},
      {"tello",
       [](const contracts::Clock& clock, const nlohmann::json& options) {
         return std::make_unique<TelloAdapter>(clock, TelloOptions::from_json(options));
       }},
      {"xfly",
       [](const contracts::Clock& clock, const nlohmann::json& options) {
         // XFly: the Tello engine with the XFly profile (adapters/xfly, docs/ADAPTERS.md).
         const XflyProfile profile;
         TelloOptions defaults;
         defaults.name = profile.name;
         defaults.drone_label = profile.label;
         defaults.wifi_hint = profile.wifi_hint;
         return std::make_unique<TelloAdapter>(
             clock, TelloOptions::from_json(xfly_engine_options(options, profile), defaults));
       }},
  };
  return kEntries;
}

}  // namespace

std::vector<std::string> adapter_names() {
  std::vector<std::string> names;
  for (const auto& [name, maker] : entries()) names.push_back(name);
  return names;
}

std::unique_ptr<control::DroneAdapter> make_adapter(std::string_view name,
                                                    const contracts::Clock& clock,
                                                    const nlohmann::json& options) {
  for (const auto& [n, maker] : entries()) {
    if (n == name) return maker(clock, options);
  }
  std::string known;
  for (const auto& n : adapter_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown adapter '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace gbdcs::adapters
