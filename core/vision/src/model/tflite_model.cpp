#include "gbdcs/vision/tflite_model.hpp"

#include <flatbuffers/flatbuffers.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>

#include "model/tflite_verify.hpp"
#include "tflite_min_generated.h"

namespace gbdcs::vision {
namespace fb = tflite_fb;

namespace {

constexpr std::size_t kMaxFileBytes = std::size_t{1} << 30;       // 1 GiB: far above any hand model
constexpr std::size_t kMaxTensorElements = std::size_t{1} << 28;  // 1 GiB of fp32

std::string op_label(std::size_t index, std::int32_t code) {
  return "operator #" + std::to_string(index) + " " + std::string(builtin_op_name(code));
}

std::string tensor_label(std::size_t index, const std::string& name) {
  return "tensor #" + std::to_string(index) + " '" + name + "'";
}

std::string shape_text(const std::vector<int>& shape) {
  std::string text = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) text += (i ? ", " : "") + std::to_string(shape[i]);
  return text + "]";
}

bool is_supported(std::int32_t code) {
  switch (static_cast<BuiltinOp>(code)) {
    case BuiltinOp::kAdd:
    case BuiltinOp::kConcatenation:
    case BuiltinOp::kConv2d:
    case BuiltinOp::kDepthwiseConv2d:
    case BuiltinOp::kDequantize:
    case BuiltinOp::kFullyConnected:
    case BuiltinOp::kLogistic:
    case BuiltinOp::kMaxPool2d:
    case BuiltinOp::kReshape:
    case BuiltinOp::kResizeBilinear:
    case BuiltinOp::kPad:
    case BuiltinOp::kMean:
    case BuiltinOp::kPrelu:
      return true;
  }
  return false;
}

Activation to_activation(fb::ActivationFunctionType type, const std::string& where) {
  switch (type) {
    case fb::ActivationFunctionType_NONE:
      return Activation::kNone;
    case fb::ActivationFunctionType_RELU:
      return Activation::kRelu;
    case fb::ActivationFunctionType_RELU_N1_TO_1:
      return Activation::kReluN1To1;
    case fb::ActivationFunctionType_RELU6:
      return Activation::kRelu6;
    case fb::ActivationFunctionType_TANH:
      throw ModelError(where + ": unsupported fused activation TANH");
    case fb::ActivationFunctionType_SIGN_BIT:
      throw ModelError(where + ": unsupported fused activation SIGN_BIT");
  }
  throw ModelError(where + ": unknown fused activation " + std::to_string(static_cast<int>(type)));
}

Padding to_padding(fb::Padding padding, const std::string& where) {
  if (padding == fb::Padding_SAME) return Padding::kSame;
  if (padding == fb::Padding_VALID) return Padding::kValid;
  throw ModelError(where + ": unknown padding " + std::to_string(static_cast<int>(padding)));
}

void require_positive(int value, const char* field, const std::string& where) {
  if (value < 1)
    throw ModelError(where + ": " + field + " " + std::to_string(value) + " (must be >= 1)");
}

// The options table an operator must carry, or NONE when it takes none we read.
fb::BuiltinOptions expected_options(BuiltinOp op) {
  switch (op) {
    case BuiltinOp::kConv2d:
      return fb::BuiltinOptions_Conv2DOptions;
    case BuiltinOp::kDepthwiseConv2d:
      return fb::BuiltinOptions_DepthwiseConv2DOptions;
    case BuiltinOp::kMaxPool2d:
      return fb::BuiltinOptions_Pool2DOptions;
    case BuiltinOp::kFullyConnected:
      return fb::BuiltinOptions_FullyConnectedOptions;
    case BuiltinOp::kConcatenation:
      return fb::BuiltinOptions_ConcatenationOptions;
    case BuiltinOp::kAdd:
      return fb::BuiltinOptions_AddOptions;
    case BuiltinOp::kResizeBilinear:
      return fb::BuiltinOptions_ResizeBilinearOptions;
    case BuiltinOp::kReshape:
      return fb::BuiltinOptions_ReshapeOptions;
    case BuiltinOp::kMean:
      return fb::BuiltinOptions_ReducerOptions;
    default:
      return fb::BuiltinOptions_NONE;
  }
}

OperatorOptions read_options(const fb::Operator& op, BuiltinOp code, const std::string& where) {
  const auto expected = expected_options(code);
  if (expected == fb::BuiltinOptions_NONE) return std::monostate{};
  const auto type = op.builtin_options_type();
  const bool present = type != fb::BuiltinOptions_NONE && op.builtin_options() != nullptr;
  if (present && type != expected) {
    throw ModelError(where + ": builtin options of type " + std::to_string(static_cast<int>(type)) +
                     ", expected " + fb::EnumNameBuiltinOptions(expected));
  }
  const bool required = code == BuiltinOp::kConv2d || code == BuiltinOp::kDepthwiseConv2d ||
                        code == BuiltinOp::kMaxPool2d;
  if (!present && required) {
    throw ModelError(where + ": missing " + fb::EnumNameBuiltinOptions(expected));
  }
  switch (code) {
    case BuiltinOp::kConv2d: {
      const auto* o = op.builtin_options_as_Conv2DOptions();
      Conv2dOptions out{to_padding(o->padding(), where),
                        o->stride_h(),
                        o->stride_w(),
                        o->dilation_h_factor(),
                        o->dilation_w_factor(),
                        1,
                        to_activation(o->fused_activation_function(), where)};
      require_positive(out.stride_h, "stride_h", where);
      require_positive(out.stride_w, "stride_w", where);
      require_positive(out.dilation_h, "dilation_h_factor", where);
      require_positive(out.dilation_w, "dilation_w_factor", where);
      return out;
    }
    case BuiltinOp::kDepthwiseConv2d: {
      const auto* o = op.builtin_options_as_DepthwiseConv2DOptions();
      Conv2dOptions out{to_padding(o->padding(), where),
                        o->stride_h(),
                        o->stride_w(),
                        o->dilation_h_factor(),
                        o->dilation_w_factor(),
                        o->depth_multiplier(),
                        to_activation(o->fused_activation_function(), where)};
      require_positive(out.stride_h, "stride_h", where);
      require_positive(out.stride_w, "stride_w", where);
      require_positive(out.dilation_h, "dilation_h_factor", where);
      require_positive(out.dilation_w, "dilation_w_factor", where);
      return out;
    }
    case BuiltinOp::kMaxPool2d: {
      const auto* o = op.builtin_options_as_Pool2DOptions();
      Pool2dOptions out{to_padding(o->padding(), where),
                        o->stride_h(),
                        o->stride_w(),
                        o->filter_height(),
                        o->filter_width(),
                        to_activation(o->fused_activation_function(), where)};
      require_positive(out.stride_h, "stride_h", where);
      require_positive(out.stride_w, "stride_w", where);
      require_positive(out.filter_h, "filter_height", where);
      require_positive(out.filter_w, "filter_width", where);
      return out;
    }
    case BuiltinOp::kFullyConnected: {
      const auto* o = present ? op.builtin_options_as_FullyConnectedOptions() : nullptr;
      if (o == nullptr) return FullyConnectedOptions{};
      if (o->weights_format() != 0) {
        throw ModelError(where + ": unsupported weights_format " +
                         std::to_string(static_cast<int>(o->weights_format())));
      }
      return FullyConnectedOptions{to_activation(o->fused_activation_function(), where),
                                   o->keep_num_dims()};
    }
    case BuiltinOp::kConcatenation: {
      const auto* o = present ? op.builtin_options_as_ConcatenationOptions() : nullptr;
      if (o == nullptr) return ConcatenationOptions{};
      return ConcatenationOptions{o->axis(), to_activation(o->fused_activation_function(), where)};
    }
    case BuiltinOp::kAdd: {
      const auto* o = present ? op.builtin_options_as_AddOptions() : nullptr;
      if (o == nullptr) return AddOptions{};
      return AddOptions{to_activation(o->fused_activation_function(), where)};
    }
    case BuiltinOp::kResizeBilinear: {
      const auto* o = present ? op.builtin_options_as_ResizeBilinearOptions() : nullptr;
      if (o == nullptr) return ResizeBilinearOptions{};
      return ResizeBilinearOptions{o->align_corners(), o->half_pixel_centers()};
    }
    case BuiltinOp::kReshape: {
      const auto* o = present ? op.builtin_options_as_ReshapeOptions() : nullptr;
      ReshapeOptions out;
      if (o != nullptr && o->new_shape() != nullptr) {
        out.new_shape.assign(o->new_shape()->begin(), o->new_shape()->end());
      }
      return out;
    }
    case BuiltinOp::kMean: {
      const auto* o = present ? op.builtin_options_as_ReducerOptions() : nullptr;
      return ReducerOptions{o != nullptr && o->keep_dims()};
    }
    default:
      return std::monostate{};
  }
}

std::vector<int> read_indices(const flatbuffers::Vector<std::int32_t>* indices, std::size_t count,
                              bool allow_optional, const std::string& where) {
  std::vector<int> out;
  if (indices == nullptr) return out;
  out.reserve(indices->size());
  for (flatbuffers::uoffset_t i = 0; i < indices->size(); ++i) {
    const std::int32_t index = indices->Get(i);
    const bool optional = allow_optional && index == -1;
    if (!optional && (index < 0 || static_cast<std::size_t>(index) >= count)) {
      throw ModelError(where + " " + std::to_string(i) + ": tensor index " + std::to_string(index) +
                       " out of range (model has " + std::to_string(count) + " tensors)");
    }
    out.push_back(index);
  }
  return out;
}

}  // namespace

