// Reads an options struct from a JSON object, key by key, and rejects what it does not know.
// Used by every options struct in the core and the adapters.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace gbdcs::contracts {

// Each read() takes a key if present (absent keys keep the struct's default); finish() throws
// std::invalid_argument naming any key that no read() asked for. Every message starts with
// the options' name and names the key, so a bad config file points at its own line.
class JsonOptionReader {
 public:
  JsonOptionReader(const nlohmann::json& doc, std::string owner);
  void read(const std::string& key, double& out);
  void read(const std::string& key, int& out);
  void finish() const;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

 private:
  const nlohmann::json& doc_;
  std::string owner_;
  std::vector<std::string> known_;
};

// Throws std::invalid_argument "<owner>: '<key>' <problem>" unless `ok`.
void require(bool ok, const std::string& owner, const std::string& key,
             const std::string& problem);

}  // namespace gbdcs::contracts
