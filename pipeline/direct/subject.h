// A subject of interest (paper 4.2.3): a detected face or a region the user marked, turned into
// a geometric proxy: the quadrilateral at the median depth inside its box in the reference view.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core/types.hpp>
#include <string>

namespace px {

struct Subject {
  std::string source;             // "face" (detected) or "user" (a region given by rectangle)
  int32_t view = -1;              // the view (ViewId value) whose pixels `box_px` is in
  cv::Rect2d box_px;              // x, y, width, height in that view's pixels
  double depth_m = 0;             // median depth inside the box, along that view's optical axis
  bool depth_known = true;        // false: no trustworthy depth there; depth_m is a nominal 1 m (2D framing only)
  double confident_fraction = 1;  // of the box's inner pixels with confident depth, [0, 1]
  double score = 0;               // detector strength (merged detections), 0 for user regions
  // The box's corners at depth_m in the world: top-left, top-right, bottom-right, bottom-left.
  std::array<Eigen::Vector3d, 4> corners_in_world = {
      Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};

  Eigen::Vector3d CentreInWorld() const;
  // Centre of the lower half of the quadrilateral: aiming here leaves the face slightly above
  // the image centre (paper 4.2.3, dolly-in/out).
  Eigen::Vector3d LowerHalfCentreInWorld() const;
  double WidthM() const;   // top edge length
  double HeightM() const;  // left edge length
};

}  // namespace px
