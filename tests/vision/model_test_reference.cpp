// A naive TFLite interpreter for the tests: plain loops, double accumulators, the semantics of
// TFLite's reference kernels (padding, resize grids, broadcasting). Slow and obvious on purpose.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "model_test_builder.hpp"

namespace gbdcs::vision::testing {
namespace {

using Shape = std::vector<int>;
using Values = std::vector<float>;

std::size_t count(const Shape& s) {
  std::size_t n = 1;
  for (int d : s) n *= static_cast<std::size_t>(d);
  return n;
}

float activate(double v, Activation a) {
  switch (a) {
    case Activation::kNone:
      return static_cast<float>(v);
    case Activation::kRelu:
      return static_cast<float>(std::max(v, 0.0));
    case Activation::kReluN1To1:
      return static_cast<float>(std::clamp(v, -1.0, 1.0));
    case Activation::kRelu6:
      return static_cast<float>(std::clamp(v, 0.0, 6.0));
  }
  return static_cast<float>(v);
}

// TFLite's ComputePaddingHeightWidth: the padding before, given the declared output size.
int pad_before(int in, int filter, int stride, int dilation, int out, Padding padding) {
  if (padding == Padding::kValid) return 0;
  const int effective = (filter - 1) * dilation + 1;
  return std::max((out - 1) * stride + effective - in, 0) / 2;
}

// Flat index into a tensor of shape `in` broadcast (NumPy, right-aligned) to `out`.
std::size_t broadcast_index(std::size_t flat, const Shape& out, const Shape& in) {
  std::size_t index = 0;
  std::size_t stride = 1;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t d = out.size() - 1 - k;
    const auto coord = flat % static_cast<std::size_t>(out[d]);
    flat /= static_cast<std::size_t>(out[d]);
    if (k < in.size()) {
      const std::size_t e = in.size() - 1 - k;
      if (in[e] != 1) index += coord * stride;
      stride *= static_cast<std::size_t>(in[e]);
    }
  }
  return index;
}

struct Interpreter {
  const TfliteModel& model;
  std::vector<Values> values;

  const Values& in(const OperatorDesc& op, std::size_t i) {
    return values.at(static_cast<std::size_t>(op.inputs.at(i)));
  }
  const Shape& shape(int t) const { return model.tensors().at(static_cast<std::size_t>(t)).shape; }
  Values& out(const OperatorDesc& op) {
    auto& v = values.at(static_cast<std::size_t>(op.outputs.at(0)));
    v.assign(count(shape(op.outputs[0])), 0.0f);
    return v;
  }

  void conv(const OperatorDesc& op, bool depthwise) {
    const auto& o = std::get<Conv2dOptions>(op.options);
    const Shape& is = shape(op.inputs[0]);
    const Shape& fs = shape(op.inputs[1]);
    const Shape& os = shape(op.outputs[0]);
    const Values& x = in(op, 0);
    const Values& f = in(op, 1);
    const bool has_bias = op.inputs.size() > 2 && op.inputs[2] >= 0;
    const Values* bias = has_bias ? &in(op, 2) : nullptr;
    Values& y = out(op);
    const int kh = fs[1], kw = fs[2], ci = is[3], co = os[3];
    const int multiplier = depthwise ? co / ci : 1;
    const int top = pad_before(is[1], kh, o.stride_h, o.dilation_h, os[1], o.padding);
    const int left = pad_before(is[2], kw, o.stride_w, o.dilation_w, os[2], o.padding);
    for (int n = 0; n < os[0]; ++n)
      for (int oy = 0; oy < os[1]; ++oy)
        for (int ox = 0; ox < os[2]; ++ox)
          for (int oc = 0; oc < co; ++oc) {
            double sum = bias ? (*bias)[static_cast<std::size_t>(oc)] : 0.0;
            for (int ky = 0; ky < kh; ++ky)
              for (int kx = 0; kx < kw; ++kx) {
                const int iy = oy * o.stride_h - top + ky * o.dilation_h;
                const int ix = ox * o.stride_w - left + kx * o.dilation_w;
                if (iy < 0 || iy >= is[1] || ix < 0 || ix >= is[2]) continue;
                const std::size_t base =
                    ((static_cast<std::size_t>(n) * is[1] + iy) * is[2] + ix) * ci;
                if (depthwise) {
                  const std::size_t fi = (static_cast<std::size_t>(ky) * kw + kx) * co + oc;
                  sum += double{x[base + static_cast<std::size_t>(oc / multiplier)]} * f[fi];
                } else {
                  for (int c = 0; c < ci; ++c) {
                    const std::size_t fi =
                        ((static_cast<std::size_t>(oc) * kh + ky) * kw + kx) * ci + c;
                    sum += double{x[base + static_cast<std::size_t>(c)]} * f[fi];
                  }
                }
              }
            y[((static_cast<std::size_t>(n) * os[1] + oy) * os[2] + ox) * co + oc] =
                activate(sum, o.activation);
          }
  }