std::string_view to_string(TensorType type) {
  switch (type) {
    case TensorType::kFloat32:
      return "FLOAT32";
    case TensorType::kFloat16:
      return "FLOAT16";
    case TensorType::kInt32:
      return "INT32";
  }
  return "?";
}

std::size_t element_size(TensorType type) {
  return type == TensorType::kFloat16 ? 2 : 4;
}

std::size_t TensorDesc::element_count() const {
  std::size_t count = 1;
  for (int d : shape) count *= static_cast<std::size_t>(d);
  return count;
}

// Turns verified flatbuffer tables into the model's plain structs, checking as it goes.
class TfliteReader {
 public:
  static TfliteModel read(std::vector<std::uint8_t> bytes) {
    TfliteModel model;
    model.bytes_ = std::move(bytes);
    const std::span<const std::uint8_t> data(model.bytes_);
    if (data.size() > kMaxFileBytes) {
      throw ModelError("model is " + std::to_string(data.size()) + " bytes (limit 1 GiB)");
    }
    if (!detail::verify_model_buffer(data)) {
      throw ModelError("malformed TFLite model: " + detail::describe_verification_failure(data));
    }
    const fb::Model* root = fb::GetModel(data.data());
    if (root->description() != nullptr) model.description_ = root->description()->str();
    read_buffers(*root, data, model);
    if (root->subgraphs() == nullptr || root->subgraphs()->size() == 0) {
      throw ModelError("model has no subgraph");
    }
    const fb::SubGraph& graph = *root->subgraphs()->Get(0);
    read_tensors(graph, model);
    read_operators(*root, graph, model);
    const std::size_t count = model.tensors_.size();
    model.inputs_ = read_indices(graph.inputs(), count, false, "subgraph input");
    model.outputs_ = read_indices(graph.outputs(), count, false, "subgraph output");
    return model;
  }

