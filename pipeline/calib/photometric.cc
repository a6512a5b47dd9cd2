#include "pipeline/calib/photometric.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>

#include "pipeline/core/option_range.h"
#include "pipeline/core/stage_clock.h"

namespace px::calib {

namespace {

constexpr int kTerms = 7;                        // 1, u, v, u^2, uv, v^2, (u^2 + v^2)^2
constexpr int kFitIterations = 8;                // iteratively reweighted least squares
constexpr float kDarkest = 8, kBrightest = 247;  // samples outside are clipped, not exposed
constexpr int kMinSamples = 200;

// The basis at normalised image coordinates u, v in [-1, 1].
void Basis(double u, double v, double* phi) {
  const double r2 = u * u + v * v;
  phi[0] = 1;
  phi[1] = u;
  phi[2] = v;
  phi[3] = u * u;
  phi[4] = u * v;
  phi[5] = v * v;
  phi[6] = r2 * r2;
}

// One channel's log-gain field at the fit's size, from the coefficients.
cv::Mat FieldOf(const cv::Vec<double, kTerms>& a, cv::Size size, double max_log_gain) {
  cv::Mat field(size, CV_32F);
  double phi[kTerms];
  for (int y = 0; y < size.height; ++y) {
    float* f = field.ptr<float>(y);
    const double v = 2.0 * (y + 0.5) / size.height - 1;
    for (int x = 0; x < size.width; ++x) {
      Basis(2.0 * (x + 0.5) / size.width - 1, v, phi);
      double g = 0;
      for (int k = 0; k < kTerms; ++k) g += a[k] * phi[k];
      f[x] = static_cast<float>(std::clamp(g, -max_log_gain, max_log_gain));
    }
  }
  return field;
}

// Robust fit of log(reference / view) over the valid samples: Tukey weights, scale by the MAD.
bool FitLogGain(const cv::Mat& reference, const cv::Mat& view, const cv::Mat& valid, cv::Vec<double, kTerms>* a) {
  struct Sample {
    double phi[kTerms];
    double y;
  };
  std::vector<Sample> samples;
  const cv::Size size = view.size();
  for (int y = 0; y < size.height; ++y) {
    const float* r = reference.ptr<float>(y);
    const float* w = view.ptr<float>(y);
    const uint8_t* m = valid.ptr<uint8_t>(y);
    for (int x = 0; x < size.width; ++x) {
      if (!m[x] || r[x] < kDarkest || r[x] > kBrightest || w[x] < kDarkest || w[x] > kBrightest) continue;
      Sample s;
      Basis(2.0 * (x + 0.5) / size.width - 1, 2.0 * (y + 0.5) / size.height - 1, s.phi);
      s.y = std::log(r[x]) - std::log(w[x]);
      samples.push_back(s);
    }
  }
  if (static_cast<int>(samples.size()) < kMinSamples) return false;
  std::vector<double> weight(samples.size(), 1.0), residual(samples.size());
  *a = cv::Vec<double, kTerms>::all(0);
  for (int iteration = 0; iteration < kFitIterations; ++iteration) {
    cv::Matx<double, kTerms, kTerms> normal = cv::Matx<double, kTerms, kTerms>::zeros();
    cv::Vec<double, kTerms> right = cv::Vec<double, kTerms>::all(0);
    for (size_t i = 0; i < samples.size(); ++i) {
      if (weight[i] <= 0) continue;
      for (int j = 0; j < kTerms; ++j) {
        right[j] += weight[i] * samples[i].phi[j] * samples[i].y;
        for (int k = 0; k < kTerms; ++k) normal(j, k) += weight[i] * samples[i].phi[j] * samples[i].phi[k];
      }
    }
    // A little ridge on the shape terms: a view seen through a small window keeps a flat field.
    for (int j = 1; j < kTerms; ++j) normal(j, j) += 1e-3 * normal(0, 0);
    if (!cv::solve(normal, right, *a, cv::DECOMP_CHOLESKY)) return false;
    for (size_t i = 0; i < samples.size(); ++i) {
      double g = 0;
      for (int k = 0; k < kTerms; ++k) g += (*a)[k] * samples[i].phi[k];
      residual[i] = std::abs(samples[i].y - g);
    }
    std::vector<double> sorted = residual;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double c = 4.685 * std::max(0.01, 1.4826 * sorted[sorted.size() / 2]);
    for (size_t i = 0; i < samples.size(); ++i) {
      const double t = residual[i] / c;
      weight[i] = t < 1 ? (1 - t * t) * (1 - t * t) : 0;
    }
  }
  return true;
}

// `field` (CV_32FC3 gains) held within the range it takes over the `valid` pixels: the fit knows
// the light only there, and its quadratic and quartic terms run away beyond (a view's corners,
// where the flow found no match, would otherwise be darkened or brightened by half or more).
void ClampToSupport(const cv::Mat& valid, cv::Mat* field) {
  if (cv::countNonZero(valid) == 0) return;
  std::vector<cv::Mat> channels;
  cv::split(*field, channels);
  for (cv::Mat& channel : channels) {
    double low, high;
    cv::minMaxLoc(channel, &low, &high, nullptr, nullptr, valid);
    channel = cv::max(cv::min(channel, high), low);
  }
  cv::merge(channels, *field);
}

// The gain field (CV_32FC3) of the log-gain `shape` shared by the channels plus each channel's
// own constant: the median of what the shape leaves of its log ratio, held to its support
// (ClampToSupport).
cv::Mat GainField(const cv::Vec<double, kTerms>& shape,
                  const std::vector<cv::Mat>& reference_channels,
                  const std::vector<cv::Mat>& view_channels,
                  const cv::Mat& valid,
                  double max_log_gain) {
  const cv::Size size = valid.size();
  const cv::Mat shape_field = FieldOf(shape, size, max_log_gain);
  std::vector<cv::Mat> fields(3);
  for (int c = 0; c < 3; ++c) {
    std::vector<float> offsets;
    for (int y = 0; y < size.height; ++y) {
      const float* r = reference_channels[c].ptr<float>(y);
      const float* w = view_channels[c].ptr<float>(y);
      const float* g = shape_field.ptr<float>(y);
      const uint8_t* m = valid.ptr<uint8_t>(y);
      for (int x = 0; x < size.width; ++x) {
        if (!m[x] || r[x] < kDarkest || r[x] > kBrightest || w[x] < kDarkest || w[x] > kBrightest) continue;
        offsets.push_back(std::log(r[x]) - std::log(w[x]) - g[x]);
      }
    }
    double offset = 0;
    if (offsets.size() >= kMinSamples) {
      std::nth_element(offsets.begin(), offsets.begin() + offsets.size() / 2, offsets.end());
      offset = offsets[offsets.size() / 2];
    }
    cv::Vec<double, kTerms> channel = shape;
    channel[0] += offset;
    fields[c] = FieldOf(channel, size, max_log_gain);
  }
  cv::Mat log_field, gain;
  cv::merge(fields, log_field);
  cv::exp(log_field, gain);
  ClampToSupport(valid, &gain);
  return gain;
}

// Mean over the channels (a colour cast counts, which grey would hide).
double MeanAbsDifference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& valid) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  const cv::Scalar mean = cv::mean(difference, valid);
  return (mean[0] + mean[1] + mean[2]) / 3;
}

}  // namespace