  void max_pool(const OperatorDesc& op) {
    const auto& o = std::get<Pool2dOptions>(op.options);
    const Shape& is = shape(op.inputs[0]);
    const Shape& os = shape(op.outputs[0]);
    const Values& x = in(op, 0);
    Values& y = out(op);
    const int top = pad_before(is[1], o.filter_h, o.stride_h, 1, os[1], o.padding);
    const int left = pad_before(is[2], o.filter_w, o.stride_w, 1, os[2], o.padding);
    for (int n = 0; n < os[0]; ++n)
      for (int oy = 0; oy < os[1]; ++oy)
        for (int ox = 0; ox < os[2]; ++ox)
          for (int c = 0; c < os[3]; ++c) {
            double best = -INFINITY;
            for (int ky = 0; ky < o.filter_h; ++ky)
              for (int kx = 0; kx < o.filter_w; ++kx) {
                const int iy = oy * o.stride_h - top + ky;
                const int ix = ox * o.stride_w - left + kx;
                if (iy < 0 || iy >= is[1] || ix < 0 || ix >= is[2]) continue;
                best = std::max<double>(
                    best, x[((static_cast<std::size_t>(n) * is[1] + iy) * is[2] + ix) * is[3] + c]);
              }
            y[((static_cast<std::size_t>(n) * os[1] + oy) * os[2] + ox) * os[3] + c] =
                activate(best, o.activation);
          }
  }

  void mean(const OperatorDesc& op) {
    const Shape& is = shape(op.inputs[0]);
    const Values& x = in(op, 0);
    Values& y = out(op);
    for (int n = 0; n < is[0]; ++n)
      for (int c = 0; c < is[3]; ++c) {
        double sum = 0;
        for (int i = 0; i < is[1] * is[2]; ++i)
          sum += x[(static_cast<std::size_t>(n) * is[1] * is[2] + i) * is[3] + c];
        y[static_cast<std::size_t>(n) * is[3] + c] = static_cast<float>(sum / (is[1] * is[2]));
      }
  }

  void fully_connected(const OperatorDesc& op) {
    const auto& o = std::get<FullyConnectedOptions>(op.options);
    const Shape& ws = shape(op.inputs[1]);
    const Values& x = in(op, 0);
    const Values& w = in(op, 1);
    const bool has_bias = op.inputs.size() > 2 && op.inputs[2] >= 0;
    const Values* bias = has_bias ? &in(op, 2) : nullptr;
    Values& y = out(op);
    const std::size_t units = static_cast<std::size_t>(ws[0]),
                      depth = static_cast<std::size_t>(ws[1]);
    for (std::size_t b = 0; b < x.size() / depth; ++b)
      for (std::size_t u = 0; u < units; ++u) {
        double sum = bias ? (*bias)[u] : 0.0;
        for (std::size_t k = 0; k < depth; ++k) sum += double{x[b * depth + k]} * w[u * depth + k];
        y[b * units + u] = activate(sum, o.activation);
      }
  }

