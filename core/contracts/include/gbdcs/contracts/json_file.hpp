// Reading a JSON document from a file, with errors that name the file and the fix.
//
//   read_json_file<Error>(path, what)   the parsed document; throws Error with
//     "PATH: cannot read the WHAT (check the path)" or "PATH: malformed JSON at byte N".
//   prefix_errors<Error>(path, f)       f(); an Error it throws comes back as "PATH: message".
// Error is the loader's own exception type (constructible from std::string), so callers keep
// their error types.
#pragma once

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace gbdcs::contracts {

template <class Error>
nlohmann::json read_json_file(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot read the " + what + " (check the path)");
  std::stringstream text;
  text << in.rdbuf();
  try {
    return nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(path + ": malformed JSON at byte " + std::to_string(e.byte));
  } catch (const nlohmann::json::exception& e) {  // e.g. a number too large for a double
    throw Error(path + ": malformed JSON: " + e.what());
  }
}

template <class Error, class F>
auto prefix_errors(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
}

}  // namespace gbdcs::contracts
