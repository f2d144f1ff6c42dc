#include "gbdcs/vision/inference_runner.hpp"

#include <pthreadpool.h>
#include <xnnpack.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "model/runner_ops.hpp"

namespace gbdcs::vision {
namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr std::size_t kAlignFloats = 16;  // 64-byte slots in the arena
constexpr std::size_t kPadFloats = XNN_EXTRA_BYTES / sizeof(float) + 1;  // XNNPACK may over-read
constexpr std::size_t kMaxArenaFloats = std::size_t{1} << 28;            // 1 GiB

void initialize_xnnpack() {
  static const xnn_status status = xnn_initialize(nullptr);
  if (status != xnn_status_success) {
    throw ModelError("xnn_initialize failed (XNNPACK status " +
                     std::to_string(static_cast<int>(status)) + "): unsupported CPU?");
  }
}

float half_to_float(std::uint16_t h) {
  const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000u) << 16;
  const std::uint32_t exponent = (h >> 10) & 0x1Fu;
  std::uint32_t mantissa = h & 0x3FFu;
  std::uint32_t bits = sign;
  if (exponent == 0x1F) {
    bits |= 0x7F800000u | (mantissa << 13);
  } else if (exponent != 0) {
    bits |= ((exponent + 112) << 23) | (mantissa << 13);
  } else if (mantissa != 0) {  // subnormal: normalise
    std::uint32_t shift = 0;
    while ((mantissa & 0x400u) == 0) {
      mantissa <<= 1;
      ++shift;
    }
    bits |= ((113 - shift) << 23) | ((mantissa & 0x3FFu) << 13);
  }
  return std::bit_cast<float>(bits);
}

struct Lifetime {
  int tensor = -1;
  std::size_t floats = 0;
  int first = 0;  // step that writes it (-1: a graph input)
  int last = 0;   // last step that reads it (steps: a graph output)
  std::size_t offset = 0;
};

// Greedy first-fit by decreasing size: tensors alive at the same time never share floats.
std::size_t plan_offsets(std::vector<Lifetime>& values) {
  std::vector<Lifetime*> order;
  for (auto& v : values) order.push_back(&v);
  std::stable_sort(order.begin(), order.end(),
                   [](const Lifetime* a, const Lifetime* b) { return a->floats > b->floats; });
  std::vector<const Lifetime*> placed;
  std::size_t total = 0;
  for (Lifetime* v : order) {
    std::vector<const Lifetime*> conflicts;
    for (const Lifetime* p : placed) {
      if (p->first <= v->last && v->first <= p->last) conflicts.push_back(p);
    }
    std::sort(conflicts.begin(), conflicts.end(),
              [](const Lifetime* a, const Lifetime* b) { return a->offset < b->offset; });
    std::size_t offset = 0;
    for (const Lifetime* c : conflicts) {
      if (offset + v->floats <= c->offset) break;
      offset = std::max(offset, c->offset + c->floats);
    }
    v->offset = offset;
    total = std::max(total, offset + v->floats);
    placed.push_back(v);
  }
  return total;
}

struct PoolDeleter {
  void operator()(pthreadpool_t pool) const { pthreadpool_destroy(pool); }
};

struct FreeDeleter {
  void operator()(float* p) const { std::free(p); }
};

class XnnRunner final : public InferenceRunner, private detail::BuildContext {
 public:
  XnnRunner(const TfliteModel& model, RunnerOptions options);

  const std::vector<TensorInfo>& inputs() const override { return inputs_; }
  const std::vector<TensorInfo>& outputs() const override { return outputs_; }
  float* input_data(std::size_t i) override {
    if (i >= input_tensors_.size()) throw std::out_of_range("input index " + std::to_string(i));
    return arena_.get() + arena_offset_[static_cast<std::size_t>(input_tensors_[i])];
  }
  const float* output_data(std::size_t i) const override {
    if (i >= output_tensors_.size()) throw std::out_of_range("output index " + std::to_string(i));
    const auto t = static_cast<std::size_t>(output_tensors_[i]);
    return is_const_[t] ? constants_[t].data() : arena_.get() + arena_offset_[t];
  }
  void invoke() override;

 private:
  // BuildContext
  const TensorDesc& tensor(int index) const override { return tensors_[at(index)]; }
  bool is_constant(int index) const override { return is_const_[at(index)] != 0; }
  const float* input(int index) override;
  const float* weights(int index) override;
  float* output(int index) override;
  pthreadpool_t threadpool() const override { return pool_.get(); }

  std::size_t at(int index) const { return static_cast<std::size_t>(index); }
  const float* constant_floats(int index);
  std::string where_tensor(int index) const {
    return building_ + ": tensor #" + std::to_string(index) + " '" + tensors_[at(index)].name + "'";
  }
  void fold_dequantize(const TfliteModel& model, std::vector<std::size_t>& runnable);
  void plan(const TfliteModel& model, const std::vector<std::size_t>& runnable);

