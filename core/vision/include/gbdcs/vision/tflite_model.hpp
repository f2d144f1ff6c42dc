// TfliteModel: a TensorFlow Lite flatbuffer, checked and read into plain structs.
//
// Inputs   the bytes of a .tflite file (from_file / from_bytes).
// Outputs  the main subgraph (subgraph 0): tensors (name, shape, type, constant data),
//          operators (TFLite builtin code, input/output tensor indices, builtin options),
//          and the subgraph's input and output tensor indices.
// Errors   ModelError, never a crash, for: a file that cannot be read; bytes that fail the
//          flatbuffers verifier (truncated, corrupt: the message gives the size and offset
//          checked); an index out of range (naming the table: "operator #3 input 2: tensor
//          index 999 out of range (model has 271 tensors)"); a constant buffer whose size
//          disagrees with its tensor's shape; a tensor type other than FLOAT32, FLOAT16 or
//          INT32; an operator we do not run ("unsupported operator SOFTMAX (code 25) at
//          operator #12"); a fused activation other than NONE, RELU, RELU_N1_TO_1, RELU6.
// Reads    our own minimal schema (core/vision/schema/tflite_min.fbs, TFLite's field ids).
//          Operator codes: the larger of deprecated_builtin_code and builtin_code, as TFLite
//          itself resolves them (older files fill only the first, newer ones both).
// Lifetime Tensor::data spans point into the model's own copy of the bytes: valid while the
//          model lives (moves keep them valid; the model is not copyable).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "gbdcs/vision/model_files.hpp"

namespace gbdcs::vision {

enum class TensorType { kFloat32, kFloat16, kInt32 };
std::string_view to_string(TensorType type);
std::size_t element_size(TensorType type);

// The TFLite builtin operator codes we run (values are TFLite's BuiltinOperator).
enum class BuiltinOp : std::int32_t {
  kAdd = 0,
  kConcatenation = 2,
  kConv2d = 3,
  kDepthwiseConv2d = 4,
  kDequantize = 6,
  kFullyConnected = 9,
  kLogistic = 14,
  kMaxPool2d = 17,
  kReshape = 22,
  kResizeBilinear = 23,
  kPad = 34,
  kMean = 40,
  kPrelu = 54,
};

// TFLite's name of any builtin code ("SOFTMAX" for 25); "UNKNOWN" past the table.
std::string_view builtin_op_name(std::int32_t code);

enum class Padding { kSame, kValid };
enum class Activation { kNone, kRelu, kReluN1To1, kRelu6 };

struct Conv2dOptions {  // CONV_2D and DEPTHWISE_CONV_2D
  Padding padding = Padding::kSame;
  int stride_h = 1;
  int stride_w = 1;
  int dilation_h = 1;
  int dilation_w = 1;
  int depth_multiplier = 1;  // DEPTHWISE_CONV_2D only; TFLite treats it as redundant
  Activation activation = Activation::kNone;
};
struct Pool2dOptions {
  Padding padding = Padding::kSame;
  int stride_h = 1;
  int stride_w = 1;
  int filter_h = 1;
  int filter_w = 1;
  Activation activation = Activation::kNone;
};
struct AddOptions {
  Activation activation = Activation::kNone;
};
struct FullyConnectedOptions {
  Activation activation = Activation::kNone;
  bool keep_num_dims = false;
};
struct ConcatenationOptions {
  int axis = 0;
  Activation activation = Activation::kNone;
};
struct ReshapeOptions {
  std::vector<int> new_shape;  // often absent: the shape then comes from input 1
};
struct ResizeBilinearOptions {
  bool align_corners = false;
  bool half_pixel_centers = false;
};
struct ReducerOptions {  // MEAN
  bool keep_dims = false;
};

using OperatorOptions =
    std::variant<std::monostate, Conv2dOptions, Pool2dOptions, AddOptions, FullyConnectedOptions,
                 ConcatenationOptions, ReshapeOptions, ResizeBilinearOptions, ReducerOptions>;

struct TensorDesc {
  std::string name;
  std::vector<int> shape;  // every dimension >= 0
  TensorType type = TensorType::kFloat32;
  std::uint32_t buffer = 0;         // index into the model's buffers
  std::span<const std::byte> data;  // constant contents; empty for activations
  bool is_constant() const { return !data.empty(); }
  std::size_t element_count() const;
};

struct OperatorDesc {
  BuiltinOp op = BuiltinOp::kAdd;
  std::vector<int> inputs;  // tensor indices; -1 = optional input left out
  std::vector<int> outputs;
  OperatorOptions options;
};

class TfliteModel {
 public:
  static TfliteModel from_file(const std::string& path);
  static TfliteModel from_bytes(std::vector<std::uint8_t> bytes);

  TfliteModel(TfliteModel&&) noexcept = default;
  TfliteModel& operator=(TfliteModel&&) noexcept = default;
  TfliteModel(const TfliteModel&) = delete;
  TfliteModel& operator=(const TfliteModel&) = delete;

  const std::vector<TensorDesc>& tensors() const { return tensors_; }
  const std::vector<OperatorDesc>& operators() const { return operators_; }
  const std::vector<std::span<const std::byte>>& buffers() const { return buffers_; }
  const std::vector<int>& inputs() const { return inputs_; }
  const std::vector<int>& outputs() const { return outputs_; }
  const std::string& description() const { return description_; }
  std::size_t size_bytes() const { return bytes_.size(); }

 private:
  TfliteModel() = default;
  friend class TfliteReader;

  std::vector<std::uint8_t> bytes_;
  std::string description_;
  std::vector<std::span<const std::byte>> buffers_;
  std::vector<TensorDesc> tensors_;
  std::vector<OperatorDesc> operators_;
  std::vector<int> inputs_;
  std::vector<int> outputs_;
};

}  // namespace gbdcs::vision
