#include "pipeline/render/segment_raster.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <limits>

namespace px::render {
namespace {

// Corners nearer than this to the novel camera (metres) cull the segment (no near-plane clipping).
constexpr double kNearM = 1e-3;

// Per frame and view: what maps a segment's plane into the novel camera (ALGORITHM.md 0 and 4).
// With n_s = K_s^T (a, b, c) the plane n_s . P_s = 1 in the source camera and P_s = R P_n + t:
// (a', b', c') = K_n^-T R^T K_s^T (a, b, c) / (1 - (a, b, c) . K_s t) is the plane's inverse depth
// in novel pixels, and H = K_s R K_n^-1 + (K_s t) (a', b', c')^T maps novel pixels to source ones.
struct ViewTransfer {
  Eigen::Matrix3d plane_map;       // K_n^-T R^T K_s^T
  Eigen::Vector3d ks_t;            // K_s t
  Eigen::Matrix3d rotation_map;    // K_s R K_n^-1
  Eigen::Matrix3d novel_rotation;  // novel cam_from_world rotation
  Eigen::Vector3d novel_translation;
  Eigen::Matrix3d novel_k;
  Rigid3 source_from_novel;
  double focal_ratio = 1;  // output focal length / source focal length
};

ViewTransfer MakeTransfer(const SceneView& view, const CameraModel& camera, const Rigid3& cam_from_world) {
  const Rigid3 source_from_novel = view.cam_from_world * cam_from_world.Inverse();
  const Eigen::Matrix3d r = source_from_novel.RotationMatrix();
  const Eigen::Matrix3d ks = view.camera.K();
  const Eigen::Matrix3d kn = camera.K();
  const Eigen::Matrix3d kn_inverse = kn.inverse();
  ViewTransfer transfer;
  transfer.plane_map = kn_inverse.transpose() * r.transpose() * ks.transpose();
  transfer.ks_t = ks * source_from_novel.translation;
  transfer.rotation_map = ks * r * kn_inverse;
  transfer.novel_rotation = cam_from_world.RotationMatrix();
  transfer.novel_translation = cam_from_world.translation;
  transfer.novel_k = kn;
  transfer.source_from_novel = source_from_novel;
  transfer.focal_ratio = kn(0, 0) / ks(0, 0);
  return transfer;
}

// Sets up one segment; false when it is culled.
bool SetUpSegment(const SceneSegment& segment,
                  const ViewTransfer& transfer,
                  const cv::Rect& region,
                  const TextureStretchOptions& stretch,
                  SegmentSetup* out) {
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d p = transfer.novel_rotation * segment.corners_in_world[k] + transfer.novel_translation;
    if (!(p.z() > kNearM)) return false;
    const double x = (transfer.novel_k(0, 0) * p.x() + transfer.novel_k(0, 2) * p.z()) / p.z();
    const double y = (transfer.novel_k(1, 1) * p.y() + transfer.novel_k(1, 2) * p.z()) / p.z();
    out->corners[k] = {static_cast<float>(x), static_cast<float>(y)};
    x_lo = std::min(x_lo, x);
    x_hi = std::max(x_hi, x);
    y_lo = std::min(y_lo, y);
    y_hi = std::max(y_hi, y);
  }
  // Pixel centres inside the bounds, within the region (clamped first: bounds may be huge).
  const double big = 1e7;
  out->x_min = std::max(region.x, static_cast<int>(std::ceil(std::clamp(x_lo, -big, big))));
  out->x_max = std::min(region.x + region.width - 1, static_cast<int>(std::floor(std::clamp(x_hi, -big, big))));
  out->y_min = std::max(region.y, static_cast<int>(std::ceil(std::clamp(y_lo, -big, big))));
  out->y_max = std::min(region.y + region.height - 1, static_cast<int>(std::floor(std::clamp(y_hi, -big, big))));
  if (out->x_min > out->x_max || out->y_min > out->y_max) return false;
  const Eigen::Vector3d abc(segment.plane[0], segment.plane[1], segment.plane[2]);
  // 1 - n_s . C with C the novel centre in the source camera: positive on the source's side of the
  // plane. On the plane (edge-on) or beyond it the novel camera would see the surface's back, which
  // the source never saw (a table's top seen from under the table): culled.
  const double denominator = 1.0 - abc.dot(transfer.ks_t);
  if (!(denominator > 1e-12)) return false;
  const Eigen::Vector3d novel_plane = transfer.plane_map * abc / denominator;
  const Eigen::Matrix3d h = transfer.rotation_map + transfer.ks_t * novel_plane.transpose();
  for (int i = 0; i < 9; ++i) out->homography[i] = static_cast<float>(h(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) out->inv_depth[i] = static_cast<float>(novel_plane[i]);
  const Eigen::Vector3d centre = transfer.novel_rotation * segment.centre_in_world + transfer.novel_translation;
  out->key = static_cast<float>(centre.z());
  out->texture_weight = 1.0f;
  if (stretch.fade_from > 0 && centre.z() > kNearM) {
    const Eigen::Vector2d centre_px(transfer.novel_k(0, 0) * centre.x() / centre.z() + transfer.novel_k(0, 2),
                                    transfer.novel_k(1, 1) * centre.y() / centre.z() + transfer.novel_k(1, 2));
    const double source_z = (transfer.source_from_novel * centre).z();
    out->texture_weight =
        TextureWeight(TextureStretch(h, centre_px, transfer.focal_ratio * source_z / centre.z()), stretch);
    if (out->texture_weight <= 0) return false;
  }
  return true;
}

}  // namespace

void SetUpFrame(const LayeredScene& scene,
                const CameraModel& camera,
                const Rigid3& cam_from_world,
                const std::vector<ViewSlots>& slots,
                const TextureStretchOptions& stretch,
                bool with_witnesses,
                std::vector<FrameView>* out) {
  const int num_views = static_cast<int>(scene.views().size());
  const int width = camera.width, height = camera.height;
  // Per view: the span of each row holding it in a slot, and its weight sum per chunk of rows.
  std::vector<std::vector<std::array<int, 2>>> rows(num_views, std::vector<std::array<int, 2>>(height, {width, -1}));
  const int num_chunks = std::max(1, std::min(height, 4 * cv::getNumThreads()));
  std::vector<std::vector<double>> chunk_weights(num_chunks, std::vector<double>(num_views, 0.0));
  // Per chunk and view: 1 where it holds a blendable slot, 2 where it holds a witness's.
  std::vector<std::vector<uint8_t>> chunk_roles(num_chunks, std::vector<uint8_t>(num_views, 0));
  cv::parallel_for_(cv::Range(0, num_chunks), [&](const cv::Range& range) {
    for (int chunk = range.start; chunk < range.end; ++chunk) {
      std::vector<double>& weights = chunk_weights[chunk];
      std::vector<uint8_t>& roles = chunk_roles[chunk];
      for (int y = chunk * height / num_chunks; y < (chunk + 1) * height / num_chunks; ++y) {
        const ViewSlots* row = slots.data() + static_cast<size_t>(y) * width;
        // Runs of pixels holding the same three views (a triangle of the mesh): spans and weight
        // sums are settled once per run.
        for (int run_begin = 0; run_begin < width;) {
          const std::array<uint8_t, 3> views = row[run_begin].view;
          const uint8_t witness = row[run_begin].witness;
          const auto same_views = [&](const ViewSlots& slot) {
            return slot.view[0] == views[0] && slot.view[1] == views[1] && slot.view[2] == views[2] &&
                   slot.witness == witness;
          };
          double sum[3] = {0, 0, 0};
          int x = run_begin;
          for (; x < width && same_views(row[x]); ++x) {
            for (int k = 0; k < 3; ++k) sum[k] += row[x].weight[k];
          }
          for (int k = 0; k < 3; ++k) {
            const int v = views[k];
            if (v == ViewSlots::kNone || (k == witness && !with_witnesses)) continue;
            weights[v] += sum[k];
            roles[v] |= k == witness ? 2 : 1;
            std::array<int, 2>& span = rows[v][y];
            span[0] = std::min(span[0], run_begin);
            span[1] = std::max(span[1], x - 1);
          }
          run_begin = x;
        }
      }
    }
  });
  std::vector<FrameView>& frame_views = *out;
  size_t drawn = 0;
  for (int v = 0; v < num_views; ++v) {
    if (drawn == frame_views.size()) frame_views.emplace_back();
    FrameView& fv = frame_views[drawn];
    fv.view = v;
    fv.weight_sum = 0;
    fv.segments.clear();
    int x_lo = width, x_hi = -1, y_lo = height, y_hi = -1;
    for (int y = 0; y < height; ++y) {
      if (rows[v][y][0] > rows[v][y][1]) continue;
      x_lo = std::min(x_lo, rows[v][y][0]);
      x_hi = std::max(x_hi, rows[v][y][1]);
      y_lo = std::min(y_lo, y);
      y_hi = y;
    }
    if (x_hi < 0) continue;
    fv.region = cv::Rect(x_lo, y_lo, x_hi - x_lo + 1, y_hi - y_lo + 1);
    fv.blends = fv.witnesses = false;
    for (int chunk = 0; chunk < num_chunks; ++chunk) {
      fv.weight_sum += chunk_weights[chunk][v];
      fv.blends = fv.blends || (chunk_roles[chunk][v] & 1) != 0;
      fv.witnesses = fv.witnesses || (chunk_roles[chunk][v] & 2) != 0;
    }
    fv.rows.swap(rows[v]);
    ++drawn;
  }
  frame_views.resize(drawn);
  // Segments: set up in parallel over views (each writes only its own list), then sorted per view.
  std::vector<ViewTransfer> transfers;
  for (const FrameView& fv : frame_views) {
    transfers.push_back(MakeTransfer(scene.views()[fv.view], camera, cam_from_world));
  }
  cv::parallel_for_(cv::Range(0, static_cast<int>(frame_views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const SceneView& view = scene.views()[frame_views[i].view];
      std::vector<SegmentSetup>& list = frame_views[i].segments;
      list.reserve(view.segments.size());
      SegmentSetup setup;
      for (size_t s = 0; s < view.segments.size(); ++s) {
        const SceneSegment& segment = view.segments[s];
        if (!segment.drawn) continue;
        setup.segment = static_cast<int32_t>(s);
        if (SetUpSegment(segment, transfers[i], frame_views[i].region, stretch, &setup)) list.push_back(setup);
      }
      std::sort(list.begin(), list.end(), [](const SegmentSetup& a, const SegmentSetup& b) {
        return a.key < b.key || (a.key == b.key && a.segment < b.segment);
      });
    }
  });
}

std::vector<std::vector<BandEntry>> BinSegmentsIntoBands(const std::vector<FrameView>& frame_views, int height) {
  const int num_bands = (height + kBandRows - 1) / kBandRows;
  std::vector<std::vector<BandEntry>> bands(num_bands);
  for (size_t i = 0; i < frame_views.size(); ++i) {
    const std::vector<SegmentSetup>& list = frame_views[i].segments;
    for (size_t s = 0; s < list.size(); ++s) {
      for (int b = list[s].y_min / kBandRows; b <= list[s].y_max / kBandRows; ++b) {
        bands[b].push_back({static_cast<int32_t>(i), static_cast<int32_t>(s)});
      }
    }
  }
  return bands;
}

}  // namespace px::render
