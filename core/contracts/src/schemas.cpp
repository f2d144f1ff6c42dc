// Schema registry: the embedded JSON Schemas, parsed once, with cross-schema "$ref"s
// ("$ref": "motion_payload") inlined before valijson sees them.
#include <map>
#include <mutex>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::contracts {
namespace embedded {
std::vector<std::pair<std::string_view, std::string_view>> embedded_files();
}

namespace {

constexpr std::string_view kSuffix = ".schema.json";

std::string_view raw_schema(std::string_view name) {
  for (const auto& [file, text] : embedded::embedded_files()) {
    if (file.size() == name.size() + kSuffix.size() && file.substr(0, name.size()) == name &&
        file.substr(name.size()) == kSuffix) {
      return text;
    }
  }
  throw std::invalid_argument("unknown schema '" + std::string(name) + "'");
}

nlohmann::json inline_refs(nlohmann::json node, int depth) {
  if (depth > 8) throw std::logic_error("schema $ref nesting too deep");
  if (node.is_object()) {
    if (auto it = node.find("$ref"); it != node.end() && it->is_string()) {
      auto target = nlohmann::json::parse(raw_schema(it->get<std::string>()));
      target.erase("$schema");
      target.erase("$id");
      return inline_refs(std::move(target), depth + 1);
    }
    for (auto& [key, value] : node.items()) value = inline_refs(value, depth);
  } else if (node.is_array()) {
    for (auto& value : node) value = inline_refs(value, depth);
  }
  return node;
}

// "<root>" "[payload]" "[vx_m_s]" -> "payload.vx_m_s"
std::string field_path(const std::vector<std::string>& context) {
  std::string path;
  for (const auto& part : context) {
    if (part == "<root>") continue;
    std::string piece = part;
    if (piece.size() >= 2 && piece.front() == '[' && piece.back() == ']') {
      piece = piece.substr(1, piece.size() - 2);
    }
    if (!piece.empty() && piece.front() == '"' && piece.back() == '"' && piece.size() >= 2) {
      piece = piece.substr(1, piece.size() - 2);
    }
    if (!path.empty()) path += '.';
    path += piece;
  }
  return path;
}

struct Registry {
  std::mutex mutex;
  std::map<std::string, std::unique_ptr<valijson::Schema>, std::less<>> parsed;

  const valijson::Schema& get(std::string_view name) {
    std::lock_guard lock(mutex);
    if (auto it = parsed.find(name); it != parsed.end()) return *it->second;
    auto doc = inline_refs(nlohmann::json::parse(raw_schema(name)), 0);
    auto schema = std::make_unique<valijson::Schema>();
    valijson::SchemaParser parser(valijson::SchemaParser::kDraft7);
    valijson::adapters::NlohmannJsonAdapter adapter(doc);
    parser.populateSchema(adapter, *schema);
    auto& ref = *schema;
    parsed.emplace(std::string(name), std::move(schema));
    return ref;
  }
};

Registry& registry() {
  static Registry r;
  return r;
}

struct Violation {
  std::string field;
  std::string problem;
};

std::vector<Violation> collect(std::string_view schema_name, const nlohmann::json& doc) {
  const auto& schema = registry().get(schema_name);
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(doc);
  std::vector<Violation> out;
  if (validator.validate(schema, target, &results)) return out;
  valijson::ValidationResults::Error error;
  // valijson reports the innermost cause last; keep the most specific one per field.
  std::map<std::string, std::string> by_field;
  std::vector<std::string> order;
  while (results.popError(error)) {
    auto path = field_path(error.context);
    if (!by_field.contains(path)) order.push_back(path);
    by_field[path] = error.description;
  }
  for (const auto& path : order) out.push_back({path, by_field[path]});
  // A nested field's message is more useful than its parents' "failed to validate" summary.
  std::stable_sort(out.begin(), out.end(), [](const Violation& a, const Violation& b) {
    return a.field.size() > b.field.size();
  });
  return out;
}

}  // namespace

ContractError::ContractError(std::string field, const std::string& message)
    : std::runtime_error(message), field_(std::move(field)) {}

std::vector<std::string> schema_names() {
  std::vector<std::string> names;
  for (const auto& [file, text] : embedded::embedded_files()) {
    names.emplace_back(file.substr(0, file.size() - kSuffix.size()));
  }
  return names;
}

std::string_view schema_text(std::string_view schema_name) { return raw_schema(schema_name); }

std::vector<std::string> violations(std::string_view schema_name, const nlohmann::json& doc) {
  std::vector<std::string> out;
  for (const auto& v : collect(schema_name, doc)) {
    out.push_back((v.field.empty() ? std::string("(document)") : v.field) + ": " + v.problem);
  }
  return out;
}

void validate(std::string_view schema_name, const nlohmann::json& doc) {
  auto found = collect(schema_name, doc);
  if (found.empty()) return;
  const auto& first = found.front();
  std::string where = first.field.empty() ? "the document" : "field '" + first.field + "'";
  throw ContractError(first.field, std::string(schema_name) + ": " + where + " is invalid: " +
                                       first.problem + " (see core/contracts/schemas/" +
                                       std::string(schema_name) + ".schema.json)");
}

nlohmann::json parse_json(std::string_view text) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw ContractError("", "malformed JSON at byte " + std::to_string(e.byte) + ": " +
                                e.what() + " (send one well-formed JSON document)");
  } catch (const nlohmann::json::exception& e) {
    // A number too large for a double (1e999) is out_of_range, not a parse_error (fuzzing).
    throw ContractError("", std::string("malformed JSON: ") + e.what() +
                                " (send one well-formed JSON document; numbers must fit a double)");
  }
}

}  // namespace gbdcs::contracts
