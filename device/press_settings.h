// What the camera's owner chose for the clips of the next presses (the web app's settings page,
// the control socket's "set_settings"), over the config's clip.* defaults. Kept in the store
// (settings.json), so a restart keeps them; each job records the settings it was pressed with.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/core/status.h"

namespace px::device {

struct ClipJobOptions;

// Each field "" = the config's own (clip.move, clip.effect, clip.format, clip.size or aspect).
struct PressSettings {
  std::string move;    // a camera move (pipeline/direct/taxonomy.h), or "auto"
  std::string effect;  // an image effect (pipeline/direct/direct_options.h), or "auto"
  std::string format;  // mp4, gif, webp or png
  std::string size;    // "WxH" (1920x1080, 1080x1920), or "source": the capture's own frame

  bool Empty() const { return move.empty() && effect.empty() && format.empty() && size.empty(); }
};

// INVALID_ARGUMENT naming the field: "effect: 'sepia' is not one of auto, none, dof_change, ...".
Status ValidatePressSettings(const PressSettings& settings);

// {"move": ..., "effect": ..., "format": ..., "size": ...}, null for a field left to the config.
nlohmann::json PressSettingsToJson(const PressSettings& settings);

// `now` with the fields `changes` holds replaced (a string, or null for the config's own) and
// the others kept; the result validated. Unknown fields and wrong types are errors naming them.
StatusOr<PressSettings> UpdatedPressSettings(const PressSettings& now, const nlohmann::json& changes);

// The clip job's options with the settings applied (validated by ValidatePressSettings).
Status ApplyPressSettings(const PressSettings& settings, ClipJobOptions* options);

// settings.json in the store: the settings saved by SavePressSettings; none saved = all "".
// A file that cannot be read as settings is an error naming it (the daemon logs it and keeps
// the config's defaults).
StatusOr<PressSettings> LoadPressSettings(const std::filesystem::path& path);
Status SavePressSettings(const std::filesystem::path& path, const PressSettings& settings);

}  // namespace px::device
