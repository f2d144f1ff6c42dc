// The TFLite model reader (core/vision), as it reads a .tflite file's bytes.
//
// Checks: from_bytes accepts or throws ModelError, nothing else; an accepted model keeps the
// promises of tflite_model.hpp: every tensor index in range (-1 only for an operator's
// optional input), every buffer index in range, every constant's byte size matching its
// shape and type, every dimension >= 0.
#include <optional>
#include <string>

#include "fuzz_harness.hpp"
#include "gbdcs/vision/tflite_model.hpp"

namespace gbdcs::fuzz {
namespace {

constexpr std::string_view kName = "tflite_model";

void check_index(int index, std::size_t count, bool optional, const std::string& where) {
  require((optional && index == -1) || (index >= 0 && static_cast<std::size_t>(index) < count),
          kName, where + ": tensor index " + std::to_string(index) + " accepted with " +
                     std::to_string(count) + " tensors");
}

}  // namespace

void tflite_model(Bytes input) {
  std::optional<vision::TfliteModel> model;
  try {
    model.emplace(vision::TfliteModel::from_bytes(std::vector<std::uint8_t>(input.begin(), input.end())));
  } catch (const vision::ModelError&) {
    return;
  }
  const auto& tensors = model->tensors();
  for (std::size_t t = 0; t < tensors.size(); ++t) {
    const auto& d = tensors[t];
    for (int dim : d.shape) require(dim >= 0, kName, "tensor " + d.name + " has a negative dimension");
    require(d.buffer < model->buffers().size() || model->buffers().empty(), kName,
            "tensor " + d.name + " names buffer " + std::to_string(d.buffer) + " of " +
                std::to_string(model->buffers().size()));
    if (d.is_constant()) {
      // The element count without wrap-around: a wrapped product could pass the size check.
      long double exact = 1;
      for (int dim : d.shape) exact *= dim;
      require(exact * static_cast<long double>(vision::element_size(d.type)) ==
                  static_cast<long double>(d.data.size()),
              kName, "constant " + d.name + ": its shape's element count wraps around");
      require(d.data.size() == d.element_count() * vision::element_size(d.type), kName,
              "constant " + d.name + " holds " + std::to_string(d.data.size()) +
                  " bytes for its shape");
    }
  }
  for (std::size_t o = 0; o < model->operators().size(); ++o) {
    const auto& op = model->operators()[o];
    const auto where = "operator #" + std::to_string(o);
    for (int i : op.inputs) check_index(i, tensors.size(), true, where + " input");
    for (int i : op.outputs) check_index(i, tensors.size(), false, where + " output");
  }
  for (int i : model->inputs()) check_index(i, tensors.size(), false, "subgraph input");
  for (int i : model->outputs()) check_index(i, tensors.size(), false, "subgraph output");
}

}  // namespace gbdcs::fuzz

GBDCS_FUZZ_ENTRY(tflite_model)
