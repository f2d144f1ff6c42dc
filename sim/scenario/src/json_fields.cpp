#include "json_fields.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace gbdcs::sim::detail {

std::string json_type_name(const nlohmann::json& v) {
  if (v.is_null()) return "null";
  if (v.is_boolean()) return "a boolean";
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_array()) return "an array";
  return "an object";
}

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (const auto& s : items) {
    if (!out.empty()) out += sep;
    out += s;
  }
  return out;
}

namespace {
std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

Fields::Fields(const nlohmann::json& doc, std::string origin, std::string path)
    : doc_(doc), origin_(std::move(origin)), path_(std::move(path)) {
  if (!doc_.is_object()) {
    throw ScenarioError(origin_ + ": " + (path_.empty() ? std::string("the document") : path_) +
                        " must be a JSON object, not " + json_type_name(doc_));
  }
}

std::string Fields::field(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void Fields::fail(const std::string& key, const std::string& problem) const {
  throw ScenarioError(origin_ + ": " + (key.empty() ? path_ : field(key)) + ": " + problem);
}

bool Fields::has(const std::string& key) {
  known_.push_back(key);
  return doc_.contains(key);
}

const nlohmann::json& Fields::get(const std::string& key) {
  if (!has(key)) fail(key, "is required (see scenarios/schema.json and docs/SCENARIOS.md)");
  return doc_.at(key);
}

std::string Fields::string(const std::string& key) {
  const auto& v = get(key);
  if (!v.is_string()) fail(key, "must be a string, not " + json_type_name(v));
  return v.get<std::string>();
}

std::optional<std::string> Fields::opt_string(const std::string& key) {
  if (!has(key)) return std::nullopt;
  return string(key);
}

double Fields::number(const std::string& key, double min, double max) {
  const auto& v = get(key);
  if (!v.is_number()) fail(key, "must be a number, not " + json_type_name(v));
  const double d = v.get<double>();
  if (!std::isfinite(d) || d < min || d > max) {
    fail(key, "is " + number_text(d) + "; use a value from " + number_text(min) + " to " +
                  number_text(max));
  }
  return d;
}

std::optional<double> Fields::opt_number(const std::string& key, double min, double max) {
  if (!has(key)) return std::nullopt;
  return number(key, min, max);
}

std::optional<int> Fields::opt_int(const std::string& key, int min, int max) {
  if (!has(key)) return std::nullopt;
  const auto& v = doc_.at(key);
  if (!v.is_number_integer()) fail(key, "must be a whole number, not " + json_type_name(v));
  const auto i = v.get<long long>();
  if (i < min || i > max) {
    fail(key, "is " + std::to_string(i) + "; use a whole number from " + std::to_string(min) +
                  " to " + std::to_string(max));
  }
  return static_cast<int>(i);
}

std::optional<bool> Fields::opt_bool(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const auto& v = doc_.at(key);
  if (!v.is_boolean()) fail(key, "must be true or false, not " + json_type_name(v));
  return v.get<bool>();
}

std::vector<std::string> Fields::strings(const std::string& key) {
  std::vector<std::string> out;
  if (!has(key)) return out;
  const auto& v = doc_.at(key);
  if (!v.is_array()) fail(key, "must be an array of strings, not " + json_type_name(v));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_string()) {
      fail(key + "[" + std::to_string(i) + "]", "must be a string, not " + json_type_name(v[i]));
    }
    out.push_back(v[i].get<std::string>());
  }
  return out;
}

std::optional<std::array<double, 2>> Fields::range(const std::string& key, double min,
                                                   double max) {
  if (!has(key)) return std::nullopt;
  const auto& v = doc_.at(key);
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number()) {
    fail(key, "must be [low, high], two numbers");
  }
  std::array<double, 2> r{v[0].get<double>(), v[1].get<double>()};
  if (r[0] > r[1]) fail(key, "low is above high; write [low, high]");
  if (r[0] < min || r[1] > max) {
    fail(key, "must lie within [" + number_text(min) + ", " + number_text(max) + "]");
  }
  return r;
}

void Fields::finish(const std::string& what) const {
  std::vector<std::string> unknown;
  for (const auto& [key, value] : doc_.items()) {
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) unknown.push_back(key);
  }
  if (unknown.empty()) return;
  auto known = known_;
  std::sort(known.begin(), known.end());
  known.erase(std::unique(known.begin(), known.end()), known.end());
  fail(unknown.front(), "unknown key for " + what + "; remove it or use one of: " + join(known));
}

}  // namespace gbdcs::sim::detail
