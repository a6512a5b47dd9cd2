#include "pipeline/core/json_fields.h"

namespace px::json {
namespace {

std::string TypeName(const nlohmann::json& value) { return value.type_name(); }

Status Mistyped(const std::string& path, const std::string& want, const nlohmann::json& got) {
  return InvalidArgumentError(path + ": want " + want + ", got " + TypeName(got));
}

}  // namespace

std::string FieldPath(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string IndexPath(const std::string& parent, size_t index) { return parent + "[" + std::to_string(index) + "]"; }

StatusOr<const nlohmann::json*> GetField(const nlohmann::json& object,
                                         const std::string& key,
                                         const std::string& parent) {
  const std::string path = FieldPath(parent, key);
  if (!object.is_object())
    return InvalidArgumentError((parent.empty() ? "document" : parent) + ": want an object, got " + TypeName(object));
  auto it = object.find(key);
  if (it == object.end()) return InvalidArgumentError(path + ": missing");
  return &*it;
}

StatusOr<double> GetNumber(const nlohmann::json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(const nlohmann::json* value, GetField(object, key, parent));
  if (!value->is_number()) return Mistyped(FieldPath(parent, key), "a number", *value);
  return value->get<double>();
}

StatusOr<int64_t> GetInteger(const nlohmann::json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(const nlohmann::json* value, GetField(object, key, parent));
  if (!value->is_number_integer()) return Mistyped(FieldPath(parent, key), "an integer", *value);
  return value->get<int64_t>();
}

StatusOr<std::string> GetString(const nlohmann::json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(const nlohmann::json* value, GetField(object, key, parent));
  if (!value->is_string()) return Mistyped(FieldPath(parent, key), "a string", *value);
  return value->get<std::string>();
}

StatusOr<bool> GetBool(const nlohmann::json& object, const std::string& key, const std::string& parent) {
  PX_ASSIGN_OR_RETURN(const nlohmann::json* value, GetField(object, key, parent));
  if (!value->is_boolean()) return Mistyped(FieldPath(parent, key), "true or false", *value);
  return value->get<bool>();
}

StatusOr<std::vector<double>> GetNumbers(const nlohmann::json& object,
                                         const std::string& key,
                                         const std::string& parent,
                                         int size) {
  PX_ASSIGN_OR_RETURN(const nlohmann::json* value, GetField(object, key, parent));
  const std::string path = FieldPath(parent, key);
  if (!value->is_array()) return Mistyped(path, "an array of numbers", *value);
  if (size >= 0 && static_cast<int>(value->size()) != size) {
    return InvalidArgumentError(path + ": want " + std::to_string(size) + " numbers, got " +
                                std::to_string(value->size()));
  }
  std::vector<double> numbers;
  for (size_t i = 0; i < value->size(); ++i) {
    if (!(*value)[i].is_number()) return Mistyped(IndexPath(path, i), "a number", (*value)[i]);
    numbers.push_back((*value)[i].get<double>());
  }
  return numbers;
}

StatusOr<double> GetNumberOr(const nlohmann::json& object,
                             const std::string& key,
                             const std::string& parent,
                             double fallback) {
  if (!object.is_object() || !object.contains(key)) return fallback;
  return GetNumber(object, key, parent);
}

StatusOr<int64_t> GetIntegerOr(const nlohmann::json& object,
                               const std::string& key,
                               const std::string& parent,
                               int64_t fallback) {
  if (!object.is_object() || !object.contains(key)) return fallback;
  return GetInteger(object, key, parent);
}

StatusOr<std::string> GetStringOr(const nlohmann::json& object,
                                  const std::string& key,
                                  const std::string& parent,
                                  const std::string& fallback) {
  if (!object.is_object() || !object.contains(key)) return fallback;
  return GetString(object, key, parent);
}

StatusOr<bool> GetBoolOr(const nlohmann::json& object,
                         const std::string& key,
                         const std::string& parent,
                         bool fallback) {
  if (!object.is_object() || !object.contains(key)) return fallback;
  return GetBool(object, key, parent);
}

StatusOr<nlohmann::json> Parse(const std::string& text, const std::string& what) {
  nlohmann::json parsed = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded()) {
    // Re-parse with exceptions only to learn where it broke; exceptions stay inside this module.
    try {
      nlohmann::json ignored = nlohmann::json::parse(text);
      (void)ignored;
    } catch (const nlohmann::json::parse_error& e) {
      return InvalidArgumentError(what + ": malformed JSON at byte " + std::to_string(e.byte) + ": " + e.what());
    } catch (const nlohmann::json::exception& e) {
      // Not only syntax: a number too large for a double ("9e9499") is out_of_range (found by
      // the control_request and recording fuzzers).
      return InvalidArgumentError(what + ": malformed JSON: " + e.what());
    }
    return InvalidArgumentError(what + ": malformed JSON");
  }
  return parsed;
}

}  // namespace px::json
