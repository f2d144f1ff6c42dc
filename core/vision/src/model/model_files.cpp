#include "gbdcs/vision/model_files.hpp"

#include <openssl/evp.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#ifndef GBDCS_DEFAULT_MODEL_DIR
#error "GBDCS_DEFAULT_MODEL_DIR must be defined by the build"
#endif

namespace gbdcs::vision {
namespace embedded {
// Generated from core/vision/models.sha256 by gbdcs_embed_files (cmake/GbdcsTarget.cmake).
using EmbeddedFiles = std::vector<std::pair<std::string_view, std::string_view>>;
EmbeddedFiles embedded_files();
}  // namespace embedded

namespace {

// "sha256  file" lines of models.sha256 → the hash for `file`, or empty.
std::string_view find_pin(std::string_view pins, std::string_view file) {
  while (!pins.empty()) {
    const auto end = pins.find('\n');
    std::string_view line = pins.substr(0, end);
    pins = end == std::string_view::npos ? std::string_view{} : pins.substr(end + 1);
    const auto space = line.find(' ');
    if (space == std::string_view::npos) continue;
    std::string_view name = line.substr(space);
    while (!name.empty() && (name.front() == ' ' || name.front() == '*')) name.remove_prefix(1);
    while (!name.empty() && (name.back() == '\r' || name.back() == ' ')) name.remove_suffix(1);
    if (name == file) return line.substr(0, space);
  }
  return {};
}

}  // namespace

std::string_view file_name(ModelKind kind) {
  switch (kind) {
    case ModelKind::kPalmDetectionLite:
      return "palm_detection_lite.tflite";
    case ModelKind::kPalmDetectionFull:
      return "palm_detection_full.tflite";
    case ModelKind::kHandLandmarkLite:
      return "hand_landmark_lite.tflite";
    case ModelKind::kHandLandmarkFull:
      return "hand_landmark_full.tflite";
  }
  throw std::invalid_argument("unknown ModelKind");
}

std::string default_model_dir() {
  const char* env = std::getenv("GBDCS_MODEL_DIR");
  if (env != nullptr && *env != '\0') return env;
  return GBDCS_DEFAULT_MODEL_DIR;
}

std::string sha256_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelError("cannot open " + path);
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) {
    throw ModelError("OpenSSL: cannot start SHA-256");
  }
  std::vector<char> chunk(1 << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const auto got = in.gcount();
    if (got > 0 && EVP_DigestUpdate(ctx.get(), chunk.data(), static_cast<std::size_t>(got)) != 1) {
      throw ModelError("OpenSSL: SHA-256 update failed for " + path);
    }
  }
  if (in.bad()) throw ModelError("read error in " + path);
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(ctx.get(), digest.data(), &length) != 1) {
    throw ModelError("OpenSSL: SHA-256 final failed for " + path);
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 0xF];
  }
  return hex;
}

std::string_view pinned_sha256(ModelKind kind) {
  for (const auto& [name, text] : embedded::embedded_files()) {
    if (name != "models.sha256") continue;
    const auto pin = find_pin(text, file_name(kind));
    if (!pin.empty()) return pin;
  }
  throw ModelError(std::string(file_name(kind)) + ": no pinned SHA-256 in models.sha256");
}

std::string verified_model_path(ModelKind kind, const std::string& dir) {
  const std::string file(file_name(kind));
  const std::filesystem::path path = std::filesystem::path(dir) / file;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw ModelError(file + " not found in " + dir +
                     " (run ci/fetch-models, or set GBDCS_MODEL_DIR)");
  }
  const std::string expected(pinned_sha256(kind));
  const std::string got = sha256_file(path.string());
  if (got != expected) {
    throw ModelError(file + ": SHA-256 mismatch: expected " + expected + ", got " + got +
                     " (delete " + dir + " and run ci/fetch-models)");
  }
  return path.string();
}

}  // namespace gbdcs::vision
