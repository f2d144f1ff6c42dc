// Model files: names, the pinned hashes, and the errors that tell a person how to fix things.
#include "gbdcs/vision/model_files.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace gbdcs::vision {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr ModelKind kAllKinds[] = {ModelKind::kPalmDetectionLite, ModelKind::kPalmDetectionFull,
                                   ModelKind::kHandLandmarkLite, ModelKind::kHandLandmarkFull};

// A fresh, empty folder under the system temp dir, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(fs::temp_directory_path() /
              ("gbdcs_vision_" + tag + "_" +
               std::to_string(::testing::UnitTest::GetInstance()->random_seed()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

TEST(ModelFiles, FileNames) {
  EXPECT_EQ(file_name(ModelKind::kPalmDetectionLite), "palm_detection_lite.tflite");
  EXPECT_EQ(file_name(ModelKind::kPalmDetectionFull), "palm_detection_full.tflite");
  EXPECT_EQ(file_name(ModelKind::kHandLandmarkLite), "hand_landmark_lite.tflite");
  EXPECT_EQ(file_name(ModelKind::kHandLandmarkFull), "hand_landmark_full.tflite");
}

TEST(ModelFiles, PinnedHashesMatchTheCheckedInFile) {
  std::ifstream pins(std::string(GBDCS_SOURCE_DIR) + "/core/vision/models.sha256");
  ASSERT_TRUE(pins) << "core/vision/models.sha256 missing";
  int found = 0;
  std::string hash;
  std::string name;
  while (pins >> hash >> name) {
    for (ModelKind kind : kAllKinds) {
      if (name == file_name(kind)) {
        EXPECT_EQ(pinned_sha256(kind), hash) << name;
        ++found;
      }
    }
  }
  EXPECT_EQ(found, 4);
  for (ModelKind kind : kAllKinds) EXPECT_EQ(pinned_sha256(kind).size(), 64u);
}

TEST(ModelFiles, Sha256OfKnownBytes) {
  TempDir dir("sha");
  write_file(dir.path() / "abc", "abc");
  EXPECT_EQ(sha256_file((dir.path() / "abc").string()),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  write_file(dir.path() / "empty", "");
  EXPECT_EQ(sha256_file((dir.path() / "empty").string()),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_THROW(sha256_file((dir.path() / "absent").string()), ModelError);
}

TEST(ModelFiles, MissingModelNamesTheFileTheFolderAndTheFix) {
  TempDir dir("missing");
  try {
    verified_model_path(ModelKind::kHandLandmarkFull, dir.path().string());
    FAIL() << "no ModelError";
  } catch (const ModelError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("hand_landmark_full.tflite not found in"),
                                HasSubstr(dir.path().string()), HasSubstr("ci/fetch-models"),
                                HasSubstr("GBDCS_MODEL_DIR")));
  }
}

TEST(ModelFiles, WrongHashNamesExpectedAndGot) {
  TempDir dir("hash");
  write_file(dir.path() / "palm_detection_lite.tflite", "not the model");
  const std::string got = sha256_file((dir.path() / "palm_detection_lite.tflite").string());
  try {
    verified_model_path(ModelKind::kPalmDetectionLite, dir.path().string());
    FAIL() << "no ModelError";
  } catch (const ModelError& e) {
    EXPECT_THAT(
        e.what(),
        AllOf(HasSubstr("palm_detection_lite.tflite: SHA-256 mismatch"),
              HasSubstr("expected " + std::string(pinned_sha256(ModelKind::kPalmDetectionLite))),
              HasSubstr("got " + got), HasSubstr("delete " + dir.path().string()),
              HasSubstr("ci/fetch-models")));
  }
}

TEST(ModelFiles, EnvironmentOverridesTheDefaultFolder) {
  const char* saved = std::getenv("GBDCS_MODEL_DIR");
  const std::string restore = saved != nullptr ? saved : "";
  ::setenv("GBDCS_MODEL_DIR", "/some/where", 1);
  EXPECT_EQ(default_model_dir(), "/some/where");
  ::unsetenv("GBDCS_MODEL_DIR");
  EXPECT_THAT(default_model_dir(), HasSubstr("models"));
  if (saved != nullptr) ::setenv("GBDCS_MODEL_DIR", restore.c_str(), 1);
}

}  // namespace
}  // namespace gbdcs::vision
