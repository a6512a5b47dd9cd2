// Over-segmentation of a view into superpixels (SLIC, Achanta et al. 2012, from OpenCV's
// ximgproc) with what the segment stage needs about each: size, bounding box, mean colour and
// which segments touch it.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

struct Superpixels {
  cv::Mat labels;  // CV_32S, 0 .. count - 1, each label one 4-connected region
  int count = 0;
  std::vector<int> sizes;                  // pixels per segment
  std::vector<cv::Rect> bboxes;            // per segment
  std::vector<cv::Point2f> centroids;      // mean pixel position per segment
  std::vector<cv::Vec3f> mean_lab;         // CIE Lab (OpenCV 8-bit scale) per segment
  std::vector<std::vector<int>> adjacent;  // 4-connected neighbours per segment, ascending
};

// SLIC on the Lab image of `bgr` (CV_8UC3, lightly blurred first, as OpenCV recommends) with
// superpixels of about region_size_px a side, compactness `ruler` (higher = more regular shapes)
// and `iterations` k-means steps; regions under a quarter of the nominal size are merged into a
// neighbour, labels are made compact.
Superpixels Oversegment(const cv::Mat& bgr, int region_size_px, float ruler, int iterations);

// Pixel indices (y * cols + x) of each segment, in raster order.
std::vector<std::vector<int>> SegmentPixels(const Superpixels& superpixels);

// Recomputes sizes, boxes, centroids, mean colours and adjacency from labels (CV_32S, 0 .. count - 1) and
// the Lab image they label.
void ComputeSuperpixelStats(const cv::Mat& lab, Superpixels* superpixels);

// The 4-connected neighbours of each label of `labels` (CV_32S, 0 .. count - 1), ascending.
std::vector<std::vector<int>> AdjacentLabels(const cv::Mat& labels, int count);

// Labels at the resolution of `bgr` (CV_8UC3, the view) from superpixels made at `factor`
// (0, 1] of it: each pixel takes, of the labels of the up to four working pixels around it, the
// one whose mean colour is closest to its own, so that segment borders follow the full-resolution
// edges instead of the working grid.
cv::Mat UpsampleLabels(const Superpixels& superpixels, const cv::Mat& bgr, double factor);

}  // namespace px::depth
