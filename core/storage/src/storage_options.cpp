#include "gbdcs/storage/storage_options.hpp"

#include <array>
#include <limits>
#include <string_view>

namespace gbdcs::storage {

namespace {

constexpr std::array<std::string_view, 5> kKnownKeys = {
    "path", "max_size_bytes", "telemetry_retention_days", "read_only", "busy_timeout_ms"};

std::string known_keys() {
  std::string out;
  for (auto key : kKnownKeys) {
    if (!out.empty()) out += ", ";
    out += key;
  }
  return out;
}

[[noreturn]] void fail(std::string_view key, const std::string& problem) {
  throw StorageError("storage options: '" + std::string(key) + "' " + problem);
}

std::int64_t integer_in(const nlohmann::json& value, std::string_view key, std::int64_t min,
                        std::int64_t max) {
  if (!value.is_number_integer()) fail(key, "must be an integer, got " + value.dump());
  // Unsigned JSON numbers above INT64_MAX would wrap; compare before converting.
  if (value.is_number_unsigned() && value.get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
    fail(key, "must be at most " + std::to_string(max) + ", got " + value.dump());
  }
  const auto v = value.get<std::int64_t>();
  if (v < min || v > max) {
    fail(key, "must be between " + std::to_string(min) + " and " + std::to_string(max) + ", got " +
                  value.dump());
  }
  return v;
}

}  // namespace

StorageOptions storage_options_from_json(const nlohmann::json& doc) {
  if (!doc.is_object()) {
    throw StorageError("storage options must be a JSON object, got " + doc.dump());
  }
  StorageOptions options;
  for (const auto& [key, value] : doc.items()) {
    if (key == "path") {
      if (!value.is_string() || value.get<std::string>().empty()) {
        fail(key, "must be a non-empty string, got " + value.dump());
      }
      options.path = value.get<std::string>();
    } else if (key == "max_size_bytes") {
      options.max_size_bytes = integer_in(value, key, 1, std::numeric_limits<std::int64_t>::max());
    } else if (key == "telemetry_retention_days") {
      // 100 years is "keep forever" without overflowing the millisecond cut-off.
      options.telemetry_retention_days = static_cast<int>(integer_in(value, key, 1, 36'500));
    } else if (key == "read_only") {
      if (!value.is_boolean()) fail(key, "must be true or false, got " + value.dump());
      options.read_only = value.get<bool>();
    } else if (key == "busy_timeout_ms") {
      options.busy_timeout_ms =
          static_cast<int>(integer_in(value, key, 0, std::numeric_limits<int>::max()));
    } else {
      fail(key, "is not a storage option (known: " + known_keys() + ")");
    }
  }
  return options;
}

}  // namespace gbdcs::storage
