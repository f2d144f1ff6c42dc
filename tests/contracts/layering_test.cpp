// The one-way rules of ARCHITECTURE.md, checked on the source tree.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace fs = std::filesystem;

namespace {

std::vector<std::pair<std::string, std::string>> offending_lines(const fs::path& root,
                                                                 const std::regex& pattern,
                                                                 const std::string& exempt = {}) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    const auto ext = entry.path().extension();
    if (ext != ".cpp" && ext != ".hpp" && ext != ".h") continue;
    if (!exempt.empty() && entry.path().string().find(exempt) != std::string::npos) continue;
    std::ifstream in(entry.path());
    std::string line;
    while (std::getline(in, line)) {
      if (std::regex_search(line, pattern)) out.emplace_back(entry.path().string(), line);
    }
  }
  return out;
}

std::string describe(const std::vector<std::pair<std::string, std::string>>& lines) {
  std::ostringstream s;
  for (const auto& [file, line] : lines) s << file << ": " << line << "\n";
  return s.str();
}

const fs::path kRoot = GBDCS_SOURCE_DIR;

TEST(Layering, CoreNeverIncludesSimOrAdapters) {
  auto bad = offending_lines(kRoot / "core",
                             std::regex(R"(#\s*include\s*[<"]gbdcs/(sim|adapters)/)"));
  EXPECT_TRUE(bad.empty()) << describe(bad);
}

TEST(Layering, AdaptersNeverIncludeServerOrOtherAdapters) {
  auto bad = offending_lines(kRoot / "adapters", std::regex(R"(#\s*include\s*[<"]gbdcs/server/)"));
  EXPECT_TRUE(bad.empty()) << describe(bad);
  // Each adapter folder includes only its own headers among gbdcs/adapters/ (the registry may
  // include all of them).
  for (const auto& dir : fs::directory_iterator(kRoot / "adapters")) {
    if (!dir.is_directory() || dir.path().filename() == "registry") continue;
    const auto own = dir.path().filename().string();
    auto foreign = offending_lines(
        dir.path(), std::regex(R"(#\s*include\s*[<"]gbdcs/adapters/(?!)" + own + R"(_))"));
    EXPECT_TRUE(foreign.empty()) << describe(foreign);
  }
}

TEST(Layering, NoBareClockReadsInCore) {
  // Time in core comes from the injected Clock; SteadyClock is the one place allowed.
  auto bad = offending_lines(kRoot / "core",
                             std::regex(R"((steady_clock|system_clock|high_resolution_clock)::now)"),
                             "contracts/src/clock.cpp");
  EXPECT_TRUE(bad.empty()) << describe(bad);
}

TEST(Layering, NoUnseededRandomnessInCore) {
  auto bad = offending_lines(kRoot / "core", std::regex(R"(std::random_device|\brand\s*\()"));
  EXPECT_TRUE(bad.empty()) << describe(bad);
}

}  // namespace
