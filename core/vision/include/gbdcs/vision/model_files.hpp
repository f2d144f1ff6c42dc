// The MediaPipe Hands model files: names, where they live, and their pinned SHA-256.
//
// Inputs   a ModelKind and a directory (default_model_dir()).
// Outputs  verified_model_path(): the path of a model whose SHA-256 equals the hash pinned in
//          core/vision/models.sha256 (embedded in the binary at build time).
// Errors   ModelError, with the fix in the message:
//            "<file> not found in <dir> (run ci/fetch-models, or set GBDCS_MODEL_DIR)"
//            "<file>: SHA-256 mismatch: expected X, got Y (delete <dir> and run ci/fetch-models)"
// Options  GBDCS_MODEL_DIR (environment) overrides the compiled-in ${CMAKE_BINARY_DIR}/models.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace gbdcs::vision {

// Any problem with a model: missing, wrong hash, malformed, unsupported.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ModelKind {
  kPalmDetectionLite,
  kPalmDetectionFull,
  kHandLandmarkLite,
  kHandLandmarkFull
};

// "palm_detection_lite.tflite", ...
std::string_view file_name(ModelKind kind);

// $GBDCS_MODEL_DIR when set and not empty, else the build tree's models folder.
std::string default_model_dir();

// Lower-case hex SHA-256 of a file's bytes. Throws ModelError if it cannot be read.
std::string sha256_file(const std::string& path);

// The pinned hash of a model (lower-case hex), from models.sha256.
std::string_view pinned_sha256(ModelKind kind);

// dir/file_name(kind), after checking it exists and matches its pinned hash.
std::string verified_model_path(ModelKind kind, const std::string& dir = default_model_dir());

}  // namespace gbdcs::vision
