// Builders for the element-wise and layout operators: ADD, LOGISTIC, PRELU, PAD,
// RESIZE_BILINEAR, RESHAPE, CONCATENATION (our own kernel: this XNNPACK has no concatenate).
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "model/runner_ops.hpp"

namespace gbdcs::vision::detail {
namespace {

std::vector<std::size_t> to_sizes(const std::vector<int>& shape) {
  return {shape.begin(), shape.end()};
}

std::size_t product(const std::vector<int>& shape, std::size_t begin, std::size_t end) {
  std::size_t p = 1;
  for (std::size_t i = begin; i < end; ++i) p *= static_cast<std::size_t>(shape[i]);
  return p;
}

void require_max_rank(const std::vector<int>& shape, const std::string& what,
                      const std::string& where) {
  if (shape.size() > XNN_MAX_TENSOR_DIMS) {
    throw ModelError(where + ": " + what + " has rank " + std::to_string(shape.size()) +
                     " (at most " + std::to_string(XNN_MAX_TENSOR_DIMS) + ")");
  }
}

// Channels-last split used by the "nc" operators: channels = last dimension.
std::pair<std::size_t, std::size_t> batch_and_channels(const TensorDesc& t) {
  const std::size_t channels = t.shape.empty() ? 1 : static_cast<std::size_t>(t.shape.back());
  return {t.element_count() / channels, channels};
}

}  // namespace

Step build_add(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 2, 2, where);
  const auto& options = std::get<AddOptions>(op.options);
  const auto& a = shape_of(ctx, op.inputs[0]);
  const auto& b = shape_of(ctx, op.inputs[1]);
  require_max_rank(a, "input 0", where);
  require_max_rank(b, "input 1", where);
  // NumPy broadcasting, aligned on the last dimension.
  const std::size_t rank = std::max(a.size(), b.size());
  std::vector<int> computed(rank);
  for (std::size_t i = 0; i < rank; ++i) {
    const int da = i < rank - a.size() ? 1 : a[i - (rank - a.size())];
    const int db = i < rank - b.size() ? 1 : b[i - (rank - b.size())];
    if (da != db && da != 1 && db != 1) {
      throw ModelError(where + ": shapes " + shape_text(a) + " and " + shape_text(b) +
                       " do not broadcast");
    }
    computed[i] = da == 1 ? db : da;
  }
  require_output_shape(ctx, op, computed, where);
  const Bounds bounds = activation_bounds(options.activation);
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_add_nd_f32(bounds.min, bounds.max, 0, &raw), where,
               "xnn_create_add_nd_f32");
  Step step;
  step.op.reset(raw);
  const auto sa = to_sizes(a);
  const auto sb = to_sizes(b);
  check_status(
      xnn_setup_add_nd_f32(raw, sa.size(), sa.data(), sb.size(), sb.data(), ctx.input(op.inputs[0]),
                           ctx.input(op.inputs[1]), ctx.output(op.outputs[0]), ctx.threadpool()),
      where, "xnn_setup_add_nd_f32");
  return step;
}

Step build_logistic(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 1, 1, where);
  require_output_shape(ctx, op, shape_of(ctx, op.inputs[0]), where);
  const auto [batch, channels] = batch_and_channels(ctx.tensor(op.inputs[0]));
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_sigmoid_nc_f32(channels, channels, channels, 0, &raw), where,
               "xnn_create_sigmoid_nc_f32");
  Step step;
  step.op.reset(raw);
  check_status(xnn_setup_sigmoid_nc_f32(raw, batch, ctx.input(op.inputs[0]),
                                        ctx.output(op.outputs[0]), ctx.threadpool()),
               where, "xnn_setup_sigmoid_nc_f32");
  return step;
}

Step build_prelu(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 2, 2, where);
  const auto& in = shape_of(ctx, op.inputs[0]);
  const int alpha = op.inputs[1];
  require_constant(ctx, alpha, "alpha", where);
  const auto& as = shape_of(ctx, alpha);
  // One slope per channel: alpha is [..., 1, C] against an input [..., C].
  const bool per_channel = !in.empty() && !as.empty() && as.size() <= in.size() &&
                           as.back() == in.back() &&
                           std::all_of(as.begin(), as.end() - 1, [](int d) { return d == 1; });
  if (!per_channel) {
    throw ModelError(where + ": alpha " + shape_text(as) + " for input " + shape_text(in) +
                     " (only one slope per channel is supported)");
  }
  require_output_shape(ctx, op, in, where);
  const auto [batch, channels] = batch_and_channels(ctx.tensor(op.inputs[0]));
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_prelu_nc_f32(channels, channels, channels, ctx.weights(alpha), 0, &raw),
               where, "xnn_create_prelu_nc_f32");
  Step step;
  step.op.reset(raw);
  check_status(xnn_setup_prelu_nc_f32(raw, batch, ctx.input(op.inputs[0]),
                                      ctx.output(op.outputs[0]), ctx.threadpool()),
               where, "xnn_setup_prelu_nc_f32");
  return step;
}

