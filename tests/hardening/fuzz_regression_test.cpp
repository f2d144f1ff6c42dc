// Replays every fuzz seed (fuzz/corpus/<harness>/) and every input a fuzzer ever crashed on
// (tests/hardening/fuzz_regressions/<harness>/, each fixed) through the same harness code the
// libFuzzer binaries run (fuzz/fuzz_harness.hpp), in the ordinary build. A harness aborts
// on a broken promise, so a regression fails (crashes) the test that replays it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_harness.hpp"

namespace {

namespace fs = std::filesystem;
const fs::path kRoot = GBDCS_SOURCE_DIR;

std::vector<fs::path> inputs_in(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().filename() != "README.md") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class FuzzReplay : public ::testing::TestWithParam<gbdcs::fuzz::Harness> {};

TEST_P(FuzzReplay, SeedCorpusAndPastCrashes) {
  const auto& h = GetParam();
  const auto seeds = inputs_in(kRoot / "fuzz" / "corpus" / std::string(h.name));
  ASSERT_FALSE(seeds.empty()) << "fuzz/corpus/" << h.name << " has no seed inputs";
  auto all = seeds;
  const auto crashes = inputs_in(kRoot / "tests" / "hardening" / "fuzz_regressions" / std::string(h.name));
  all.insert(all.end(), crashes.begin(), crashes.end());
  for (const auto& p : all) {
    SCOPED_TRACE(p.string());
    const auto bytes = read_bytes(p);
    h.run(gbdcs::fuzz::Bytes(bytes.data(), bytes.size()));
  }
}

INSTANTIATE_TEST_SUITE_P(Harnesses, FuzzReplay, ::testing::ValuesIn(gbdcs::fuzz::harnesses()),
                         [](const auto& p) { return std::string(p.param.name); });

}  // namespace