 private:
  static void read_buffers(const fb::Model& root, std::span<const std::uint8_t> file,
                           TfliteModel& model) {
    if (root.buffers() == nullptr) return;
    model.buffers_.reserve(root.buffers()->size());
    for (flatbuffers::uoffset_t i = 0; i < root.buffers()->size(); ++i) {
      const fb::Buffer* buffer = root.buffers()->Get(i);
      std::span<const std::byte> bytes;
      if (buffer->data() != nullptr && buffer->data()->size() > 0) {
        bytes = std::as_bytes(std::span(buffer->data()->data(), buffer->data()->size()));
      } else if (buffer->offset() > 1) {  // TFLite: data stored after the flatbuffer
        const std::uint64_t offset = buffer->offset();
        const std::uint64_t size = buffer->size();
        if (offset > file.size() || size > file.size() - offset) {
          throw ModelError("buffer #" + std::to_string(i) + ": external data [" +
                           std::to_string(offset) + ", +" + std::to_string(size) +
                           ") runs past the end of the file (" + std::to_string(file.size()) +
                           " bytes)");
        }
        bytes = std::as_bytes(file.subspan(offset, size));
      }
      model.buffers_.push_back(bytes);
    }
  }

  static void read_tensors(const fb::SubGraph& graph, TfliteModel& model) {
    if (graph.tensors() == nullptr) return;
    model.tensors_.reserve(graph.tensors()->size());
    for (flatbuffers::uoffset_t i = 0; i < graph.tensors()->size(); ++i) {
      const fb::Tensor* t = graph.tensors()->Get(i);
      TensorDesc desc;
      desc.name = t->name() != nullptr ? t->name()->str() : "";
      const std::string where = tensor_label(i, desc.name);
      std::size_t elements = 1;
      if (t->shape() != nullptr) {
        for (std::int32_t d : *t->shape()) {
          if (d < 0) throw ModelError(where + ": negative dimension " + std::to_string(d));
          desc.shape.push_back(d);
          elements *= static_cast<std::size_t>(d);
          if (elements > kMaxTensorElements) {
            throw ModelError(where + ": more than 2^28 elements");
          }
        }
      }
      switch (t->type()) {
        case fb::TensorType_FLOAT32:
          desc.type = TensorType::kFloat32;
          break;
        case fb::TensorType_FLOAT16:
          desc.type = TensorType::kFloat16;
          break;
        case fb::TensorType_INT32:
          desc.type = TensorType::kInt32;
          break;
        default:
          throw ModelError(where + ": unsupported type " +
                           std::string(fb::EnumNameTensorType(t->type())) + " (code " +
                           std::to_string(static_cast<int>(t->type())) + "; float models only)");
      }
      desc.buffer = t->buffer();
      if (desc.buffer >= model.buffers_.size() && desc.buffer != 0) {
        throw ModelError(where + ": buffer index " + std::to_string(desc.buffer) +
                         " out of range (model has " + std::to_string(model.buffers_.size()) +
                         " buffers)");
      }
      if (desc.buffer < model.buffers_.size()) desc.data = model.buffers_[desc.buffer];
      const std::size_t needed = elements * element_size(desc.type);
      if (!desc.data.empty() && desc.data.size() != needed) {
        throw ModelError(where + ": buffer #" + std::to_string(desc.buffer) + " holds " +
                         std::to_string(desc.data.size()) + " bytes, shape " +
                         shape_text(desc.shape) + " " + std::string(to_string(desc.type)) +
                         " needs " + std::to_string(needed));
      }
      model.tensors_.push_back(std::move(desc));
    }
  }

