// The secret scan: looks through text for keys, tokens and passwords before they are committed.
//
// Rules (each finding names one)
//   private-key     a PEM private key header
//   aws-access-key  AKIA/ASIA followed by 16 upper-case letters or digits
//   github-token    ghp_/gho_/ghu_/ghs_/ghr_ followed by 36 characters, or github_pat_...
//   slack-token     xoxb-/xoxp-/xoxa-/xoxr-/xoxs-...
//   jwt             three base64url parts, the first two starting with eyJ
//   password-assign password/secret/token/api_key assigned a quoted literal of 8+ characters
//                   that has a digit or mixed case (not a plain word like 'new-password')
//   high-entropy    a base64-like run of 32+ characters with upper case, lower case and digits
//                   and Shannon entropy above 4.3 bits per character, whose lower-case runs
//                   are short (random text, not CamelCase identifiers or words)
// Allow-list (`.secret-scan-allow` at the repository root): one entry a line, `#` comments;
// `PATH_GLOB` allows every rule in matching files, `PATH_GLOB rule` one rule. Globs use `*`
// (any characters but `/`) and `**` (any characters).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace gbdcs::hardening {

struct Finding {
  std::string path;
  int line = 0;
  std::string rule;
  std::string excerpt;  // the matched text, middle masked
};

struct AllowEntry {
  std::string glob;
  std::string rule;  // empty = every rule
};

std::vector<Finding> scan_text(const std::string& path, std::string_view text);
double shannon_entropy_bits(std::string_view s);
bool glob_match(std::string_view glob, std::string_view path);
// Throws std::invalid_argument naming the line of a malformed entry.
std::vector<AllowEntry> parse_allow_list(std::string_view text);
bool allowed(const Finding& finding, const std::vector<AllowEntry>& allow);

}  // namespace gbdcs::hardening
