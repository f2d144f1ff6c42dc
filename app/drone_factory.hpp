// make_drone: every drone the binary can fly, by name. The registry's adapters (dummy, ...)
// plus the MuJoCo twin, which lives in sim/ and so cannot be registered in adapters/registry
// (adapters never depend on sim). The app hands this to core as a control::AdapterFactory.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"

namespace gbdcs::app {

// "twin" -> sim::TwinAdapter (options: sim::TwinAdapterOptions JSON); anything else ->
// adapters::make_adapter. Throws std::invalid_argument for an unknown name or a bad option,
// std::runtime_error when the twin's model cannot be loaded.
std::unique_ptr<control::DroneAdapter> make_drone(std::string_view name,
                                                  const contracts::Clock& clock,
                                                  const nlohmann::json& options = {});
std::vector<std::string> drone_names();

}  // namespace gbdcs::app