  std::unique_ptr<pthreadpool, PoolDeleter> pool_;  // destroyed after the operators below
  std::vector<TensorDesc> tensors_;
  std::vector<char> is_const_;
  std::vector<char> read_at_run_;              // constants a step reads while invoking
  std::vector<std::vector<float>> constants_;  // fp32 copies, padded for XNNPACK's over-reads
  std::vector<std::size_t> arena_offset_;
  // calloc: zeroed pages arrive on first touch, so a model that fails its checks after
  // planning costs no time even when its (corrupt) shapes ask for a huge arena.
  std::unique_ptr<float[], FreeDeleter> arena_;
  std::vector<detail::Step> steps_;
  std::vector<int> input_tensors_;
  std::vector<int> output_tensors_;
  std::vector<TensorInfo> inputs_;
  std::vector<TensorInfo> outputs_;
  std::string building_;  // the operator being built, for messages
};

XnnRunner::XnnRunner(const TfliteModel& model, RunnerOptions options) {
  if (options.threads < 1) {
    throw std::invalid_argument("RunnerOptions.threads must be >= 1, got " +
                                std::to_string(options.threads));
  }
  initialize_xnnpack();
  if (options.threads > 1) {
    pool_.reset(pthreadpool_create(static_cast<std::size_t>(options.threads)));
    if (!pool_) throw std::runtime_error("pthreadpool_create failed");
  }
  tensors_ = model.tensors();
  const std::size_t n = tensors_.size();
  is_const_.resize(n);
  read_at_run_.resize(n);
  constants_.resize(n);
  arena_offset_.assign(n, kNone);
  for (std::size_t i = 0; i < n; ++i) is_const_[i] = tensors_[i].is_constant();

  std::vector<std::size_t> runnable;  // operators left once constant DEQUANTIZEs are folded
  fold_dequantize(model, runnable);
  plan(model, runnable);
  for (std::size_t k : runnable) {
    const OperatorDesc& op = model.operators()[k];
    building_ = detail::op_label(op, k);
    steps_.push_back(detail::build_step(op, k, *this));
  }
  building_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    tensors_[i].data = {};  // points into the model, which may go away now
    const bool graph_output = std::find(model.outputs().begin(), model.outputs().end(),
                                        static_cast<int>(i)) != model.outputs().end();
    if (!read_at_run_[i] && !graph_output) std::vector<float>().swap(constants_[i]);
  }
  for (int t : input_tensors_) inputs_.push_back({tensors_[at(t)].name, tensors_[at(t)].shape});
  for (int t : output_tensors_) {
    if (is_const_[at(t)]) weights(t);  // a constant output must be FLOAT32 too
    outputs_.push_back({tensors_[at(t)].name, tensors_[at(t)].shape});
  }
}

void XnnRunner::fold_dequantize(const TfliteModel& model, std::vector<std::size_t>& runnable) {
  const auto& ops = model.operators();
  for (std::size_t k = 0; k < ops.size(); ++k) {
    const OperatorDesc& op = ops[k];
    if (op.op != BuiltinOp::kDequantize) {
      runnable.push_back(k);
      continue;
    }
    building_ = detail::op_label(op, k);
    if (op.inputs.size() != 1 || op.outputs.size() != 1 || op.inputs[0] < 0) {
      throw ModelError(building_ + ": expected one input and one output");
    }
    const int in = op.inputs[0];
    const int out = op.outputs[0];
    const TensorDesc& source = tensors_[at(in)];
    const TensorDesc& target = tensors_[at(out)];
    if (!is_const_[at(in)]) {
      throw ModelError(building_ + ": DEQUANTIZE of a non-constant tensor ('" + source.name +
                       "') is not supported");
    }
    if (is_const_[at(out)]) throw ModelError(where_tensor(out) + " is written twice");
    if (source.type != TensorType::kFloat16 && source.type != TensorType::kFloat32) {
      throw ModelError(where_tensor(in) + ": DEQUANTIZE from " +
                       std::string(to_string(source.type)) + " is not supported (fp16 only)");
    }
    if (target.type != TensorType::kFloat32 || target.element_count() != source.element_count()) {
      throw ModelError(where_tensor(out) + ": expected FLOAT32 " +
                       detail::shape_text(source.shape));
    }
    std::vector<float> values(source.element_count() + kPadFloats, 0.0f);
    if (source.type == TensorType::kFloat16) {
      for (std::size_t i = 0; i < source.element_count(); ++i) {
        std::uint16_t h = 0;
        std::memcpy(&h, source.data.data() + 2 * i, sizeof h);
        values[i] = half_to_float(h);
      }
    } else {
      std::memcpy(values.data(), source.data.data(), source.data.size());
    }
    constants_[at(out)] = std::move(values);
    is_const_[at(out)] = 1;
  }
  building_.clear();
}

