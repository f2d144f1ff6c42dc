#include "model_test_builder.hpp"

#include <flatbuffers/flatbuffers.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "gbdcs/vision/inference_runner.hpp"
#include "tflite_min_generated.h"

namespace gbdcs::vision::testing {
namespace fb = tflite_fb;

namespace {

template <typename T>
std::pair<std::uint8_t, std::uint32_t> options(fb::BuiltinOptions type, flatbuffers::Offset<T> o) {
  return {static_cast<std::uint8_t>(type), o.o};
}

fb::Padding pad(std::int8_t p) {
  return static_cast<fb::Padding>(p);
}
fb::ActivationFunctionType act(std::int8_t a) {
  return static_cast<fb::ActivationFunctionType>(a);
}

template <typename T>
std::vector<std::uint8_t> raw_bytes(const std::vector<T>& values) {
  std::vector<std::uint8_t> bytes(values.size() * sizeof(T));
  if (!bytes.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
  return bytes;
}

}  // namespace

OptionsWriter conv_options(std::int8_t padding, int stride_h, int stride_w, std::int8_t activation,
                           int dilation_h, int dilation_w) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_Conv2DOptions,
                   fb::CreateConv2DOptions(b, pad(padding), stride_w, stride_h, act(activation),
                                           dilation_w, dilation_h));
  };
}

OptionsWriter depthwise_options(std::int8_t padding, int stride_h, int stride_w, int multiplier,
                                std::int8_t activation, int dilation_h, int dilation_w) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_DepthwiseConv2DOptions,
                   fb::CreateDepthwiseConv2DOptions(b, pad(padding), stride_w, stride_h, multiplier,
                                                    act(activation), dilation_w, dilation_h));
  };
}

OptionsWriter pool_options(std::int8_t padding, int stride_h, int stride_w, int filter_h,
                           int filter_w, std::int8_t activation) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_Pool2DOptions,
                   fb::CreatePool2DOptions(b, pad(padding), stride_w, stride_h, filter_w, filter_h,
                                           act(activation)));
  };
}

OptionsWriter fully_connected_options(std::int8_t activation, bool keep_num_dims) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_FullyConnectedOptions,
                   fb::CreateFullyConnectedOptions(b, act(activation), 0, keep_num_dims));
  };
}

OptionsWriter concatenation_options(int axis, std::int8_t activation) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_ConcatenationOptions,
                   fb::CreateConcatenationOptions(b, axis, act(activation)));
  };
}

OptionsWriter add_options(std::int8_t activation) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_AddOptions, fb::CreateAddOptions(b, act(activation)));
  };
}

OptionsWriter resize_bilinear_options(bool align_corners, bool half_pixel_centers) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_ResizeBilinearOptions,
                   fb::CreateResizeBilinearOptions(b, align_corners, half_pixel_centers));
  };
}

OptionsWriter reshape_options(std::vector<int> new_shape) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_ReshapeOptions,
                   fb::CreateReshapeOptionsDirect(b, &new_shape));
  };
}

OptionsWriter reducer_options(bool keep_dims) {
  return [=](flatbuffers::FlatBufferBuilder& b) {
    return options(fb::BuiltinOptions_ReducerOptions, fb::CreateReducerOptions(b, keep_dims));
  };
}

int ModelBuilder::tensor(const std::string& name, std::vector<int> shape, std::int8_t type,
                         std::vector<std::uint8_t> data) {
  tensors_.push_back({name, std::move(shape), type, std::move(data)});
  return static_cast<int>(tensors_.size()) - 1;
}

int ModelBuilder::input(const std::string& name, std::vector<int> shape) {
  const int t = tensor(name, std::move(shape));
  inputs_.push_back(t);
  return t;
}

int ModelBuilder::constant(const std::string& name, std::vector<int> shape,
                           const std::vector<float>& values) {
  return tensor(name, std::move(shape), kFloat32, raw_bytes(values));
}

int ModelBuilder::constant_fp16(const std::string& name, std::vector<int> shape,
                                const std::vector<std::uint16_t>& halves) {
  return tensor(name, std::move(shape), kFloat16, raw_bytes(halves));
}

int ModelBuilder::constant_int32(const std::string& name, std::vector<int> shape,
                                 const std::vector<std::int32_t>& values) {
  return tensor(name, std::move(shape), kInt32, raw_bytes(values));
}

void ModelBuilder::op(std::int32_t code, std::vector<int> inputs, std::vector<int> outputs,
                      OptionsWriter options) {
  ops_.push_back({code, std::move(inputs), std::move(outputs), std::move(options)});
}

