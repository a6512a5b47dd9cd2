// Texture stretch: how much more a segment's texture is magnified along its worst direction in the
// output camera than a surface facing that camera at the same place would be. A segment seen
// nearly edge-on by its own view but face-on by the output camera (a wrong plane tilted along a
// depth edge, a wall met at a grazing angle) spreads each source texel over many output pixels: a
// streak. Its fragments are faded out (TextureWeight) so that the other views, or the hole
// filling, draw the place instead. Both back ends use these functions.
#pragma once

#include <Eigen/Core>

namespace px {

struct TextureStretchOptions {
  // Fragments of a segment stretched by more than fade_from are faded, linearly, to nothing at
  // fade_to. A uniform magnification (a close-up, a longer focal length, a larger output) is not
  // stretch and is never faded; a surface turned 60 degrees further from the output camera than
  // from its own view is stretched 2x. fade_from = 0: off. fade_from in [0, 100], fade_to above it.
  double fade_from = 3.0;
  double fade_to = 6.0;
};

namespace render {

// The stretch of a segment at output pixel `novel_px`: `novel_to_source` maps output pixels to the
// segment's source pixels (its homography), `uniform_magnification` = (f_output / f_source) *
// (z_source / z_output) at that point, what a face-on surface there would get. 1 = none.
double TextureStretch(const Eigen::Matrix3d& novel_to_source,
                      const Eigen::Vector2d& novel_px,
                      double uniform_magnification);

// The weight (0..1) a segment's fragments are drawn with at that stretch.
float TextureWeight(double stretch, const TextureStretchOptions& options);

}  // namespace render
}  // namespace px
