// Options for rendering novel views from layered depth (paper section 6; ALGORITHM.md). Every field
// has a default, a unit and a range; Validate() names the first bad field and its value.
#pragma once

#include <string_view>

#include "pipeline/core/status.h"
#include "pipeline/render/border_holes.h"
#include "pipeline/render/consistent_blend_options.h"
#include "pipeline/render/seam_skirt_options.h"
#include "pipeline/render/texture_stretch.h"

namespace px {

// Preview: the interactive renderer of paper 6.1 (three hard-z rendering buffers, reverse soft z
// hole filling, circle-of-confusion depth of field). Offline: paper 6.2 (one soft z over all
// fragments, exemplar inpainting of large holes, synthetic-aperture depth of field).
enum class RenderQuality { kPreview, kOffline };

std::string_view RenderQualityName(RenderQuality quality);  // "preview", "offline"
StatusOr<RenderQuality> ParseRenderQuality(std::string_view name);

struct RenderOptions {
  RenderQuality quality = RenderQuality::kPreview;
  // Soft z-buffer (eq. 1): gamma = soft_z_gamma_fraction * rho, rho the scene's depth range. The
  // paper uses 1/10. (0, 0.5).
  double soft_z_gamma_fraction = 0.1;
  // rho in metres; 0 = from the scene (1st to 99th percentile of the views' depths). [0, 1e4].
  double depth_range_m = 0;
  // A pixel counts as covered (not a hole) when its blended alpha reaches this. (0, 1].
  double covered_alpha = 0.5;
  // Reverse soft z hole filling window radius: 3 = the paper's 7x7, which fills holes under 6 px
  // completely in one pass. [1, 8].
  int hole_window_radius_px = 3;
  // Viewing weights raised to this power and renormalised (ALGORITHM.md section 3): 1 = the
  // paper's barycentric weights; below 1 the pixel's (up to) three views share the blend more
  // evenly, which averages their independent resampling errors, while a view still enters and
  // leaves the blend at weight 0, so a moving camera sees no jump. Ours. 0.5 scores about
  // 0.15 dB above 1 on the simulated scenes (`parallax eval render`) and the same on HCI and fern,
  // for about 1 % of a preview frame's CPU (the square root is fused into ComputeWeights). (0, 1].
  double viewing_weight_exponent = 0.5;
  // Holes are first drawn again from the views not blended there whose image holds the pixel's
  // ray (hole_views.h), nearest first; false: straight to filling. Our addition, not the paper's.
  bool holes_from_other_views = true;
  // Holes at the frame's border (outside every source's view) carried straight out from their
  // inner edge, fading to the local mean (border_holes.h), before the reverse soft z fills the
  // rest. Ours. It fills the holes of turned and backed-away viewpoints 0.1 to 3.9 dB better than
  // the reverse soft z alone (`parallax eval render`), HCI and fern unchanged. spread in [0, 4].
  render::BorderHoleFillOptions border_holes;
  // Offline exemplar inpainting: patch radius (2 = the paper's 5x5) and search window radius
  // (50 = the paper's 100x100). [1, 6] and [4, 1000].
  int inpaint_patch_radius_px = 2;
  int inpaint_window_radius_px = 50;
  // Offline depth of field: viewpoints averaged over the aperture. [1, 256].
  int aperture_samples = 24;
  // Seam skirts (seam_skirts.h): texels on a seam between two segments of one surface also carry
  // the neighbour, so that the seam cannot crack open in a magnified view. max_step = 0: off.
  // Both back ends.
  SeamSkirtOptions seam_skirts;
  // Where the views a pixel blends contradict each other (a subject that moved between shots, a
  // sliver of wrong depth), draw it from the views the more heavily weighted ones do not
  // contradict (contradictions.h; the preview only).
  ConsistentBlendOptions consistent_blend;
  // Segments whose texture the output camera stretches far more than a face-on surface's (seen
  // edge-on by their own view) fade out, so that other views or the hole filling draw the place
  // rather than a streak (texture_stretch.h). Both back ends.
  TextureStretchOptions texture_stretch;
  // Measure double images in every preview frame (FrameRender::double_image; the evaluation's
  // figure): the contradictions are then found even with the consistent blend off.
  bool measure_double_images = false;
  // Output images larger than this many pixels are refused (memory: about 100 bytes per pixel
  // while rendering). [1, 1e9].
  double max_output_pixels = 64e6;

  Status Validate() const;
};

}  // namespace px
