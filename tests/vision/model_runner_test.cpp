// InferenceRunner against the naive reference interpreter, op by op, on models the tests
// build themselves. Tolerance 1e-4 (absolute) on values of order 1.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numeric>

#include "gbdcs/vision/inference_runner.hpp"
#include "model_test_builder.hpp"

namespace gbdcs::vision {
namespace {

using ::testing::HasSubstr;
using testing::ModelBuilder;
namespace t = gbdcs::vision::testing;

constexpr double kTolerance = 1e-4;
constexpr std::int32_t kAdd = 0, kConcat = 2, kConv = 3, kDepthwise = 4, kDequantize = 6,
                       kFullyConnected = 9, kLogistic = 14, kMaxPool = 17, kReshape = 22,
                       kResize = 23, kPad = 34, kMean = 40, kPrelu = 54;

std::size_t count(const std::vector<int>& shape) {
  return std::accumulate(shape.begin(), shape.end(), std::size_t{1},
                         [](std::size_t a, int d) { return a * static_cast<std::size_t>(d); });
}

std::vector<float> random(std::uint32_t seed, const std::vector<int>& shape, float scale = 1.0f) {
  std::mt19937 rng(seed);
  return t::random_values(rng, count(shape), -scale, scale);
}

// Builds, runs both ways, and checks every output within tolerance.
t::Comparison expect_matches(const ModelBuilder& builder, std::uint32_t seed,
                             float input_scale = 1.0f, double tolerance = kTolerance) {
  const TfliteModel model = TfliteModel::from_bytes(builder.finish());
  t::Comparison c = t::run_both(model, seed, -input_scale, input_scale);
  EXPECT_LE(c.max_abs_error, tolerance);
  EXPECT_GT(c.max_abs_reference, 0.0) << "all-zero outputs prove nothing";
  return c;
}

TEST(Runner, Conv2dSameStride2Relu6WithBias) {
  ModelBuilder b;
  const int x = b.input("x", {1, 7, 9, 3});
  const int f = b.constant("f", {4, 3, 3, 3}, random(1, {4, 3, 3, 3}));
  const int bias = b.constant("bias", {4}, random(2, {4}));
  const int y = b.tensor("y", {1, 4, 5, 4});
  b.op(kConv, {x, f, bias}, {y}, t::conv_options(t::kSame, 2, 2, t::kActRelu6));
  b.output(y);
  const auto c = expect_matches(b, 3, 4.0f);
  // Inputs of +-4 through 27 taps: RELU6 must have clamped something at both ends.
  EXPECT_THAT(c.runner[0], ::testing::Contains(6.0f));
  EXPECT_THAT(c.runner[0], ::testing::Contains(0.0f));
}

TEST(Runner, Conv2dValidDilatedWithoutBias) {
  ModelBuilder b;
  const int x = b.input("x", {1, 9, 8, 2});
  const int f = b.constant("f", {3, 3, 3, 2}, random(4, {3, 3, 3, 2}));
  const int y = b.tensor("y", {1, 5, 4, 3});
  b.op(kConv, {x, f}, {y}, t::conv_options(t::kValid, 1, 1, t::kActNone, 2, 2));
  b.output(y);
  expect_matches(b, 5);
}

TEST(Runner, Conv2dWithFp16WeightsBehindDequantize) {
  ModelBuilder b;
  std::vector<std::uint16_t> filter;
  for (float v : random(6, {5, 1, 1, 4}))
    filter.push_back(t::to_half(std::round(v * 256) / 256 + 2.0f));
  const int x = b.input("x", {1, 6, 6, 4});
  const int f16 = b.constant_fp16("f16", {5, 1, 1, 4}, filter);
  const int b16 = b.constant_fp16("b16", {5},
                                  {t::to_half(0.5f), t::to_half(-1.25f), t::to_half(3.0f),
                                   t::to_half(0.0078125f), t::to_half(-0.75f)});
  const int f = b.tensor("f", {5, 1, 1, 4});
  const int bias = b.tensor("bias", {5});
  const int y = b.tensor("y", {1, 6, 6, 5});
  b.op(kDequantize, {f16}, {f});
  b.op(kDequantize, {b16}, {bias});
  b.op(kConv, {x, f, bias}, {y}, t::conv_options(t::kSame, 1, 1, t::kActNone));
  b.output(y);
  expect_matches(b, 7);
}

TEST(Runner, DepthwiseSameStride2Multiplier2Relu) {
  ModelBuilder b;
  const int x = b.input("x", {1, 8, 7, 3});
  const int f = b.constant("f", {1, 5, 5, 6}, random(8, {1, 5, 5, 6}));
  const int bias = b.constant("bias", {6}, random(9, {6}));
  const int y = b.tensor("y", {1, 4, 4, 6});
  b.op(kDepthwise, {x, f, bias}, {y}, t::depthwise_options(t::kSame, 2, 2, 2, t::kActRelu));
  b.output(y);
  expect_matches(b, 10);
}

TEST(Runner,
     DepthwiseLikePalmDetection) {  // 5x5, stride 2 on an even size: padding 1 before, 2 after
  ModelBuilder b;
  const int x = b.input("x", {1, 12, 12, 8});
  const int f = b.constant("f", {1, 5, 5, 8}, random(11, {1, 5, 5, 8}));
  const int bias = b.constant("bias", {8}, random(12, {8}));
  const int y = b.tensor("y", {1, 6, 6, 8});
  b.op(kDepthwise, {x, f, bias}, {y}, t::depthwise_options(t::kSame, 2, 2, 1, t::kActNone));
  b.output(y);
  expect_matches(b, 13);
}

TEST(Runner, AddWithBroadcastAndRelu) {
  ModelBuilder b;
  const int x = b.input("x", {2, 1, 5, 1});
  const int z = b.input("z", {1, 4, 1, 3});
  const int k = b.constant("k", {1, 1, 1, 3}, random(14, {3}));
  const int s = b.tensor("s", {2, 4, 5, 3});
  const int y = b.tensor("y", {2, 4, 5, 3});
  b.op(kAdd, {x, z}, {s}, t::add_options(t::kActNone));
  b.op(kAdd, {s, k}, {y}, t::add_options(t::kActRelu));
  b.output(y);
  const auto c = expect_matches(b, 15);
  EXPECT_THAT(c.runner[0], ::testing::Contains(0.0f));
}

TEST(Runner, PadWithZeros) {
  ModelBuilder b;
  const int x = b.input("x", {1, 5, 4, 3});
  const int p = b.constant_int32("p", {4, 2}, {0, 0, 1, 2, 0, 1, 0, 3});
  const int y = b.tensor("y", {1, 8, 5, 6});
  b.op(kPad, {x, p}, {y});
  b.output(y);
  const auto c = expect_matches(b, 16);
  EXPECT_EQ(c.runner[0][0], 0.0f);  // a padded corner
}

TEST(Runner, MaxPoolValidAndSame) {
  ModelBuilder b;
  const int x = b.input("x", {1, 6, 8, 3});
  const int y = b.tensor("y", {1, 3, 4, 3});
  b.op(kMaxPool, {x}, {y}, t::pool_options(t::kValid, 2, 2, 2, 2));
  const int z = b.input("z", {1, 7, 5, 2});
  const int w = b.tensor("w", {1, 4, 3, 2});
  b.op(kMaxPool, {z}, {w}, t::pool_options(t::kSame, 2, 2, 3, 3));
  b.output(y);
  b.output(w);
  expect_matches(b, 17);
}

TEST(Runner, MeanOverHeightAndWidth) {
  ModelBuilder b;
  const int x = b.input("x", {1, 5, 6, 7});
  const int axes = b.constant_int32("axes", {2}, {1, 2});
  const int y = b.tensor("y", {1, 7});
  b.op(kMean, {x, axes}, {y}, t::reducer_options(false));
  const int axes2 = b.constant_int32("axes2", {2}, {-3, -2});
  const int z = b.tensor("z", {1, 1, 1, 7});
  b.op(kMean, {x, axes2}, {z}, t::reducer_options(true));
  b.output(y);
  b.output(z);
  expect_matches(b, 18);
}

TEST(Runner, FullyConnectedWithBiasAndBatch) {
  ModelBuilder b;
  const int x = b.input("x", {3, 20});
  const int w = b.constant("w", {7, 20}, random(19, {7, 20}));
  const int bias = b.constant("bias", {7}, random(20, {7}));
  const int y = b.tensor("y", {3, 7});
  b.op(kFullyConnected, {x, w, bias}, {y}, t::fully_connected_options(t::kActRelu));
  b.output(y);
  expect_matches(b, 21);
}

TEST(Runner, ResizeBilinearHalfPixelAlignCornersAndLegacy) {
  ModelBuilder b;
  const int x = b.input("x", {1, 3, 4, 5});
  const int size = b.constant_int32("size", {2}, {6, 8});
  const int half = b.tensor("half", {1, 6, 8, 5});
  b.op(kResize, {x, size}, {half}, t::resize_bilinear_options(false, true));
  const int size2 = b.constant_int32("size2", {2}, {5, 7});
  const int corners = b.tensor("corners", {1, 5, 7, 5});
  b.op(kResize, {x, size2}, {corners}, t::resize_bilinear_options(true, false));
  const int legacy = b.tensor("legacy", {1, 5, 7, 5});
  b.op(kResize, {x, size2}, {legacy}, t::resize_bilinear_options(false, false));
  b.output(half);
  b.output(corners);
  b.output(legacy);
  const auto c = expect_matches(b, 22);
  // The three grids differ, so the test would notice a wrong flag.
  EXPECT_NE(c.runner[1], c.runner[2]);
}

TEST(Runner, PreluOneSlopePerChannel) {
  ModelBuilder b;
  const int x = b.input("x", {1, 6, 6, 4});
  const int alpha = b.constant("alpha", {1, 1, 4}, {0.25f, -0.5f, 2.0f, 0.0f});
  const int y = b.tensor("y", {1, 6, 6, 4});
  b.op(kPrelu, {x, alpha}, {y});
  b.output(y);
  expect_matches(b, 23);
}

TEST(Runner, LogisticAndReshape) {
  ModelBuilder b;
  const int x = b.input("x", {1, 4, 4, 6});
  const int shape = b.constant_int32("shape", {3}, {1, -1, 3});
  const int r = b.tensor("r", {1, 32, 3});
  const int y = b.tensor("y", {1, 32, 3});
  b.op(kReshape, {x, shape}, {r});
  b.op(kLogistic, {r}, {y});
  b.output(y);
  expect_matches(b, 24, 6.0f);
}

TEST(Runner, ConcatenationAlongChannelsAndAlongRows) {
  ModelBuilder b;
  const int a = b.input("a", {1, 4, 4, 2});
  const int c = b.input("c", {1, 4, 4, 3});
  const int k = b.constant("k", {1, 4, 4, 1}, random(25, {1, 4, 4, 1}));
  const int y = b.tensor("y", {1, 4, 4, 6});
  b.op(kConcat, {a, c, k}, {y}, t::concatenation_options(3));
  const int p = b.input("p", {1, 6, 2});
  const int q = b.input("q", {1, 4, 2});
  const int z = b.tensor("z", {1, 10, 2});
  b.op(kConcat, {p, q}, {z}, t::concatenation_options(-2));
  b.output(y);
  b.output(z);
  expect_matches(b, 26);
}

// A miniature palm detector: two blocks with residuals, PReLU, max-pool + channel pad,
// upsampling, and two heads reshaped and concatenated. Intermediate tensors share arena
// memory here, so a planning mistake shows up as a wrong number.
TEST(Runner, SmallNetworkLikeTheRealOnes) {
  ModelBuilder b;
  const int x = b.input("image", {1, 16, 16, 3});
  auto conv = [&](int in, std::vector<int> in_shape, int out_c, int stride, std::uint32_t seed) {
    const int oh = (in_shape[1] + stride - 1) / stride, ow = (in_shape[2] + stride - 1) / stride;
    const int f = b.constant("f" + std::to_string(seed), {out_c, 3, 3, in_shape[3]},
                             random(seed, {out_c, 3, 3, in_shape[3]}, 0.5f));
    const int bias =
        b.constant("b" + std::to_string(seed), {out_c}, random(seed + 1, {out_c}, 0.1f));
    const int y = b.tensor("c" + std::to_string(seed), {1, oh, ow, out_c});
    b.op(kConv, {in, f, bias}, {y}, t::conv_options(t::kSame, stride, stride, t::kActNone));
    return y;
  };
  auto block = [&](int in, std::vector<int> shape, std::uint32_t seed) {
    const int dwf = b.constant("dw" + std::to_string(seed), {1, 5, 5, shape[3]},
                               random(seed, {1, 5, 5, shape[3]}, 0.3f));
    const int dw = b.tensor("dwo" + std::to_string(seed), shape);
    b.op(kDepthwise, {in, dwf}, {dw}, t::depthwise_options(t::kSame, 1, 1, 1, t::kActNone));
    const int pw = conv(dw, shape, shape[3], 1, seed + 10);
    const int sum = b.tensor("sum" + std::to_string(seed), shape);
    b.op(kAdd, {pw, in}, {sum}, t::add_options(t::kActNone));
    const int alpha = b.constant("a" + std::to_string(seed), {1, 1, shape[3]},
                                 random(seed + 20, {shape[3]}, 0.3f));
    const int act = b.tensor("act" + std::to_string(seed), shape);
    b.op(kPrelu, {sum, alpha}, {act});
    return act;
  };
  const int c0 = conv(x, {1, 16, 16, 3}, 8, 2, 100);  // 8x8x8
  const int b0 = block(c0, {1, 8, 8, 8}, 200);
  const int pool = b.tensor("pool", {1, 4, 4, 8});
  b.op(kMaxPool, {b0}, {pool}, t::pool_options(t::kValid, 2, 2, 2, 2));
  const int pads = b.constant_int32("pads", {4, 2}, {0, 0, 0, 0, 0, 0, 0, 8});
  const int padded = b.tensor("padded", {1, 4, 4, 16});
  b.op(kPad, {pool, pads}, {padded});
  const int down = conv(b0, {1, 8, 8, 8}, 16, 2, 300);  // 4x4x16
  const int sum = b.tensor("down_sum", {1, 4, 4, 16});
  b.op(kAdd, {down, padded}, {sum}, t::add_options(t::kActRelu));
  const int b1 = block(sum, {1, 4, 4, 16}, 400);
  const int size = b.constant_int32("size", {2}, {8, 8});
  const int up = b.tensor("up", {1, 8, 8, 16});
  b.op(kResize, {b1, size}, {up}, t::resize_bilinear_options(false, true));
  const int head_a = conv(up, {1, 8, 8, 16}, 6, 1, 500);  // 8x8x6
  const int head_b = conv(b1, {1, 4, 4, 16}, 6, 1, 600);  // 4x4x6
  const int shape = b.constant_int32("shape", {3}, {1, -1, 3});
  const int ra = b.tensor("ra", {1, 128, 3});
  const int rb = b.tensor("rb", {1, 32, 3});
  b.op(kReshape, {head_a, shape}, {ra});
  b.op(kReshape, {head_b, shape}, {rb});
  const int boxes = b.tensor("boxes", {1, 160, 3});
  b.op(kConcat, {ra, rb}, {boxes}, t::concatenation_options(1));
  const int axes = b.constant_int32("axes", {2}, {1, 2});
  const int pooled = b.tensor("pooled", {1, 16});
  b.op(kMean, {b1, axes}, {pooled}, t::reducer_options(false));
  const int w = b.constant("w", {2, 16}, random(700, {2, 16}, 0.5f));
  const int logits = b.tensor("logits", {1, 2});
  b.op(kFullyConnected, {pooled, w}, {logits}, t::fully_connected_options(t::kActNone));
  const int score = b.tensor("score", {1, 2});
  b.op(kLogistic, {logits}, {score});
  b.output(boxes);
  b.output(score);
  const auto c = expect_matches(b, 27);
  EXPECT_EQ(c.runner[0].size(), 480u);
}

TEST(Runner, InvokeTwiceGivesTheSameAnswerAndThreadsAgree) {
  ModelBuilder b;
  const int x = b.input("x", {1, 20, 20, 8});
  const int f = b.constant("f", {16, 3, 3, 8}, random(30, {16, 3, 3, 8}));
  const int y = b.tensor("y", {1, 10, 10, 16});
  b.op(kConv, {x, f}, {y}, t::conv_options(t::kSame, 2, 2, t::kActNone));
  b.output(y);
  const TfliteModel model = TfliteModel::from_bytes(b.finish());
  const auto one = t::run_both(model, 31, -1, 1, 1);
  const auto two = t::run_both(model, 31, -1, 1, 2);
  EXPECT_LE(one.max_abs_error, kTolerance);
  EXPECT_LE(two.max_abs_error, kTolerance);
  auto runner = InferenceRunner::create(model);
  std::fill_n(runner->input_data(0), 20 * 20 * 8, 0.5f);
  runner->invoke();
  const std::vector<float> first(runner->output_data(0), runner->output_data(0) + 1600);
  runner->invoke();
  EXPECT_EQ(first, std::vector<float>(runner->output_data(0), runner->output_data(0) + 1600));
}

TEST(Runner, ModelMayGoAwayAfterCreate) {
  ModelBuilder b;
  const int x = b.input("x", {1, 4});
  const int k = b.constant("k", {1, 4}, {1, 2, 3, 4});
  const int y = b.tensor("y", {1, 4});
  b.op(kAdd, {x, k}, {y}, t::add_options(t::kActNone));
  b.output(y);
  std::unique_ptr<InferenceRunner> runner;
  {
    const TfliteModel model = TfliteModel::from_bytes(b.finish());
    runner = InferenceRunner::create(model);
  }
  std::fill_n(runner->input_data(0), 4, 10.0f);
  runner->invoke();
  EXPECT_THAT(std::vector<float>(runner->output_data(0), runner->output_data(0) + 4),
              ::testing::ElementsAre(11, 12, 13, 14));
  EXPECT_EQ(runner->output_index("y"), 0u);
  EXPECT_THROW(runner->output_index("nope"), ModelError);
  EXPECT_THROW(runner->input_data(1), std::out_of_range);
  EXPECT_THROW(runner->output_data(1), std::out_of_range);
}

// The reference itself, against numbers worked by hand.
TEST(Reference, ConvSameStride2ByHand) {
  ModelBuilder b;
  const int x = b.input("x", {1, 3, 3, 1});
  const int f = b.constant("f", {1, 2, 2, 1}, {1, 10, 100, 1000});
  const int y = b.tensor("y", {1, 2, 2, 1});
  b.op(kConv, {x, f}, {y}, t::conv_options(t::kSame, 2, 2, t::kActNone));
  b.output(y);
  const TfliteModel model = TfliteModel::from_bytes(b.finish());
  // in 3, stride 2 → out 2, total padding 1, all of it after: windows start at 0 and 2.
  const auto out = t::reference_run(model, {{1, 2, 3, 4, 5, 6, 7, 8, 9}});
  EXPECT_THAT(out[0], ::testing::ElementsAre(1 + 20 + 400 + 5000, 3 + 600, 7 + 80, 9));
  const auto c = t::run_both(model, 1);
  EXPECT_LE(c.max_abs_error, kTolerance);
}

TEST(Reference, ResizeHalfPixelByHand) {
  ModelBuilder b;
  const int x = b.input("x", {1, 1, 2, 1});
  const int size = b.constant_int32("size", {2}, {1, 4});
  const int y = b.tensor("y", {1, 1, 4, 1});
  b.op(kResize, {x, size}, {y}, t::resize_bilinear_options(false, true));
  b.output(y);
  const TfliteModel model = TfliteModel::from_bytes(b.finish());
  // Sample points x = -0.25, 0.25, 0.75, 1.25 on [0, 4], clamped at the ends.
  EXPECT_THAT(t::reference_run(model, {{0, 4}})[0], ::testing::ElementsAre(0, 1, 3, 4));
  EXPECT_LE(t::run_both(model, 2).max_abs_error, kTolerance);
}

TEST(Runner, RejectsWhatItCannotRunExactly) {
  auto error_of = [](const ModelBuilder& b) -> std::string {
    try {
      InferenceRunner::create(TfliteModel::from_bytes(b.finish()));
    } catch (const ModelError& e) {
      return e.what();
    }
    return "no error";
  };
  {  // declared output shape disagrees with the convolution
    ModelBuilder b;
    const int x = b.input("x", {1, 8, 8, 3});
    const int f = b.constant("f", {4, 3, 3, 3}, random(1, {4, 3, 3, 3}));
    const int y = b.tensor("y", {1, 8, 8, 4});
    b.op(kConv, {x, f}, {y}, t::conv_options(t::kSame, 2, 2, t::kActNone));
    b.output(y);
    EXPECT_THAT(error_of(b), HasSubstr("operator #0 CONV_2D: output 'y' declared [1, 8, 8, 4] but "
                                       "the operator computes [1, 4, 4, 4]"));
  }
  {  // a filter that is not constant
    ModelBuilder b;
    const int x = b.input("x", {1, 4, 4, 3});
    const int f = b.input("f", {4, 1, 1, 3});
    const int y = b.tensor("y", {1, 4, 4, 4});
    b.op(kConv, {x, f}, {y}, t::conv_options(t::kSame, 1, 1, t::kActNone));
    b.output(y);
    EXPECT_THAT(error_of(b), HasSubstr("filter (tensor 'f') must be constant"));
  }
  {  // MEAN over the channels
    ModelBuilder b;
    const int x = b.input("x", {1, 4, 4, 3});
    const int axes = b.constant_int32("axes", {1}, {3});
    const int y = b.tensor("y", {1, 4, 4});
    b.op(kMean, {x, axes}, {y}, t::reducer_options(false));
    b.output(y);
    EXPECT_THAT(error_of(b), HasSubstr("MEAN over axes [3] is not supported"));
  }
  {  // reading a tensor nobody wrote
    ModelBuilder b;
    const int x = b.input("x", {1, 4});
    const int ghost = b.tensor("ghost", {1, 4});
    const int y = b.tensor("y", {1, 4});
    b.op(kAdd, {x, ghost}, {y}, t::add_options(t::kActNone));
    b.output(y);
    EXPECT_THAT(error_of(b), HasSubstr("reads tensor #1 'ghost' before any operator writes it"));
  }
  {  // shapes that do not broadcast
    ModelBuilder b;
    const int x = b.input("x", {1, 4});
    const int z = b.input("z", {1, 3});
    const int y = b.tensor("y", {1, 4});
    b.op(kAdd, {x, z}, {y}, t::add_options(t::kActNone));
    b.output(y);
    EXPECT_THAT(error_of(b), HasSubstr("do not broadcast"));
  }
  {  // a DEQUANTIZE of a runtime tensor
    ModelBuilder b;
    const int x = b.input("x", {1, 4});
    const int y = b.tensor("y", {1, 4});
    b.op(kDequantize, {x}, {y});
    b.output(y);
    EXPECT_THAT(error_of(b), HasSubstr("DEQUANTIZE of a non-constant tensor"));
  }
  EXPECT_THROW(InferenceRunner::create(TfliteModel::from_bytes(ModelBuilder{}.finish()), {0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::vision
