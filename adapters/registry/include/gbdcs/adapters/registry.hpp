// The adapter registry: one line per drone. Adding a drone touches its own folder and this
// registry, nothing else. The app hands make_adapter to core as a control::AdapterFactory.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"

namespace gbdcs::adapters {

std::vector<std::string> adapter_names();
// Throws std::invalid_argument naming the known adapters for an unknown name, or a bad option.
std::unique_ptr<control::DroneAdapter> make_adapter(std::string_view name,
                                                    const contracts::Clock& clock,
                                                    const nlohmann::json& options = {});

}  // namespace gbdcs::adapters
