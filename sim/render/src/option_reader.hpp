// OptionReader: reads an options struct from a JSON object key by key and rejects keys it was
// not asked for, with contracts::JsonOptionReader's message format
// ("<owner>: '<key>' <problem>"). It adds the bool and string keys the render options need.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::sim::detail {

class OptionReader {
 public:
  OptionReader(const nlohmann::json& doc, std::string owner) : doc_(doc), owner_(std::move(owner)) {
    contracts::require(doc_.is_object(), owner_, "(document)", "must be a JSON object");
  }

  template <typename T>
  void read(const std::string& key, T& out) {
    known_.push_back(key);
    const auto it = doc_.find(key);
    if (it == doc_.end()) {
      return;
    }
    if constexpr (std::is_same_v<T, bool>) {
      contracts::require(it->is_boolean(), owner_, key, "must be true or false");
    } else if constexpr (std::is_same_v<T, std::string>) {
      contracts::require(it->is_string(), owner_, key, "must be a string");
    } else if constexpr (std::is_integral_v<T>) {
      contracts::require(it->is_number_integer(), owner_, key, "must be an integer");
    } else {
      contracts::require(it->is_number(), owner_, key, "must be a number");
    }
    out = it->get<T>();
  }

  void finish() const {
    for (const auto& item : doc_.items()) {
      bool known = false;
      for (const auto& key : known_) {
        known = known || key == item.key();
      }
      contracts::require(known, owner_, item.key(), "is not a known option");
    }
  }

 private:
  const nlohmann::json& doc_;
  std::string owner_;
  std::vector<std::string> known_;
};

}  // namespace gbdcs::sim::detail
