// Strict reading of one JSON object of a scenario file: every error names the field as a JSON
// path ("criteria[2].within_ms") and says how to fix it; finish() rejects unknown keys.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gbdcs/sim/scenario.hpp"

namespace gbdcs::sim::detail {

class Fields {
 public:
  // `path` is the object's own JSON path ("" for the document, "events[3]").
  Fields(const nlohmann::json& doc, std::string origin, std::string path);

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;
  std::string field(const std::string& key) const;  // "events[3].at_s"

  bool has(const std::string& key);  // marks the key known
  const nlohmann::json& get(const std::string& key);  // required; marks it known

  std::string string(const std::string& key);  // required
  std::optional<std::string> opt_string(const std::string& key);
  double number(const std::string& key, double min, double max);  // required, in [min, max]
  std::optional<double> opt_number(const std::string& key, double min, double max);
  std::optional<int> opt_int(const std::string& key, int min, int max);
  std::optional<bool> opt_bool(const std::string& key);
  std::vector<std::string> strings(const std::string& key);  // optional array; [] if absent
  std::optional<std::array<double, 2>> range(const std::string& key, double min, double max);
  void finish(const std::string& what) const;  // unknown keys -> fail naming them and `what`

  const std::string& origin() const { return origin_; }
  const std::string& path() const { return path_; }

 private:
  const nlohmann::json& doc_;
  std::string origin_;
  std::string path_;
  std::vector<std::string> known_;
};

std::string json_type_name(const nlohmann::json& v);
std::string join(const std::vector<std::string>& items, const std::string& sep = ", ");

}  // namespace gbdcs::sim::detail
