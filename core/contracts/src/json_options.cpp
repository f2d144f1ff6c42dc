#include "gbdcs/contracts/json_options.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

namespace gbdcs::contracts {

JsonOptionReader::JsonOptionReader(const nlohmann::json& doc, std::string owner)
    : doc_(doc), owner_(std::move(owner)) {
  if (!doc_.is_object()) {
    throw std::invalid_argument(owner_ + ": options must be a JSON object, got " +
                                std::string(doc_.type_name()));
  }
}

void JsonOptionReader::read(const std::string& key, double& out) {
  known_.push_back(key);
  const auto it = doc_.find(key);
  if (it == doc_.end()) return;
  // Booleans are not numbers here, although nlohmann would convert them.
  if (!it->is_number()) fail(key, "must be a number, got " + std::string(it->type_name()));
  out = it->get<double>();
}

void JsonOptionReader::read(const std::string& key, int& out) {
  known_.push_back(key);
  const auto it = doc_.find(key);
  if (it == doc_.end()) return;
  if (!it->is_number_integer()) {
    fail(key, "must be an integer, got " + std::string(it->type_name()) + " " + it->dump());
  }
  const auto value = it->get<std::int64_t>();
  if (value < -1'000'000 || value > 1'000'000) fail(key, "is out of range: " + it->dump());
  out = static_cast<int>(value);
}

void JsonOptionReader::finish() const {
  for (const auto& [key, value] : doc_.items()) {
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) {
      std::string list;
      for (const auto& k : known_) list += (list.empty() ? "" : ", ") + k;
      fail(key, "is not a known option (known: " + list + ")");
    }
  }
}

void JsonOptionReader::fail(const std::string& key, const std::string& problem) const {
  throw std::invalid_argument(owner_ + ": '" + key + "' " + problem);
}

void require(bool ok, const std::string& owner, const std::string& key,
             const std::string& problem) {
  if (!ok) throw std::invalid_argument(owner + ": '" + key + "' " + problem);
}

}  // namespace gbdcs::contracts