std::vector<std::uint8_t> ModelBuilder::finish(OpCodeStyle style) const {
  flatbuffers::FlatBufferBuilder b;
  // Buffer 0 is the empty sentinel, as TFLite writes it.
  std::vector<flatbuffers::Offset<fb::Buffer>> buffers{fb::CreateBuffer(b)};
  std::vector<flatbuffers::Offset<fb::Tensor>> tensors;
  for (const Tensor& t : tensors_) {
    std::uint32_t buffer = 0;
    if (!t.data.empty()) {
      b.ForceVectorAlignment(t.data.size(), sizeof(std::uint8_t), 16);
      const auto data = b.CreateVector(t.data);
      buffers.push_back(fb::CreateBuffer(b, data));
      buffer = static_cast<std::uint32_t>(buffers.size() - 1);
    }
    tensors.push_back(fb::CreateTensorDirect(b, &t.shape, static_cast<fb::TensorType>(t.type),
                                             buffer, t.name.c_str()));
  }
  std::vector<std::int32_t> codes;
  std::vector<flatbuffers::Offset<fb::Operator>> operators;
  for (const Op& op : ops_) {
    auto found = std::find(codes.begin(), codes.end(), op.code);
    const auto index = static_cast<std::uint32_t>(found - codes.begin());
    if (found == codes.end()) codes.push_back(op.code);
    std::pair<std::uint8_t, std::uint32_t> written{0, 0};
    if (op.options) written = op.options(b);
    operators.push_back(fb::CreateOperatorDirect(
        b, index, &op.inputs, &op.outputs, static_cast<fb::BuiltinOptions>(written.first),
        written.first != 0 ? flatbuffers::Offset<void>(written.second) : 0));
  }
  std::vector<flatbuffers::Offset<fb::OperatorCode>> opcodes;
  for (std::int32_t code : codes) {
    const auto deprecated = static_cast<std::int8_t>(std::min(code, 127));
    switch (style) {
      case OpCodeStyle::kBoth:
        opcodes.push_back(fb::CreateOperatorCode(b, deprecated, 0, 1, code));
        break;
      case OpCodeStyle::kDeprecatedOnly:
        opcodes.push_back(fb::CreateOperatorCode(b, deprecated, 0, 1, 0));
        break;
      case OpCodeStyle::kExtendedOnly:
        opcodes.push_back(fb::CreateOperatorCode(b, 0, 0, 1, code));
        break;
    }
  }
  const auto graph = fb::CreateSubGraphDirect(b, &tensors, &inputs_, &outputs_, &operators, "main");
  std::vector<flatbuffers::Offset<fb::SubGraph>> graphs{graph};
  const auto model =
      fb::CreateModelDirect(b, 3, &opcodes, &graphs, "built by the GBDCS tests", &buffers);
  fb::FinishModelBuffer(b, model);
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

std::uint16_t to_half(float value) {
  if (value == 0.0f) return std::signbit(value) ? 0x8000 : 0;
  int exponent = 0;
  const float mantissa = std::frexp(std::fabs(value), &exponent);  // value = m * 2^e, m in [0.5, 1)
  const int biased = exponent - 1 + 15;
  if (biased < 1 || biased > 30) throw std::invalid_argument("to_half: out of the normal range");
  const float fraction = mantissa * 2.0f - 1.0f;  // in [0, 1)
  const auto bits = static_cast<std::uint16_t>(std::lround(fraction * 1024.0f));
  if (bits >= 1024 ||
      std::ldexp(1.0f + static_cast<float>(bits) / 1024.0f, exponent - 1) != std::fabs(value)) {
    throw std::invalid_argument("to_half: value not exactly representable");
  }
  return static_cast<std::uint16_t>((value < 0 ? 0x8000 : 0) | (biased << 10) | bits);
}

float from_half(std::uint16_t half) {
  const int exponent = (half >> 10) & 0x1F;
  const int fraction = half & 0x3FF;
  float magnitude = 0.0f;
  if (exponent == 0) {
    magnitude = std::ldexp(static_cast<float>(fraction), -24);
  } else if (exponent == 31) {
    magnitude = fraction == 0 ? INFINITY : NAN;
  } else {
    magnitude = std::ldexp(1.0f + static_cast<float>(fraction) / 1024.0f, exponent - 15);
  }
  return (half & 0x8000) != 0 ? -magnitude : magnitude;
}

std::vector<float> random_values(std::mt19937& rng, std::size_t count, float low, float high) {
  std::uniform_real_distribution<float> dist(low, high);
  std::vector<float> values(count);
  for (float& v : values) v = dist(rng);
  return values;
}

Comparison run_both(const TfliteModel& model, std::uint32_t seed, float low, float high,
                    int threads) {
  std::mt19937 rng(seed);
  auto runner = InferenceRunner::create(model, RunnerOptions{threads});
  std::vector<std::vector<float>> inputs;
  for (std::size_t i = 0; i < runner->inputs().size(); ++i) {
    std::size_t n = 1;
    for (int d : runner->inputs()[i].shape) n *= static_cast<std::size_t>(d);
    inputs.push_back(random_values(rng, n, low, high));
    std::copy(inputs.back().begin(), inputs.back().end(), runner->input_data(i));
  }
  runner->invoke();
  Comparison result;
  result.reference = reference_run(model, inputs);
  for (std::size_t i = 0; i < runner->outputs().size(); ++i) {
    const auto& ref = result.reference.at(i);
    result.runner.emplace_back(runner->output_data(i), runner->output_data(i) + ref.size());
    for (std::size_t k = 0; k < ref.size(); ++k) {
      const double error = std::fabs(double{result.runner[i][k]} - ref[k]);
      result.max_abs_error =
          std::isfinite(error) ? std::max(result.max_abs_error, error) : INFINITY;
      result.max_abs_reference = std::max(result.max_abs_reference, std::fabs(double{ref[k]}));
    }
  }
  return result;
}

}  // namespace gbdcs::vision::testing