  void add(const OperatorDesc& op) {
    const auto& o = std::get<AddOptions>(op.options);
    const Shape& os = shape(op.outputs[0]);
    Values& y = out(op);
    for (std::size_t i = 0; i < y.size(); ++i) {
      const double a = in(op, 0)[broadcast_index(i, os, shape(op.inputs[0]))];
      const double b = in(op, 1)[broadcast_index(i, os, shape(op.inputs[1]))];
      y[i] = activate(a + b, o.activation);
    }
  }

  void prelu(const OperatorDesc& op) {
    const Shape& os = shape(op.outputs[0]);
    Values& y = out(op);
    for (std::size_t i = 0; i < y.size(); ++i) {
      const float v = in(op, 0)[i];
      y[i] = v >= 0 ? v : v * in(op, 1)[broadcast_index(i, os, shape(op.inputs[1]))];
    }
  }

  void pad(const OperatorDesc& op) {
    const Shape& is = shape(op.inputs[0]);
    const Shape& os = shape(op.outputs[0]);
    std::vector<std::int32_t> pads(count(shape(op.inputs[1])));
    std::memcpy(pads.data(), model.tensors()[static_cast<std::size_t>(op.inputs[1])].data.data(),
                pads.size() * 4);
    const Values& x = in(op, 0);
    Values& y = out(op);
    for (std::size_t i = 0; i < y.size(); ++i) {
      std::size_t rest = i, src = 0, stride = 1;
      bool inside = true;
      for (std::size_t k = 0; k < os.size(); ++k) {
        const std::size_t d = os.size() - 1 - k;
        const int coord = static_cast<int>(rest % static_cast<std::size_t>(os[d])) - pads[2 * d];
        rest /= static_cast<std::size_t>(os[d]);
        if (coord < 0 || coord >= is[d])
          inside = false;
        else
          src += static_cast<std::size_t>(coord) * stride;
        stride *= static_cast<std::size_t>(is[d]);
      }
      y[i] = inside ? x[src] : 0.0f;
    }
  }

  // TFLite reference_ops::ResizeBilinear (ComputeInterpolationValues).
  void resize(const OperatorDesc& op) {
    const auto& o = std::get<ResizeBilinearOptions>(op.options);
    const Shape& is = shape(op.inputs[0]);
    const Shape& os = shape(op.outputs[0]);
    const Values& x = in(op, 0);
    Values& y = out(op);
    auto scale = [&](int in_size, int out_size) {
      return o.align_corners && out_size > 1 ? static_cast<float>(in_size - 1) / (out_size - 1)
                                             : static_cast<float>(in_size) / out_size;
    };
    const float sy = scale(is[1], os[1]);
    const float sx = scale(is[2], os[2]);
    auto grid = [&](int v, float s, int in_size, float* scaled, int* lo, int* hi) {
      *scaled = o.half_pixel_centers ? (static_cast<float>(v) + 0.5f) * s - 0.5f
                                     : static_cast<float>(v) * s;
      *lo = std::max(static_cast<int>(std::floor(*scaled)), 0);
      *hi = std::min(static_cast<int>(std::ceil(*scaled)), in_size - 1);
    };
    auto at = [&](int n, int yy, int xx, int c) {
      return double{x[((static_cast<std::size_t>(n) * is[1] + yy) * is[2] + xx) * is[3] + c]};
    };
    for (int n = 0; n < os[0]; ++n)
      for (int oy = 0; oy < os[1]; ++oy)
        for (int ox = 0; ox < os[2]; ++ox) {
          float fy, fx;
          int y0, y1, x0, x1;
          grid(oy, sy, is[1], &fy, &y0, &y1);
          grid(ox, sx, is[2], &fx, &x0, &x1);
          const double dy = fy - y0, dx = fx - x0;
          for (int c = 0; c < os[3]; ++c) {
            const double v = at(n, y0, x0, c) * (1 - dy) * (1 - dx) +
                             at(n, y1, x0, c) * dy * (1 - dx) + at(n, y0, x1, c) * (1 - dy) * dx +
                             at(n, y1, x1, c) * dy * dx;
            y[((static_cast<std::size_t>(n) * os[1] + oy) * os[2] + ox) * os[3] + c] =
                static_cast<float>(v);
          }
        }
  }

