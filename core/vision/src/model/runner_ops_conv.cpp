// Builders for the windowed and matrix operators: CONV_2D, DEPTHWISE_CONV_2D,
// FULLY_CONNECTED, MAX_POOL_2D, MEAN (global average over H, W).
#include <algorithm>
#include <cstdint>
#include <limits>
#include <set>

#include "model/runner_ops.hpp"

namespace gbdcs::vision::detail {
namespace {

constexpr std::int64_t kMaxWindowParam =
    4096;  // kernel, stride, dilation: far above any real model

struct Window {
  int out = 0;
  std::uint32_t before = 0;
  std::uint32_t after = 0;
};

// TensorFlow's output size and padding along one spatial axis. SAME pads (total) so that
// out = ceil(in / stride), the extra row or column going after, as TF does.
Window window(int in, int kernel, int stride, int dilation, Padding padding, const char* axis,
              const std::string& where) {
  for (const std::int64_t v :
       {std::int64_t{kernel}, std::int64_t{stride}, std::int64_t{dilation}}) {
    if (v < 1 || v > kMaxWindowParam) {
      throw ModelError(where + ": " + axis + " kernel/stride/dilation " + std::to_string(kernel) +
                       "/" + std::to_string(stride) + "/" + std::to_string(dilation) +
                       " out of range");
    }
  }
  const std::int64_t effective = std::int64_t{kernel - 1} * dilation + 1;
  Window w;
  if (padding == Padding::kSame) {
    const std::int64_t out = (std::int64_t{in} + stride - 1) / stride;
    const std::int64_t total = std::max<std::int64_t>((out - 1) * stride + effective - in, 0);
    w.out = static_cast<int>(out);
    w.before = static_cast<std::uint32_t>(total / 2);
    w.after = static_cast<std::uint32_t>(total - total / 2);
  } else {
    if (in < effective) {
      throw ModelError(where + ": " + axis + " input " + std::to_string(in) +
                       " is smaller than the VALID window " + std::to_string(effective));
    }
    w.out = static_cast<int>((in - effective) / stride + 1);
  }
  return w;
}

int optional_input(const OperatorDesc& op, std::size_t i) {
  return op.inputs.size() > i ? op.inputs[i] : -1;
}

const float* bias_weights(BuildContext& ctx, int bias, int channels, const std::string& where) {
  if (bias < 0) return nullptr;
  require_constant(ctx, bias, "bias", where);
  if (ctx.tensor(bias).element_count() != static_cast<std::size_t>(channels)) {
    throw ModelError(where + ": bias has shape " + shape_text(shape_of(ctx, bias)) +
                     ", expected [" + std::to_string(channels) + "]");
  }
  return ctx.weights(bias);
}

Step convolution(const OperatorDesc& op, const std::string& where, BuildContext& ctx,
                 bool depthwise) {
  require_arity(op, 2, 3, where);
  const auto& options = std::get<Conv2dOptions>(op.options);
  const int input = op.inputs[0];
  const int filter = op.inputs[1];
  require_rank(ctx, input, 4, "input", where);
  require_rank(ctx, filter, 4, "filter", where);
  require_constant(ctx, filter, "filter", where);
  const auto& in = shape_of(ctx, input);
  const auto& fs = shape_of(ctx, filter);
  const int channels_in = in[3];
  int channels_out = 0;
  std::uint32_t groups = 1;
  std::size_t group_in = 0;
  std::size_t group_out = 0;
  if (depthwise) {  // TFLite filter [1, KH, KW, Cin * M]; XNNPACK HWG with groups = Cin
    channels_out = fs[3];
    if (fs[0] != 1 || channels_in == 0 || channels_out % channels_in != 0) {
      throw ModelError(where + ": filter " + shape_text(fs) + " does not fit input " +
                       shape_text(in) + " (expected [1, KH, KW, Cin * multiplier])");
    }
    groups = static_cast<std::uint32_t>(channels_in);
    group_in = 1;
    group_out = static_cast<std::size_t>(channels_out / channels_in);
  } else {  // TFLite filter OHWI = XNNPACK's layout with one group
    channels_out = fs[0];
    if (fs[3] != channels_in) {
      throw ModelError(where + ": filter " + shape_text(fs) + " does not fit input " +
                       shape_text(in) + " (expected [Cout, KH, KW, " + std::to_string(channels_in) +
                       "])");
    }
    group_in = static_cast<std::size_t>(channels_in);
    group_out = static_cast<std::size_t>(channels_out);
  }
  const float* bias = bias_weights(ctx, optional_input(op, 2), channels_out, where);
  const Window wy =
      window(in[1], fs[1], options.stride_h, options.dilation_h, options.padding, "height", where);
  const Window wx =
      window(in[2], fs[2], options.stride_w, options.dilation_w, options.padding, "width", where);
  require_output_shape(ctx, op, {in[0], wy.out, wx.out, channels_out}, where);
  const Bounds bounds = activation_bounds(options.activation);
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_convolution2d_nhwc_f32(
                   wy.before, wx.after, wy.after, wx.before, static_cast<std::uint32_t>(fs[1]),
                   static_cast<std::uint32_t>(fs[2]), static_cast<std::uint32_t>(options.stride_h),
                   static_cast<std::uint32_t>(options.stride_w),
                   static_cast<std::uint32_t>(options.dilation_h),
                   static_cast<std::uint32_t>(options.dilation_w), groups, group_in, group_out,
                   static_cast<std::size_t>(channels_in), static_cast<std::size_t>(channels_out),
                   ctx.weights(filter), bias, bounds.min, bounds.max,
                   depthwise ? XNN_FLAG_DEPTHWISE_CONVOLUTION : 0, &raw),
               where, "xnn_create_convolution2d_nhwc_f32");
  Step step;
  step.op.reset(raw);
  check_status(xnn_setup_convolution2d_nhwc_f32(raw, static_cast<std::size_t>(in[0]),
                                                static_cast<std::size_t>(in[1]),
                                                static_cast<std::size_t>(in[2]), ctx.input(input),
                                                ctx.output(op.outputs[0]), ctx.threadpool()),
               where, "xnn_setup_convolution2d_nhwc_f32");
  return step;
}

}  // namespace