Step build_pad(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 2, 2, where);
  const auto& in = shape_of(ctx, op.inputs[0]);
  require_max_rank(in, "input", where);
  const auto pads = int32_values(ctx, op.inputs[1], "paddings", where);
  if (in.empty() ||
      shape_of(ctx, op.inputs[1]) != std::vector<int>{static_cast<int>(in.size()), 2}) {
    throw ModelError(where + ": paddings " + shape_text(shape_of(ctx, op.inputs[1])) +
                     " for input " + shape_text(in) + " (expected [rank, 2])");
  }
  std::vector<std::size_t> before(in.size());
  std::vector<std::size_t> after(in.size());
  std::vector<int> computed(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (pads[2 * i] < 0 || pads[2 * i + 1] < 0 || pads[2 * i] > (1 << 20) ||
        pads[2 * i + 1] > (1 << 20)) {
      throw ModelError(where + ": padding of dimension " + std::to_string(i) + " out of range");
    }
    before[i] = static_cast<std::size_t>(pads[2 * i]);
    after[i] = static_cast<std::size_t>(pads[2 * i + 1]);
    computed[i] = in[i] + pads[2 * i] + pads[2 * i + 1];
  }
  require_output_shape(ctx, op, computed, where);
  const float zero = 0.0f;
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_constant_pad_nd_x32(&zero, 0, &raw), where,
               "xnn_create_constant_pad_nd_x32");
  Step step;
  step.op.reset(raw);
  const auto sizes = to_sizes(in);
  check_status(xnn_setup_constant_pad_nd_x32(raw, sizes.size(), sizes.data(), before.data(),
                                             after.data(), ctx.input(op.inputs[0]),
                                             ctx.output(op.outputs[0]), ctx.threadpool()),
               where, "xnn_setup_constant_pad_nd_x32");
  return step;
}

Step build_resize_bilinear(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 2, 2, where);
  const auto& options = std::get<ResizeBilinearOptions>(op.options);
  const int input = op.inputs[0];
  require_rank(ctx, input, 4, "input", where);
  const auto& in = shape_of(ctx, input);
  const auto size = int32_values(ctx, op.inputs[1], "size", where);
  if (size.size() != 2 || size[0] < 1 || size[1] < 1 || size[0] > (1 << 16) ||
      size[1] > (1 << 16)) {
    throw ModelError(where + ": size must be two positive values [height, width]");
  }
  if (options.align_corners && options.half_pixel_centers) {
    throw ModelError(where + ": align_corners and half_pixel_centers are exclusive");
  }
  require_output_shape(ctx, op, {in[0], size[0], size[1], in[3]}, where);
  // XNNPACK's default is half-pixel centres; TF 1.x's corner-aligned grid is its legacy mode.
  std::uint32_t flags = 0;
  if (options.align_corners) {
    flags = XNN_FLAG_ALIGN_CORNERS;
  } else if (!options.half_pixel_centers) {
    flags = XNN_FLAG_TENSORFLOW_LEGACY_MODE;
  }
  const auto channels = static_cast<std::size_t>(in[3]);
  xnn_operator_t raw = nullptr;
  check_status(xnn_create_resize_bilinear2d_nhwc_f32(channels, channels, channels, flags, &raw),
               where, "xnn_create_resize_bilinear2d_nhwc_f32");
  Step step;
  step.op.reset(raw);
  check_status(xnn_setup_resize_bilinear2d_nhwc_f32(
                   raw, static_cast<std::size_t>(in[0]), static_cast<std::size_t>(in[1]),
                   static_cast<std::size_t>(in[2]), static_cast<std::size_t>(size[0]),
                   static_cast<std::size_t>(size[1]), ctx.input(input), ctx.output(op.outputs[0]),
                   ctx.threadpool()),
               where, "xnn_setup_resize_bilinear2d_nhwc_f32");
  return step;
}

