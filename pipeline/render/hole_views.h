// Holes drawn again from the views the view mesh did not blend there (ALGORITHM.md section 6,
// "other views"; our addition, not the paper's). The mesh gives each pixel the (up to) three views
// nearest its ray; a pixel none of them covers is often seen by another view of the scene: a
// turned camera looks past the side of the lattice that the far lenses see, a disocclusion is
// seen by a lens farther out. Those pixels are composited again, before any hole filling, from up
// to three other views whose image holds the pixel's ray within the scene's depth range, nearest
// centre of projection first. Only the hole pixels' bounding box is drawn, so a frame with small
// holes pays little. What the other views do not cover stays a hole for the usual filling.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/render/compositor.h"
#include "pipeline/render/layered_scene.h"
#include "pipeline/render/render_options.h"
#include "pipeline/render/view_mesh.h"

namespace px::render {

// The slots of a second composite over `crop` (a rectangle of the frame): at each pixel where
// `holes` (CV_8U, frame size) is non-zero, up to three views that are not in that pixel's `slots`
// (the frame's viewing weights, frame size) and whose image holds the pixel's ray somewhere
// between the scene's near and far depths, nearest to the camera centre first, weighted by
// inverse distance; elsewhere no view. Row-major, crop.width * crop.height entries.
std::vector<ViewSlots> OtherViewSlots(const LayeredScene& scene,
                                      const CameraModel& camera,
                                      const Rigid3& cam_from_world,
                                      const std::vector<ViewSlots>& slots,
                                      const cv::Mat& holes,
                                      const cv::Rect& crop);

// The holes of `known` (CV_8U, 0 = hole) that the reverse soft z's first pass with radius
// small_hole_radius_px does not fill whole (SmallHoles, hole_fill.h; every hole when the radius
// is 0) into `holes` (CV_8U, 255 = such a hole), and their bounding box (empty: none). Cheap when
// there are none (an erosion of the holes' box), so a renderer can ask before it prepares anything.
cv::Rect LargeHoles(const cv::Mat& known, int small_hole_radius_px, cv::Mat* holes);

struct OtherViewsReport {
  int hole_pixels = 0;  // holes before (small ones included)
  int covered = 0;      // covered by other views (alpha >= covered_alpha)
};

// Composites the pixels where `known` (CV_8U) is 0 again from other views (OtherViewSlots) with
// the compositor of `quality`, and writes the colour and depth of those it covers into
// `composite` (colour, depth), marking them in `known`. `slots` are the frame's viewing weights.
// small_hole_radius_px > 0: holes that the reverse soft z's first pass with this radius fills
// whole (SmallHoles, hole_fill.h) are left alone, so frames with only small holes cost nothing.
OtherViewsReport CoverHolesFromOtherViews(const LayeredScene& scene,
                                          const CameraModel& camera,
                                          const Rigid3& cam_from_world,
                                          const std::vector<ViewSlots>& slots,
                                          RenderQuality quality,
                                          double covered_alpha,
                                          const TextureStretchOptions& stretch,
                                          int small_hole_radius_px,
                                          cv::Mat* known,
                                          FrameComposite* composite);

// The same for holes already found by LargeHoles (`holes`, `crop`): for a renderer that asked
// first, before preparing the scene. Returns the pixels covered.
int CoverLargeHolesFromOtherViews(const LayeredScene& scene,
                                  const CameraModel& camera,
                                  const Rigid3& cam_from_world,
                                  const std::vector<ViewSlots>& slots,
                                  RenderQuality quality,
                                  double covered_alpha,
                                  const TextureStretchOptions& stretch,
                                  const cv::Mat& holes,
                                  const cv::Rect& crop,
                                  cv::Mat* known,
                                  FrameComposite* composite);

}  // namespace px::render
