#include "device/press_settings.h"

#include <array>
#include <utility>

#include "device/clip_job.h"
#include "pipeline/clip/clip_writer.h"
#include "pipeline/core/json_fields.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/output_frame.h"
#include "pipeline/direct/taxonomy.h"
#include "pipeline/io/durable_file.h"

namespace px::device {
namespace {

constexpr std::array<const char*, 4> kFields = {"move", "effect", "format", "size"};

std::string* FieldOf(PressSettings& settings, const std::string& name) {
  if (name == "move") return &settings.move;
  if (name == "effect") return &settings.effect;
  if (name == "format") return &settings.format;
  if (name == "size") return &settings.size;
  return nullptr;
}

// The output frame a size setting names: "source" = the capture's own (the default frame).
StatusOr<OutputFrameOptions> FrameOfSize(const std::string& size) {
  OutputFrameOptions frame;
  if (size == "source") return frame;
  if (size.find('x') == std::string::npos) {
    return InvalidArgumentError("size: '" + size.substr(0, 40) + "' is not WxH (e.g. 1920x1080) or source");
  }
  PX_RETURN_IF_ERROR(ParseOutputSize(size, &frame).WithContext("size"));  // names a size out of range
  return frame;
}

}  // namespace

Status ValidatePressSettings(const PressSettings& settings) {
  if (!settings.move.empty() && !IsKnownMove(settings.move)) {
    return InvalidArgumentError("move: '" + settings.move.substr(0, 40) + "' is not one of " + KnownMovesText());
  }
  if (!settings.effect.empty()) {
    if (settings.effect != "auto" && !direct::ParseEffect(settings.effect).ok()) {
      return InvalidArgumentError("effect: '" + settings.effect.substr(0, 40) + "' is not one of " +
                                  KnownEffectsText());
    }
  }
  if (!settings.format.empty()) {
    if (!clip::ParseClipFormat(settings.format).ok()) {
      return InvalidArgumentError("format: '" + settings.format.substr(0, 40) + "' is not one of mp4, gif, webp, png");
    }
  }
  if (!settings.size.empty()) PX_RETURN_IF_ERROR(FrameOfSize(settings.size).status());
  return OkStatus();
}

nlohmann::json PressSettingsToJson(const PressSettings& settings) {
  nlohmann::json j = nlohmann::json::object();
  PressSettings copy = settings;
  for (const char* name : kFields) {
    const std::string& value = *FieldOf(copy, name);
    j[name] = value.empty() ? nlohmann::json(nullptr) : nlohmann::json(value);
  }
  return j;
}

StatusOr<PressSettings> UpdatedPressSettings(const PressSettings& now, const nlohmann::json& changes) {
  if (!changes.is_object()) {
    return InvalidArgumentError(std::string("settings: want an object, got ") + changes.type_name());
  }
  PressSettings updated = now;
  for (const auto& [key, value] : changes.items()) {
    std::string* field = FieldOf(updated, key);
    if (field == nullptr) {
      return InvalidArgumentError("settings: unknown field '" + key.substr(0, 40) +
                                  "' (known: move, effect, format, size)");
    }
    if (value.is_null()) {
      field->clear();
    } else if (value.is_string()) {
      *field = value.get<std::string>();
    } else {
      return InvalidArgumentError(key + ": want a string or null, got " + value.type_name());
    }
  }
  PX_RETURN_IF_ERROR(ValidatePressSettings(updated));
  return updated;
}

Status ApplyPressSettings(const PressSettings& settings, ClipJobOptions* options) {
  PX_RETURN_IF_ERROR(ValidatePressSettings(settings));
  if (!settings.move.empty()) options->pipeline.direct.move = settings.move;
  if (!settings.effect.empty()) options->pipeline.direct.effect = settings.effect;
  if (!settings.format.empty()) options->clip.format = clip::ParseClipFormat(settings.format).value();
  if (!settings.size.empty()) options->pipeline.direct.output = FrameOfSize(settings.size).value();
  return OkStatus();
}

StatusOr<PressSettings> LoadPressSettings(const std::filesystem::path& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) {
    if (text.status().code() == StatusCode::kNotFound) return PressSettings{};
    return text.status();
  }
  const std::string what = path.string();
  PX_ASSIGN_OR_RETURN(nlohmann::json j, json::Parse(*text, what));
  StatusOr<PressSettings> settings = UpdatedPressSettings(PressSettings{}, j);
  if (!settings.ok()) return settings.status().WithContext(what);
  return settings;
}

Status SavePressSettings(const std::filesystem::path& path, const PressSettings& settings) {
  return WriteFileAtomically(path, PressSettingsToJson(settings).dump(2) + "\n");
}

}  // namespace px::device
