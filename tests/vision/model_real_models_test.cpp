// The four MediaPipe Hands models, as fetched by ci/fetch-models: verified, loaded, run, and
// checked against the naive reference interpreter. A missing model is a failure, not a skip.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <random>

#include "gbdcs/vision/inference_runner.hpp"
#include "gbdcs/vision/model_files.hpp"
#include "gbdcs/vision/tflite_model.hpp"
#include "model_test_builder.hpp"

namespace gbdcs::vision {
namespace {

using ::testing::ElementsAre;
namespace t = gbdcs::vision::testing;

std::string shape_text(const std::vector<int>& shape) {
  std::string text = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) text += (i ? ", " : "") + std::to_string(shape[i]);
  return text + "]";
}

// The verified model, or a test failure carrying the fix (run ci/fetch-models).
std::optional<TfliteModel> load(ModelKind kind) {
  try {
    return TfliteModel::from_file(verified_model_path(kind));
  } catch (const ModelError& e) {
    ADD_FAILURE() << e.what();
    return std::nullopt;
  }
}

class RealModel : public ::testing::TestWithParam<ModelKind> {};

TEST_P(RealModel, LoadsVerifiesAndRuns) {
  const auto model = load(GetParam());
  ASSERT_TRUE(model);
  auto runner = InferenceRunner::create(*model);
  std::cout << file_name(GetParam()) << ": " << model->operators().size() << " operators\n";
  for (const auto& in : runner->inputs())
    std::cout << "  input  " << in.name << " " << shape_text(in.shape) << "\n";
  for (const auto& out : runner->outputs())
    std::cout << "  output " << out.name << " " << shape_text(out.shape) << "\n";

  const bool palm =
      GetParam() == ModelKind::kPalmDetectionLite || GetParam() == ModelKind::kPalmDetectionFull;
  ASSERT_EQ(runner->inputs().size(), 1u);
  EXPECT_EQ(runner->inputs()[0].name, "input_1");
  if (palm) {
    EXPECT_THAT(runner->inputs()[0].shape, ElementsAre(1, 192, 192, 3));
    ASSERT_EQ(runner->outputs().size(), 2u);
    EXPECT_THAT(runner->outputs()[runner->output_index("Identity")].shape,
                ElementsAre(1, 2016, 18));
    EXPECT_THAT(runner->outputs()[runner->output_index("Identity_1")].shape,
                ElementsAre(1, 2016, 1));
  } else {
    EXPECT_THAT(runner->inputs()[0].shape, ElementsAre(1, 224, 224, 3));
    ASSERT_EQ(runner->outputs().size(), 4u);
    EXPECT_THAT(runner->outputs()[runner->output_index("Identity")].shape,
                ElementsAre(1, 63));  // landmarks
    EXPECT_THAT(runner->outputs()[runner->output_index("Identity_1")].shape,
                ElementsAre(1, 1));  // presence
    EXPECT_THAT(runner->outputs()[runner->output_index("Identity_2")].shape,
                ElementsAre(1, 1));  // handedness
    EXPECT_THAT(runner->outputs()[runner->output_index("Identity_3")].shape,
                ElementsAre(1, 63));  // world
  }

  // An image-like input in [0, 1] (the models' range), then every output finite.
  const auto& shape = runner->inputs()[0].shape;
  const std::size_t n = static_cast<std::size_t>(shape[1]) * shape[2] * shape[3];
  std::mt19937 rng(7);
  const auto pixels = t::random_values(rng, n, 0.0f, 1.0f);
  std::copy(pixels.begin(), pixels.end(), runner->input_data(0));
  runner->invoke();
  for (std::size_t o = 0; o < runner->outputs().size(); ++o) {
    std::size_t count = 1;
    for (int d : runner->outputs()[o].shape) count *= static_cast<std::size_t>(d);
    for (std::size_t i = 0; i < count; ++i) {
      ASSERT_TRUE(std::isfinite(runner->output_data(o)[i]))
          << runner->outputs()[o].name << "[" << i << "]";
    }
  }
  if (!palm) {  // presence and handedness come out of a LOGISTIC inside the model
    for (const char* name : {"Identity_1", "Identity_2"}) {
      const float p = runner->output_data(runner->output_index(name))[0];
      EXPECT_GE(p, 0.0f) << name;
      EXPECT_LE(p, 1.0f) << name;
    }
  }
}

// The whole real graph through XNNPACK and through the naive interpreter: every output
// within 1e-3 of the reference, relative to the largest reference value.
TEST_P(RealModel, MatchesTheReferenceInterpreter) {
  const auto model = load(GetParam());
  ASSERT_TRUE(model);
  const t::Comparison c = t::run_both(*model, 11, 0.0f, 1.0f);
  std::cout << file_name(GetParam()) << ": max |runner - reference| = " << c.max_abs_error
            << " (largest |reference| " << c.max_abs_reference << ")\n";
  EXPECT_GT(c.max_abs_reference, 0.0);
  EXPECT_LE(c.max_abs_error, 1e-3 * std::max(1.0, c.max_abs_reference));
}

TEST_P(RealModel, TwoThreadsAgreeWithOne) {
  const auto model = load(GetParam());
  ASSERT_TRUE(model);
  auto one = InferenceRunner::create(*model, {1});
  auto two = InferenceRunner::create(*model, {2});
  const auto& shape = one->inputs()[0].shape;
  const std::size_t n = static_cast<std::size_t>(shape[1]) * shape[2] * shape[3];
  std::mt19937 rng(3);
  const auto pixels = t::random_values(rng, n, 0.0f, 1.0f);
  std::copy(pixels.begin(), pixels.end(), one->input_data(0));
  std::copy(pixels.begin(), pixels.end(), two->input_data(0));
  one->invoke();
  two->invoke();
  for (std::size_t o = 0; o < one->outputs().size(); ++o) {
    std::size_t count = 1;
    for (int d : one->outputs()[o].shape) count *= static_cast<std::size_t>(d);
    for (std::size_t i = 0; i < count; ++i) {
      EXPECT_NEAR(one->output_data(o)[i], two->output_data(o)[i],
                  1e-3f * (1.0f + std::fabs(one->output_data(o)[i])))
          << one->outputs()[o].name << "[" << i << "]";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Hands, RealModel,
                         ::testing::Values(ModelKind::kPalmDetectionLite,
                                           ModelKind::kPalmDetectionFull,
                                           ModelKind::kHandLandmarkLite,
                                           ModelKind::kHandLandmarkFull),
                         [](const ::testing::TestParamInfo<ModelKind>& param) {
                           std::string name(file_name(param.param));
                           return name.substr(0, name.find('.'));
                         });

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(RealModelBytes, TruncatedFilesAreErrorsThatSayWhere) {
  std::string path;
  try {
    path = verified_model_path(ModelKind::kHandLandmarkLite);
  } catch (const ModelError& e) {
    FAIL() << e.what();
  }
  const auto bytes = read_bytes(path);
  ASSERT_GT(bytes.size(), 100000u);
  for (std::size_t n : {std::size_t{0}, std::size_t{4}, std::size_t{8}, std::size_t{16},
                        std::size_t{100}, std::size_t{1000}, bytes.size() / 4, bytes.size() / 2,
                        bytes.size() - 16, bytes.size() - 1}) {
    try {
      TfliteModel::from_bytes({bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n)});
      ADD_FAILURE() << "a prefix of " << n << " bytes loaded";
    } catch (const ModelError& e) {
      const std::string what = e.what();
      EXPECT_THAT(what, ::testing::HasSubstr("malformed TFLite model")) << n;
      if (n >= 1000) {
        EXPECT_THAT(what, ::testing::ContainsRegex("offset [0-9]+")) << what;
      }
      std::cout << n << " bytes: " << what << "\n";
    }
  }
}

TEST(RealModelBytes, RandomCorruptionIsAnErrorOrAWorkingModel) {
  std::string path;
  try {
    path = verified_model_path(ModelKind::kHandLandmarkLite);
  } catch (const ModelError& e) {
    FAIL() << e.what();
  }
  const auto bytes = read_bytes(path);
  std::mt19937 rng(2024);
  // The tables (tensors, operators, options) sit in the first few kilobytes and the
  // last few; the middle is weight data.
  std::uniform_int_distribution<std::size_t> head(0, 16383);
  std::uniform_int_distribution<std::size_t> tail(bytes.size() - 16384, bytes.size() - 1);
  std::uniform_int_distribution<int> value(0, 255);
  int rejected = 0;
  int ran = 0;
  for (int trial = 0; trial < 60; ++trial) {
    auto bad = bytes;
    for (int k = 0; k < 4; ++k) {
      bad[trial % 2 == 0 ? head(rng) : tail(rng)] = static_cast<std::uint8_t>(value(rng));
    }
    try {
      const TfliteModel model = TfliteModel::from_bytes(std::move(bad));
      auto runner = InferenceRunner::create(model);
      runner->invoke();
      ++ran;
    } catch (const ModelError&) {
      ++rejected;
    }
  }
  std::cout << "corrupted copies: " << rejected << " rejected, " << ran << " ran\n";
  EXPECT_EQ(rejected + ran, 60);
}

}  // namespace
}  // namespace gbdcs::vision
