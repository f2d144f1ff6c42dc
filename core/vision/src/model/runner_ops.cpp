#include "model/runner_ops.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace gbdcs::vision::detail {

std::string op_label(const OperatorDesc& op, std::size_t index) {
  return "operator #" + std::to_string(index) + " " +
         std::string(builtin_op_name(static_cast<std::int32_t>(op.op)));
}

std::string shape_text(const std::vector<int>& shape) {
  std::string text = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) text += (i ? ", " : "") + std::to_string(shape[i]);
  return text + "]";
}

void check_status(xnn_status status, const std::string& where, const char* call) {
  if (status != xnn_status_success) {
    throw ModelError(where + ": " + call + " failed (XNNPACK status " +
                     std::to_string(static_cast<int>(status)) + ")");
  }
}

void require_arity(const OperatorDesc& op, std::size_t min_inputs, std::size_t max_inputs,
                   const std::string& where) {
  if (op.inputs.size() < min_inputs || op.inputs.size() > max_inputs) {
    throw ModelError(where + ": " + std::to_string(op.inputs.size()) + " inputs, expected " +
                     (min_inputs == max_inputs
                          ? std::to_string(min_inputs)
                          : std::to_string(min_inputs) + " to " + std::to_string(max_inputs)));
  }
  if (op.outputs.size() != 1) {
    throw ModelError(where + ": " + std::to_string(op.outputs.size()) + " outputs, expected 1");
  }
  for (std::size_t i = 0; i < min_inputs; ++i) {
    if (op.inputs[i] < 0) throw ModelError(where + ": input " + std::to_string(i) + " is missing");
  }
}

const std::vector<int>& shape_of(BuildContext& ctx, int index) {
  return ctx.tensor(index).shape;
}

void require_rank(BuildContext& ctx, int index, std::size_t rank, const std::string& what,
                  const std::string& where) {
  const auto& shape = shape_of(ctx, index);
  if (shape.size() != rank) {
    throw ModelError(where + ": " + what + " has shape " + shape_text(shape) + ", expected " +
                     std::to_string(rank) + "-D");
  }
}

void require_constant(BuildContext& ctx, int index, const std::string& what,
                      const std::string& where) {
  if (!ctx.is_constant(index)) {
    throw ModelError(where + ": " + what + " (tensor '" + ctx.tensor(index).name +
                     "') must be constant");
  }
}

void require_output_shape(BuildContext& ctx, const OperatorDesc& op,
                          const std::vector<int>& computed, const std::string& where) {
  const auto& declared = shape_of(ctx, op.outputs[0]);
  if (declared != computed) {
    throw ModelError(where + ": output '" + ctx.tensor(op.outputs[0]).name + "' declared " +
                     shape_text(declared) + " but the operator computes " + shape_text(computed));
  }
}

std::vector<std::int32_t> int32_values(BuildContext& ctx, int index, const std::string& what,
                                       const std::string& where) {
  require_constant(ctx, index, what, where);
  const TensorDesc& t = ctx.tensor(index);
  if (t.type != TensorType::kInt32) {
    throw ModelError(where + ": " + what + " has type " + std::string(to_string(t.type)) +
                     ", expected INT32");
  }
  std::vector<std::int32_t> values(t.element_count());
  std::memcpy(values.data(), t.data.data(), values.size() * sizeof(std::int32_t));
  return values;
}

Bounds activation_bounds(Activation activation) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  switch (activation) {
    case Activation::kNone:
      return {-kInf, kInf};
    case Activation::kRelu:
      return {0.0f, kInf};
    case Activation::kReluN1To1:
      return {-1.0f, 1.0f};
    case Activation::kRelu6:
      return {0.0f, 6.0f};
  }
  return {-kInf, kInf};
}

Step build_step(const OperatorDesc& op, std::size_t index, BuildContext& ctx) {
  const std::string where = op_label(op, index);
  Step step;
  switch (op.op) {
    case BuiltinOp::kConv2d:
      step = build_conv2d(op, where, ctx);
      break;
    case BuiltinOp::kDepthwiseConv2d:
      step = build_depthwise_conv2d(op, where, ctx);
      break;
    case BuiltinOp::kFullyConnected:
      step = build_fully_connected(op, where, ctx);
      break;
    case BuiltinOp::kMaxPool2d:
      step = build_max_pool2d(op, where, ctx);
      break;
    case BuiltinOp::kMean:
      step = build_mean(op, where, ctx);
      break;
    case BuiltinOp::kAdd:
      step = build_add(op, where, ctx);
      break;
    case BuiltinOp::kLogistic:
      step = build_logistic(op, where, ctx);
      break;
    case BuiltinOp::kPrelu:
      step = build_prelu(op, where, ctx);
      break;
    case BuiltinOp::kPad:
      step = build_pad(op, where, ctx);
      break;
    case BuiltinOp::kResizeBilinear:
      step = build_resize_bilinear(op, where, ctx);
      break;
    case BuiltinOp::kReshape:
      step = build_reshape(op, where, ctx);
      break;
    case BuiltinOp::kConcatenation:
      step = build_concatenation(op, where, ctx);
      break;
    case BuiltinOp::kDequantize:
      throw ModelError(where + ": DEQUANTIZE of a non-constant tensor is not supported");
  }
  step.label = where;
  return step;
}

}  // namespace gbdcs::vision::detail