Step build_reshape(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  require_arity(op, 1, 2, where);
  const TensorDesc& in = ctx.tensor(op.inputs[0]);
  const TensorDesc& out = ctx.tensor(op.outputs[0]);
  // The requested shape (options, else the shape tensor), with one -1 resolved.
  std::vector<std::int32_t> wanted = std::get<ReshapeOptions>(op.options).new_shape;
  if (op.inputs.size() == 2 && op.inputs[1] >= 0) {
    wanted = int32_values(ctx, op.inputs[1], "shape", where);
  }
  if (!wanted.empty()) {
    std::size_t known = 1;
    int unknown = -1;
    for (std::size_t i = 0; i < wanted.size(); ++i) {
      if (wanted[i] == -1 && unknown < 0) {
        unknown = static_cast<int>(i);
      } else if (wanted[i] < 0) {
        throw ModelError(where + ": bad new shape " + shape_text({wanted.begin(), wanted.end()}));
      } else {
        known *= static_cast<std::size_t>(wanted[i]);
      }
    }
    if (unknown >= 0 && known > 0) {
      wanted[static_cast<std::size_t>(unknown)] = static_cast<int>(in.element_count() / known);
    }
    require_output_shape(ctx, op, {wanted.begin(), wanted.end()}, where);
  }
  if (in.element_count() != out.element_count()) {
    throw ModelError(where + ": reshape of " + shape_text(in.shape) + " into " +
                     shape_text(out.shape) + " changes the element count");
  }
  const float* source = ctx.input(op.inputs[0]);
  float* target = ctx.output(op.outputs[0]);
  const std::size_t bytes = in.element_count() * sizeof(float);
  Step step;
  step.kernel = [source, target, bytes] { std::memcpy(target, source, bytes); };
  return step;
}

Step build_concatenation(const OperatorDesc& op, const std::string& where, BuildContext& ctx) {
  if (op.inputs.empty() || op.outputs.size() != 1) {
    throw ModelError(where + ": needs at least one input and exactly one output");
  }
  const auto& options = std::get<ConcatenationOptions>(op.options);
  const auto& first = shape_of(ctx, op.inputs[0]);
  const int rank = static_cast<int>(first.size());
  const int axis = options.axis < 0 ? options.axis + rank : options.axis;
  if (axis < 0 || axis >= rank) {
    throw ModelError(where + ": axis " + std::to_string(options.axis) + " out of range for rank " +
                     std::to_string(rank));
  }
  const auto axis_index = static_cast<std::size_t>(axis);
  std::vector<int> computed = first;
  computed[axis_index] = 0;
  struct Part {
    const float* data;
    std::size_t chunk;  // floats per outer index
  };
  std::vector<Part> parts;
  for (std::size_t i = 0; i < op.inputs.size(); ++i) {
    if (op.inputs[i] < 0) throw ModelError(where + ": input " + std::to_string(i) + " is missing");
    const auto& s = shape_of(ctx, op.inputs[i]);
    bool fits = s.size() == first.size();
    for (std::size_t d = 0; fits && d < s.size(); ++d) fits = d == axis_index || s[d] == first[d];
    if (!fits) {
      throw ModelError(where + ": input " + std::to_string(i) + " " + shape_text(s) +
                       " does not match " + shape_text(first) + " outside axis " +
                       std::to_string(axis));
    }
    const std::int64_t joined = std::int64_t{computed[axis_index]} + s[axis_index];
    if (joined > (std::int64_t{1} << 28)) throw ModelError(where + ": concatenated axis too large");
    computed[axis_index] = static_cast<int>(joined);
    parts.push_back({ctx.input(op.inputs[i]), product(s, axis_index, s.size())});
  }
  require_output_shape(ctx, op, computed, where);
  const std::size_t outer = product(computed, 0, axis_index);
  const std::size_t row = product(computed, axis_index, computed.size());
  float* out = ctx.output(op.outputs[0]);
  const Bounds bounds = activation_bounds(options.activation);
  const bool clamp = options.activation != Activation::kNone;
  Step step;
  step.kernel = [parts = std::move(parts), outer, row, out, bounds, clamp] {
    float* dst = out;
    for (std::size_t o = 0; o < outer; ++o) {
      for (const Part& part : parts) {
        std::memcpy(dst, part.data + o * part.chunk, part.chunk * sizeof(float));
        dst += part.chunk;
      }
    }
    if (clamp) {
      for (std::size_t i = 0; i < outer * row; ++i)
        out[i] = std::clamp(out[i], bounds.min, bounds.max);
    }
  };
  return step;
}

}  // namespace gbdcs::vision::detail
