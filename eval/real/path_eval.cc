#include "eval/real/path_eval.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "eval/real/contact_sheet.h"
#include "eval/real/path_measures.h"
#include "eval/render/image_metrics.h"

namespace px::eval {
namespace {

// The frames on the sheet: evenly spread, first and last included.
std::set<int> SheetFrames(int num_frames, int count) {
  std::set<int> frames;
  if (num_frames <= 0) return frames;
  count = std::max(1, std::min(count, num_frames));
  for (int i = 0; i < count; ++i) {
    frames.insert(count == 1 ? 0
                             : static_cast<int>(std::lround(static_cast<double>(i) * (num_frames - 1) / (count - 1))));
  }
  return frames;
}

// Measures every novel-view frame as the pipeline renders it and keeps the sheet's frames and maps.
class PathWatcher final : public PipelineObserver, public FrameSink {
 public:
  explicit PathWatcher(const PathEvalOptions& options) : options_(options) {}

  void OnScene(const std::vector<View>& views, const std::vector<DepthMap>& depth) override {
    views_ = views;
    depth_ = depth;
  }

  void OnFrame(int index, const VirtualCamera& camera, const FrameRender& frame) override {
    FrameFigures figures;
    cv::Mat torn_map, flicker_map;
    const bool keep_maps = !options_.dump_dir.empty();
    figures.torn = TornFraction(frame, camera, views_, depth_, {}, keep_maps ? &torn_map : nullptr);
    cv::Mat double_map;
    figures.double_measured = !frame.double_image.empty();
    figures.double_image = std::max(0.0, DoubleImageFraction(frame.double_image, keep_maps ? &double_map : nullptr));
    if (!previous_bgr_.empty()) {
      figures.flicker =
          FlickerFraction(previous_bgr_, previous_camera_, frame, camera, 40, keep_maps ? &flicker_map : nullptr);
    }
    figures.holes = frame.holes.hole_ratio;
    figures_.push_back(figures);
    previous_bgr_ = frame.bgr.clone();
    previous_camera_ = camera;
    ++novel_frames_;
    if (keep_maps) {
      maps_[index] = {
          torn_map, double_map, flicker_map.empty() ? cv::Mat::zeros(frame.bgr.size(), CV_8U) : flicker_map};
    }
  }

  Status Consume(int index, const cv::Mat& bgr) override {
    frames_.emplace_back(index, bgr.clone());
    return OkStatus();
  }

  struct FrameFigures {
    double torn = 0, double_image = 0, flicker = 0, holes = 0;
    bool double_measured = false;  // the compositor drew the double-image map (preview quality)
  };
  struct FrameMaps {
    cv::Mat torn, double_image, flicker;
  };
  const std::vector<FrameFigures>& figures() const { return figures_; }
  const std::vector<std::pair<int, cv::Mat>>& frames() const { return frames_; }
  const std::vector<View>& views() const { return views_; }
  const std::vector<DepthMap>& depth() const { return depth_; }
  const std::map<int, FrameMaps>& maps() const { return maps_; }
  int novel_frames() const { return novel_frames_; }

