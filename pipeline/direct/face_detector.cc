#include "pipeline/direct/face_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

namespace px::direct {

namespace {

// The frame-filling search (FaceDetector::Detect): the padding on every side as a fraction of
// the frame's shorter side, the padded frame's longer side searched, and the share of a find's
// box that must lie inside the frame.
constexpr double kFrameFillingPad = 0.5;
constexpr int kFrameFillingSearchPx = 400;
constexpr double kFrameFillingInside = 0.7;

struct Raw {
  cv::Rect2d box;
  double score = 0;
  int cascades = 1;
  int cascade = 0;  // index of the cascade that found it
};

// Two detections are one face when they overlap well, or one's centre lies in the other and
// their sizes are within a factor of two (frontal and profile boxes frame a face differently).
bool SameFace(const cv::Rect2d& a, const cv::Rect2d& b) {
  if (BoxIou(a, b) > 0.3) return true;
  const cv::Point2d ca(a.x + a.width / 2, a.y + a.height / 2), cb(b.x + b.width / 2, b.y + b.height / 2);
  const double ratio = a.width / b.width;
  return ratio > 0.5 && ratio < 2.0 && (a.contains(cb) || b.contains(ca));
}

}  // namespace

double BoxIou(const cv::Rect2d& a, const cv::Rect2d& b) {
  const double inter = (a & b).area();
  const double uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

FaceDetector::FaceDetector(std::vector<Loaded> cascades) : cascades_(std::move(cascades)) {}
FaceDetector::~FaceDetector() = default;

StatusOr<std::unique_ptr<FaceDetector>> FaceDetector::Create(const std::vector<CascadeText>& cascades) {
  std::vector<Loaded> loaded;
  bool frontal = false;
  for (const CascadeText& text : cascades) {
    Loaded entry;
    entry.name = text.name;
    entry.profile = text.profile;
    entry.classifier = std::make_unique<cv::CascadeClassifier>();
    bool ok = false;
    try {
      cv::FileStorage storage(text.xml, cv::FileStorage::READ | cv::FileStorage::MEMORY);
      ok = storage.isOpened() && entry.classifier->read(storage.getFirstTopLevelNode()) && !entry.classifier->empty();
    } catch (const cv::Exception& e) {
      return InvalidArgumentError("face cascade '" + text.name + "': " + e.what());
    }
    if (!ok) {
      return InvalidArgumentError("face cascade '" + text.name + "' (" + std::to_string(text.xml.size()) +
                                  " bytes) is not an OpenCV cascade classifier");
    }
    frontal = frontal || !text.profile;
    loaded.push_back(std::move(entry));
  }
  if (!frontal) {
    return InvalidArgumentError("face detector: no frontal cascade among the " + std::to_string(cascades.size()) +
                                " given");
  }
  return std::unique_ptr<FaceDetector>(new FaceDetector(std::move(loaded)));
}

std::string FaceDetector::Describe() const {
  std::string text;
  for (const Loaded& cascade : cascades_) text += (text.empty() ? "" : " + ") + cascade.name;
  return text;
}

std::vector<FaceBox> FaceDetector::Detect(const cv::Mat& image, const FaceDetectionOptions& options) const {
  if (image.empty()) return {};
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = image.clone();
  }
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);
  const cv::Size image_size = grey.size();
  const int longer = std::max(grey.cols, grey.rows), shorter = std::min(grey.cols, grey.rows);
  const double scale = options.upscale_below_px > 0 && longer < options.upscale_below_px
                           ? std::min(3.0, static_cast<double>(options.upscale_below_px) / longer)
                           : 1.0;
  // A face too large for the frame: the cascades' window must lie inside the searched image, so
  // a close-up whose face touches the frame's edges (a film camera's lens tile, a selfie) is
  // found only with the frame padded out. The padded frame, at a reduced size, is searched for
  // faces of at least half the frame's shorter side; a find must keep most of its box inside.
  const int pad = options.frame_filling ? static_cast<int>(std::lround(kFrameFillingPad * shorter)) : 0;
  cv::Mat padded;
  double padded_scale = 1.0;
  if (pad > 0) {
    cv::copyMakeBorder(grey, padded, pad, pad, pad, pad, cv::BORDER_REPLICATE);
    padded_scale = std::min(1.0, static_cast<double>(kFrameFillingSearchPx) / std::max(padded.cols, padded.rows));
    cv::resize(padded, padded, cv::Size(), padded_scale, padded_scale, cv::INTER_AREA);
    cv::equalizeHist(padded, padded);
  }
  if (scale != 1.0) cv::resize(grey, grey, cv::Size(), scale, scale, cv::INTER_LINEAR);
  cv::equalizeHist(grey, grey);
  const int min_side = std::max(8, static_cast<int>(std::lround(options.min_face_px * scale)));