Status PhotometricOptions::Validate() const {
  if (working_width_px < 32 || working_width_px > 1024)
    return OptionOutOfRange("photometric options", "working_width_px", working_width_px, "[32, 1024]");
  if (!(blur_fraction > 0 && blur_fraction <= 0.2))
    return OptionOutOfRange("photometric options", "blur_fraction", blur_fraction, "(0, 0.2]");
  if (!(min_change >= 0 && min_change < 1))
    return OptionOutOfRange("photometric options", "min_change", min_change, "[0, 1)");
  if (!(min_difference >= 0 && min_difference < 255))
    return OptionOutOfRange("photometric options", "min_difference", min_difference, "[0, 255)");
  if (!(min_improvement >= 0 && min_improvement < 1))
    return OptionOutOfRange("photometric options", "min_improvement", min_improvement, "[0, 1)");
  if (!(max_gain > 1 && max_gain <= 10))
    return OptionOutOfRange("photometric options", "max_gain", max_gain, "(1, 10]");
  return OkStatus();
}

std::string PhotometricReport::Summary() const {
  std::ostringstream text;
  int applied = 0;
  for (const ViewPhotometry& v : views) applied += v.applied ? 1 : 0;
  text << applied << " of " << views.size() - 1 << " views equalised to view " << reference.value << ":";
  char item[160];
  for (const ViewPhotometry& v : views) {
    if (v.view == reference) continue;
    if (v.applied) {
      std::snprintf(item,
                    sizeof(item),
                    " view %d gain %.2f/%.2f/%.2f corner %.2f, difference %.1f -> %.1f;",
                    v.view.value,
                    v.centre_gain[2],
                    v.centre_gain[1],
                    v.centre_gain[0],
                    v.corner_falloff,
                    v.difference_before,
                    v.difference_after);
    } else {
      std::snprintf(item, sizeof(item), " view %d as it is (%s);", v.view.value, v.note.c_str());
    }
    text << item;
  }
  std::snprintf(item, sizeof(item), " %.0f ms", ms);
  text << item;
  return text.str();
}