  void concat(const OperatorDesc& op) {
    const auto& o = std::get<ConcatenationOptions>(op.options);
    const Shape& os = shape(op.outputs[0]);
    const int axis = o.axis < 0 ? o.axis + static_cast<int>(os.size()) : o.axis;
    Values& y = out(op);
    std::size_t outer = 1;
    for (int d = 0; d < axis; ++d)
      outer *= static_cast<std::size_t>(os[static_cast<std::size_t>(d)]);
    std::size_t written = 0;
    for (std::size_t b = 0; b < outer; ++b)
      for (std::size_t i = 0; i < op.inputs.size(); ++i) {
        const Values& x = in(op, i);
        const std::size_t chunk = x.size() / outer;
        for (std::size_t k = 0; k < chunk; ++k)
          y[written++] = activate(x[b * chunk + k], o.activation);
      }
  }

  void run(const OperatorDesc& op) {
    switch (op.op) {
      case BuiltinOp::kConv2d:
        return conv(op, false);
      case BuiltinOp::kDepthwiseConv2d:
        return conv(op, true);
      case BuiltinOp::kMaxPool2d:
        return max_pool(op);
      case BuiltinOp::kMean:
        return mean(op);
      case BuiltinOp::kFullyConnected:
        return fully_connected(op);
      case BuiltinOp::kAdd:
        return add(op);
      case BuiltinOp::kPrelu:
        return prelu(op);
      case BuiltinOp::kPad:
        return pad(op);
      case BuiltinOp::kResizeBilinear:
        return resize(op);
      case BuiltinOp::kConcatenation:
        return concat(op);
      case BuiltinOp::kLogistic: {
        Values& y = out(op);
        for (std::size_t i = 0; i < y.size(); ++i)
          y[i] = static_cast<float>(1.0 / (1.0 + std::exp(-double{in(op, 0)[i]})));
        return;
      }
      case BuiltinOp::kReshape:
      case BuiltinOp::kDequantize: {
        const Values x = in(op, 0);
        out(op) = x;
        return;
      }
    }
    throw std::logic_error("reference: unknown op");
  }
};

}  // namespace

std::vector<std::vector<float>> reference_run(const TfliteModel& model,
                                              const std::vector<std::vector<float>>& inputs) {
  Interpreter interp{model, std::vector<Values>(model.tensors().size())};
  for (std::size_t t = 0; t < model.tensors().size(); ++t) {
    const TensorDesc& d = model.tensors()[t];
    if (!d.is_constant()) continue;
    Values& v = interp.values[t];
    v.resize(d.element_count());
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (d.type == TensorType::kFloat32) {
        std::memcpy(&v[i], d.data.data() + 4 * i, 4);
      } else if (d.type == TensorType::kFloat16) {
        std::uint16_t h;
        std::memcpy(&h, d.data.data() + 2 * i, 2);
        v[i] = from_half(h);
      }  // INT32 parameters are read where needed
    }
  }
  for (std::size_t i = 0; i < inputs.size(); ++i)
    interp.values[static_cast<std::size_t>(model.inputs()[i])] = inputs[i];
  for (const OperatorDesc& op : model.operators()) interp.run(op);
  std::vector<std::vector<float>> outputs;
  for (int t : model.outputs()) outputs.push_back(interp.values[static_cast<std::size_t>(t)]);
  return outputs;
}

}  // namespace gbdcs::vision::testing
