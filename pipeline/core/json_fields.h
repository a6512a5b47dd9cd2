// Typed access to JSON fields with errors that name the field's path:
//   PX_ASSIGN_OR_RETURN(double fx, GetNumber(j, "fx", "lenses[3].camera"));
//   -> "lenses[3].camera.fx: missing" / "lenses[3].camera.fx: want a number, got string"
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::json {

std::string FieldPath(const std::string& parent, const std::string& key);
std::string IndexPath(const std::string& parent, size_t index);

StatusOr<const nlohmann::json*> GetField(const nlohmann::json& object,
                                         const std::string& key,
                                         const std::string& parent);
StatusOr<double> GetNumber(const nlohmann::json& object, const std::string& key, const std::string& parent);
StatusOr<int64_t> GetInteger(const nlohmann::json& object, const std::string& key, const std::string& parent);
StatusOr<std::string> GetString(const nlohmann::json& object, const std::string& key, const std::string& parent);
StatusOr<bool> GetBool(const nlohmann::json& object, const std::string& key, const std::string& parent);
// An array of exactly `size` numbers (size < 0: any length).
StatusOr<std::vector<double>> GetNumbers(const nlohmann::json& object,
                                         const std::string& key,
                                         const std::string& parent,
                                         int size = -1);

// Optional variants: the default when the key is absent, an error when present but mistyped.
StatusOr<double> GetNumberOr(const nlohmann::json& object,
                             const std::string& key,
                             const std::string& parent,
                             double fallback);
StatusOr<int64_t> GetIntegerOr(const nlohmann::json& object,
                               const std::string& key,
                               const std::string& parent,
                               int64_t fallback);
StatusOr<std::string> GetStringOr(const nlohmann::json& object,
                                  const std::string& key,
                                  const std::string& parent,
                                  const std::string& fallback);
StatusOr<bool> GetBoolOr(const nlohmann::json& object,
                         const std::string& key,
                         const std::string& parent,
                         bool fallback);

// Parses text; a syntax error names `what` and the byte offset.
StatusOr<nlohmann::json> Parse(const std::string& text, const std::string& what);

}  // namespace px::json
