// The layered scene for a renderer in a web browser (WebGL 2, tests/browser/web_scene_renderer.js):
// what GlSceneRenderer uploads to its context (view_texels.h) and what it sets each frame's draws
// up from (cameras, segment planes, the view mesh, rho), in one binary file, so the browser draws
// the GL back end's frames from the same data. Exported by the preview worker for
// POST /api/jobs/ID/preview/scene.
//
// Layout, little-endian: "PXWS", uint32 version (1), uint32 header length H, uint32 0; H bytes of
// JSON (spaces pad it to a multiple of 8); then per view its texels (height rows of width texels,
// 4 uint32 each, packed as view_texels.h says) and its kept segments (8 float64 each: bbox x, y,
// width, height, inverse-depth plane a, b, c, segment index). The header names each block's byte
// offset from the start of the file.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/render/gl/gl_scene_renderer.h"

namespace px::render::gl {

inline constexpr int kWebSceneVersion = 1;

// Errors: no views, a view's images of the wrong type or size (naming it), no view with depth.
StatusOr<std::string> ExportWebScene(std::vector<PosedLayeredView> views, const GlSceneRendererOptions& options);

}  // namespace px::render::gl
