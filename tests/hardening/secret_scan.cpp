#include "secret_scan.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace gbdcs::hardening {
namespace {

struct Rule {
  const char* name;
  std::regex pattern;
};

const std::vector<Rule>& rules() {
  static const std::vector<Rule> kRules = [] {
    const auto flags = std::regex::ECMAScript | std::regex::optimize;
    std::vector<Rule> r;
    r.push_back({"private-key", std::regex(R"(-----BEGIN ([A-Z]+ )?PRIVATE KEY-----)", flags)});
    r.push_back({"aws-access-key", std::regex(R"(\b(AKIA|ASIA)[0-9A-Z]{16}\b)", flags)});
    r.push_back({"github-token",
                 std::regex(R"(\b(gh[pousr]_[A-Za-z0-9]{36}|github_pat_[A-Za-z0-9_]{40,}))", flags)});
    r.push_back({"slack-token", std::regex(R"(\bxox[bpars]-[A-Za-z0-9-]{10,})", flags)});
    r.push_back({"jwt",
                 std::regex(R"(\beyJ[A-Za-z0-9_-]{8,}\.eyJ[A-Za-z0-9_-]{8,}\.[A-Za-z0-9_-]{8,})", flags)});
    r.push_back({"password-assign",
                 std::regex(R"((password|passwd|secret|token|api[_-]?key)[A-Za-z_]*["']?\s*[:=]\s*["']([^"'\s]{8,})["'])",
                            flags | std::regex::icase)});
    return r;
  }();
  return kRules;
}

std::string mask(std::string_view s) {
  if (s.size() <= 8) return std::string(s.size(), '*');
  return std::string(s.substr(0, 4)) + "..." + std::string(s.substr(s.size() - 4));
}

bool looks_random(const std::string& value) {
  bool upper = false, lower = false, digit = false;
  for (char c : value) {
    upper |= std::isupper(static_cast<unsigned char>(c)) != 0;
    lower |= std::islower(static_cast<unsigned char>(c)) != 0;
    digit |= std::isdigit(static_cast<unsigned char>(c)) != 0;
  }
  return digit || (upper && lower);
}

bool is_token_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/' || c == '=' ||
         c == '_' || c == '-';
}

// Mean length of the runs of lower-case letters: about 1.7 in random base64, 4 and more in
// CamelCase identifiers and words.
double mean_lower_run(std::string_view s) {
  int runs = 0, letters = 0;
  bool in_run = false;
  for (char c : s) {
    const bool lower = std::islower(static_cast<unsigned char>(c)) != 0;
    if (lower) {
      ++letters;
      if (!in_run) ++runs;
    }
    in_run = lower;
  }
  return runs == 0 ? 0.0 : static_cast<double>(letters) / runs;
}

// Base64-like runs of 32+ characters with all three character classes and high entropy.
void scan_entropy(const std::string& path, int line_no, std::string_view line,
                  std::vector<Finding>& out) {
  std::size_t i = 0;
  while (i < line.size()) {
    if (!is_token_char(line[i])) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < line.size() && is_token_char(line[j])) ++j;
    const std::string_view run = line.substr(i, j - i);
    if (run.size() >= 32) {
      bool upper = false, lower = false, digit = false;
      for (char c : run) {
        upper |= std::isupper(static_cast<unsigned char>(c)) != 0;
        lower |= std::islower(static_cast<unsigned char>(c)) != 0;
        digit |= std::isdigit(static_cast<unsigned char>(c)) != 0;
      }
      // Paths and identifiers (a/b/c, snake_case_words) are long but low in entropy.
      if (upper && lower && digit && shannon_entropy_bits(run) > 4.3 && mean_lower_run(run) < 2.5)
        out.push_back({path, line_no, "high-entropy", mask(run)});
    }
    i = j;
  }
}

}  // namespace

double shannon_entropy_bits(std::string_view s) {
  if (s.empty()) return 0.0;
  std::array<int, 256> counts{};
  for (unsigned char c : s) ++counts[c];
  double h = 0.0;
  for (int n : counts) {
    if (n == 0) continue;
    const double p = static_cast<double>(n) / static_cast<double>(s.size());
    h -= p * std::log2(p);
  }
  return h;
}

std::vector<Finding> scan_text(const std::string& path, std::string_view text) {
  std::vector<Finding> out;
  int line_no = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string line(text.substr(start, end - start));
    ++line_no;
    for (const auto& rule : rules()) {
      std::smatch m;
      if (!std::regex_search(line, m, rule.pattern)) continue;
      // A literal without digits or mixed case ('new-password', 'smoke-token') is a word, not a
      // credential.
      if (std::string_view(rule.name) == "password-assign" && !looks_random(m.str(2))) continue;
      out.push_back({path, line_no, rule.name, mask(m.str(0))});
    }
    scan_entropy(path, line_no, line, out);
    if (end == text.size()) break;
    start = end + 1;
  }
  return out;
}

bool glob_match(std::string_view glob, std::string_view path) {
  if (glob.empty()) return path.empty();
  if (glob.substr(0, 2) == "**") {
    for (std::size_t k = 0; k <= path.size(); ++k)
      if (glob_match(glob.substr(2), path.substr(k))) return true;
    return false;
  }
  if (glob[0] == '*') {
    for (std::size_t k = 0; k <= path.size(); ++k) {
      if (glob_match(glob.substr(1), path.substr(k))) return true;
      if (k < path.size() && path[k] == '/') break;
    }
    return false;
  }
  return !path.empty() && glob[0] == path[0] && glob_match(glob.substr(1), path.substr(1));
}

std::vector<AllowEntry> parse_allow_list(std::string_view text) {
  std::vector<AllowEntry> out;
  std::istringstream in{std::string(text)};
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    AllowEntry e;
    std::string extra;
    if (!(words >> e.glob)) continue;
    words >> e.rule;
    if (words >> extra)
      throw std::invalid_argument(".secret-scan-allow line " + std::to_string(n) +
                                  ": expected `PATH_GLOB [rule]`, got a third word '" + extra +
                                  "'; put comments after #");
    out.push_back(e);
  }
  return out;
}

bool allowed(const Finding& finding, const std::vector<AllowEntry>& allow) {
  for (const auto& e : allow)
    if (glob_match(e.glob, finding.path) && (e.rule.empty() || e.rule == finding.rule))
      return true;
  return false;
}

}  // namespace gbdcs::hardening
