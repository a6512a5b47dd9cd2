#include "sim/faults/fault_spec.h"

#include <algorithm>
#include <array>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pipeline/core/json_fields.h"

namespace px {
namespace {

struct KindInfo {
  FaultKind kind;
  const char* name;
  std::vector<std::string> fields;  // besides kind, capture, seed
};

const std::vector<KindInfo>& Kinds() {
  static const std::vector<KindInfo> kKinds = {
      {FaultKind::kTruncate, "truncate", {"view", "keep"}},
      {FaultKind::kGarble, "garble", {"view", "bytes", "flagged"}},
      {FaultKind::kDrop, "drop", {"view"}},
      {FaultKind::kReorder, "reorder", {}},
      {FaultKind::kReformat, "reformat", {"view", "pixel_format", "width", "height"}},
      {FaultKind::kStall, "stall", {}},
      {FaultKind::kVanish, "vanish", {"forever"}},
  };
  return kKinds;
}

const KindInfo& InfoOf(FaultKind kind) {
  for (const KindInfo& info : Kinds()) {
    if (info.kind == kind) return info;
  }
  return Kinds().front();
}

std::string Number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

std::string_view FaultKindName(FaultKind kind) { return InfoOf(kind).name; }

StatusOr<FaultKind> ParseFaultKind(std::string_view name) {
  std::string known;
  for (const KindInfo& info : Kinds()) {
    if (name == info.name) return info.kind;
    known += (known.empty() ? "" : ", ") + std::string(info.name);
  }
  return InvalidArgumentError("'" + std::string(name) + "' is not one of " + known);
}

Status FaultSpec::Validate(const std::string& field) const {
  auto bad = [&](const std::string& key, const std::string& what) {
    return InvalidArgumentError(json::FieldPath(field, key) + ": " + what);
  };
  if (capture < 0) return bad("capture", std::to_string(capture) + " is negative (0 = every capture)");
  if (view < 0) return bad("view", std::to_string(view) + " is negative");
  if (kind == FaultKind::kTruncate && !(keep >= 0 && keep < 1)) return bad("keep", Number(keep) + " is not in [0, 1)");
  if (kind == FaultKind::kGarble && bytes < 1) return bad("bytes", std::to_string(bytes) + " is below 1");
  if (kind == FaultKind::kReformat) {
    if (width < 0 || width > 32768) return bad("width", std::to_string(width) + " is not in [0, 32768]");
    if (height < 0 || height > 32768) return bad("height", std::to_string(height) + " is not in [0, 32768]");
    if (!pixel_format && width == 0 && height == 0) {
      return bad("pixel_format", "missing, and width and height are 0: a reformat must change something");
    }
  }
  return OkStatus();
}

StatusOr<FaultSpec> FaultSpecFromJson(const nlohmann::json& j, const std::string& field) {
  if (!j.is_object()) return InvalidArgumentError(field + ": want an object, got " + j.type_name());
  FaultSpec spec;
  PX_ASSIGN_OR_RETURN(std::string kind_name, json::GetString(j, "kind", field));
  StatusOr<FaultKind> kind = ParseFaultKind(kind_name);
  if (!kind.ok()) return kind.status().WithContext(json::FieldPath(field, "kind"));
  spec.kind = *kind;
  const KindInfo& info = InfoOf(spec.kind);
  std::vector<std::string> allowed = {"kind", "capture", "seed"};
  allowed.insert(allowed.end(), info.fields.begin(), info.fields.end());
  for (const auto& [key, value] : j.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string list;
    for (const std::string& k : allowed) list += (list.empty() ? "" : ", ") + k;
    return InvalidArgumentError(json::FieldPath(field, key) + ": unknown field for a " + info.name +
                                " fault (known: " + list + ")");
  }
  PX_ASSIGN_OR_RETURN(int64_t capture, json::GetIntegerOr(j, "capture", field, spec.capture));
  PX_ASSIGN_OR_RETURN(int64_t seed, json::GetIntegerOr(j, "seed", field, 1));
  PX_ASSIGN_OR_RETURN(int64_t view, json::GetIntegerOr(j, "view", field, spec.view));
  PX_ASSIGN_OR_RETURN(spec.keep, json::GetNumberOr(j, "keep", field, spec.keep));
  PX_ASSIGN_OR_RETURN(int64_t bytes, json::GetIntegerOr(j, "bytes", field, spec.bytes));
  PX_ASSIGN_OR_RETURN(spec.flagged, json::GetBoolOr(j, "flagged", field, spec.flagged));
  PX_ASSIGN_OR_RETURN(int64_t width, json::GetIntegerOr(j, "width", field, 0));
  PX_ASSIGN_OR_RETURN(int64_t height, json::GetIntegerOr(j, "height", field, 0));
  PX_ASSIGN_OR_RETURN(spec.forever, json::GetBoolOr(j, "forever", field, spec.forever));
  if (j.contains("pixel_format")) {
    PX_ASSIGN_OR_RETURN(std::string format, json::GetString(j, "pixel_format", field));
    spec.pixel_format = ParsePixelFormat(format);
    if (!spec.pixel_format) {
      return InvalidArgumentError(json::FieldPath(field, "pixel_format") + ": '" + format +
                                  "' is not one of RGB888, BGR888, GRAY8, YUYV, NV12, SRGGB8");
    }
  }
  auto in_int = [&](const char* key, int64_t v) -> Status {
    if (v < INT32_MIN || v > INT32_MAX) {
      return InvalidArgumentError(json::FieldPath(field, key) + ": " + std::to_string(v) + " is out of range");
    }
    return OkStatus();
  };
  PX_RETURN_IF_ERROR(in_int("capture", capture));
  PX_RETURN_IF_ERROR(in_int("view", view));
  PX_RETURN_IF_ERROR(in_int("bytes", bytes));
  PX_RETURN_IF_ERROR(in_int("width", width));
  PX_RETURN_IF_ERROR(in_int("height", height));
  if (seed < 0)
    return InvalidArgumentError(json::FieldPath(field, "seed") + ": " + std::to_string(seed) + " is negative");
  spec.capture = static_cast<int>(capture);
  spec.view = static_cast<int>(view);
  spec.bytes = static_cast<int>(bytes);
  spec.width = static_cast<int>(width);
  spec.height = static_cast<int>(height);
  spec.seed = static_cast<uint64_t>(seed);
  PX_RETURN_IF_ERROR(spec.Validate(field));
  return spec;
}

nlohmann::json FaultSpecToJson(const FaultSpec& spec) {
  nlohmann::json j = {{"kind", FaultKindName(spec.kind)}, {"capture", spec.capture}, {"seed", spec.seed}};
  for (const std::string& key : InfoOf(spec.kind).fields) {
    if (key == "view") j[key] = spec.view;
    if (key == "keep") j[key] = spec.keep;
    if (key == "bytes") j[key] = spec.bytes;
    if (key == "flagged") j[key] = spec.flagged;
    if (key == "pixel_format" && spec.pixel_format) j[key] = PixelFormatName(*spec.pixel_format);
    if (key == "width") j[key] = spec.width;
    if (key == "height") j[key] = spec.height;
    if (key == "forever") j[key] = spec.forever;
  }
  return j;
}

StatusOr<std::vector<FaultSpec>> FaultSpecsFromJson(const nlohmann::json& j, const std::string& field) {
  if (!j.is_array()) return InvalidArgumentError(field + ": want an array, got " + j.type_name());
  std::vector<FaultSpec> specs;
  for (size_t i = 0; i < j.size(); ++i) {
    PX_ASSIGN_OR_RETURN(FaultSpec spec, FaultSpecFromJson(j[i], json::IndexPath(field, i)));
    specs.push_back(spec);
  }
  return specs;
}

nlohmann::json FaultSpecsToJson(const std::vector<FaultSpec>& specs) {
  nlohmann::json j = nlohmann::json::array();
  for (const FaultSpec& spec : specs) j.push_back(FaultSpecToJson(spec));
  return j;
}

std::string DescribeFault(const FaultSpec& spec) {
  std::string text = std::string(FaultKindName(spec.kind)) +
                     (spec.capture == 0 ? " at every capture" : " at capture " + std::to_string(spec.capture));
  const nlohmann::json j = FaultSpecToJson(spec);
  std::string extra;
  for (const auto& [key, value] : j.items()) {
    if (key == "kind" || key == "capture" || key == "seed") continue;
    extra += (extra.empty() ? "" : ", ") + key + " " + (value.is_string() ? value.get<std::string>() : value.dump());
  }
  return extra.empty() ? text : text + " (" + extra + ")";
}

}  // namespace px
