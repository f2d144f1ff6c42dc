// InferenceRunner: runs a TfliteModel's main subgraph on XNNPACK's operator API, in fp32.
//
// Inputs   a TfliteModel; RunnerOptions. Per call: the input tensors, written through
//          input_data(i) (NHWC float32, shape as inputs()[i].shape).
// Outputs  invoke() fills the output tensors, read through output_data(i) or
//          output_data(output_index("Identity")).
// Options  threads 1 (>= 1): XNNPACK's worker threads; a pthreadpool only when > 1.
// Ops      CONV_2D, DEPTHWISE_CONV_2D, FULLY_CONNECTED, ADD (numpy broadcasting), MEAN over
//          H and W of a 4-D tensor, LOGISTIC, MAX_POOL_2D, PRELU (one slope per channel),
//          PAD (constant zero), RESIZE_BILINEAR, RESHAPE, CONCATENATION (our own kernel:
//          this XNNPACK has no concatenate), fused NONE/RELU/RELU_N1_TO_1/RELU6; constant
//          FLOAT16 weights behind DEQUANTIZE are converted to fp32 once, at create().
// Errors   create() throws ModelError naming the operator and the reason for anything it
//          cannot run exactly (a shape that disagrees with what the op computes, a weight
//          that is not constant, an axis or layout we do not handle), never crashes; invoke()
//          throws ModelError if XNNPACK fails. input_data/output_data throw std::out_of_range.
// Memory   all activations live in one arena, planned at create() so tensors whose lifetimes
//          do not overlap share memory; the runner keeps its own copy of every constant it
//          needs, so the model may be destroyed after create().
// Threads  one invoke() at a time per runner; separate runners are independent.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/vision/tflite_model.hpp"

namespace gbdcs::vision {

struct RunnerOptions {
  int threads = 1;
};

struct TensorInfo {
  std::string name;
  std::vector<int> shape;
};

class InferenceRunner {
 public:
  static std::unique_ptr<InferenceRunner> create(const TfliteModel& model,
                                                 RunnerOptions options = {});
  virtual ~InferenceRunner() = default;
  InferenceRunner(const InferenceRunner&) = delete;
  InferenceRunner& operator=(const InferenceRunner&) = delete;

  virtual const std::vector<TensorInfo>& inputs() const = 0;
  virtual const std::vector<TensorInfo>& outputs() const = 0;
  virtual float* input_data(std::size_t i) = 0;
  virtual void invoke() = 0;
  virtual const float* output_data(std::size_t i) const = 0;
  // Index of the output tensor with this name; throws ModelError listing the names if none.
  std::size_t output_index(std::string_view name) const;

 protected:
  InferenceRunner() = default;
};

}  // namespace gbdcs::vision
