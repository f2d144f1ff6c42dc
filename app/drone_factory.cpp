#include "drone_factory.hpp"

#include <stdexcept>

#include "gbdcs/adapters/registry.hpp"
#include "gbdcs/sim/twin_adapter.hpp"

namespace gbdcs::app {

std::unique_ptr<control::DroneAdapter> make_drone(std::string_view name,
                                                  const contracts::Clock& clock,
                                                  const nlohmann::json& options) {
  if (name == "twin") {
    return std::make_unique<sim::TwinAdapter>(
        clock, options.is_null() ? sim::TwinAdapterOptions{}
                                 : sim::TwinAdapterOptions::from_json(options));
  }
  try {
    return adapters::make_adapter(name, clock, options);
  } catch (const std::invalid_argument& e) {
    // The registry lists its own drones; add the twin to an unknown-name message.
    const std::string what = e.what();
    if (what.rfind("unknown adapter", 0) == 0 && what.back() == ')') {
      throw std::invalid_argument(what.substr(0, what.size() - 1) + ", twin)");
    }
    throw;
  }
}

std::vector<std::string> drone_names() {
  auto names = adapters::adapter_names();
  names.emplace_back("twin");
  return names;
}

}  // namespace gbdcs::app