Step build_conv2d(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  return convolution(op, where, ctx, false);
}

Step build_depthwise_conv2d(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  return convolution(op, where, ctx, true);
}

Step build_fully_connected(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 2, 3, where);
  const auto& options = std::get<FullyConnectedOptions>(op.options);
  const int input = op.inputs[0];
  const int weights = op.inputs[1];
  require_rank(ctx, weights, 2, "weights", where);
  require_constant(ctx, weights, "weights", where);
  const auto& ws = shape_of(ctx, weights);  // [outputs, inputs]
  const int units = ws[0];
  const int depth = ws[1];
  const auto& in = shape_of(ctx, input);
  const std::size_t elements = ctx.tensor(input).element_count();
  if (depth == 0 || elements % static_cast<std::size_t>(depth) != 0) {
    throw ModelError(where + ": input " + shape_text(in) + " does not fit weights " +
                     shape_text(ws));
  }
  const std::size_t batch = elements / static_cast<std::size_t>(depth);
  std::vector<int> computed{static_cast<int>(batch), units};
  if (options.keep_num_dims) {
    if (in.empty() || in.back() != depth) {
      throw ModelError(where + ": keep_num_dims needs the input's last dimension to be " +
                       std::to_string(depth));
    }
    computed = in;
    computed.back() = units;
  }
  const float* bias = bias_weights(ctx, optional_input(op, 2), units, where);
  require_output_shape(ctx, op, computed, where);
  const Bounds bounds = activation_bounds(options.activation);
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_fully_connected_nc_f32(
                   static_cast<std::size_t>(depth), static_cast<std::size_t>(units),
                   static_cast<std::size_t>(depth), static_cast<std::size_t>(units),
                   ctx.weights(weights), bias, bounds.min, bounds.max, 0, &raw),
               where, "xnn_create_fully_connected_nc_f32");
  Step step;
  step.op.reset(raw);
  check_status(xnn_setup_fully_connected_nc_f32(raw, batch, ctx.input(input),
                                                ctx.output(op.outputs[0]), ctx.threadpool()),
               where, "xnn_setup_fully_connected_nc_f32");
  return step;
}

