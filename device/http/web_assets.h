// The web app's static files (device/web), compiled into parallaxd by cmake/PxEmbedFiles.cmake,
// so the daemon serves exactly the pages it was built with and reads nothing from disk for them.
#pragma once

#include <string_view>
#include <vector>

namespace px::device {

struct EmbeddedFile {
  std::string_view name;  // relative to device/web: "index.html", "app.js"
  std::string_view bytes;
};

const std::vector<EmbeddedFile>& WebAssets();

}  // namespace px::device
