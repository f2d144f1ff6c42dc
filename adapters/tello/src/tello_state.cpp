#include "gbdcs/adapters/tello_state.hpp"

#include <cctype>
#include <charconv>
#include <cmath>

namespace gbdcs::adapters {
namespace {

constexpr std::size_t kMaxDatagram = 2048;

bool key_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}

std::optional<double> number(const std::string& text) {
  const char* first = text.data();
  const char* last = text.data() + text.size();
  while (first < last && *first == ' ') ++first;
  if (first < last && *first == '+') ++first;
  double value = 0;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec != std::errc() || ptr != last || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

std::optional<std::map<std::string, std::string>> parse_state_pairs(std::string_view datagram,
                                                                    std::string& why) {
  if (datagram.empty()) {
    why = "empty datagram";
    return std::nullopt;
  }
  if (datagram.size() > kMaxDatagram) {
    why = "datagram of " + std::to_string(datagram.size()) + " bytes (a state is < 300)";
    return std::nullopt;
  }
  while (!datagram.empty() && (datagram.back() == '\n' || datagram.back() == '\r' ||
                               datagram.back() == ' ' || datagram.back() == '\0')) {
    datagram.remove_suffix(1);
  }
  std::map<std::string, std::string> pairs;
  std::size_t start = 0;
  while (start <= datagram.size()) {
    const auto end = std::min(datagram.find(';', start), datagram.size());
    std::string_view piece = datagram.substr(start, end - start);
    start = end + 1;
    while (!piece.empty() && piece.front() == ' ') piece.remove_prefix(1);
    if (piece.empty()) continue;
    const auto colon = piece.find(':');
    if (colon == std::string_view::npos || colon == 0) {
      why = "piece '" + std::string(piece.substr(0, 40)) + "' is not key:value";
      return std::nullopt;
    }
    const auto key = piece.substr(0, colon);
    const auto value = piece.substr(colon + 1);
    for (char c : key) {
      if (!key_char(c)) {
        why = "bad character in key '" + std::string(key.substr(0, 40)) + "'";
        return std::nullopt;
      }
    }
    for (char c : value) {
      if (c < 0x20 || c > 0x7e) {
        why = "non-printable byte in the value of '" + std::string(key) + "'";
        return std::nullopt;
      }
    }
    pairs[std::string(key)] = std::string(value);
  }
  if (pairs.empty()) {
    why = "no key:value pairs";
    return std::nullopt;
  }
  return pairs;
}

std::optional<TelloState> decode_state(std::string_view datagram, std::string& why) {
  auto pairs = parse_state_pairs(datagram, why);
  if (!pairs) return std::nullopt;
  TelloState s;
  struct Field {
    const char* key;
    double* out;
    bool required;
  };
  const Field fields[] = {
      {"pitch", &s.pitch_deg, false}, {"roll", &s.roll_deg, false}, {"yaw", &s.yaw_deg, true},
      {"vgx", &s.vgx, false},         {"vgy", &s.vgy, false},       {"vgz", &s.vgz, false},
      {"templ", &s.templ_c, false},   {"temph", &s.temph_c, false}, {"tof", &s.tof_cm, false},
      {"h", &s.h_cm, true},           {"bat", &s.bat_pct, true},    {"baro", &s.baro_m, false},
      {"time", &s.time_s, false},     {"agx", &s.agx, false},       {"agy", &s.agy, false},
      {"agz", &s.agz, false},
  };
  for (const auto& f : fields) {
    const auto it = pairs->find(f.key);
    if (it == pairs->end()) {
      if (f.required) {
        why = std::string("no '") + f.key + "' field";
        return std::nullopt;
      }
      continue;
    }
    const auto v = number(it->second);
    if (!v) {
      why = std::string("'") + f.key + "' is not a number: '" + it->second.substr(0, 20) + "'";
      return std::nullopt;
    }
    *f.out = *v;
  }
  if (s.bat_pct < 0 || s.bat_pct > 100) {
    why = "'bat' out of 0...100: " + pairs->at("bat");
    return std::nullopt;
  }
  s.fields = std::move(*pairs);
  return s;
}

}  // namespace gbdcs::adapters
