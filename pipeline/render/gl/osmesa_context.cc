// OSMesa: Mesa's off-screen GL (llvmpipe) into client memory, opened with dlopen. The context is
// bound to a 1x1 client buffer that nothing draws to: all rendering goes to framebuffer objects.
#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "pipeline/render/gl/gl_context.h"
#include "pipeline/render/gl/shared_library.h"

namespace px::render::gl {
namespace {

// From <GL/osmesa.h> (Mesa 22), which is not included: it pulls in <GL/gl.h>, whose
// declarations clash with <GL/glcorearb.h>, and this file needs only these.
using OsmesaContextHandle = struct osmesa_context*;
using OsmesaCreateContextAttribsFn = OsmesaContextHandle (*)(const int* attribs, OsmesaContextHandle share);
using OsmesaDestroyContextFn = void (*)(OsmesaContextHandle context);
using OsmesaMakeCurrentFn =
    unsigned char (*)(OsmesaContextHandle context, void* buffer, GLenum type, int width, int height);
using OsmesaGetProcAddressFn = void* (*)(const char* name);
constexpr int kOsmesaFormat = 0x22;
constexpr int kOsmesaDepthBits = 0x30;
constexpr int kOsmesaStencilBits = 0x31;
constexpr int kOsmesaAccumBits = 0x32;
constexpr int kOsmesaProfile = 0x33;
constexpr int kOsmesaCoreProfile = 0x34;
constexpr int kOsmesaContextMajorVersion = 0x36;
constexpr int kOsmesaContextMinorVersion = 0x37;

struct OsmesaLibrary {
  OsmesaCreateContextAttribsFn create = nullptr;
  OsmesaDestroyContextFn destroy = nullptr;
  OsmesaMakeCurrentFn make_current = nullptr;
  OsmesaGetProcAddressFn get_proc_address = nullptr;
};

StatusOr<OsmesaLibrary> LoadOsmesa(const std::string& soname) {
  PX_ASSIGN_OR_RETURN(void* handle, OpenSharedLibrary(soname, "osmesa", "libosmesa6"));
  OsmesaLibrary library;
  library.create = reinterpret_cast<OsmesaCreateContextAttribsFn>(LibrarySymbol(handle, "OSMesaCreateContextAttribs"));
  library.destroy = reinterpret_cast<OsmesaDestroyContextFn>(LibrarySymbol(handle, "OSMesaDestroyContext"));
  library.make_current = reinterpret_cast<OsmesaMakeCurrentFn>(LibrarySymbol(handle, "OSMesaMakeCurrent"));
  library.get_proc_address = reinterpret_cast<OsmesaGetProcAddressFn>(LibrarySymbol(handle, "OSMesaGetProcAddress"));
  if (library.create == nullptr || library.destroy == nullptr || library.make_current == nullptr ||
      library.get_proc_address == nullptr) {
    return UnavailableError("osmesa: " + soname + " lacks OSMesaCreateContextAttribs (Mesa 11.2 or newer is needed)");
  }
  return library;
}

class OsmesaContext final : public GlContext {
 public:
  OsmesaContext(OsmesaLibrary library, OsmesaContextHandle context) : library_(library), context_(context) {}
  ~OsmesaContext() override {
    ReleaseCurrent();
    library_.destroy(context_);
  }

  Status MakeCurrent() override {
    if (!library_.make_current(context_, buffer_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      return UnavailableError("osmesa: OSMesaMakeCurrent failed");
    }
    return OkStatus();
  }
  // A null context unbinds whatever is current on this thread (Mesa's OSMesaMakeCurrent).
  void ReleaseCurrent() override { library_.make_current(nullptr, nullptr, 0, 0, 0); }

  Status Init(const GlContextOptions& options) {
    PX_RETURN_IF_ERROR(MakeCurrent());
    auto resolve = [get = library_.get_proc_address](const char* name) { return get(name); };
    return LoadFunctionsAndInfo(resolve, "osmesa", options.allow_software);
  }

 private:
  OsmesaLibrary library_;
  OsmesaContextHandle context_;
  std::array<uint8_t, 4> buffer_{};  // the 1x1 RGBA surface OSMesa insists on
};

}  // namespace

StatusOr<std::unique_ptr<GlContext>> CreateOsmesaContext(const GlContextOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(OsmesaLibrary library, LoadOsmesa(options.osmesa_library));
  const int attribs[] = {kOsmesaFormat,
                         GL_RGBA,
                         kOsmesaDepthBits,
                         0,
                         kOsmesaStencilBits,
                         0,
                         kOsmesaAccumBits,
                         0,
                         kOsmesaProfile,
                         kOsmesaCoreProfile,
                         kOsmesaContextMajorVersion,
                         options.gl_major,
                         kOsmesaContextMinorVersion,
                         options.gl_minor,
                         0};
  OsmesaContextHandle handle = library.create(attribs, nullptr);
  if (handle == nullptr) {
    return UnavailableError("osmesa: OSMesaCreateContextAttribs refused a GL " + std::to_string(options.gl_major) +
                            "." + std::to_string(options.gl_minor) + " core context");
  }
  auto context = std::make_unique<OsmesaContext>(library, handle);
  PX_RETURN_IF_ERROR(context->Init(options));
  return std::unique_ptr<GlContext>(std::move(context));
}

}  // namespace px::render::gl
