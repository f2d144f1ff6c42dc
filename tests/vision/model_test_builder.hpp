// Builds small TFLite models in memory, with the flatbuffers builder over the reader's own
// schema, and runs them through a naive reference interpreter written for the tests.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "gbdcs/vision/tflite_model.hpp"

namespace flatbuffers {
class FlatBufferBuilder;
}

namespace gbdcs::vision::testing {

// Which OperatorCode fields carry the builtin code (real files use either).
enum class OpCodeStyle { kBoth, kDeprecatedOnly, kExtendedOnly };

// TFLite's enum values, so the tests do not need the generated header.
constexpr std::int8_t kFloat32 = 0;
constexpr std::int8_t kFloat16 = 1;
constexpr std::int8_t kInt32 = 2;
constexpr std::int8_t kInt8 = 9;
constexpr std::int8_t kSame = 0;
constexpr std::int8_t kValid = 1;
constexpr std::int8_t kActNone = 0;
constexpr std::int8_t kActRelu = 1;
constexpr std::int8_t kActRelu6 = 3;
constexpr std::int8_t kActTanh = 4;

// Writes one operator's builtin options into the builder: (union type, table offset).
using OptionsWriter =
    std::function<std::pair<std::uint8_t, std::uint32_t>(flatbuffers::FlatBufferBuilder&)>;

OptionsWriter conv_options(std::int8_t padding, int stride_h, int stride_w, std::int8_t act,
                           int dilation_h = 1, int dilation_w = 1);
OptionsWriter depthwise_options(std::int8_t padding, int stride_h, int stride_w, int multiplier,
                                std::int8_t act, int dilation_h = 1, int dilation_w = 1);
OptionsWriter pool_options(std::int8_t padding, int stride_h, int stride_w, int filter_h,
                           int filter_w, std::int8_t act = kActNone);
OptionsWriter fully_connected_options(std::int8_t act, bool keep_num_dims = false);
OptionsWriter concatenation_options(int axis, std::int8_t act = kActNone);
OptionsWriter add_options(std::int8_t act);
OptionsWriter resize_bilinear_options(bool align_corners, bool half_pixel_centers);
OptionsWriter reshape_options(std::vector<int> new_shape);
OptionsWriter reducer_options(bool keep_dims);

class ModelBuilder {
 public:
  int tensor(const std::string& name, std::vector<int> shape, std::int8_t type = kFloat32,
             std::vector<std::uint8_t> data = {});
  int input(const std::string& name, std::vector<int> shape);  // a subgraph input
  int constant(const std::string& name, std::vector<int> shape, const std::vector<float>& values);
  int constant_fp16(const std::string& name, std::vector<int> shape,
                    const std::vector<std::uint16_t>& halves);
  int constant_int32(const std::string& name, std::vector<int> shape,
                     const std::vector<std::int32_t>& values);
  void output(int tensor) { outputs_.push_back(tensor); }
  void op(std::int32_t code, std::vector<int> inputs, std::vector<int> outputs,
          OptionsWriter options = {});
  std::vector<std::uint8_t> finish(OpCodeStyle style = OpCodeStyle::kBoth) const;

 private:
  struct Tensor {
    std::string name;
    std::vector<int> shape;
    std::int8_t type;
    std::vector<std::uint8_t> data;
  };
  struct Op {
    std::int32_t code;
    std::vector<int> inputs;
    std::vector<int> outputs;
    OptionsWriter options;
  };
  std::vector<Tensor> tensors_;
  std::vector<Op> ops_;
  std::vector<int> inputs_;
  std::vector<int> outputs_;
};

// Half-precision helpers: exact for the values the tests use (|x| in [2^-14, 65504] or 0).
std::uint16_t to_half(float value);
float from_half(std::uint16_t half);

std::vector<float> random_values(std::mt19937& rng, std::size_t count, float low = -1.0f,
                                 float high = 1.0f);

// Runs the same random inputs through InferenceRunner and reference_run().
struct Comparison {
  std::vector<std::vector<float>> runner;
  std::vector<std::vector<float>> reference;
  double max_abs_error = 0;  // over every output element
  double max_abs_reference = 0;
};
Comparison run_both(const TfliteModel& model, std::uint32_t seed, float low = -1.0f,
                    float high = 1.0f, int threads = 1);

// Runs a model op by op with plain loops (fp32, TFLite reference semantics). Returns the
// subgraph outputs in order.
std::vector<std::vector<float>> reference_run(const TfliteModel& model,
                                              const std::vector<std::vector<float>>& inputs);

}  // namespace gbdcs::vision::testing