StatusOr<PhotometricReport> EqualisePhotometry(std::vector<View>* views,
                                               int reference_index,
                                               const PhotometricOptions& options) {
  const StageClock::time_point start = StageClock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  if (views == nullptr || reference_index < 0 || reference_index >= static_cast<int>(views->size())) {
    return InvalidArgumentError("photometric: reference view index " + std::to_string(reference_index) +
                                " is outside the views");
  }
  for (const View& view : *views) {
    if (view.image.empty() || view.image.type() != CV_8UC3) {
      return InvalidArgumentError("photometric: view " + std::to_string(view.id.value) + " is not a CV_8UC3 image");
    }
  }
  PhotometricReport report;
  const View& reference = (*views)[reference_index];
  report.reference = reference.id;
  const double scale = std::min(1.0, static_cast<double>(options.working_width_px) / reference.image.cols);
  const cv::Size small(std::max(1, static_cast<int>(std::lround(reference.image.cols * scale))),
                       std::max(1, static_cast<int>(std::lround(reference.image.rows * scale))));
  const double sigma = options.blur_fraction * small.width;
  // Sharp reduced images for the flow, blurred ones for the fit.
  const auto reduce = [&](const cv::Mat& image) {
    cv::Mat reduced;
    cv::resize(image, reduced, small, 0, 0, cv::INTER_AREA);
    reduced.convertTo(reduced, CV_32FC3);
    return reduced;
  };
  const auto blurred = [&](const cv::Mat& image) {
    cv::Mat out;
    cv::GaussianBlur(image, out, cv::Size(), sigma);
    return out;
  };
  const auto grey8 = [](const cv::Mat& bgr) {
    cv::Mat grey, out;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(out, CV_8U);
    return out;
  };
  const cv::Mat reference_sharp = reduce(reference.image);
  const cv::Mat reference_grey = grey8(reference_sharp);
  const double max_log_gain = std::log(options.max_gain);
  // DIS normalises each patch's mean, so exposure and vignetting do not bend the flow.
  cv::Ptr<cv::DISOpticalFlow> flow = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);

  for (size_t i = 0; i < views->size(); ++i) {
    View& view = (*views)[i];
    ViewPhotometry result;
    result.view = view.id;
    if (static_cast<int>(i) == reference_index) {
      result.note = "the reference";
      report.views.push_back(result);
      continue;
    }
    if (small.width < 16 || small.height < 16) {
      result.note = "too small to compare";
      report.views.push_back(result);
      continue;
    }
    const cv::Mat view_sharp = reduce(view.image);
    const cv::Mat view_grey = grey8(view_sharp);
    // The reference moved onto the view along the dense flow between them, so parallax (a lens
    // array's, a hand-held step's) is not taken for light; pixels whose flow does not come back
    // (occlusions, a moving subject) and the frame's border are left out of the fit.
    cv::Mat to_reference, to_view;
    flow->calc(view_grey, reference_grey, to_reference);
    flow->calc(reference_grey, view_grey, to_view);
    cv::Mat map(small, CV_32FC2), valid(small, CV_8U, cv::Scalar(0));
    for (int y = 0; y < small.height; ++y) {
      const cv::Vec2f* f = to_reference.ptr<cv::Vec2f>(y);
      cv::Vec2f* m = map.ptr<cv::Vec2f>(y);
      uint8_t* v = valid.ptr<uint8_t>(y);
      for (int x = 0; x < small.width; ++x) {
        m[x] = cv::Vec2f(x + f[x][0], y + f[x][1]);
        const int bx = static_cast<int>(std::lround(m[x][0])), by = static_cast<int>(std::lround(m[x][1]));
        if (bx < 0 || by < 0 || bx >= small.width || by >= small.height) continue;
        const cv::Vec2f back = to_view.at<cv::Vec2f>(by, bx);
        v[x] = std::hypot(f[x][0] + back[0], f[x][1] + back[1]) < 1.0 ? 255 : 0;
      }
    }
    cv::Mat aligned_sharp;
    cv::remap(reference_sharp, aligned_sharp, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    const cv::Mat aligned = blurred(aligned_sharp), view_small = blurred(view_sharp);
    cv::erode(valid, valid, cv::Mat(), cv::Point(-1, -1), std::max(1, static_cast<int>(std::ceil(sigma))));
    result.difference_before = MeanAbsDifference(aligned, view_small, valid);

    if (result.difference_before < options.min_difference) {
      result.note = "already alike";
      report.views.push_back(result);
      continue;
    }
    // The field's shape (vignetting, tilt) from the grey images; each channel only adds its own
    // constant (a colour cast): a shape per channel would fit parallax in a channel's few samples.
    cv::Mat aligned_grey, view_small_grey;
    cv::cvtColor(aligned, aligned_grey, cv::COLOR_BGR2GRAY);
    cv::cvtColor(view_small, view_small_grey, cv::COLOR_BGR2GRAY);
    cv::Vec<double, kTerms> shape;
    if (!FitLogGain(aligned_grey, view_small_grey, valid, &shape)) {
      result.note = "too few comparable pixels (dark, saturated or outside the overlap)";
      report.views.push_back(result);
      continue;
    }
    std::vector<cv::Mat> reference_channels, view_channels;
    cv::split(aligned, reference_channels);
    cv::split(view_small, view_channels);
    // An exposure and a cast alone first; the shape (vignetting) only where it explains clearly
    // more: on a strip with much parallax the shape terms would otherwise fit the parallax.
    const cv::Mat flat_gain =
        GainField(cv::Vec<double, kTerms>::all(0), reference_channels, view_channels, valid, max_log_gain);
    const double flat_after = MeanAbsDifference(aligned, view_small.mul(flat_gain), valid);
    const cv::Mat shaped_gain = GainField(shape, reference_channels, view_channels, valid, max_log_gain);
    const double shaped_after = MeanAbsDifference(aligned, view_small.mul(shaped_gain), valid);
    const bool shaped = shaped_after < (1 - options.min_improvement) * flat_after;
    const cv::Mat gain_small = shaped ? shaped_gain : flat_gain;
    std::vector<cv::Mat> fields;
    cv::Mat log_gain;
    cv::log(gain_small, log_gain);
    cv::split(log_gain, fields);
    double largest_change = 0;
    for (const cv::Mat& field : fields) {
      double low, high;
      cv::minMaxLoc(field, &low, &high);
      largest_change = std::max({largest_change, std::abs(std::exp(low) - 1), std::abs(std::exp(high) - 1)});
    }
    result.difference_after = shaped ? shaped_after : flat_after;
    const cv::Vec3f centre = gain_small.at<cv::Vec3f>(small.height / 2, small.width / 2);
    result.centre_gain = cv::Vec3d(centre[0], centre[1], centre[2]);
    double falloff = 0;
    for (const cv::Point corner : {cv::Point(0, 0),
                                   cv::Point(small.width - 1, 0),
                                   cv::Point(0, small.height - 1),
                                   cv::Point(small.width - 1, small.height - 1)}) {
      const cv::Vec3f g = gain_small.at<cv::Vec3f>(corner);
      for (int c = 0; c < 3; ++c) falloff += g[c] / centre[c] / 12;
    }
    result.corner_falloff = falloff;
    if (largest_change < options.min_change) {
      result.note = "the same exposure";
    } else if (!(result.difference_after < (1 - options.min_improvement) * result.difference_before)) {
      char note[120];
      std::snprintf(note,
                    sizeof(note),
                    "no gain field brings it closer: difference %.1f -> %.1f",
                    result.difference_before,
                    result.difference_after);
      result.note = note;
    } else {
      cv::Mat gain, equalised;
      cv::resize(gain_small, gain, view.image.size(), 0, 0, cv::INTER_LINEAR);
      view.image.convertTo(equalised, CV_32FC3);
      equalised = equalised.mul(gain);
      cv::Mat out;  // a new buffer: a tile may share its pixels with the raw frame
      equalised.convertTo(out, CV_8UC3);
      view.image = out;
      result.applied = true;
    }
    report.views.push_back(result);
  }
  report.ms = MsSince(start);
  return report;
}

}  // namespace px::calib