 private:
  const PathEvalOptions& options_;
  std::vector<View> views_;
  std::vector<DepthMap> depth_;
  cv::Mat previous_bgr_;
  VirtualCamera previous_camera_;
  std::vector<FrameFigures> figures_;
  std::vector<std::pair<int, cv::Mat>> frames_;
  std::map<int, FrameMaps> maps_;
  int novel_frames_ = 0;
};

// Inverse depth as a colour map (near warm, far cool) over the map's 2nd to 98th percentiles; black
// where unknown; the confidence's dark where below a quarter.
cv::Mat DepthPicture(const DepthMap& depth) {
  std::vector<float> inverse;
  for (int y = 0; y < depth.depth_m.rows; y += 2) {
    for (int x = 0; x < depth.depth_m.cols; x += 2) {
      const float z = depth.depth_m.at<float>(y, x);
      if (z > 0) inverse.push_back(1.0f / z);
    }
  }
  cv::Mat picture(depth.depth_m.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  if (inverse.empty()) return picture;
  std::sort(inverse.begin(), inverse.end());
  const float lo = inverse[inverse.size() / 50], hi = inverse[inverse.size() - 1 - inverse.size() / 50];
  cv::Mat levels(depth.depth_m.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < levels.rows; ++y) {
    for (int x = 0; x < levels.cols; ++x) {
      const float z = depth.depth_m.at<float>(y, x);
      if (z > 0)
        levels.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(255.0f * (1.0f / z - lo) / std::max(hi - lo, 1e-9f));
    }
  }
  cv::applyColorMap(levels, picture, cv::COLORMAP_TURBO);
  picture.setTo(cv::Scalar(0, 0, 0), depth.depth_m <= 0);
  if (!depth.confidence.empty()) {
    cv::Mat dim;
    cv::multiply(picture, cv::Scalar::all(0.4), dim);
    dim.copyTo(picture, depth.confidence < 0.25f);
  }
  return picture;
}

cv::Mat Overlay(const cv::Mat& frame, const cv::Mat& mask, const cv::Scalar& colour) {
  cv::Mat shown = frame.clone();
  if (!mask.empty()) shown.setTo(colour, mask);
  return shown;
}

Status DumpSheets(const PathEvalOptions& options, const std::string& set, const PathWatcher& watcher, int num_frames) {
  const std::set<int> chosen = SheetFrames(num_frames, options.sheet_frames);
  std::vector<LabelledImage> frames, maps;
  for (const auto& [index, bgr] : watcher.frames()) {
    if (!chosen.count(index)) continue;
    char label[96];
    if (index < static_cast<int>(watcher.figures().size())) {
      const auto& f = watcher.figures()[index];
      char double_image[16] = "-";  // offline frames do not measure it
      if (f.double_measured) std::snprintf(double_image, sizeof(double_image), "%.2f%%", 100 * f.double_image);
      std::snprintf(label,
                    sizeof(label),
                    "frame %d  torn %.2f%% double %s holes %.1f%%",
                    index,
                    100 * f.torn,
                    double_image,
                    100 * f.holes);
    } else {
      std::snprintf(label, sizeof(label), "frame %d", index);
    }
    frames.push_back({bgr, label});
    const auto found = watcher.maps().find(index);
    if (found != watcher.maps().end()) {
      cv::Mat marked = Overlay(bgr, found->second.torn, cv::Scalar(0, 0, 255));
      marked = Overlay(marked, found->second.double_image, cv::Scalar(255, 0, 255));
      marked = Overlay(marked, found->second.flicker, cv::Scalar(0, 255, 255));
      maps.push_back({marked, "frame " + std::to_string(index) + ": torn red, double magenta, flicker yellow"});
    }
  }
  PX_RETURN_IF_ERROR(WritePng(options.dump_dir / (SafeFileName(set) + "_path.png"), ContactSheet(frames, 4, 400)));
  // The views and their depth, as the renderer drew them.
  std::vector<LabelledImage> depth_cells;
  for (size_t i = 0; i < watcher.views().size() && i < watcher.depth().size(); ++i) {
    const std::string name = "view " + std::to_string(watcher.views()[i].id.value);
    depth_cells.push_back({watcher.views()[i].image, name});
    depth_cells.push_back({DepthPicture(watcher.depth()[i]), name + " depth (dark: unconfident)"});
  }
  if (!depth_cells.empty()) {
    PX_RETURN_IF_ERROR(
        WritePng(options.dump_dir / (SafeFileName(set) + "_depth.png"), ContactSheet(depth_cells, 4, 400)));
  }
  // The first, middle and last frames at full size, to look at closely.
  for (const auto& [index, bgr] : watcher.frames()) {
    if (index == 0 || index == num_frames / 2 || index == num_frames - 1) {
      PX_RETURN_IF_ERROR(
          WritePng(options.dump_dir / (SafeFileName(set) + "_frame" + std::to_string(index) + ".png"), bgr));
    }
  }
  if (!maps.empty()) {
    PX_RETURN_IF_ERROR(WritePng(options.dump_dir / (SafeFileName(set) + "_path_maps.png"), ContactSheet(maps, 4, 400)));
  }
  return OkStatus();
}

}  // namespace

StatusOr<PathResult> EvaluatePath(const RealSet& set, const PathEvalOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PathWatcher watcher(options);
  PipelineOptions pipeline = options.pipeline;
  pipeline.render_backend.backend = render::gl::RenderBackend::kCpu;
  pipeline.render.measure_double_images = true;
  if (set.capture.kind == FrameSetKind::kLatticeFrame) pipeline.lattice = set.lattice;
  pipeline.observer = &watcher;
  if (options.progress) options.progress(set.name + ": the automatic clip");
  PX_ASSIGN_OR_RETURN(PipelineReport report, RunPipeline(set.capture, RigCalibration{}, pipeline, &watcher));
  PathResult result;
  result.set = set.name;
  result.mode = report.path.kind == PathKind::kNovelView ? "3D move"
                : report.path.kind == PathKind::kMorph   ? "morph"
                                                         : "2D pan and zoom";
  result.move = report.path.move;
  result.reason = report.path.reason;
  result.frames = report.frames_rendered;
  result.width = report.path.width;
  result.height = report.path.height;
  result.warnings = report.warnings;
  result.depth_confident = report.depth.confident_fraction;
  result.depth_consistent = report.depth.consistent_fraction;
  const auto& figures = watcher.figures();
  result.measured = !figures.empty();
  for (const auto& f : figures) {
    result.torn += f.torn;
    result.double_measured = result.double_measured || f.double_measured;
    result.double_image += f.double_image;
    result.flicker += f.flicker;
    result.holes += f.holes;
    result.torn_max = std::max(result.torn_max, f.torn);
    result.double_image_max = std::max(result.double_image_max, f.double_image);
    result.flicker_max = std::max(result.flicker_max, f.flicker);
    result.holes_max = std::max(result.holes_max, f.holes);
  }
  if (!figures.empty()) {
    const double n = static_cast<double>(figures.size());
    result.torn /= n;
    result.double_image /= n;
    result.holes /= n;
    // The first frame has no predecessor.
    result.flicker = figures.size() > 1 ? result.flicker / (n - 1) : 0.0;
  }
  if (!options.dump_dir.empty()) PX_RETURN_IF_ERROR(DumpSheets(options, set.name, watcher, result.frames));
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace px::eval
