// The fuzz harnesses: one function per input the product reads from outside, each taking
// arbitrary bytes. fuzz/<name>.cpp defines gbdcs::fuzz::<name>; built with GBDCS_FUZZ=ON
// (clang) each becomes a libFuzzer binary fuzz_<name>; in the normal build they form
// gbdcs_fuzz_harnesses, which tests/hardening replays over fuzz/corpus/<name>/ and every
// crash kept in tests/hardening/fuzz_regressions/<name>/ (fuzz/README.md).
//
// A harness returns normally for input the code rejects the documented way (its error type,
// a nullopt, an error response). Anything else is a finding: a sanitizer report, an
// exception of another type escaping, or a broken promise checked with require() (e.g. an
// encoded message that fails its own schema), which aborts with the reason.
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace gbdcs::fuzz {

using Bytes = std::span<const std::uint8_t>;

void json_messages(Bytes input);    // contracts: parse_json, schemas, message decoders
void rest_request(Bytes input);     // Beast's HTTP parser -> router -> handlers -> SQLite
void tello_state(Bytes input);      // the Tello state datagram
void airsim_rpc(Bytes input);       // msgpack-RPC stream from AirSim
void tflite_model(Bytes input);     // the .tflite reader
void scenario_loader(Bytes input);  // scenario files
void fixture_recipe(Bytes input);   // fixture recipes

struct Harness {
  std::string_view name;
  void (*run)(Bytes);
};
inline void PrintTo(const Harness& h, std::ostream* out) { *out << h.name; }  // gtest
// Every harness above, by name (the regression test walks this list).
const std::vector<Harness>& harnesses();

// Aborts with "fuzz: <harness>: <what>" unless `ok`: a promise of the code under test broke.
void require(bool ok, std::string_view harness, const std::string& what);

inline std::string_view as_text(Bytes input) {
  return {reinterpret_cast<const char*>(input.data()), input.size()};
}

}  // namespace gbdcs::fuzz

// libFuzzer's entry point, compiled only into the fuzz_<name> binaries.
#ifdef GBDCS_LIBFUZZER
#define GBDCS_FUZZ_ENTRY(name)                                                      \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    gbdcs::fuzz::name(gbdcs::fuzz::Bytes(data, size));                              \
    return 0;                                                                       \
  }
#else
#define GBDCS_FUZZ_ENTRY(name)
#endif