  static void read_operators(const fb::Model& root, const fb::SubGraph& graph, TfliteModel& model) {
    if (graph.operators() == nullptr) return;
    const auto* codes = root.operator_codes();
    const std::size_t code_count = codes == nullptr ? 0 : codes->size();
    model.operators_.reserve(graph.operators()->size());
    for (flatbuffers::uoffset_t i = 0; i < graph.operators()->size(); ++i) {
      const fb::Operator* op = graph.operators()->Get(i);
      const std::string index_label = "operator #" + std::to_string(i);
      if (op->opcode_index() >= code_count) {
        throw ModelError(index_label + ": opcode_index " + std::to_string(op->opcode_index()) +
                         " out of range (model has " + std::to_string(code_count) +
                         " operator codes)");
      }
      const fb::OperatorCode* opcode = codes->Get(op->opcode_index());
      // TFLite's rule: the extended field wins once it is used (codes >= 127).
      const std::int32_t code =
          std::max<std::int32_t>(opcode->deprecated_builtin_code(), opcode->builtin_code());
      if (!is_supported(code)) {
        std::string name(builtin_op_name(code));
        if (code == 32 && opcode->custom_code() != nullptr) {
          name += " '" + opcode->custom_code()->str() + "'";
        }
        throw ModelError("unsupported operator " + name + " (code " + std::to_string(code) +
                         ") at " + index_label);
      }
      const std::string where = op_label(i, code);
      OperatorDesc desc;
      desc.op = static_cast<BuiltinOp>(code);
      const std::size_t count = model.tensors_.size();
      desc.inputs = read_indices(op->inputs(), count, true, where + " input");
      desc.outputs = read_indices(op->outputs(), count, false, where + " output");
      desc.options = read_options(*op, desc.op, where);
      model.operators_.push_back(std::move(desc));
    }
  }
};

TfliteModel TfliteModel::from_bytes(std::vector<std::uint8_t> bytes) {
  return TfliteReader::read(std::move(bytes));
}

TfliteModel TfliteModel::from_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw ModelError("cannot open model " + path);
  const std::streamoff size = in.tellg();
  if (size < 0) throw ModelError("cannot read model " + path);
  if (static_cast<std::uint64_t>(size) > kMaxFileBytes) {
    throw ModelError(path + ": " + std::to_string(size) + " bytes (limit 1 GiB)");
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) {
    throw ModelError("cannot read model " + path);
  }
  try {
    return from_bytes(std::move(bytes));
  } catch (const ModelError& e) {
    throw ModelError(path + ": " + e.what());
  }
}

}  // namespace gbdcs::vision
