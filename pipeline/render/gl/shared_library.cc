#include "pipeline/render/gl/shared_library.h"

#include <dlfcn.h>

#include <map>
#include <mutex>

namespace px::render::gl {

StatusOr<void*> OpenSharedLibrary(const std::string& soname, std::string_view platform, std::string_view package) {
  static std::mutex mutex;
  static std::map<std::string, void*> opened;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = opened.find(soname); it != opened.end()) return it->second;
  // RTLD_LOCAL: the library's GL symbols must not interpose on anything else in the process.
  void* handle = dlopen(soname.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* reason = dlerror();
    return UnavailableError(std::string(platform) + ": cannot load " + soname + " (" +
                            (reason != nullptr ? reason : "unknown reason") + "; Debian package " +
                            std::string(package) + ")");
  }
  opened.emplace(soname, handle);
  return handle;
}

void* LibrarySymbol(void* library, const char* name) { return dlsym(library, name); }

}  // namespace px::render::gl
