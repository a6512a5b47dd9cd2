#include "tools/texture_stretch_flags.h"

namespace px::cli {

void AddTextureStretchFlags(CLI::App& command, TextureStretchOptions* options) {
  command
      .add_option("--stretch-fade-from",
                  options->fade_from,
                  "Segments whose texture the rendered view stretches more than this many times (against a "
                  "face-on surface there) start to fade out, [0, 100]; 0 = never")
      ->capture_default_str();
  command.add_option("--stretch-fade-to", options->fade_to, "... and are gone at this stretch (above the start)")
      ->capture_default_str();
}

}  // namespace px::cli
