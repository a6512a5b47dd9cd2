// What the GL renderer uploads of a scene, made on the CPU (PrepareScene): each view's segment
// texels, the view mesh and the scene's depth range. GlSceneRenderer uploads them to its context;
// ExportWebScene (web_scene.h) writes the same for a renderer in a browser.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/render/gl/gl_view_mesh.h"
#include "pipeline/render/seam_skirt_options.h"

namespace px::render::gl {

// One input view: its layered depth and where its camera was.
struct PosedLayeredView {
  LayeredDepthView depth;
  Rigid3 cam_from_world;
};

// One view's texels (CV_32SC4): layers 0 and 1 as packed BGRA8 (weight in the top byte), then
// their segment indices (-1 none). Texels with a bad weight or segment are dropped (weight 0) and
// counted; segments whose plane is not finite or not in front over their rectangle are dropped.
struct ViewTexels {
  cv::Mat texels;
  std::vector<int> kept_segments;  // indices into the view's segments, ascending
  int dropped_segments = 0;
  int dropped_texels = 0;
  int kept_texels = 0;
};

// The scene as the GL back end draws it.
struct PreparedScene {
  std::vector<ViewTexels> texels;     // per view; no kept segments where no texel is kept
  std::vector<std::string> warnings;  // dropped segments and texels, each naming its view
  GlViewMesh mesh;                    // over the views with something to draw; vertex views index the views
  // The scene depth range rho of eq. (1) (ALGORITHM.md 1): the 1st to 99th percentile of layer-0
  // depth over all views, at least 1 % of the median; 1 m and 1 m without any depth.
  double rho_m = 1;
  double median_depth_m = 1;
};

// Applies `skirts` to every view in place (as the CPU reference's LayeredScene::Create does), then
// makes the texels (the colours prefiltered for the bilinear sample, as the CPU reference's), the
// mesh and the depth range. Errors: a view's images of the wrong type or size (naming it), no view
// with depth.
StatusOr<PreparedScene> PrepareScene(std::vector<PosedLayeredView>* views, const SeamSkirtOptions& skirts);

// "view 3 (id 7)": how errors and warnings name the view at `index`.
std::string ViewName(const LayeredDepthView& view, int index);

// The weight shader's mesh (x, y, view, 0): each triangle's corners, then each outer edge's ends;
// one zero vector for an empty mesh, since GLSL arrays have at least one element.
std::vector<std::array<float, 4>> MeshUniforms(const GlViewMesh& mesh);

}  // namespace px::render::gl
