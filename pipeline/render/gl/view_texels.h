// What the GL renderer uploads of a scene, made on the CPU: each view's segment texels, the view
// mesh as the weight shader's uniform array, and the scene's depth range. GlSceneRenderer uploads
// them to its context; ExportWebScene (web_scene.h) writes the same for a renderer in a browser.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/render/gl/gl_view_mesh.h"

namespace px::render::gl {

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

// INVALID_ARGUMENT, naming `view_name`, unless both layers' colour, weight and segment images are
// CV_8UC3, CV_32F and CV_32S of the camera's size.
Status CheckLayerImages(const LayeredDepthView& view, const std::string& view_name);

// `view` as the renderer draws it: its seam skirts applied already (WithSeamSkirts). The colours
// are prefiltered for the bilinear sample (PrefilterForBilinear), as the CPU reference's texels.
ViewTexels MakeViewTexels(const LayeredDepthView& view);

// The warnings MakeViewTexels' counts call for, each naming the view.
std::vector<std::string> ViewTexelWarnings(const ViewTexels& texels, int num_segments, const std::string& view_name);

// The view mesh over the views with something to draw (`drawn`: indices into `cam_from_world`,
// ascending); its vertex views index `cam_from_world`. FAILED_PRECONDITION when none is drawn.
StatusOr<GlViewMesh> MeshOfDrawnViews(const std::vector<Rigid3>& cam_from_world, const std::vector<int>& drawn);

// The weight shader's mesh (x, y, view, 0): each triangle's corners, then each outer edge's ends;
// one zero vector for an empty mesh, since GLSL arrays have at least one element.
std::vector<std::array<float, 4>> MeshUniforms(const GlViewMesh& mesh);

// The scene depth range rho of eq. (1) (ALGORITHM.md 1): the 1st to 99th percentile of layer-0
// depth over all views, at least 1 % of the median; 1 m and 1 m without any depth.
void SceneDepthRange(const std::vector<LayeredDepthView>& views, double* rho, double* median);

}  // namespace px::render::gl
