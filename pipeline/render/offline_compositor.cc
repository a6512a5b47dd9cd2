// The offline soft z-buffer: every fragment of every contributing view kept per pixel, composited
// per view in exact per-pixel depth order, then weighted together in one soft z (ALGORITHM.md 10).
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>

#include "pipeline/render/compositor.h"

namespace px::render {
namespace {

struct Fragment {
  int32_t key;  // (pixel in band) * 3 + slot
  float z;
  float alpha;
  float bgr[3];  // un-premultiplied
};

// A visibility share at least this makes a fragment the soft z's reference surface.
constexpr float kReferenceShare = 0.5f;

}  // namespace

void CompositeOffline(const LayeredScene& scene,
                      const std::vector<FrameView>& frame_views,
                      const std::vector<ViewSlots>& slots,
                      int width,
                      int height,
                      FrameComposite* out) {
  out->colour.create(height, width, CV_32FC3);
  out->alpha.create(height, width, CV_32F);
  out->depth.create(height, width, CV_32F);
  const std::vector<std::vector<BandEntry>> bands = BinSegmentsIntoBands(frame_views, height);
  const SoftZ& soft_z = scene.soft_z();
  std::atomic<long> total{0};
  cv::parallel_for_(cv::Range(0, static_cast<int>(bands.size())), [&](const cv::Range& range) {
    std::vector<Fragment> fragments;
    std::vector<float> share;
    for (int band = range.start; band < range.end; ++band) {
      const int row_begin = band * kBandRows, row_end = std::min(height, row_begin + kBandRows);
      fragments.clear();
      for (const BandEntry& entry : bands[band]) {
        const FrameView& fv = frame_views[entry.frame_view];
        if (!fv.blends) continue;  // a witness only: the offline blend never asks one
        const SceneView& view = scene.views()[fv.view];
        RasterizeSegment(
            view,
            fv,
            fv.segments[entry.setup],
            slots,
            width,
            row_begin,
            row_end,
            true,
            [&](int x, int y, int slot) { return slot == slots[static_cast<size_t>(y) * width + x].witness; },
            [&](int x, int y, int slot, float alpha, const float* bgr, float z) {
              const float inv = 1.0f / alpha;
              fragments.push_back({static_cast<int32_t>(((y - row_begin) * width + x) * 3 + slot),
                                   z,
                                   alpha,
                                   {bgr[0] * inv, bgr[1] * inv, bgr[2] * inv}});
            });
      }
      total += static_cast<long>(fragments.size());
      std::sort(fragments.begin(), fragments.end(), [](const Fragment& a, const Fragment& b) {
        return a.key < b.key || (a.key == b.key && a.z < b.z);
      });
      share.resize(fragments.size());
      // Per pixel: the fragments of its three slots are contiguous, each slot's by depth.
      size_t next = 0;
      for (int y = row_begin; y < row_end; ++y) {
        const ViewSlots* slot_row = slots.data() + static_cast<size_t>(y) * width;
        float* alpha_row = out->alpha.ptr<float>(y);
        float* depth_row = out->depth.ptr<float>(y);
        cv::Vec3f* colour_row = out->colour.ptr<cv::Vec3f>(y);
        for (int x = 0; x < width; ++x) {
          const int32_t first_key = ((y - row_begin) * width + x) * 3;
          const size_t begin = next;
          while (next < fragments.size() && fragments[next].key < first_key + 3) ++next;
          alpha_row[x] = 0;
          depth_row[x] = 0;
          colour_row[x] = cv::Vec3f(0, 0, 0);
          if (begin == next) continue;
          const ViewSlots& vs = slot_row[x];
          // Per slot: visibility shares front to back, and the slot's total alpha.
          float slot_alpha[3] = {0, 0, 0};
          for (size_t i = begin; i < next; ++i) {
            const int slot = fragments[i].key - first_key;
            share[i] = std::max(0.0f, std::min(fragments[i].alpha, 1.0f - slot_alpha[slot]));
            slot_alpha[slot] += share[i];
          }
          // Tiers (section 5): weighted views first; zero-weight views only where none saw anything.
          bool tier1 = false;
          for (int k = 0; k < 3; ++k) tier1 = tier1 || (slot_alpha[k] > 0 && vs.weight[k] > 0);
          float view_weight[3];
          for (int k = 0; k < 3; ++k) {
            view_weight[k] = tier1 ? vs.weight[k] : (slot_alpha[k] > 0 && k != vs.witness ? 1.0f : 0.0f);
          }
          // Reference depth: the nearest fragment covering most of its pixel, else the nearest.
          float z_ref = std::numeric_limits<float>::infinity(), z_any = z_ref;
          for (size_t i = begin; i < next; ++i) {
            const int slot = fragments[i].key - first_key;
            if (!(view_weight[slot] > 0) || share[i] <= 0) continue;
            z_any = std::min(z_any, fragments[i].z);
            if (share[i] >= kReferenceShare) z_ref = std::min(z_ref, fragments[i].z);
          }
          if (!(z_ref < std::numeric_limits<float>::infinity())) z_ref = z_any;
          if (!(z_ref < std::numeric_limits<float>::infinity())) continue;
          // A fragment seen through a nearer one of its own view (a boundary matte's other layer)
          // is part of what that view sees there: it weighs at least as much as that view's
          // front fragment, so each view keeps its own matting, as in the preview's buffers.
          float front_weight[3] = {-1, -1, -1};
          for (size_t i = begin; i < next; ++i) {
            const int slot = fragments[i].key - first_key;
            if (front_weight[slot] < 0 && share[i] > 0) front_weight[slot] = soft_z.Weight(fragments[i].z - z_ref);
          }
          float sum_omega = 0, sum_gw = 0, sum_gwz = 0;
          float bgr[3] = {0, 0, 0};
          for (size_t i = begin; i < next; ++i) {
            const int slot = fragments[i].key - first_key;
            if (!(view_weight[slot] > 0) || share[i] <= 0) continue;
            const float w = std::max(soft_z.Weight(fragments[i].z - z_ref), front_weight[slot]);
            const float gw = share[i] * w;
            const float omega = view_weight[slot] * gw;
            sum_omega += omega;
            sum_gw += gw;
            sum_gwz += gw * fragments[i].z;
            for (int c = 0; c < 3; ++c) bgr[c] += omega * fragments[i].bgr[c];
          }
          if (!(sum_omega > 0)) continue;
          float sum_v = 0, sum_va = 0;
          for (int k = 0; k < 3; ++k) {
            if (!(slot_alpha[k] > 0) || !(view_weight[k] > 0)) continue;
            sum_v += view_weight[k];
            sum_va += view_weight[k] * slot_alpha[k];
          }
          alpha_row[x] = sum_va / sum_v;
          depth_row[x] = sum_gwz / sum_gw;
          const float inv = 1.0f / sum_omega;
          colour_row[x] = cv::Vec3f(bgr[0] * inv, bgr[1] * inv, bgr[2] * inv);
        }
      }
    }
  });
  out->fragments = total;
}

}  // namespace px::render
