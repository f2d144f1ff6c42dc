#include "fuzz_harness.hpp"

#include <cstdio>
#include <cstdlib>

namespace gbdcs::fuzz {

void require(bool ok, std::string_view harness, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz: %.*s: %s\n", static_cast<int>(harness.size()), harness.data(),
               what.c_str());
  std::abort();
}

}  // namespace gbdcs::fuzz
