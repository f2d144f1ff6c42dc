// TfliteModel: what it reads from a flatbuffer, and the errors for bad, truncated or
// unsupported files (never a crash).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "gbdcs/vision/inference_runner.hpp"
#include "gbdcs/vision/tflite_model.hpp"
#include "model_test_builder.hpp"

namespace gbdcs::vision {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing::ModelBuilder;
using testing::OpCodeStyle;
namespace t = gbdcs::vision::testing;

std::string load_error(const std::vector<std::uint8_t>& bytes) {
  try {
    TfliteModel::from_bytes(bytes);
  } catch (const ModelError& e) {
    return e.what();
  }
  return "no error";
}

// One of each operator we read, with options that are not the defaults.
ModelBuilder every_op() {
  ModelBuilder b;
  const int x = b.input("image", {1, 8, 8, 2});
  const int f = b.constant("filter", {4, 3, 3, 2}, std::vector<float>(72, 0.5f));
  const int conv = b.tensor("conv", {1, 4, 4, 4});
  b.op(3, {x, f, -1}, {conv}, t::conv_options(t::kSame, 2, 2, t::kActRelu6, 1, 1));
  const int dwf = b.constant("dw_filter", {1, 3, 3, 8}, std::vector<float>(72, 0.25f));
  const int dw = b.tensor("dw", {1, 4, 4, 8});
  b.op(4, {conv, dwf}, {dw}, t::depthwise_options(t::kSame, 1, 1, 2, t::kActRelu, 1, 1));
  const int pooled = b.tensor("pooled", {1, 2, 2, 8});
  b.op(17, {dw}, {pooled}, t::pool_options(t::kValid, 2, 2, 2, 2));
  const int shape = b.constant_int32("shape", {2}, {1, 32});
  const int flat = b.tensor("flat", {1, 32});
  b.op(22, {pooled, shape}, {flat}, t::reshape_options({1, 32}));
  const int cat = b.tensor("cat", {1, 64});
  b.op(2, {flat, flat}, {cat}, t::concatenation_options(-1, t::kActNone));
  const int w16 =
      b.constant_fp16("w16", {3, 64}, std::vector<std::uint16_t>(192, t::to_half(0.5f)));
  const int w = b.tensor("w", {3, 64});
  b.op(6, {w16}, {w});
  const int fc = b.tensor("fc", {1, 3});
  b.op(9, {cat, w}, {fc}, t::fully_connected_options(t::kActNone, true));
  const int size = b.constant_int32("size", {2}, {8, 8});
  const int up = b.tensor("up", {1, 8, 8, 8});
  b.op(23, {dw, size}, {up}, t::resize_bilinear_options(false, true));
  const int axes = b.constant_int32("axes", {2}, {1, 2});
  const int mean = b.tensor("mean", {1, 1, 1, 8});
  b.op(40, {up, axes}, {mean}, t::reducer_options(true));
  b.output(fc);
  b.output(mean);
  return b;
}

TEST(Reader, ReadsTensorsOperatorsAndOptions) {
  const TfliteModel model = TfliteModel::from_bytes(every_op().finish());
  ASSERT_EQ(model.tensors().size(), 16u);
  EXPECT_EQ(model.description(), "built by the GBDCS tests");
  const TensorDesc& image = model.tensors()[0];
  EXPECT_EQ(image.name, "image");
  EXPECT_THAT(image.shape, ElementsAre(1, 8, 8, 2));
  EXPECT_EQ(image.type, TensorType::kFloat32);
  EXPECT_FALSE(image.is_constant());
  const TensorDesc& filter = model.tensors()[1];
  EXPECT_TRUE(filter.is_constant());
  EXPECT_EQ(filter.data.size(), 72u * 4);
  EXPECT_EQ(model.buffers().at(filter.buffer).data(), filter.data.data());
  EXPECT_EQ(model.tensors()[9].type, TensorType::kFloat16);
  EXPECT_EQ(model.tensors()[6].type, TensorType::kInt32);
  EXPECT_THAT(model.inputs(), ElementsAre(0));
  EXPECT_THAT(model.outputs(), ElementsAre(11, 15));

  const auto& ops = model.operators();
  ASSERT_EQ(ops.size(), 9u);
  EXPECT_EQ(ops[0].op, BuiltinOp::kConv2d);
  EXPECT_THAT(ops[0].inputs, ElementsAre(0, 1, -1));
  const auto& conv = std::get<Conv2dOptions>(ops[0].options);
  EXPECT_EQ(conv.padding, Padding::kSame);
  EXPECT_EQ(conv.stride_h, 2);
  EXPECT_EQ(conv.stride_w, 2);
  EXPECT_EQ(conv.activation, Activation::kRelu6);
  const auto& dw = std::get<Conv2dOptions>(ops[1].options);
  EXPECT_EQ(dw.padding, Padding::kSame);
  EXPECT_EQ(dw.depth_multiplier, 2);
  EXPECT_EQ(dw.activation, Activation::kRelu);
  const auto& pool = std::get<Pool2dOptions>(ops[2].options);
  EXPECT_EQ(pool.padding, Padding::kValid);
  EXPECT_EQ(pool.filter_h, 2);
  EXPECT_EQ(pool.stride_w, 2);
  EXPECT_THAT(std::get<ReshapeOptions>(ops[3].options).new_shape, ElementsAre(1, 32));
  EXPECT_EQ(std::get<ConcatenationOptions>(ops[4].options).axis, -1);
  EXPECT_EQ(ops[5].op, BuiltinOp::kDequantize);
  EXPECT_TRUE(std::get<FullyConnectedOptions>(ops[6].options).keep_num_dims);
  const auto& resize = std::get<ResizeBilinearOptions>(ops[7].options);
  EXPECT_FALSE(resize.align_corners);
  EXPECT_TRUE(resize.half_pixel_centers);
  EXPECT_TRUE(std::get<ReducerOptions>(ops[8].options).keep_dims);
  // And it runs: every operator above, against the reference.
  EXPECT_LE(t::run_both(model, 1).max_abs_error, 1e-4);
}

TEST(Reader, OperatorCodeInEitherField) {
  for (OpCodeStyle style :
       {OpCodeStyle::kBoth, OpCodeStyle::kDeprecatedOnly, OpCodeStyle::kExtendedOnly}) {
    const TfliteModel model = TfliteModel::from_bytes(every_op().finish(style));
    std::vector<BuiltinOp> ops;
    for (const auto& op : model.operators()) ops.push_back(op.op);
    EXPECT_THAT(
        ops, ElementsAre(BuiltinOp::kConv2d, BuiltinOp::kDepthwiseConv2d, BuiltinOp::kMaxPool2d,
                         BuiltinOp::kReshape, BuiltinOp::kConcatenation, BuiltinOp::kDequantize,
                         BuiltinOp::kFullyConnected, BuiltinOp::kResizeBilinear, BuiltinOp::kMean))
        << static_cast<int>(style);
  }
}

TEST(Reader, UnsupportedOperatorIsNamed) {
  ModelBuilder b;
  const int x = b.input("x", {1, 10});
  const int y = b.tensor("y", {1, 10});
  const int z = b.tensor("z", {1, 10});
  b.op(14, {x}, {y});
  b.op(25, {y}, {z});  // SOFTMAX
  b.output(z);
  EXPECT_THAT(load_error(b.finish()),
              HasSubstr("unsupported operator SOFTMAX (code 25) at operator #1"));
  ModelBuilder g;  // a code past the int8 field: GELU (150) in builtin_code, 127 in the old one
  const int gx = g.input("x", {1, 10});
  const int gy = g.tensor("y", {1, 10});
  g.op(150, {gx}, {gy});
  g.output(gy);
  EXPECT_THAT(load_error(g.finish()),
              HasSubstr("unsupported operator GELU (code 150) at operator #0"));
}

TEST(Reader, BadIndicesTypesAndOptionsAreNamed) {
  {
    ModelBuilder b;
    const int x = b.input("x", {1, 4});
    const int y = b.tensor("y", {1, 4});
    b.op(14, {x, 99}, {y});
    b.output(y);
    EXPECT_THAT(
        load_error(b.finish()),
        HasSubstr(
            "operator #0 LOGISTIC input 1: tensor index 99 out of range (model has 2 tensors)"));
  }
  {
    ModelBuilder b;
    const int x = b.input("x", {1, 4});
    b.output(7);
    EXPECT_THAT(load_error(b.finish()),
                HasSubstr("subgraph output 0: tensor index 7 out of range"));
    (void)x;
  }
  {
    ModelBuilder b;
    b.tensor("weights", {2, 2}, t::kFloat32, std::vector<std::uint8_t>(12, 0));
    EXPECT_THAT(
        load_error(b.finish()),
        HasSubstr("tensor #0 'weights': buffer #1 holds 12 bytes, shape [2, 2] FLOAT32 needs 16"));
  }
  {
    ModelBuilder b;
    b.tensor("q", {4}, t::kInt8);
    EXPECT_THAT(load_error(b.finish()), HasSubstr("tensor #0 'q': unsupported type INT8"));
  }
  {
    ModelBuilder b;
    b.tensor("neg", {1, -3});
    EXPECT_THAT(load_error(b.finish()), HasSubstr("tensor #0 'neg': negative dimension -3"));
  }
  {
    ModelBuilder b;
    const int x = b.input("x", {1, 4, 4, 1});
    const int f = b.constant("f", {1, 1, 1, 1}, {1.0f});
    const int y = b.tensor("y", {1, 4, 4, 1});
    b.op(3, {x, f}, {y}, t::conv_options(t::kSame, 1, 1, t::kActTanh));
    EXPECT_THAT(load_error(b.finish()),
                HasSubstr("operator #0 CONV_2D: unsupported fused activation TANH"));
  }
  {
    ModelBuilder b;
    const int x = b.input("x", {1, 4, 4, 1});
    const int f = b.constant("f", {1, 1, 1, 1}, {1.0f});
    const int y = b.tensor("y", {1, 4, 4, 1});
    b.op(3, {x, f}, {y});
    EXPECT_THAT(load_error(b.finish()), HasSubstr("operator #0 CONV_2D: missing Conv2DOptions"));
  }
  {
    ModelBuilder b;
    const int x = b.input("x", {1, 4, 4, 1});
    const int f = b.constant("f", {1, 1, 1, 1}, {1.0f});
    const int y = b.tensor("y", {1, 4, 4, 1});
    b.op(3, {x, f}, {y}, t::pool_options(t::kSame, 1, 1, 2, 2));
    EXPECT_THAT(load_error(b.finish()), HasSubstr("expected Conv2DOptions"));
  }
  {
    ModelBuilder b;
    const int x = b.input("x", {1, 4, 4, 1});
    const int f = b.constant("f", {1, 1, 1, 1}, {1.0f});
    const int y = b.tensor("y", {1, 4, 4, 1});
    b.op(3, {x, f}, {y}, t::conv_options(t::kSame, 0, 1, t::kActNone));
    EXPECT_THAT(load_error(b.finish()), HasSubstr("stride_h 0 (must be >= 1)"));
  }
}

TEST(Reader, GarbageIsRejected) {
  EXPECT_THAT(load_error({}), HasSubstr("too short"));
  EXPECT_THAT(load_error({1, 2, 3}), HasSubstr("too short"));
  const std::string text = "this is not a flatbuffer at all, just text";
  EXPECT_THAT(load_error({text.begin(), text.end()}), HasSubstr("no \"TFL3\" identifier"));
  std::vector<std::uint8_t> fake{0xFF, 0xFF, 0xFF, 0x7F, 'T', 'F', 'L', '3', 0, 0, 0, 0};
  EXPECT_THAT(load_error(fake), HasSubstr("root table offset"));
  EXPECT_THAT(load_error(fake), HasSubstr("malformed TFLite model"));
}

// Every prefix of a small model: each one a ModelError, none a crash.
TEST(Reader, EveryTruncationIsAnError) {
  const auto bytes = every_op().finish();
  int errors = 0;
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const std::vector<std::uint8_t> cut(bytes.begin(),
                                        bytes.begin() + static_cast<std::ptrdiff_t>(n));
    const std::string error = load_error(cut);
    EXPECT_NE(error, "no error") << "prefix of " << n << " of " << bytes.size() << " bytes loaded";
    if (error.find("malformed TFLite model") != std::string::npos) ++errors;
  }
  EXPECT_EQ(errors, static_cast<int>(bytes.size()));
}

// Every single-byte corruption of a small model: it loads (and then creates and runs) or it
// is a ModelError; nothing else. Run under the sanitizers this also proves no stray reads.
TEST(Reader, EveryByteFlipIsHandled) {
  const auto bytes = every_op().finish();
  int rejected = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    for (std::uint8_t mask : {std::uint8_t{0xFF}, std::uint8_t{0x01}, std::uint8_t{0x80}}) {
      auto bad = bytes;
      bad[i] ^= mask;
      try {
        const TfliteModel model = TfliteModel::from_bytes(bad);
        auto runner = InferenceRunner::create(model);
        runner->invoke();
      } catch (const ModelError&) {
        ++rejected;
      }
    }
  }
  EXPECT_GT(rejected, static_cast<int>(bytes.size()) / 4);  // most bytes are structure
}

}  // namespace
}  // namespace gbdcs::vision