void XnnRunner::plan(const TfliteModel& model, const std::vector<std::size_t>& runnable) {
  const std::size_t n = tensors_.size();
  std::vector<int> first(n, std::numeric_limits<int>::max());
  std::vector<int> last(n, -1);
  auto define = [&](int t, int step, const std::string& who) {
    const TensorDesc& d = tensors_[at(t)];
    if (is_const_[at(t)] || first[at(t)] != std::numeric_limits<int>::max()) {
      throw ModelError(who + ": tensor #" + std::to_string(t) + " '" + d.name +
                       "' is constant or already written");
    }
    if (d.type != TensorType::kFloat32) {
      throw ModelError(who + ": tensor #" + std::to_string(t) + " '" + d.name + "' has type " +
                       std::string(to_string(d.type)) + " (only FLOAT32 activations are run)");
    }
    if (d.element_count() == 0) {
      throw ModelError(who + ": tensor #" + std::to_string(t) + " '" + d.name + "' is empty " +
                       detail::shape_text(d.shape));
    }
    first[at(t)] = step;
    last[at(t)] = step;
  };
  for (int t : model.inputs()) {
    define(t, -1, "subgraph input");
    input_tensors_.push_back(t);
  }
  for (std::size_t s = 0; s < runnable.size(); ++s) {
    const OperatorDesc& op = model.operators()[runnable[s]];
    const std::string who = detail::op_label(op, runnable[s]);
    const int step = static_cast<int>(s);
    for (int t : op.inputs) {
      if (t < 0 || is_const_[at(t)]) continue;
      if (first[at(t)] == std::numeric_limits<int>::max()) {
        throw ModelError(who + " reads tensor #" + std::to_string(t) + " '" + tensors_[at(t)].name +
                         "' before any operator writes it");
      }
      last[at(t)] = step;
    }
    for (int t : op.outputs) define(t, step, who);
  }
  const int end = static_cast<int>(runnable.size());
  for (int t : model.outputs()) {
    if (!is_const_[at(t)] && first[at(t)] == std::numeric_limits<int>::max()) {
      throw ModelError("subgraph output tensor #" + std::to_string(t) + " '" +
                       tensors_[at(t)].name + "' is never written");
    }
    last[at(t)] = end;
    output_tensors_.push_back(t);
  }
  std::vector<Lifetime> values;
  for (std::size_t t = 0; t < n; ++t) {
    if (first[t] == std::numeric_limits<int>::max()) continue;
    const std::size_t floats =
        (tensors_[t].element_count() + kAlignFloats - 1) / kAlignFloats * kAlignFloats;
    values.push_back({static_cast<int>(t), floats, first[t], last[t], 0});
  }
  const std::size_t total = plan_offsets(values);
  if (total > kMaxArenaFloats) {
    throw ModelError("activations need " + std::to_string(total * sizeof(float)) +
                     " bytes (limit 1 GiB)");
  }
  arena_.reset(static_cast<float*>(std::calloc(total + kPadFloats, sizeof(float))));
  if (!arena_)
    throw ModelError("cannot allocate " + std::to_string(total * sizeof(float)) + " bytes");
  for (const Lifetime& v : values) arena_offset_[at(v.tensor)] = v.offset;
}

const float* XnnRunner::constant_floats(int index) {
  auto& values = constants_[at(index)];
  const TensorDesc& t = tensors_[at(index)];
  if (values.empty()) {
    values.assign(t.element_count() + kPadFloats, 0.0f);
    std::memcpy(values.data(), t.data.data(), t.element_count() * sizeof(float));
  }
  return values.data();
}

const float* XnnRunner::weights(int index) {
  const TensorDesc& t = tensors_[at(index)];
  if (t.type != TensorType::kFloat32) {
    throw ModelError(where_tensor(index) + " has type " + std::string(to_string(t.type)) +
                     ", expected FLOAT32");
  }
  if (!is_const_[at(index)]) throw ModelError(where_tensor(index) + " must be constant");
  return constant_floats(index);
}

const float* XnnRunner::input(int index) {
  if (is_const_[at(index)]) {
    const float* data = weights(index);
    read_at_run_[at(index)] = 1;
    return data;
  }
  return arena_.get() + arena_offset_[at(index)];
}

float* XnnRunner::output(int index) {
  return arena_.get() + arena_offset_[at(index)];
}

void XnnRunner::invoke() {
  for (const detail::Step& step : steps_) {
    if (step.op) {
      const xnn_status status = xnn_run_operator(step.op.get(), pool_.get());
      if (status != xnn_status_success) {
        throw ModelError(step.label + ": xnn_run_operator failed (XNNPACK status " +
                         std::to_string(static_cast<int>(status)) + ")");
      }
    } else {
      step.kernel();
    }
  }
}

}  // namespace

std::unique_ptr<InferenceRunner> InferenceRunner::create(const TfliteModel& model,
                                                         RunnerOptions options) {
  return std::make_unique<XnnRunner>(model, options);
}

std::size_t InferenceRunner::output_index(std::string_view name) const {
  const auto& list = outputs();
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (list[i].name == name) return i;
  }
  std::string names;
  for (const auto& info : list) names += (names.empty() ? "" : ", ") + info.name;
  throw ModelError("no output named '" + std::string(name) + "' (outputs: " + names + ")");
}

}  // namespace gbdcs::vision