  std::vector<Raw> raw;
  // The cascades over `searched` into `out`, each box mapped to the image as box / factor - offset.
  const auto search = [&](const cv::Mat& searched, double factor, double offset, int min_face, std::vector<Raw>* out) {
    cv::Mat mirrored;
    for (size_t c = 0; c < cascades_.size(); ++c) {
      const Loaded& cascade = cascades_[c];
      if (cascade.profile && !options.profiles) continue;
      for (int side = 0; side < (cascade.profile ? 2 : 1); ++side) {
        const cv::Mat* input = &searched;
        if (side == 1) {
          if (mirrored.empty()) cv::flip(searched, mirrored, 1);
          input = &mirrored;
        }
        std::vector<cv::Rect> found;
        std::vector<int> neighbours;
        cascade.classifier->detectMultiScale(
            *input, found, neighbours, options.scale_factor, options.min_neighbors, 0, cv::Size(min_face, min_face));
        for (size_t i = 0; i < found.size(); ++i) {
          cv::Rect2d box(found[i]);
          if (side == 1) box.x = input->cols - box.x - box.width;
          box = cv::Rect2d(box.x / factor - offset, box.y / factor - offset, box.width / factor, box.height / factor);
          const cv::Rect2d inside = box & cv::Rect2d(0, 0, image_size.width, image_size.height);
          if (inside.area() < kFrameFillingInside * box.area()) continue;
          Raw detection;
          detection.box = inside;
          detection.score = i < neighbours.size() ? neighbours[i] : options.min_neighbors;
          detection.cascade = static_cast<int>(c);
          out->push_back(detection);
        }
      }
    }
  };
  {
    std::lock_guard<std::mutex> lock(mutex_);
    search(grey, scale, 0.0, min_side, &raw);
    if (pad > 0) {
      std::vector<Raw> filling;
      search(padded,
             padded_scale,
             pad,
             std::max(8, static_cast<int>(std::lround(0.5 * shorter * padded_scale))),
             &filling);
      // The padded borders are streaks a cascade can misread: a frame-filling face needs two
      // cascades that agree on it.
      for (const Raw& find : filling) {
        const bool agreed = std::any_of(filling.begin(), filling.end(), [&](const Raw& other) {
          return other.cascade != find.cascade && SameFace(other.box, find.box);
        });
        if (agreed) raw.push_back(find);
      }
    }
  }

  // Merge detections of one face, strongest first, into a score-weighted box.
  std::sort(raw.begin(), raw.end(), [](const Raw& a, const Raw& b) { return a.score > b.score; });
  std::vector<Raw> merged;
  for (const Raw& detection : raw) {
    auto same =
        std::find_if(merged.begin(), merged.end(), [&](const Raw& m) { return SameFace(m.box, detection.box); });
    if (same == merged.end()) {
      merged.push_back(detection);
      continue;
    }
    const double w0 = same->score, w1 = detection.score, sum = w0 + w1;
    same->box = cv::Rect2d((w0 * same->box.x + w1 * detection.box.x) / sum,
                           (w0 * same->box.y + w1 * detection.box.y) / sum,
                           (w0 * same->box.width + w1 * detection.box.width) / sum,
                           (w0 * same->box.height + w1 * detection.box.height) / sum);
    same->score = sum;
    same->cascades += 1;
  }
  std::vector<FaceBox> faces;
  for (const Raw& m : merged) faces.push_back({m.box, m.score, m.cascades});
  std::sort(faces.begin(), faces.end(), [](const FaceBox& a, const FaceBox& b) { return a.box.area() > b.box.area(); });
  return faces;
}

}  // namespace px::direct
