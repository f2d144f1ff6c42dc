#include "gbdcs/adapters/xfly_profile.hpp"

#include <stdexcept>

namespace gbdcs::adapters {

nlohmann::json xfly_engine_options(const nlohmann::json& options, const XflyProfile& profile) {
  if (!options.is_null() && !options.is_object()) {
    throw std::invalid_argument("xfly options: options must be a JSON object, got " +
                                std::string(options.type_name()));
  }
  nlohmann::json merged = profile.defaults;
  if (options.is_object()) {
    for (const auto& [key, value] : options.items()) merged[key] = value;
  }
  return merged;
}

}  // namespace gbdcs::adapters
