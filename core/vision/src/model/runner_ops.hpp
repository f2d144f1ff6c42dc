// The runner's operator builders: one TFLite operator → one step (an XNNPACK operator set up
// on fixed arena pointers, or one of our own kernels). Private to core/vision.
#pragma once

#include <xnnpack.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gbdcs/vision/tflite_model.hpp"

namespace gbdcs::vision::detail {

struct XnnOperatorDeleter {
  void operator()(xnn_operator_t op) const { xnn_delete_operator(op); }
};
using XnnOperatorPtr = std::unique_ptr<xnn_operator, XnnOperatorDeleter>;

struct Step {
  std::string label;             // "operator #12 CONV_2D", for errors at invoke
  XnnOperatorPtr op;             // run with xnn_run_operator, or …
  std::function<void()> kernel;  // … our own kernel
};

// What a builder may ask of the runner while it is being created.
class BuildContext {
 public:
  virtual ~BuildContext() = default;
  virtual const TensorDesc& tensor(int index) const = 0;
  virtual bool is_constant(int index) const = 0;
  // fp32 data read while the runner runs (an activation in the arena, or a constant).
  virtual const float* input(int index) = 0;
  // fp32 constant that XNNPACK packs at create time (filters, biases, slopes).
  virtual const float* weights(int index) = 0;
  virtual float* output(int index) = 0;
  virtual pthreadpool_t threadpool() const = 0;
};

// Throws ModelError naming the operator when it cannot be run exactly.
Step build_step(const OperatorDesc& op, std::size_t index, BuildContext& ctx);

// Shared helpers of the builders.
std::string op_label(const OperatorDesc& op, std::size_t index);
std::string shape_text(const std::vector<int>& shape);
void check_status(xnn_status status, const std::string& where, const char* call);

Step build_conv2d(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_depthwise_conv2d(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_fully_connected(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_max_pool2d(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_mean(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_add(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_logistic(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_prelu(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_pad(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_resize_bilinear(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_reshape(const OperatorDesc& op, const std::string& where, BuildContext& ctx);
Step build_concatenation(const OperatorDesc& op, const std::string& where, BuildContext& ctx);

// Small shared checks.
void require_arity(const OperatorDesc& op, std::size_t min_inputs, std::size_t max_inputs,
                   const std::string& where);
const std::vector<int>& shape_of(BuildContext& ctx, int index);
void require_rank(BuildContext& ctx, int index, std::size_t rank, const std::string& what,
                  const std::string& where);
void require_constant(BuildContext& ctx, int index, const std::string& what,
                      const std::string& where);
void require_output_shape(BuildContext& ctx, const OperatorDesc& op,
                          const std::vector<int>& computed, const std::string& where);
std::vector<std::int32_t> int32_values(BuildContext& ctx, int index, const std::string& what,
                                       const std::string& where);
struct Bounds {
  float min;
  float max;
};
Bounds activation_bounds(Activation activation);

}  // namespace gbdcs::vision::detail