Step build_max_pool2d(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 1, 1, where);
  const auto& options = std::get<Pool2dOptions>(op.options);
  const int input = op.inputs[0];
  require_rank(ctx, input, 4, "input", where);
  const auto& in = shape_of(ctx, input);
  if (options.filter_h == 1 && options.filter_w == 1) {
    throw ModelError(where + ": 1x1 max pooling is not supported");
  }
  const Window wy =
      window(in[1], options.filter_h, options.stride_h, 1, options.padding, "height", where);
  const Window wx =
      window(in[2], options.filter_w, options.stride_w, 1, options.padding, "width", where);
  require_output_shape(ctx, op, {in[0], wy.out, wx.out, in[3]}, where);
  const Bounds bounds = activation_bounds(options.activation);
  const auto channels = static_cast<std::size_t>(in[3]);
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_max_pooling2d_nhwc_f32(wy.before, wx.after, wy.after, wx.before,
                                                 static_cast<std::uint32_t>(options.filter_h),
                                                 static_cast<std::uint32_t>(options.filter_w),
                                                 static_cast<std::uint32_t>(options.stride_h),
                                                 static_cast<std::uint32_t>(options.stride_w), 1, 1,
                                                 channels, channels, channels, bounds.min,
                                                 bounds.max, 0, &raw),
               where, "xnn_create_max_pooling2d_nhwc_f32");
  Step step;
  step.op.reset(raw);
  check_status(xnn_setup_max_pooling2d_nhwc_f32(raw, static_cast<std::size_t>(in[0]),
                                                static_cast<std::size_t>(in[1]),
                                                static_cast<std::size_t>(in[2]), ctx.input(input),
                                                ctx.output(op.outputs[0]), ctx.threadpool()),
               where, "xnn_setup_max_pooling2d_nhwc_f32");
  return step;
}

Step build_mean(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 2, 2, where);
  const auto& options = std::get<ReducerOptions>(op.options);
  const int input = op.inputs[0];
  require_rank(ctx, input, 4, "input", where);
  const auto& in = shape_of(ctx, input);
  std::set<int> axes;
  for (std::int32_t axis : int32_values(ctx, op.inputs[1], "axes", where)) {
    axes.insert(axis < 0 ? axis + 4 : axis);
  }
  if (axes != std::set<int>{1, 2}) {
    std::string listed;
    for (int a : axes) listed += (listed.empty() ? "" : ", ") + std::to_string(a);
    throw ModelError(where + ": MEAN over axes [" + listed +
                     "] is not supported (only H and W of a 4-D tensor)");
  }
  require_output_shape(
      ctx, op,
      options.keep_dims ? std::vector<int>{in[0], 1, 1, in[3]} : std::vector<int>{in[0], in[3]},
      where);
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const auto channels = static_cast<std::size_t>(in[3]);
  xnn_operator_t raw = nullptr;
  check_status(
      xnn_create_global_average_pooling_nwc_f32(channels, channels, channels, -kInf, kInf, 0, &raw),
      where, "xnn_create_global_average_pooling_nwc_f32");
  Step step;
  step.op.reset(raw);
  check_status(xnn_setup_global_average_pooling_nwc_f32(
                   raw, static_cast<std::size_t>(in[0]),
                   static_cast<std::size_t>(in[1]) * static_cast<std::size_t>(in[2]),
                   ctx.input(input), ctx.output(op.outputs[0]), ctx.threadpool()),
               where, "xnn_setup_global_average_pooling_nwc_f32");
  return step;
}

}  // namespace gbdcs::vision::detail
