#include "pipeline/lattice/boundary_profile.h"

#include <algorithm>
#include <cmath>

#include "pipeline/core/check.h"
#include "pipeline/core/order_statistics.h"

namespace px::lattice {
namespace {

// Band half-widths tried, working pixels: narrow gaps to broad vignetting dips.
constexpr int kHalfWidths[] = {2, 4, 8, 16};
// A strip's response may sit this many working pixels off the line (tiles turned individually).
constexpr int kStripSlackPx = 2;

// Column medians of each horizontal strip: rows = strips, cols = x.
cv::Mat StripColumnMedians(const cv::Mat& grey, int strip_height) {
  const int strips = grey.rows / strip_height;
  cv::Mat medians(strips, grey.cols, CV_32F);
  cv::Mat transposed;
  std::vector<float> column(strip_height);
  for (int s = 0; s < strips; ++s) {
    cv::transpose(grey.rowRange(s * strip_height, (s + 1) * strip_height), transposed);
    float* out = medians.ptr<float>(s);
    for (int x = 0; x < grey.cols; ++x) {
      const float* in = transposed.ptr<float>(x);
      column.assign(in, in + strip_height);
      out[x] = MedianInPlace(std::span<float>(column));
    }
  }
  return medians;
}

// Band response of one strip's profile at half-width w: how far the value lies beyond both of its
// sides, w away (the nearer of the two differences); negative for a dark band, positive for a
// bright one, zero on a slope or step (so the flanks of a wide band do not respond) and where a
// side leaves the frame.
void BandResponse(const float* profile, int size, int w, float* out) {
  for (int x = 0; x < size; ++x) {
    if (x - w < 0 || x + w >= size) {
      out[x] = 0.0f;
      continue;
    }
    const float left = profile[x] - profile[x - w], right = profile[x] - profile[x + w];
    out[x] = left > 0 && right > 0 ? std::min(left, right) : left < 0 && right < 0 ? std::max(left, right) : 0.0f;
  }
}

// Keeps, at each x, the response of largest magnitude within +-slack (with its sign).
void SignedMaxAbs(const float* in, int size, int slack, float* out) {
  for (int x = 0; x < size; ++x) {
    float best = 0.0f;
    for (int k = std::max(0, x - slack); k <= std::min(size - 1, x + slack); ++k) {
      if (std::abs(in[k]) > std::abs(best)) best = in[k];
    }
    out[x] = best;
  }
}

float Interpolate(const float* profile, int size, double x) {
  if (x < 0 || x > size - 1) return 0.0f;
  const int x0 = std::min(static_cast<int>(x), size - 2);
  const double t = x - x0;
  return static_cast<float>((1 - t) * profile[x0] + t * profile[x0 + 1]);
}

}  // namespace

int BoundaryProfile::ArgMaxZ(int begin, int end) const {
  begin = std::max(begin, 0);
  end = std::min(end, size());
  int best = begin;
  for (int x = begin; x < end; ++x) {
    if (z[x] > z[best]) best = x;
  }
  return best;
}

BoundaryProfile VerticalBoundaryProfile(const cv::Mat& grey, double max_rotation_deg) {
  PX_CHECK(grey.type() == CV_32F && grey.rows >= 16 && grey.cols >= 16) << "grey " << grey.cols << "x" << grey.rows;
  const int width = grey.cols;
  const int strip_height = std::max(8, grey.rows / 32);
  const cv::Mat medians = StripColumnMedians(grey, strip_height);
  const int strips = medians.rows;
  const double centre_y = 0.5 * strips * strip_height;

  // Shears: successive ones move a line's ends by at most the strip slack.
  const double max_shear = std::tan(max_rotation_deg * CV_PI / 180.0);
  const int shear_steps = static_cast<int>(std::ceil(max_shear * centre_y / kStripSlackPx));
  std::vector<double> shears;
  for (int j = -shear_steps; j <= shear_steps; ++j)
    shears.push_back(shear_steps == 0 ? 0.0 : max_shear * j / shear_steps);

  BoundaryProfile profile;
  profile.strength.assign(width, 0.0f);
  profile.z.assign(width, -1e9f);
  profile.polarity.assign(width, 0);
  profile.half_width.assign(width, 0);
  profile.level.assign(width, 0.0f);

  // Band responses of every strip at every width, each allowed to sit a little off the line.
  std::vector<int> widths;
  std::vector<cv::Mat> slacks;
  cv::Mat response(strips, width, CV_32F);
  for (int w : kHalfWidths) {
    if (4 * w >= width) break;
    cv::Mat slack(strips, width, CV_32F);
    for (int s = 0; s < strips; ++s) {
      BandResponse(medians.ptr<float>(s), width, w, response.ptr<float>(s));
      SignedMaxAbs(response.ptr<float>(s), width, kStripSlackPx, slack.ptr<float>(s));
    }
    widths.push_back(w);
    slacks.push_back(slack);
  }
  // The frame's shear: cheap means across strips find it; lines of a tilted frame add up only there.
  std::vector<double> shear_score(shears.size(), 0.0);
  for (size_t j = 0; j < shears.size(); ++j) {
    for (const cv::Mat& slack : slacks) {
      for (int x = 0; x < width; ++x) {
        double sum = 0;
        for (int s = 0; s < strips; ++s) {
          sum += Interpolate(slack.ptr<float>(s), width, x + ((s + 0.5) * strip_height - centre_y) * shears[j]);
        }
        shear_score[j] += sum * sum;
      }
    }
  }
  const int best = static_cast<int>(std::max_element(shear_score.begin(), shear_score.end()) - shear_score.begin());
  profile.shear = shears[best];

  // Robust evidence (medians across strips) at that shear and its neighbours only.
  std::vector<float> across(strips);
  std::vector<float> strength(width), signed_value(width);
  for (size_t i = 0; i < widths.size(); ++i) {
    const int w = widths[i];
    const cv::Mat& slack = slacks[i];
    std::fill(strength.begin(), strength.end(), 0.0f);
    std::fill(signed_value.begin(), signed_value.end(), 0.0f);
    for (int j = std::max(0, best - 1); j <= std::min<int>(shears.size() - 1, best + 1); ++j) {
      for (int x = 0; x < width; ++x) {
        across.clear();
        for (int s = 0; s < strips; ++s) {
          const double xs = x + ((s + 0.5) * strip_height - centre_y) * shears[j];
          if (xs < w || xs > width - 1 - w) continue;
          across.push_back(Interpolate(slack.ptr<float>(s), width, xs));
        }
        if (across.size() * 2 < static_cast<size_t>(strips)) continue;
        const float value = MedianInPlace(std::span<float>(across));
        if (std::abs(value) > strength[x]) {
          strength[x] = std::abs(value);
          signed_value[x] = value;
        }
      }
    }
    // Each width against its own background: broad bands vary more with content than narrow ones.
    std::vector<float> sorted = strength;
    const float median = MedianInPlace(std::span<float>(sorted));
    for (float& v : sorted) v = std::abs(v - median);
    const double sigma =
        std::max(1.4826 * MedianInPlace(std::span<float>(sorted)), 1.0);  // a grey level at least (flat frames)
    for (int x = 0; x < width; ++x) {
      const float z = static_cast<float>((strength[x] - median) / sigma);
      if (z <= profile.z[x]) continue;
      profile.z[x] = z;
      profile.strength[x] = strength[x];
      profile.polarity[x] = signed_value[x] < 0 ? -1 : 1;
      profile.half_width[x] = static_cast<int8_t>(w);
      profile.background_median = median;
      profile.background_sigma = sigma;
    }
  }

  // The grey level along the lines of the frame's shear, for telling gaps from tiles.
  for (int x = 0; x < width; ++x) {
    across.clear();
    for (int s = 0; s < strips; ++s) {
      const double xs = x + ((s + 0.5) * strip_height - centre_y) * profile.shear;
      if (xs >= 0 && xs <= width - 1) across.push_back(Interpolate(medians.ptr<float>(s), width, xs));
    }
    profile.level[x] = MedianInPlace(std::span<float>(across));
  }
  return profile;
}

}  // namespace px::lattice
