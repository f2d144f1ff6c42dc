// The secret scan over every tracked file, and proof that each rule finds what it is for.
// Planted secrets are assembled at run time so this file itself stays clean.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "secret_scan.hpp"

namespace gbdcs::hardening {
namespace {

std::vector<std::string> rules_found(const std::string& text) {
  std::vector<std::string> out;
  for (const auto& f : scan_text("planted.txt", text)) out.push_back(f.rule);
  return out;
}

bool found(const std::string& text, const std::string& rule) {
  const auto r = rules_found(text);
  return std::find(r.begin(), r.end(), rule) != r.end();
}

TEST(SecretScan, FindsEachKindOfSecret) {
  EXPECT_TRUE(found("-----BEGIN " + std::string("RSA PRIVATE KEY-----"), "private-key"));
  EXPECT_TRUE(found("id = " + std::string("AKIA") + "Z7Q2MXL4KD9PW3RT", "aws-access-key"));
  EXPECT_TRUE(found(std::string("ghp_") + std::string(36, 'a'), "github-token"));
  EXPECT_TRUE(found(std::string("xoxb-") + "1234567890-abcdef", "slack-token"));
  EXPECT_TRUE(found(std::string("eyJ") + "hbGciOiJIUzI1NiJ9." + "eyJ" + "zdWIiOiIxMjM0In0." +
                        "dBjftJeZ4CVPmB92" + "K27uhbUJU1p1r_wW1gFWFOEjXk",
                    "jwt"));
  EXPECT_TRUE(found(std::string("db_pass") + "word = \"" + "hunter2hunter2\"", "password-assign"));
  EXPECT_TRUE(found(std::string("GBDCS_JWT_SEC") + "RET: 'k8Vd3pQz77LmN2'", "password-assign"));
  EXPECT_TRUE(found("blob " + std::string("q9X2") + "vT7mLr4ZkP0wYc8N" + std::string("bH3sJd6FgA1eUi5Oy"), "high-entropy"));
}

TEST(SecretScan, LeavesOrdinaryCodeAlone) {
  EXPECT_TRUE(rules_found("const std::string password = read_env(\"GBDCS_JWT_SECRET\");").empty());
  EXPECT_TRUE(rules_found("core/contracts/include/gbdcs/contracts/json_options_reader.hpp").empty());
  EXPECT_TRUE(rules_found("token = \"\";  // set at login").empty());
  EXPECT_TRUE(rules_found("autoComplete={login ? 'current-password' : 'new-password'}").empty());
  EXPECT_TRUE(rules_found("token: 'smoke-token',").empty());
  EXPECT_TRUE(rules_found("e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855").empty())
      << "a hex digest has no upper case: not a secret by itself";
  EXPECT_TRUE(rules_found("ThisIsAVeryLongCamelCaseIdentifierName2").empty())
      << "identifiers are long but low in entropy";
}

TEST(SecretScan, MasksWhatItReports) {
  const auto f = scan_text("x", "key " + std::string("AKIA") + "Z7Q2MXL4KD9PW3RT");
  ASSERT_FALSE(f.empty());
  EXPECT_EQ(f[0].line, 1);
  EXPECT_EQ(f[0].excerpt.find("Z7Q2MXL4KD9P"), std::string::npos);
}

TEST(SecretScan, AllowListByGlobAndRule) {
  const auto allow = parse_allow_list("# fixtures\nweb/package-lock.json high-entropy\ntests/**/keys/*\n");
  ASSERT_EQ(allow.size(), 2u);
  EXPECT_TRUE(allowed({"web/package-lock.json", 3, "high-entropy", ""}, allow));
  EXPECT_FALSE(allowed({"web/package-lock.json", 3, "jwt", ""}, allow));
  EXPECT_TRUE(allowed({"tests/server/keys/test.pem", 1, "private-key", ""}, allow));
  EXPECT_FALSE(allowed({"tests/server/keys/sub/test.pem", 1, "private-key", ""}, allow));
  EXPECT_FALSE(allowed({"core/server/src/auth.cpp", 9, "jwt", ""}, allow));
  EXPECT_THROW(parse_allow_list("a b c\n"), std::invalid_argument);
}

std::string run(const std::string& command) {
  std::array<char, 4096> buf{};
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return out;
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe.get())) > 0) out.append(buf.data(), n);
  return out;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The gate: no tracked file holds a secret, except what the allow-list names.
TEST(SecretScan, TrackedFilesHoldNoSecrets) {
  // GBDCS_SECRET_SCAN_ROOT scans another checkout (a branch before it is merged).
  const char* other = std::getenv("GBDCS_SECRET_SCAN_ROOT");
  const std::filesystem::path root = other && *other ? other : GBDCS_SOURCE_DIR;
  const std::string listing = run("git -C '" + root.string() + "' ls-files -z 2>/dev/null");
  ASSERT_FALSE(listing.empty()) << root << " is not a git checkout (or git is missing): the "
                                << "scan needs `git ls-files`; run it from a clone";
  std::vector<AllowEntry> allow;
  if (std::filesystem::exists(root / ".secret-scan-allow"))
    allow = parse_allow_list(read_file(root / ".secret-scan-allow"));

  std::size_t files = 0;
  std::vector<Finding> findings;
  std::size_t start = 0;
  while (start < listing.size()) {
    std::size_t end = listing.find('\0', start);
    if (end == std::string::npos) end = listing.size();
    const std::string rel = listing.substr(start, end - start);
    start = end + 1;
    const auto path = root / rel;
    if (!std::filesystem::is_regular_file(path)) continue;
    const std::string text = read_file(path);
    if (text.find('\0') != std::string::npos) continue;  // binary (models, images)
    ++files;
    for (auto& f : scan_text(rel, text))
      if (!allowed(f, allow)) findings.push_back(std::move(f));
  }
  EXPECT_GT(files, 50u) << "too few files scanned: is " << root << " the repository?";
  for (const auto& f : findings)
    ADD_FAILURE() << f.path << ":" << f.line << ": possible secret (" << f.rule << ": "
                  << f.excerpt << "). Remove it and read it from the environment "
                  << "(.env.example); if it is a harmless test fixture, add `" << f.path << " "
                  << f.rule << "` to .secret-scan-allow";
}

}  // namespace
}  // namespace gbdcs::hardening
