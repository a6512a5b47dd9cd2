// Opens a GL platform library (libEGL, libOSMesa) at run time. Handles are kept for the life of
// the process: Mesa's drivers do not survive being unloaded and reloaded.
#pragma once

#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px::render::gl {

// dlopen(soname). Errors are UNAVAILABLE and name the platform, the library, the loader's reason
// and the Debian package that provides it.
StatusOr<void*> OpenSharedLibrary(const std::string& soname, std::string_view platform, std::string_view package);

// dlsym; nullptr when absent.
void* LibrarySymbol(void* library, const char* name);

}  // namespace px::render::gl
