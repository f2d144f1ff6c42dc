#include "model/tflite_verify.hpp"

#include <flatbuffers/flatbuffers.h>

#include <optional>
#include <string_view>

#include "tflite_min_generated.h"

namespace gbdcs::vision::detail {
namespace fb = tflite_fb;
namespace {

using Bytes = std::span<const std::uint8_t>;

// Generated tables derive privately from flatbuffers::Table, which sits at their address.
const flatbuffers::Table* as_table(const void* table) {
  return static_cast<const flatbuffers::Table*>(table);
}

std::string offset_of(Bytes bytes, const void* p) {
  return std::to_string(static_cast<const std::uint8_t*>(p) - bytes.data());
}

flatbuffers::Verifier make_verifier(Bytes bytes) {
  return flatbuffers::Verifier(bytes.data(), bytes.size());
}

bool table_start_ok(Bytes bytes, const void* table) {
  auto v = make_verifier(bytes);
  return as_table(table)->VerifyTableStart(v);
}

// The field's offset slot is inside the file and points inside it.
bool offset_field_ok(Bytes bytes, const void* table, flatbuffers::voffset_t field) {
  const auto v = make_verifier(bytes);
  return as_table(table)->VerifyOffset(v, field);
}

template <typename T>
bool vector_ok(Bytes bytes, const flatbuffers::Vector<T>* vec) {
  const auto v = make_verifier(bytes);
  return v.VerifyVector(vec);
}

// Checks a vector-of-tables field: the slot, the vector, then each element in order.
// `inner` may describe a bad element in more detail.
template <typename Parent, typename T, typename Inner>
std::optional<std::string> check_tables(
    Bytes bytes, const Parent* parent, flatbuffers::voffset_t field,
    const flatbuffers::Vector<flatbuffers::Offset<T>>* (Parent::*get)() const,
    const std::string& what, Inner inner) {
  if (!offset_field_ok(bytes, parent, field)) {
    return what + " (a field of the table at offset " + offset_of(bytes, parent) +
           ") points past the end of the file";
  }
  const auto* vec = (parent->*get)();
  if (vec == nullptr) return std::nullopt;
  if (!vector_ok(bytes, vec)) {
    return what + ": vector at offset " + offset_of(bytes, vec) + " runs past the end of the file";
  }
  for (flatbuffers::uoffset_t i = 0; i < vec->size(); ++i) {
    const T* element = vec->Get(i);
    const std::string name = what + "[" + std::to_string(i) + "]";
    auto v = make_verifier(bytes);
    if (element->Verify(v)) continue;
    if (auto detail = inner(element, name)) return detail;
    return name + " (table at offset " + offset_of(bytes, element) + ") is truncated or corrupt";
  }
  return std::nullopt;
}

constexpr auto kNoDetail = [](const auto*, const std::string&) -> std::optional<std::string> {
  return std::nullopt;
};

std::optional<std::string> check_subgraph(Bytes bytes, const fb::SubGraph* subgraph,
                                          const std::string& what) {
  if (!table_start_ok(bytes, subgraph)) {
    return what + " (table at offset " + offset_of(bytes, subgraph) +
           "): header or vtable outside the file";
  }
  if (auto bad = check_tables(bytes, subgraph, fb::SubGraph::VT_TENSORS, &fb::SubGraph::tensors,
                              what + ".tensors", kNoDetail)) {
    return bad;
  }
  return check_tables(bytes, subgraph, fb::SubGraph::VT_OPERATORS, &fb::SubGraph::operators,
                      what + ".operators", kNoDetail);
}

}  // namespace

bool verify_model_buffer(Bytes bytes) {
  if (bytes.size() >= FLATBUFFERS_MAX_BUFFER_SIZE) return false;
  auto v = make_verifier(bytes);
  return fb::VerifyModelBuffer(v);
}

std::string describe_verification_failure(Bytes bytes) {
  const std::string size = std::to_string(bytes.size()) + " bytes";
  if (bytes.size() >= FLATBUFFERS_MAX_BUFFER_SIZE) return "file too large (" + size + ")";
  if (bytes.size() < 2 * sizeof(flatbuffers::uoffset_t)) {
    return "file is " + size + ", too short for a TFLite flatbuffer";
  }
  if (!fb::ModelBufferHasIdentifier(bytes.data())) {
    return "no \"TFL3\" identifier at offset 4: not a TFLite model";
  }
  const auto root_offset = make_verifier(bytes).VerifyOffset(0);
  if (root_offset == 0)
    return "root table offset (at offset 0) points outside the file (" + size + ")";
  const auto* model = fb::GetModel(bytes.data());
  if (!table_start_ok(bytes, model)) {
    return "Model table at offset " + std::to_string(root_offset) +
           ": header or vtable outside the file (" + size + ")";
  }
  if (auto bad = check_tables(bytes, model, fb::Model::VT_OPERATOR_CODES,
                              &fb::Model::operator_codes, "operator_codes", kNoDetail)) {
    return *bad + " (file is " + size + ")";
  }
  if (auto bad = check_tables(bytes, model, fb::Model::VT_SUBGRAPHS, &fb::Model::subgraphs,
                              "subgraphs", [&](const fb::SubGraph* s, const std::string& what) {
                                return check_subgraph(bytes, s, what);
                              })) {
    return *bad + " (file is " + size + ")";
  }
  if (auto bad = check_tables(bytes, model, fb::Model::VT_BUFFERS, &fb::Model::buffers, "buffers",
                              kNoDetail)) {
    return *bad + " (file is " + size + ")";
  }
  return "flatbuffer verification failed (file is " + size +
         "): a field of the Model table is out of bounds, or the nesting is too deep";
}

}  // namespace gbdcs::vision::detail
